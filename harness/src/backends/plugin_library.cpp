// Loading a plugin library and checking its table (backends/plugin_library.h).
#include "backends/plugin_library.h"

#include <dlfcn.h>

#include <array>
#include <cstdint>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>

#include <fmt/format.h>

#include "io/error.h"

namespace raybench {
namespace {

// SHA-256 (FIPS 180-4), streaming.
class Sha256 {
 public:
  void update(const unsigned char* p, std::size_t n) {
    length_ += n;
    while (n > 0) {
      const std::size_t take = std::min(n, sizeof(block_) - used_);
      std::memcpy(block_ + used_, p, take);
      used_ += take;
      p += take;
      n -= take;
      if (used_ == sizeof(block_)) {
        compress(block_);
        used_ = 0;
      }
    }
  }
  std::string hex() {
    const std::uint64_t bits = length_ * 8;
    const unsigned char one = 0x80, zero = 0;
    update(&one, 1);
    while (used_ != 56) update(&zero, 1);
    unsigned char len[8];
    for (int i = 0; i < 8; ++i) len[i] = static_cast<unsigned char>(bits >> (56 - 8 * i));
    update(len, 8);
    std::string out;
    for (std::uint32_t word : h_) out += fmt::format("{:08x}", word);
    return out;
  }

 private:
  static std::uint32_t rotr(std::uint32_t x, int n) { return (x >> n) | (x << (32 - n)); }
  void compress(const unsigned char* b) {
    static constexpr std::uint32_t k[64] = {
        0x428a2f98, 0x71374491, 0xb5c0fbcf, 0xe9b5dba5, 0x3956c25b, 0x59f111f1, 0x923f82a4, 0xab1c5ed5,
        0xd807aa98, 0x12835b01, 0x243185be, 0x550c7dc3, 0x72be5d74, 0x80deb1fe, 0x9bdc06a7, 0xc19bf174,
        0xe49b69c1, 0xefbe4786, 0x0fc19dc6, 0x240ca1cc, 0x2de92c6f, 0x4a7484aa, 0x5cb0a9dc, 0x76f988da,
        0x983e5152, 0xa831c66d, 0xb00327c8, 0xbf597fc7, 0xc6e00bf3, 0xd5a79147, 0x06ca6351, 0x14292967,
        0x27b70a85, 0x2e1b2138, 0x4d2c6dfc, 0x53380d13, 0x650a7354, 0x766a0abb, 0x81c2c92e, 0x92722c85,
        0xa2bfe8a1, 0xa81a664b, 0xc24b8b70, 0xc76c51a3, 0xd192e819, 0xd6990624, 0xf40e3585, 0x106aa070,
        0x19a4c116, 0x1e376c08, 0x2748774c, 0x34b0bcb5, 0x391c0cb3, 0x4ed8aa4a, 0x5b9cca4f, 0x682e6ff3,
        0x748f82ee, 0x78a5636f, 0x84c87814, 0x8cc70208, 0x90befffa, 0xa4506ceb, 0xbef9a3f7, 0xc67178f2};
    std::uint32_t w[64];
    for (int i = 0; i < 16; ++i)
      w[i] = std::uint32_t{b[4 * i]} << 24 | std::uint32_t{b[4 * i + 1]} << 16 | std::uint32_t{b[4 * i + 2]} << 8 |
             std::uint32_t{b[4 * i + 3]};
    for (int i = 16; i < 64; ++i) {
      const std::uint32_t s0 = rotr(w[i - 15], 7) ^ rotr(w[i - 15], 18) ^ (w[i - 15] >> 3);
      const std::uint32_t s1 = rotr(w[i - 2], 17) ^ rotr(w[i - 2], 19) ^ (w[i - 2] >> 10);
      w[i] = w[i - 16] + s0 + w[i - 7] + s1;
    }
    std::uint32_t a = h_[0], bb = h_[1], c = h_[2], d = h_[3], e = h_[4], f = h_[5], g = h_[6], h = h_[7];
    for (int i = 0; i < 64; ++i) {
      const std::uint32_t t1 = h + (rotr(e, 6) ^ rotr(e, 11) ^ rotr(e, 25)) + ((e & f) ^ (~e & g)) + k[i] + w[i];
      const std::uint32_t t2 = (rotr(a, 2) ^ rotr(a, 13) ^ rotr(a, 22)) + ((a & bb) ^ (a & c) ^ (bb & c));
      h = g;
      g = f;
      f = e;
      e = d + t1;
      d = c;
      c = bb;
      bb = a;
      a = t1 + t2;
    }
    h_[0] += a, h_[1] += bb, h_[2] += c, h_[3] += d, h_[4] += e, h_[5] += f, h_[6] += g, h_[7] += h;
  }

  std::array<std::uint32_t, 8> h_{0x6a09e667, 0xbb67ae85, 0x3c6ef372, 0xa54ff53a,
                                  0x510e527f, 0x9b05688c, 0x1f83d9ab, 0x5be0cd19};
  unsigned char block_[64];
  std::size_t used_ = 0;
  std::uint64_t length_ = 0;
};

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// A string of the table: printable, one line.
bool printable_line(const char* s) {
  for (; *s; ++s)
    if (static_cast<unsigned char>(*s) < 0x20 || *s == 0x7f) return false;
  return true;
}

std::unique_ptr<PluginLibrary> load(const std::string& path, const std::string& backend_name) {
  const std::string where = fmt::format("backend '{}'", backend_name);
  const std::string hint_abi = "rebuild it against this raybench's raybench/plugin.h";
  void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (handle == nullptr) {
    const char* why = dlerror();
    throw InputError(path, fmt::format("{}: not a loadable shared library ({})", where, why ? why : "dlopen failed"));
  }
  // From here on the library stays loaded even when it is refused: its
  // static constructors have run, and unloading a library that started
  // threads or registered handlers is less safe than keeping it.
  dlerror();
  void* symbol = dlsym(handle, RAYBENCH_PLUGIN_ENTRY_POINT);
  if (symbol == nullptr)
    throw InputError(path, fmt::format("{}: the library has no entry point '{}' (export it with C linkage and "
                                       "RAYBENCH_PLUGIN_EXPORT, raybench/plugin.h)",
                                       where, RAYBENCH_PLUGIN_ENTRY_POINT));
  const auto entry = reinterpret_cast<raybench_plugin_entry>(symbol);
  const raybench_plugin_table* table = nullptr;
  try {
    table = entry();
  } catch (const std::exception& e) {
    throw InputError(path, fmt::format("{}: {}() threw: {}", where, RAYBENCH_PLUGIN_ENTRY_POINT, e.what()));
  } catch (...) {
    throw InputError(path, fmt::format("{}: {}() threw an exception", where, RAYBENCH_PLUGIN_ENTRY_POINT));
  }
  if (table == nullptr)
    throw InputError(path, fmt::format("{}: {}() returned no table (NULL)", where, RAYBENCH_PLUGIN_ENTRY_POINT));
  // The version first: the rest of the table is laid out as that version says.
  if (table->abi_version != RAYBENCH_PLUGIN_ABI_VERSION)
    throw InputError(path, fmt::format("{}: the plugin was built for plugin ABI version {}, this raybench speaks "
                                       "version {}; {}",
                                       where, table->abi_version, RAYBENCH_PLUGIN_ABI_VERSION, hint_abi));
  std::string missing;
  const auto need = [&](bool present, const char* field) {
    if (!present) missing += (missing.empty() ? "" : ", ") + std::string(field);
  };
  need(table->name != nullptr && *table->name != '\0', "name");
  need(table->accuracy_class != nullptr, "accuracy_class");
  need(table->build != nullptr, "build");
  need(table->memory_bytes != nullptr, "memory_bytes");
  need(table->intersect != nullptr, "intersect");
  need(table->occluded != nullptr, "occluded");
  need(table->destroy != nullptr, "destroy");
  if (!missing.empty())
    throw InputError(path, fmt::format("{}: the plugin's table lacks {} (NULL or empty; raybench/plugin.h)", where,
                                       missing));
  for (const char* s : {table->name, table->description, table->accuracy_class})
    if (s != nullptr && !printable_line(s))
      throw InputError(path, fmt::format("{}: the plugin's name, description and accuracy_class must be one printable "
                                         "line each",
                                         where));
  if (!is_plugin_accuracy_class(table->accuracy_class))
    throw InputError(path, fmt::format("{}: the plugin reports accuracy class '{}'; it must be one of fast, epsilon, "
                                       "watertight, exact (raybench/plugin.h)",
                                       where, table->accuracy_class));
  auto library = std::make_unique<PluginLibrary>();
  library->path = path;
  library->sha256 = sha256_of_file(path);
  library->table = table;
  library->name = table->name;
  library->description = table->description ? table->description : "";
  library->accuracy_class = table->accuracy_class;
  return library;
}

}  // namespace

bool is_plugin_accuracy_class(const std::string& accuracy_class) {
  return accuracy_class == "fast" || accuracy_class == "epsilon" || accuracy_class == "watertight" ||
         accuracy_class == "exact";
}

PluginName split_plugin_name(const std::string& backend_name) {
  static const std::string kPrefix = "plugin:";
  if (backend_name.rfind(kPrefix, 0) != 0)
    throw InputError("", fmt::format("backend '{}' is not a plugin name (plugin:PATH[:options])", backend_name));
  const std::string rest = backend_name.substr(kPrefix.size());
  PluginName out{rest, ""};
  for (std::size_t colon = rest.find(':'); colon != std::string::npos; colon = rest.find(':', colon + 1)) {
    const std::string before = rest.substr(0, colon);
    if (ends_with(before, ".so") || ends_with(before, ".dylib") || ends_with(before, ".dll")) {
      out = {before, rest.substr(colon + 1)};
      break;
    }
  }
  if (out.path.empty())
    throw InputError("", fmt::format("backend '{}' names no library: use plugin:PATH.so[:options]", backend_name));
  return out;
}

const PluginLibrary& load_plugin_library(const std::string& path, const std::string& backend_name) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path given(path);
  if (!fs::exists(given, ec))
    throw InputError(path, fmt::format("backend '{}': plugin library not found{}", backend_name,
                                       path.find(':') == std::string::npos
                                           ? ""
                                           : " (a plugin's options follow the first ':' after its .so, .dylib or "
                                             ".dll name)"));
  if (fs::is_directory(given, ec))
    throw InputError(path, fmt::format("backend '{}': a folder, not a plugin library", backend_name));
  const fs::path canonical = fs::canonical(given, ec);
  if (ec) throw InputError(path, fmt::format("backend '{}': {}", backend_name, ec.message()));
  static std::mutex mutex;
  static std::map<std::string, std::unique_ptr<PluginLibrary>> loaded;
  const std::lock_guard<std::mutex> lock(mutex);
  auto& slot = loaded[canonical.string()];
  if (!slot) {
    try {
      slot = load(canonical.string(), backend_name);
    } catch (...) {
      loaded.erase(canonical.string());
      throw;
    }
  }
  return *slot;
}

std::string sha256_hex(const void* data, std::size_t size) {
  Sha256 h;
  h.update(static_cast<const unsigned char*>(data), size);
  return h.hex();
}

std::string sha256_of_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "cannot be read");
  Sha256 h;
  std::array<char, 1 << 16> buffer;
  while (in) {
    in.read(buffer.data(), buffer.size());
    h.update(reinterpret_cast<const unsigned char*>(buffer.data()), static_cast<std::size_t>(in.gcount()));
  }
  if (in.bad()) throw InputError(path, "cannot be read");
  return h.hex();
}

}  // namespace raybench
