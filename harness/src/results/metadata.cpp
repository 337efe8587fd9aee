#include "results/metadata.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <thread>

#include <assimp/version.h>
#include <fmt/chrono.h>
#include <fmt/format.h>
#include <oneapi/tbb/version.h>
#include <sys/utsname.h>
#include <unistd.h>

#include "io/atomic_file.h"
#include "io/command_output.h"
#include "io/default_paths.h"
#include "backends/embree_backend.h"
#include "build_info.h"
#include "source_state.h"

namespace raybench {
namespace {

// The first processor's entry of /proc/cpuinfo ("model name", "cpu family",
// "flags", ...), read once for both CPU fields; empty where there is none.
std::map<std::string, std::string> first_cpu_entry() {
  std::ifstream in("/proc/cpuinfo");
  std::map<std::string, std::string> fields;
  std::string line;
  while (std::getline(in, line) && !line.empty()) {  // a blank line ends the entry
    const auto colon = line.find(':');
    if (colon == std::string::npos) continue;
    const auto key_end = line.find_last_not_of(" \t", colon - 1);
    const auto value_start = line.find_first_not_of(" \t", colon + 1);
    fields[line.substr(0, key_end == std::string::npos ? 0 : key_end + 1)] =
        value_start == std::string::npos ? std::string() : line.substr(value_start);
  }
  return fields;
}

std::string field_or(const std::map<std::string, std::string>& fields, const std::string& key, const std::string& fallback) {
  const auto it = fields.find(key);
  return it == fields.end() || it->second.empty() ? fallback : it->second;
}

// A virtual machine's model name can be generic ("AMD EPYC" for Zen 4 and
// Zen 5 alike, which traced our BVHs 19 % apart relative to Embree): the
// family, model and stepping and the widest vector instructions say which.
std::string cpu_id(const std::map<std::string, std::string>& cpu) {
  std::string flags = field_or(cpu, "flags", "");  // padded, so that each flag is found as " name "
  flags.insert(flags.begin(), ' ');
  flags.push_back(' ');
  const char* isa = flags.find(" avx512f ") != std::string::npos ? "avx512f" : flags.find(" avx2 ") != std::string::npos ? "avx2" : "sse";
  return fmt::format("family {} model {} stepping {}, {}", field_or(cpu, "cpu family", "?"), field_or(cpu, "model", "?"),
                     field_or(cpu, "stepping", "?"), isa);
}

std::string toml_string(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (c == '\n') { out += "\\n"; continue; }
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) { out += fmt::format("\\u{:04x}", static_cast<int>(c)); continue; }
    out += c;
  }
  return out + "\"";
}

}  // namespace

std::string toml_key(const std::string& name) {
  const bool bare = !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
  });
  return bare ? name : toml_string(name);
}

std::string source_state(const std::string& dir) {
  const std::string git = "git -C '" + dir + "' ";
  std::string commit = command_output(git + "rev-parse HEAD 2>/dev/null");
  if (commit.empty()) return "unknown";
  if (!command_output(git + "status --porcelain --untracked-files=no -- . ':(exclude,top)results' 2>/dev/null").empty())
    commit += "-dirty";
  return commit;
}

const std::string& record_source_state() {
  static const std::string state =
      default_paths().build_tree ? source_state(RAYBENCH_SOURCE_DIR) : std::string(RAYBENCH_BUILT_SOURCE_STATE);
  return state;
}

Metadata collect_metadata(const Metadata& extra) {
  utsname u{};
  ::uname(&u);
  char host[256] = {};
  ::gethostname(host, sizeof host - 1);
  const auto cpu = first_cpu_entry();
  Metadata m = {
      {"date", fmt::format("{:%Y-%m-%dT%H:%M:%SZ}", fmt::gmtime(std::chrono::system_clock::to_time_t(std::chrono::system_clock::now())))},
      {"host", host},
      {"cpu", field_or(cpu, "model name", "unknown")},
      {"cpu_id", cpu_id(cpu)},
      {"hardware_threads", std::to_string(std::thread::hardware_concurrency())},
      {"os", fmt::format("{} {} {}", u.sysname, u.release, u.machine)},
      {"compiler", RAYBENCH_COMPILER},
      {"build_type", RAYBENCH_BUILD_TYPE},
      {"flags", RAYBENCH_CXX_FLAGS},
      {"embree", embree_version()},
      {"assimp", fmt::format("{}.{}.{}", aiGetVersionMajor(), aiGetVersionMinor(), aiGetVersionPatch())},
      {"tbb", TBB_VERSION_STRING},
      {"git_commit", record_source_state()},
      {"raybench_version", RAYBENCH_VERSION},
  };
  m.insert(m.end(), extra.begin(), extra.end());
  return m;
}

std::string metadata_path_for(const std::string& csv_path) {
  std::filesystem::path p(csv_path);
  if (p.extension() == ".csv") p.replace_extension();
  return p.string() + ".meta.toml";
}

void write_metadata(const std::string& path, const Metadata& metadata) {
  write_file_atomically(path, [&](std::ostream& out) {
    out << "# What the results beside this file depend on (written by raybench).\n";
    for (const auto& [key, value] : metadata) out << key << " = " << toml_string(value) << '\n';
  });
}

}  // namespace raybench
