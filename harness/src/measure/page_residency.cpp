// How much anonymous memory sits in huge pages, and the kernel's THP mode:
// Linux's /proc and /sys texts parsed (see page_residency.h).
#include "measure/page_residency.h"

#include <charconv>
#include <fstream>
#include <sstream>

namespace raybench {

namespace {

std::string read_text(const char* path) {
  std::ifstream in(path);
  if (!in) return {};
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string_view trim_spaces(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

}  // namespace

std::optional<std::size_t> parse_anon_huge_page_bytes(std::string_view smaps_text) {
  constexpr std::string_view kField = "AnonHugePages:";
  std::optional<std::size_t> total;
  while (!smaps_text.empty()) {
    const std::size_t end = smaps_text.find('\n');
    std::string_view line = smaps_text.substr(0, end);
    smaps_text.remove_prefix(end == std::string_view::npos ? smaps_text.size() : end + 1);
    if (!line.starts_with(kField)) continue;
    line = trim_spaces(line.substr(kField.size()));
    if (!line.ends_with("kB")) return std::nullopt;
    line = trim_spaces(line.substr(0, line.size() - 2));
    std::size_t kib = 0;
    const auto [rest, error] = std::from_chars(line.data(), line.data() + line.size(), kib);
    if (error != std::errc() || rest != line.data() + line.size()) return std::nullopt;
    total = total.value_or(0) + kib * 1024;
  }
  return total;
}

std::optional<std::size_t> anon_huge_page_bytes() {
#if defined(__linux__)
  return parse_anon_huge_page_bytes(read_text("/proc/self/smaps_rollup"));
#else
  return std::nullopt;
#endif
}

std::string parse_thp_mode(std::string_view enabled_text) {
  const std::size_t open = enabled_text.find('[');
  if (open == std::string_view::npos) return {};
  const std::size_t close = enabled_text.find(']', open);
  if (close == std::string_view::npos || close == open + 1) return {};
  return std::string(enabled_text.substr(open + 1, close - open - 1));
}

std::string transparent_huge_pages_mode() {
#if defined(__linux__)
  const std::string mode = parse_thp_mode(read_text("/sys/kernel/mm/transparent_hugepage/enabled"));
  return mode.empty() ? "unavailable" : mode;
#else
  return "unavailable";
#endif
}

}  // namespace raybench
