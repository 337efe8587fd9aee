// Reading Embree's verbose output (backends/embree_selection.h).
#include "backends/embree_selection.h"

#include <cctype>

#include <fmt/format.h>

namespace raybench {
namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return s;
}

// The value of a "  key  = value" or "  key  : value" line whose key is
// `key`; empty when the line is another one.
std::string_view value_of(std::string_view line, std::string_view key, char separator) {
  const std::size_t at = line.find(separator);
  if (at == std::string_view::npos || trim(line.substr(0, at)) != key) return {};
  return trim(line.substr(at + 1));
}

}  // namespace

EmbreeSelection parse_embree_verbose(std::string_view text) {
  EmbreeSelection s;
  bool in_selected = false;  // after "selected scene intersector"
  bool built = false;        // the first "building" line read
  while (!text.empty()) {
    const std::size_t end = text.find('\n');
    const std::string_view line = text.substr(0, end);
    text.remove_prefix(end == std::string_view::npos ? text.size() : end + 1);
    if (std::string_view v = value_of(line, "CPU", ':'); !v.empty()) s.cpu = v;
    else if (std::string_view b = value_of(line, "Build", ':'); !b.empty()) s.banner_build = b;
    else if (std::string_view f = value_of(line, "frequency_level", '='); !f.empty()) s.frequency_level = f;
    else if (std::string_view h = value_of(line, "hugepages", '='); !h.empty()) s.hugepages = h;
    else if (!built && line.rfind("building ", 0) == 0) {
      // "building BVH8<triangle4> using avx::BVH8BuilderSAH ..."
      const std::size_t open = line.find('<'), close = line.find('>'), using_at = line.find(" using ");
      if (open == std::string_view::npos || close == std::string_view::npos || close < open) continue;
      built = true;
      s.accel = std::string(trim(line.substr(9, open - 9)));
      std::string leaf(line.substr(open + 1, close - open - 1));
      if (!leaf.empty()) leaf[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(leaf[0])));
      s.leaf = leaf.empty() ? kEmbreeUnknown : leaf;
      if (using_at != std::string_view::npos) {
        std::string_view builder = line.substr(using_at + 7);
        builder = trim(builder.substr(0, builder.find(' ')));
        if (!builder.empty()) s.builder = builder;
      }
    } else if (trim(line) == "selected scene intersector") {
      in_selected = true;
    } else if (std::string_view i = value_of(line, "intersector1", '='); in_selected && !i.empty()) {
      // "avx512::BVH8Triangle4Intersector1Moeller"
      const std::size_t colons = i.find("::");
      if (colons != std::string_view::npos) {
        s.isa = i.substr(0, colons);
        s.intersector1 = i.substr(colons + 2);
      } else {
        s.intersector1 = i;
      }
      in_selected = false;
    }
  }
  return s;
}

std::string assertions_from_library_bytes(std::string_view library_bytes) {
  if (library_bytes.empty()) return kEmbreeUnknown;
  return library_bytes.find(std::string_view("__assert_fail\0", 14)) != std::string_view::npos ? "enabled"
                                                                                                : "disabled";
}

std::vector<std::pair<std::string, std::string>> embree_provenance(const EmbreeSelection& selection,
                                                                   const std::string& device_config, bool huge_pages,
                                                                   const std::string& library,
                                                                   const std::string& assertions) {
  std::vector<std::pair<std::string, std::string>> p = {
      {"isa", selection.isa},
      {"accel", selection.accel},
      {"leaf", selection.leaf},
      {"builder", selection.builder},
      {"intersector1", selection.intersector1},
      {"frequency_level", selection.frequency_level},
      {"huge_pages", huge_pages ? "on" : "off"},
      {"embree_hugepages", selection.hugepages},
      {"cpu", selection.cpu},
      {"device_config", device_config},
      {"library", library},
      {"assertions", assertions == "enabled"    ? "enabled (the library calls __assert_fail: compiled without NDEBUG)"
                     : assertions == "disabled" ? "disabled (the library does not call __assert_fail)"
                                                : assertions},
      {"banner_build", selection.banner_build},
  };
  if (!selection.complete())
    p.emplace_back("probe", "Embree's verbose output could not be read: the fields marked unknown were not found");
  return p;
}

std::string embree_summary(const EmbreeSelection& s, bool huge_pages) {
  std::string line = fmt::format("ISA {}, {} {}, intersector {}, frequency_level {}, huge pages {}", s.isa, s.accel,
                                 s.leaf, s.intersector1, s.frequency_level, huge_pages ? "on" : "off");
  if (!s.complete()) line += " (Embree's verbose output could not be read: unknown fields)";
  return line;
}

}  // namespace raybench
