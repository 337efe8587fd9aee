// A C++ test plugin that throws through the C interface, which a plugin
// must not do (raybench/plugin.h) and raybench survives: option
// "build", "intersect" or "occluded" names the call that throws
// std::runtime_error, "after=N" (brute_force.h) spares scenes of at most N
// triangles, "late" spares the first 4 calls of intersect (so that it
// throws only in the timed loop, after the untimed trace). The C++ plugin's exceptions cross the boundary as C++
// exceptions do on this platform; raybench catches them there.
#include <atomic>
#include <stdexcept>
#include <string>

#include "brute_force.h"

namespace {

struct Accel {
  void* inner;
  bool throw_intersect, throw_occluded;
  int spared_calls;
  mutable std::atomic<int> calls{0};
};

bool misbehaves(const raybench_build_input* input) { return input->triangle_count > brute_after(input->options); }

void* build(const raybench_build_input* input, char* error, size_t error_size) {
  const std::string options = input->options;
  if (misbehaves(input) && options.find("build") != std::string::npos)
    throw std::runtime_error("throwing_plugin: build throws, as asked");
  void* inner = brute_build(input, error, error_size);
  if (inner == nullptr) return nullptr;
  return new Accel{inner, misbehaves(input) && options.find("intersect") != std::string::npos,
                   misbehaves(input) && options.find("occluded") != std::string::npos,
                   options.find("late") != std::string::npos ? 4 : 0};
}

size_t memory_bytes(const void* accel) { return brute_memory_bytes(static_cast<const Accel*>(accel)->inner); }

int intersect(const void* accel, const raybench_ray* rays, size_t count, raybench_hit* hits) {
  const Accel* a = static_cast<const Accel*>(accel);
  if (a->throw_intersect && a->calls++ >= a->spared_calls) throw std::runtime_error("throwing_plugin: intersect throws, as asked");
  return brute_intersect(a->inner, rays, count, hits);
}

int occluded(const void* accel, const raybench_ray* rays, size_t count, uint8_t* occluded) {
  const Accel* a = static_cast<const Accel*>(accel);
  if (a->throw_occluded) throw 42;  // not even a std::exception
  return brute_occluded(a->inner, rays, count, occluded);
}

void destroy(void* accel) {
  Accel* a = static_cast<Accel*>(accel);
  brute_destroy(a->inner);
  delete a;
}

const raybench_plugin_table kTable = {
    RAYBENCH_PLUGIN_ABI_VERSION, "throwing_plugin", "a C++ test plugin that throws", "fast", nullptr, build,
    memory_bytes, intersect, occluded, destroy,
};

}  // namespace

extern "C" RAYBENCH_PLUGIN_EXPORT const raybench_plugin_table* raybench_plugin(void) { return &kTable; }
