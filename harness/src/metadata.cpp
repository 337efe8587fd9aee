#include "metadata.h"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <thread>

#include <assimp/version.h>
#include <fmt/chrono.h>
#include <fmt/format.h>
#include <oneapi/tbb/version.h>
#include <sys/utsname.h>
#include <unistd.h>

#include "atomic_file.h"
#include "backends/backend_families.h"
#include "build_info.h"

namespace raybench {
namespace {

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) == 0) {
      const auto colon = line.find(':');
      if (colon != std::string::npos) return line.substr(line.find_first_not_of(' ', colon + 1));
    }
  }
  return "unknown";
}

// A virtual machine's model name can be generic ("AMD EPYC" for Zen 4 and
// Zen 5 alike, which traced our BVHs 19 % apart relative to Embree): the
// family, model and stepping and the widest vector instructions say which.
std::string cpu_id() {
  std::ifstream in("/proc/cpuinfo");
  std::string line, family = "?", model = "?", stepping = "?", isa = "sse";
  const auto value = [&line] {
    const auto colon = line.find(':');
    const auto start = colon == std::string::npos ? colon : line.find_first_not_of(" \t", colon + 1);
    return start == std::string::npos ? std::string() : line.substr(start);
  };
  while (std::getline(in, line)) {
    if (line.rfind("cpu family", 0) == 0) family = value();
    else if (line.rfind("model\t", 0) == 0) model = value();
    else if (line.rfind("stepping", 0) == 0) stepping = value();
    else if (line.rfind("flags", 0) == 0) {
      std::string flags = value();  // padded with spaces, so that each flag is found as " name "
      flags.insert(flags.begin(), ' ');
      flags.push_back(' ');
      isa = flags.find(" avx512f ") != std::string::npos ? "avx512f" : flags.find(" avx2 ") != std::string::npos ? "avx2" : "sse";
      break;  // the first processor's entry is the machine's
    }
  }
  return fmt::format("family {} model {} stepping {}, {}", family, model, stepping, isa);
}

std::string run_command(const std::string& command) {
  std::string out;
  if (FILE* p = ::popen(command.c_str(), "r")) {
    char buffer[256];
    while (std::fgets(buffer, sizeof buffer, p)) out += buffer;
    ::pclose(p);
  }
  while (!out.empty() && (out.back() == '\n' || out.back() == ' ')) out.pop_back();
  return out;
}

std::string toml_string(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (c == '\n') { out += "\\n"; continue; }
    out += c;
  }
  return out + "\"";
}

}  // namespace

std::string source_state(const std::string& dir) {
  const std::string git = "git -C '" + dir + "' ";
  std::string commit = run_command(git + "rev-parse HEAD 2>/dev/null");
  if (commit.empty()) return "unknown";
  if (!run_command(git + "status --porcelain --untracked-files=no -- . ':(exclude,top)results' 2>/dev/null").empty())
    commit += "-dirty";
  return commit;
}

const std::string& record_source_state() {
  static const std::string state = source_state(RAYBENCH_SOURCE_DIR);
  return state;
}

Metadata collect_metadata(const Metadata& extra) {
  utsname u{};
  ::uname(&u);
  char host[256] = {};
  ::gethostname(host, sizeof host - 1);
  Metadata m = {
      {"date", fmt::format("{:%Y-%m-%dT%H:%M:%SZ}", fmt::gmtime(std::chrono::system_clock::to_time_t(std::chrono::system_clock::now())))},
      {"host", host},
      {"cpu", cpu_model()},
      {"cpu_id", cpu_id()},
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
