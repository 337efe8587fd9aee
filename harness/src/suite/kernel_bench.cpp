#include "suite/kernel_bench.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <iostream>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>

#include <Eigen/Geometry>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "io/atomic_file.h"
#include "io/error.h"
#include "measure/gbench.h"
#include "io/interrupt.h"
#include "results/metadata.h"
#include "scene/random.h"
#include "raybench/simd/wide_box.h"
#include "raybench/simd/wide_triangle.h"
#include "raybench/variants.h"

namespace raybench {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// --- Random geometry -----------------------------------------------------------

Vec3f uniform_in_cube(Rng& rng, float half) {
  return {static_cast<float>((2 * rng.next_double() - 1) * half), static_cast<float>((2 * rng.next_double() - 1) * half),
          static_cast<float>((2 * rng.next_double() - 1) * half)};
}

Vec3f uniform_on_sphere(Rng& rng, float radius) {
  const double z = 2 * rng.next_double() - 1, phi = 2 * std::numbers::pi * rng.next_double();
  const double s = std::sqrt(std::max(0.0, 1 - z * z));
  return Vec3f{static_cast<float>(s * std::cos(phi)), static_cast<float>(z), static_cast<float>(s * std::sin(phi))} * radius;
}

// Each family: a random primitive near the origin, a random point inside it
// (to aim hits), a translation, and the referee that classifies a pair.
struct TriangleFamily {
  static constexpr const char* name = "triangle";
  using Prim = Triangle;
  using Variants = TriangleTests;
  static Prim random(Rng& rng) { return {uniform_in_cube(rng, 1), uniform_in_cube(rng, 1), uniform_in_cube(rng, 1)}; }
  static Vec3f inside(Rng& rng, const Prim& t) {
    const double a = rng.next_double(), b = rng.next_double() * (1 - a);
    return t.v0 + (t.v1 - t.v0) * static_cast<float>(a) + (t.v2 - t.v0) * static_cast<float>(b);
  }
  static Prim translate(Prim t, Vec3f d) { return {t.v0 + d, t.v1 + d, t.v2 + d}; }
  static bool referee(const Ray& r, const Prim& t) {
    TriangleHit h;
    return MollerTrumboreDouble::intersect(r, kInf, t, h);
  }
  template <typename V>
  static auto kernel(std::vector<Prim> prims) {
    std::vector<typename V::Prepared> prepared;
    for (const Prim& p : prims) prepared.push_back(V::prepare(p));
    return [prepared = std::move(prepared)](const Ray& r, std::size_t i) {
      TriangleHit h;
      return V::intersect(V::precompute(r), kInf, prepared[i], h);
    };
  }
};

struct BoxFamily {
  static constexpr const char* name = "box";
  using Prim = BBox;
  using Variants = BoxTests;
  static Prim random(Rng& rng) {
    BBox b;
    const Vec3f c = uniform_in_cube(rng, 1);
    b.extend(c + uniform_in_cube(rng, 0.5f));
    b.extend(c + uniform_in_cube(rng, 0.5f));
    return b;
  }
  static Vec3f inside(Rng& rng, const Prim& b) {
    const Vec3f e = b.extent();
    return b.lower + Vec3f{e.x * static_cast<float>(rng.next_double()), e.y * static_cast<float>(rng.next_double()),
                           e.z * static_cast<float>(rng.next_double())};
  }
  static Prim translate(Prim b, Vec3f d) { return {b.lower + d, b.upper + d}; }
  static bool referee(const Ray& r, const Prim& b) {
    BoxHit h;
    return SlabRobust::intersect(SlabRobust::precompute(r), b, kInf, h);
  }
  template <typename V>
  static auto kernel(std::vector<Prim> prims) {
    return [prims = std::move(prims)](const Ray& r, std::size_t i) {
      BoxHit h;
      return V::intersect(V::precompute(r), prims[i], kInf, h);
    };
  }
};

struct SphereFamily {
  static constexpr const char* name = "sphere";
  using Prim = Sphere;
  using Variants = SphereTests;
  static Prim random(Rng& rng) { return {uniform_in_cube(rng, 1), static_cast<float>(0.1 + 0.9 * rng.next_double())}; }
  static Vec3f inside(Rng& rng, const Prim& s) { return s.center + uniform_on_sphere(rng, s.radius * static_cast<float>(rng.next_double())); }
  static Prim translate(Prim s, Vec3f d) { return {s.center + d, s.radius}; }
  static bool referee(const Ray& r, const Prim& s) {
    SphereHit h;
    return SpherePrecise::intersect(r, kInf, s, h);
  }
  template <typename V>
  static auto kernel(std::vector<Prim> prims) {
    return [prims = std::move(prims)](const Ray& r, std::size_t i) {
      SphereHit h;
      return V::intersect(r, kInf, prims[i], h);
    };
  }
};

struct ObbFamily {
  static constexpr const char* name = "obb";
  using Prim = OrientedBox;
  using Variants = ObbTests;
  static Prim random(Rng& rng) {
    const Eigen::Quaterniond q =
        Eigen::Quaterniond(rng.next_double() - 0.5, rng.next_double() - 0.5, rng.next_double() - 0.5, rng.next_double() - 0.5)
            .normalized();
    const Eigen::Matrix3d m = q.toRotationMatrix();
    OrientedBox b;
    b.center = uniform_in_cube(rng, 1);
    for (int a = 0; a < 3; ++a) {
      b.axis[a] = {static_cast<float>(m(0, a)), static_cast<float>(m(1, a)), static_cast<float>(m(2, a))};
      b.half_extent[a] = static_cast<float>(0.05 + 0.45 * rng.next_double());
    }
    return b;
  }
  static Vec3f inside(Rng& rng, const Prim& b) {
    Vec3f p = b.center;
    for (int a = 0; a < 3; ++a) p = p + b.axis[a] * (b.half_extent[a] * static_cast<float>(2 * rng.next_double() - 1));
    return p;
  }
  static Prim translate(Prim b, Vec3f d) {
    b.center = b.center + d;
    return b;
  }
  static bool referee(const Ray& r, const Prim& b) {
    BoxHit h;
    return Obb::intersect(r, kInf, b, h);
  }
  template <typename V>
  static auto kernel(std::vector<Prim> prims) {
    return [prims = std::move(prims)](const Ray& r, std::size_t i) {
      BoxHit h;
      return V::intersect(r, kInf, prims[i], h);
    };
  }
};

template <typename Prim>
struct Pairs {
  std::vector<Ray> rays;
  std::vector<Prim> prims;  // prims[i] with rays[i]; or 8 per ray for batched inputs
};

// A ray from a sphere of radius 4 around the origin towards `target`.
Ray ray_towards(Rng& rng, Vec3f target) {
  const Vec3f org = uniform_on_sphere(rng, 4.0f);
  return Ray{org, 0.0f, normalize(target - org), kInf};
}

// `lanes` primitives per ray that the referee classifies as all hit or all
// miss. Hits aim at a point inside; misses at a point nearby, resampled until
// the referee says miss.
template <typename Family>
Pairs<typename Family::Prim> make_pairs(std::size_t rays, int lanes, bool hit, std::uint64_t stream) {
  Pairs<typename Family::Prim> out;
  for (std::size_t i = 0; i < rays; ++i) {
    Rng rng(2026, stream, i);
    const Vec3f target = uniform_in_cube(rng, 1);
    const Ray r = ray_towards(rng, target);
    out.rays.push_back(r);
    for (int lane = 0; lane < lanes; ++lane) {
      for (int attempt = 0;; ++attempt) {
        // Move a random primitive so that its inside point lands on the target
        // (a hit), or lands a little off it (usually a miss).
        const auto prim = Family::random(rng);
        const Vec3f offset = hit ? Vec3f{} : uniform_in_cube(rng, 0.6f);
        const auto placed = Family::translate(prim, target + offset - Family::inside(rng, prim));
        if (Family::referee(r, placed) == hit) {
          out.prims.push_back(placed);
          break;
        }
        if (attempt > 1000) throw std::logic_error("kernel bench: cannot sample a pair");
      }
    }
  }
  return out;
}

KernelResult describe(std::string family, std::string variant, std::string form, bool hit, std::string accuracy,
                      std::size_t tests) {
  KernelResult r;
  r.family = std::move(family);
  r.variant = std::move(variant);
  r.form = std::move(form);
  r.input = hit ? "hit" : "miss";
  r.accuracy = std::move(accuracy);
  r.tests_per_iteration = tests;
  return r;
}

struct Case {
  std::string name;
  KernelResult result;
  std::function<std::size_t()> run;  // one iteration: every test once; returns the hits
};

template <typename Family>
void add_family(std::vector<Case>& cases, std::size_t pairs) {
  for (const bool hit : {true, false}) {
    auto inputs = std::make_shared<Pairs<typename Family::Prim>>(
        make_pairs<Family>(pairs, 1, hit, hash_string(Family::name) ^ (hit ? 1u : 2u)));
    for_each_variant<typename Family::Variants>([&](auto variant) {
      using V = decltype(variant);
      auto kernel = std::make_shared<decltype(Family::template kernel<V>(inputs->prims))>(
          Family::template kernel<V>(inputs->prims));
      Case c;
      c.result = describe(Family::name, std::string(V::name), "scalar", hit, std::string(to_string(V::accuracy)),
                          inputs->rays.size());
      c.run = [inputs, kernel] {
        std::size_t hits = 0;
        for (std::size_t i = 0; i < inputs->rays.size(); ++i) hits += (*kernel)(inputs->rays[i], i);
        return hits;
      };
      cases.push_back(std::move(c));
    });
  }
}

// The 8-wide forms: 1 ray against 8 primitives, AVX2 and its scalar fallback.
void add_batched(std::vector<Case>& cases, std::size_t pairs) {
  const std::size_t rays = std::max<std::size_t>(1, pairs / 8);
  for (const bool hit : {true, false}) {
    auto tri = make_pairs<TriangleFamily>(rays, 8, hit, hash_string("triangle8") ^ hit);
    auto tri_rays = std::make_shared<std::vector<Ray>>(tri.rays);
    auto box = make_pairs<BoxFamily>(rays, 8, hit, hash_string("box8") ^ hit);
    auto box_rays = std::make_shared<std::vector<Ray>>(box.rays);
    auto boxes = std::make_shared<std::vector<BBox8>>();
    for (std::size_t i = 0; i < rays; ++i) boxes->push_back(BBox8::pack({box.prims.data() + 8 * i, 8}));

    // Packs of the leaves' two forms: stored normals (mt_normal) or edges
    // only (mt_edges, the normal recomputed per test).
    const auto triangle_case = [&]<typename Pack>(const char* form, int (*fn)(const Ray&, float, const Pack&, TriangleHit&)) {
      auto packs = std::make_shared<std::vector<Pack>>();
      for (std::size_t i = 0; i < rays; ++i) packs->push_back(Pack::pack({tri.prims.data() + 8 * i, 8}));
      Case c;
      c.result = describe("triangle", std::string(Pack::Kernel::name), form, hit, "fast", 8 * rays);
      c.run = [tri_rays, packs, fn] {
        std::size_t hits = 0;
        // One closest-hit call per ray, as a BVH leaf makes it; it reports
        // the nearest lane only, so hits here count rays, not lanes.
        for (std::size_t i = 0; i < tri_rays->size(); ++i) {
          TriangleHit h;
          hits += fn((*tri_rays)[i], kInf, (*packs)[i], h) >= 0;
        }
        return 8 * hits;  // in units of tests: a ray with a hit counts as 8
      };
      cases.push_back(std::move(c));
    };
    const auto box_case = [&](const char* form, unsigned (*fn)(const Slab::Precomputed&, float, const BBox8&, float*)) {
      Case c;
      c.result = describe("box", "slab", form, hit, "fast", 8 * rays);
      c.run = [box_rays, boxes, fn] {
        std::size_t hits = 0;
        alignas(32) float entry[8];
        for (std::size_t i = 0; i < box_rays->size(); ++i)
          hits += static_cast<std::size_t>(__builtin_popcount(fn(Slab::precompute((*box_rays)[i]), kInf, (*boxes)[i], entry)));
        return hits;
      };
      cases.push_back(std::move(c));
    };
    triangle_case("scalar_x8", intersect_pack_scalar<Triangle8>);
    triangle_case("scalar_x8", intersect_pack_scalar<TriangleEdgePack<8>>);
    box_case("scalar_x8", intersect_boxes_scalar<Slab, 8>);
#if defined(__AVX2__)
    triangle_case("avx2_x8", intersect_pack_simd<Triangle8>);
    triangle_case("avx2_x8", intersect_pack_simd<TriangleEdgePack<8>>);
    box_case("avx2_x8", intersect_boxes_simd<Slab, 8>);
#endif
  }
}

const std::vector<std::string>& kernel_columns() {
  static const std::vector<std::string> c = {"family", "variant", "form", "input", "accuracy", "tests", "ns_per_test",
                                             "ns_min", "ns_max", "reps", "ns_samples", "hit_fraction"};
  return c;
}

}  // namespace

std::vector<KernelResult> run_kernel_benchmarks(const KernelBenchOptions& options) {
  if (options.repetitions < 1) throw InputError("", "--reps must be at least 1");
  if (options.pairs < 8) throw InputError("", "--pairs must be at least 8");
  // Where the results go is checked before minutes of timing, not after.
  check_writable(options.out_csv);
  if (!options.out_json.empty()) check_writable(options.out_json);
  print_stderr_line(fmt::format("raybench: making inputs ({} pairs per family and input)", options.pairs));
  std::vector<Case> all;
  add_family<TriangleFamily>(all, options.pairs);
  add_family<BoxFamily>(all, options.pairs);
  add_family<SphereFamily>(all, options.pairs);
  add_family<ObbFamily>(all, options.pairs);
  add_batched(all, options.pairs);
  std::vector<Case> cases;
  for (Case& c : all) {
    c.name = fmt::format("kernel/{}/{}/{}/{}", c.result.family, c.result.variant, c.result.form, c.result.input);
    if (options.filter.empty() || c.name.find(options.filter) != std::string::npos) cases.push_back(std::move(c));
  }
  if (cases.empty()) throw InputError("", fmt::format("--filter '{}' matches no kernel case", options.filter));

  for (Case& c : cases) c.result.hit_fraction = static_cast<double>(c.run()) / c.result.tests_per_iteration;

  // Google Benchmark writes its JSON as it goes: into a temporary file that
  // becomes out_json only when every result is written, and is removed on
  // every other path (an error, a signal).
  std::optional<TemporaryFile> json_temp;
  std::vector<std::string> flags = {"--benchmark_enable_random_interleaving=true"};
  if (!options.out_json.empty()) {
    json_temp.emplace(options.out_json + ".tmp.gbench");
    flags.push_back("--benchmark_out=" + json_temp->path());
    flags.push_back("--benchmark_out_format=json");
  }
  initialize_google_benchmark(flags);
  benchmark::ClearRegisteredBenchmarks();
  for (const Case& c : cases) {
    const Case* cp = &c;
    benchmark::RegisterBenchmark(c.name.c_str(),
                                 [cp](benchmark::State& state) {
                                   std::size_t sink = 0;
                                   for (auto _ : state) {
                                     sink += cp->run();
                                     benchmark::DoNotOptimize(sink);
                                   }
                                   state.counters["tests"] = benchmark::Counter(
                                       static_cast<double>(cp->result.tests_per_iteration),
                                       benchmark::Counter::kIsIterationInvariantRate);
                                 })
        ->Repetitions(options.repetitions)
        ->MinTime(options.min_time)
        ->MinWarmUpTime(options.min_time)
        ->Unit(benchmark::kMicrosecond);
  }
  CollectingReporter reporter("tests", 0.0, "ns/test", cases.size());
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::ClearRegisteredBenchmarks();

  std::vector<KernelResult> results;
  for (Case& c : cases) {
    KernelResult r = c.result;
    r.samples = reporter.samples(c.name);
    r.reps = static_cast<int>(r.samples.size());
    r.ns_per_test = median(r.samples);
    r.ns_min = *std::min_element(r.samples.begin(), r.samples.end());
    r.ns_max = *std::max_element(r.samples.begin(), r.samples.end());
    results.push_back(std::move(r));
  }
  const SignalsDeferred deferred;  // the CSV, its metadata and the JSON land together
  write_file_atomically(options.out_csv, [&](std::ostream& out) {
    const auto& columns = kernel_columns();
    for (std::size_t i = 0; i < columns.size(); ++i) out << (i ? "," : "") << columns[i];
    out << '\n';
    for (const KernelResult& r : results) {
      out << fmt::format("{},{},{},{},{},{},{:.4g},{:.4g},{:.4g},{},{:.4g},{:.6g}\n", r.family, r.variant, r.form, r.input,
                         r.accuracy, r.tests_per_iteration, r.ns_per_test, r.ns_min, r.ns_max, r.reps,
                         fmt::join(r.samples, ";"), r.hit_fraction);
    }
  });
  write_metadata(metadata_path_for(options.out_csv),
                 collect_metadata({{"command", options.command_line},
                                   {"pairs", std::to_string(options.pairs)},
                                   {"repetitions", std::to_string(options.repetitions)},
                                   {"min_time_s", fmt::format("{}", options.min_time)},
                                   {"avx2", kHaveAvx2 ? "true" : "false"}}));
  if (json_temp) json_temp->keep_as(options.out_json);
  return results;
}

std::string format_kernel_table(const std::vector<KernelResult>& results) {
  std::string out = fmt::format("{:<9} {:<17} {:<10} {:<5} {:<12} {:>9} {:>19} {:>9}\n", "family", "variant", "form",
                                "input", "accuracy", "ns/test", "[min - max]", "hit frac");
  for (const KernelResult& r : results)
    out += fmt::format("{:<9} {:<17} {:<10} {:<5} {:<12} {:>9.2f} {:>19} {:>9.4f}\n", r.family, r.variant, r.form, r.input,
                       r.accuracy, r.ns_per_test, fmt::format("[{:.2f} - {:.2f}]", r.ns_min, r.ns_max), r.hit_fraction);
  return out;
}

}  // namespace raybench
