// The plugin backend family: "plugin:PATH[:options]" is a kernel in a shared
// library written against raybench/plugin.h (ABI version 1), loaded once per
// process (backends/plugin_library.h, which also states the PATH/options
// rule). Everything crosses the boundary without a copy: the scene's
// triangles as 9 floats each, rays and hits as the plugin's structs (the
// static_asserts below), one C call per batch of rays.
// Guarantee: nothing a plugin reports or throws escapes as anything but an
// exception of one line naming the backend (InputError for what the plugin
// refuses or fails at, std::runtime_error for a failed trace), so the run
// keeps every finished row. The options are checked when the backend is
// made, before any scene is loaded. A plugin that crashes the process is
// beyond this: the rows of finished scenes are on disk already.
#include <cstddef>
#include <exception>
#include <stdexcept>
#include <type_traits>

#include <fmt/format.h>

#include "backends/backend.h"
#include "backends/plugin_library.h"
#include "io/error.h"

namespace raybench {

// The zero-copy contract: raybench's own types are the plugin's structs.
static_assert(sizeof(Ray) == sizeof(raybench_ray) && alignof(Ray) == alignof(raybench_ray));
static_assert(std::is_standard_layout_v<Ray> && std::is_standard_layout_v<raybench_ray>);
static_assert(offsetof(Ray, org) == offsetof(raybench_ray, org_x) && offsetof(Ray, tnear) == offsetof(raybench_ray, tnear) &&
              offsetof(Ray, dir) == offsetof(raybench_ray, dir_x) && offsetof(Ray, tfar) == offsetof(raybench_ray, tfar));
static_assert(sizeof(Vec3f) == 3 * sizeof(float) && offsetof(Vec3f, y) == sizeof(float) &&
              offsetof(Vec3f, z) == 2 * sizeof(float));
static_assert(sizeof(Hit) == sizeof(raybench_hit) && alignof(Hit) == alignof(raybench_hit));
static_assert(offsetof(Hit, t) == offsetof(raybench_hit, t) && offsetof(Hit, prim) == offsetof(raybench_hit, prim) &&
              offsetof(Hit, u) == offsetof(raybench_hit, u) && offsetof(Hit, v) == offsetof(raybench_hit, v));
static_assert(std::is_same_v<decltype(Hit::prim), decltype(raybench_hit::prim)> && kNoHit == RAYBENCH_NO_HIT);
static_assert(sizeof(Triangle) == 9 * sizeof(float) && alignof(Triangle) == alignof(float) &&
              offsetof(Triangle, v1) == 3 * sizeof(float) && offsetof(Triangle, v2) == 6 * sizeof(float));

namespace {

// What an exception in flight says, for one line.
std::string exception_text() {
  try {
    throw;
  } catch (const std::exception& e) {
    return fmt::format("threw an exception: {}", e.what());
  } catch (...) {
    return "threw an exception";
  }
}

// A plugin's message buffer as one line (it promised one, NUL terminated;
// the last byte is forced to NUL in case it did not).
std::string message_of(char (&error)[RAYBENCH_PLUGIN_ERROR_SIZE]) {
  error[RAYBENCH_PLUGIN_ERROR_SIZE - 1] = '\0';
  std::string m(error);
  for (char& c : m)
    if (static_cast<unsigned char>(c) < 0x20) c = ' ';
  return m.empty() ? "no message" : m;
}

class PluginBackend final : public Backend {
 public:
  PluginBackend(std::string name, const PluginLibrary& library, std::string options, int threads)
      : name_(std::move(name)), library_(library), table_(*library.table), options_(std::move(options)),
        threads_(threads < 1 ? 1 : threads) {}

  ~PluginBackend() override { release(); }

  const std::string& name() const override { return name_; }
  std::string accuracy_class() const override { return library_.accuracy_class; }
  std::string plugin_name() const override { return library_.name; }
  std::vector<std::pair<std::string, std::string>> provenance() const override {
    return {{"path", library_.path},
            {"sha256", library_.sha256},
            {"name", library_.name},
            {"description", library_.description},
            {"abi_version", std::to_string(table_.abi_version)},
            {"options", options_}};
  }

  void build(const Scene& scene) override {
    release();  // the old accel freed first, as the built-in backends do
    scene_ = scene.name;
    if (scene.triangles.empty())
      throw InputError("", fmt::format("{}: scene '{}' has no triangles to build from", who(), scene_));
    const raybench_build_input input{reinterpret_cast<const float*>(scene.triangles.data()), scene.triangles.size(),
                                     options_.c_str(), threads_};
    char error[RAYBENCH_PLUGIN_ERROR_SIZE] = {};
    void* accel = nullptr;
    try {
      accel = table_.build(&input, error, sizeof(error));
    } catch (...) {
      throw std::runtime_error(fmt::format("{}: build {} on scene '{}'", who(), exception_text(), scene_));
    }
    if (accel == nullptr)
      throw InputError("", fmt::format("{}: build failed on scene '{}': {}", who(), scene_, message_of(error)));
    accel_ = accel;
  }

  std::size_t memory_bytes() const override {
    if (accel_ == nullptr) return 0;
    try {
      return table_.memory_bytes(accel_);
    } catch (...) {
      throw std::runtime_error(fmt::format("{}: memory_bytes {} on scene '{}'", who(), exception_text(), scene_));
    }
  }

  void intersect(std::span<const Ray> rays, std::span<Hit> hits) const override {
    if (rays.empty()) return;
    int status = 0;
    try {
      status = table_.intersect(accel_, reinterpret_cast<const raybench_ray*>(rays.data()), rays.size(),
                                reinterpret_cast<raybench_hit*>(hits.data()));
    } catch (...) {
      throw std::runtime_error(fmt::format("{}: intersect {} on scene '{}'", who(), exception_text(), scene_));
    }
    if (status != 0) fail("intersect", status);
  }

  void occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded) const override {
    if (rays.empty()) return;
    int status = 0;
    try {
      status = table_.occluded(accel_, reinterpret_cast<const raybench_ray*>(rays.data()), rays.size(), occluded.data());
    } catch (...) {
      throw std::runtime_error(fmt::format("{}: occluded {} on scene '{}'", who(), exception_text(), scene_));
    }
    if (status != 0) fail("occluded", status);
  }

 private:
  std::string who() const { return fmt::format("backend '{}' ({})", name_, library_.name); }

  [[noreturn]] void fail(const char* call, int status) const {
    throw std::runtime_error(fmt::format("{}: {} returned error {} on scene '{}'", who(), call, status, scene_));
  }

  void release() noexcept {
    if (accel_ == nullptr) return;
    try {
      table_.destroy(accel_);
    } catch (...) {
      // A destructor cannot report; the accel is lost either way.
    }
    accel_ = nullptr;
  }

  std::string name_;
  const PluginLibrary& library_;
  const raybench_plugin_table& table_;
  std::string options_;
  int threads_;
  std::string scene_;
  void* accel_ = nullptr;
};

std::unique_ptr<Backend> make_plugin_backend(const std::string& name, const std::vector<std::string>&,
                                             const BackendConfig& config) {
  const PluginName parts = split_plugin_name(name);
  const PluginLibrary& library = load_plugin_library(parts.path, name);
  if (library.table->check_options != nullptr) {
    char error[RAYBENCH_PLUGIN_ERROR_SIZE] = {};
    int status = 0;
    try {
      status = library.table->check_options(parts.options.c_str(), error, sizeof(error));
    } catch (...) {
      throw InputError(parts.path, fmt::format("backend '{}' ({}): check_options {}", name, library.name,
                                               exception_text()));
    }
    if (status != 0)
      throw InputError(parts.path, fmt::format("backend '{}' ({}): options '{}' refused: {}", name, library.name,
                                               parts.options, message_of(error)));
  }
  return std::make_unique<PluginBackend>(name, library, parts.options, config.threads);
}

std::vector<BackendInfo> plugin_backend_names() {
  return {{"plugin:PATH.so[:options]",
           "a kernel in a shared library built against raybench/plugin.h (docs/plugins.md); the options follow the "
           "first ':' after .so/.dylib/.dll and go to the plugin; its accuracy class is the one it reports",
           "fast", false, true}};
}

}  // namespace

RAYBENCH_BACKEND_FAMILY("plugin", 950, make_plugin_backend, plugin_backend_names);

}  // namespace raybench
