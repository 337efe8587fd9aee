// main() of the test binaries built for one instruction set whatever the
// host (kernels/tests/CMakeLists.txt: the wide traversal's AVX2 and AVX-512
// paths): where the CPU lacks that set, every test is skipped with a visible
// note instead of the binary dying of SIGILL. This file is compiled without
// those flags, and it asks the CPU before any test runs; the test files it
// links must run no code of theirs in static initialisers but gtest's
// registration (checked with objdump: docs/notes/kernels-wide-traversal.md).
#include <cstdio>

#include <gtest/gtest.h>

namespace {

#if defined(RAYBENCH_TEST_NEEDS_AVX512)
constexpr const char* kIsa = "AVX-512 (F, VL)";
bool cpu_has_isa() { return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl"); }
#elif defined(RAYBENCH_TEST_NEEDS_AVX2)
constexpr const char* kIsa = "AVX2 with FMA";
bool cpu_has_isa() { return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"); }
#else
#error "isa_test_main.cpp: define RAYBENCH_TEST_NEEDS_AVX512 or RAYBENCH_TEST_NEEDS_AVX2"
#endif

class SkipEveryTest : public ::testing::Environment {
 public:
  void SetUp() override { GTEST_SKIP() << "this CPU lacks " << kIsa << ": these tests of that path are skipped"; }
};

}  // namespace

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  if (!cpu_has_isa()) {
    std::fprintf(stderr, "NOTE: this CPU lacks %s; every test of this binary is skipped.\n", kIsa);
    ::testing::AddGlobalTestEnvironment(new SkipEveryTest);
  }
  return RUN_ALL_TESTS();
}
