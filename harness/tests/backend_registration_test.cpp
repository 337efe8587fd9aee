// Specification of the documented way to add a backend: one .cpp in
// harness/src/backends/ that registers its family with
// RAYBENCH_BACKEND_FAMILY (backends/backend.h). This executable is the harness plus one such file,
// testonly_backend.cpp, which nothing else declares or names; the registry
// must find it by name.
#include <algorithm>
#include <stdexcept>

#include <gtest/gtest.h>

#include "backends/backend.h"
#include "scene/scene.h"

namespace raybench {
namespace {

TEST(BackendRegistration, ANewBackendFileIsMadeByName) {
  const std::unique_ptr<Backend> backend = make_backend("testonly");
  ASSERT_NE(backend, nullptr);
  EXPECT_EQ(backend->name(), "testonly");
  Scene scene;
  scene.name = "one";
  scene.triangles = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}};
  backend->build(scene);
  const std::vector<Ray> rays{{{0.25f, 0.25f, 1}, 0.0f, {0, 0, -1}, 10.0f}, {{2, 2, 1}, 0.0f, {0, 0, -1}, 10.0f}};
  std::vector<Hit> hits(rays.size());
  backend->intersect(rays, hits);
  EXPECT_EQ(hits[0].prim, 0);
  EXPECT_FLOAT_EQ(hits[0].t, 1.0f);
  EXPECT_FALSE(hits[1].hit());
}

TEST(BackendRegistration, ANewBackendFileIsListedAfterTheFamiliesBeforeIt) {
  std::vector<std::string> names;
  for (const BackendInfo& b : list_backends()) names.push_back(b.name);
  ASSERT_FALSE(names.empty());
  EXPECT_EQ(names.front(), "embree");   // order 100
  EXPECT_EQ(names.back(), "testonly");  // order 1000: after reference (900)
  EXPECT_EQ(std::count(names.begin(), names.end(), "testonly"), 1);
}

TEST(BackendRegistration, ANewBackendFileHasItsAccuracyClass) {
  EXPECT_EQ(backend_accuracy_class("testonly"), "fast");
}

TEST(BackendRegistration, AFamilyNameRegisteredTwiceIsRefused) {
  EXPECT_THROW(register_backend_family("testonly", 1, nullptr, nullptr), std::logic_error);
  EXPECT_THROW(register_backend_family("bvh2", 1, nullptr, nullptr), std::logic_error);
  EXPECT_EQ(list_backends().back().name, "testonly");  // the refused registrations left no trace
}

}  // namespace
}  // namespace raybench
