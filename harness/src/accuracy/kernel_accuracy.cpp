#include "accuracy/kernel_accuracy.h"

#include <algorithm>
#include <cctype>
#include <cfloat>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include "accuracy/judge.h"
#include "accuracy/prim_raysets.h"
#include "io/error.h"
#include "io/interrupt.h"
#include "measure/gbench.h"
#include "results/metadata.h"
#include "io/npy.h"
#include "raybench/math/inline.h"
#include "raybench/variants.h"
#include "referee/exact_primitives.h"
#include "referee/exact_triangle.h"

namespace raybench {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// The referee's answer for one ray.
struct Truth {
  bool valid = false;      // is_exact_ray
  bool hit = false;
  bool ambiguous = false;  // touched at t = max(tnear, 0) only (ExactPrimitiveHit::start_contact)
  bool exit = false;       // the first crossing in the interval is the exit / far root
  double t = std::numeric_limits<double>::quiet_NaN();
};

// A variant's answer: t[0] the entry / near root / triangle t, t[1] the exit
// / far root (the triangle t again).
struct Answer {
  bool hit = false;
  float t[2] = {kNaN, kNaN};
};

Truth from_exact(const Ray& ray, const ExactPrimitiveHit& h) { return {is_exact_ray(ray), h.hit, h.start_contact, h.exit, h.t}; }

// The triangle referee judges only rays inside Embree's range (is_traceable:
// no coordinate beyond 1.844e18), which would make |d| = 1e20 (G16) or
// FLT_MAX (G15) a miss by fiat. At this level the length of d is no
// criterion, so the ray is first rescaled by a power of two, d' = d 2^s with
// max |d'_i| in [1, 2), which is exact and changes nothing geometric:
// o + t d = o + t' d' with t = t' 2^s, and the interval scales by 2^-s. When a
// scaled component or bound would lose bits (a direction spanning more than
// 2^149 between its components, a huge tfar) the ray is judged unscaled.
Truth triangle_truth(const Ray& ray, const Triangle& tri) {
  Truth out;
  out.valid = is_exact_ray(ray);
  if (!out.valid) return out;
  int exponent = 0;
  std::frexp(std::max({std::fabs(ray.dir.x), std::fabs(ray.dir.y), std::fabs(ray.dir.z)}), &exponent);
  int s = 1 - exponent;  // the largest component times 2^s lies in [1, 2)
  Ray scaled = ray;
  for (int a = 0; a < 3; ++a) scaled.dir[a] = std::ldexp(ray.dir[a], s);
  scaled.tnear = std::ldexp(ray.tnear, -s);
  scaled.tfar = std::ldexp(ray.tfar, -s);
  bool exact = std::ldexp(scaled.tnear, s) == ray.tnear && std::ldexp(scaled.tfar, s) == ray.tfar;
  for (int a = 0; a < 3; ++a) exact = exact && std::ldexp(scaled.dir[a], -s) == ray.dir[a];
  if (!exact) scaled = ray, s = 0;
  const ExactTriangleHit h = exact_intersect(scaled, tri);
  out.hit = h.hit;
  if (h.hit) out.t = std::ldexp(h.t, s);
  return out;
}

// --- The families: ray sets, referee, and how a variant is called -------------

// What the box, OBB and sphere families share: the kernels take the primitive
// as it is, and the exact referee of referee/exact_primitives.h judges it.
template <typename P>
struct AnalyticFamily {
  using Prim = P;
  static Truth truth(const Ray& r, const Prim& p) { return from_exact(r, exact_intersect(r, p)); }
  template <typename V>
  using Prepared = Prim;
  template <typename V>
  static Prim prepare(const Prim& p) { return p; }
};

struct BoxFamily : AnalyticFamily<BBox> {
  using Variants = BoxTests;
  static std::vector<PrimRaySet<Prim>> raysets(std::size_t n, std::uint64_t seed) { return box_raysets(n, seed); }
  template <typename V>
  RAYBENCH_INLINE static Answer answer(const Ray& r, const Prim& box) {
    BoxHit h{kNaN, kNaN};
    Answer a;
    a.hit = V::intersect(V::precompute(r), box, r.tfar, h);
    a.t[0] = h.t_entry, a.t[1] = h.t_exit;
    return a;
  }
};

struct ObbFamily : AnalyticFamily<OrientedBox> {
  using Variants = ObbTests;
  static std::vector<PrimRaySet<Prim>> raysets(std::size_t n, std::uint64_t seed) { return obb_raysets(n, seed); }
  template <typename V>
  RAYBENCH_INLINE static Answer answer(const Ray& r, const Prim& box) {
    BoxHit h{kNaN, kNaN};
    Answer a;
    a.hit = V::intersect(r, r.tfar, box, h);
    a.t[0] = h.t_entry, a.t[1] = h.t_exit;
    return a;
  }
};

struct SphereFamily : AnalyticFamily<Sphere> {
  using Variants = SphereTests;
  static std::vector<PrimRaySet<Prim>> raysets(std::size_t n, std::uint64_t seed) { return sphere_raysets(n, seed); }
  template <typename V>
  RAYBENCH_INLINE static Answer answer(const Ray& r, const Prim& s) {
    SphereHit h{kNaN, kNaN};
    Answer a;
    a.hit = V::intersect(r, r.tfar, s, h);
    a.t[0] = h.t_near, a.t[1] = h.t_far;
    return a;
  }
};

struct TriangleFamily {
  using Prim = Triangle;
  using Variants = TriangleTests;
  static std::vector<PrimRaySet<Prim>> raysets(std::size_t n, std::uint64_t seed) { return triangle_raysets(n, seed); }
  static Truth truth(const Ray& r, const Prim& p) { return triangle_truth(r, p); }
  template <typename V>
  using Prepared = typename V::Prepared;
  template <typename V>
  static Prepared<V> prepare(const Prim& p) { return V::prepare(p); }
  template <typename V>
  RAYBENCH_INLINE static Answer answer(const Ray& r, const Prepared<V>& tri) {
    TriangleHit h{kNaN, kNaN, kNaN};
    Answer a;
    a.hit = V::intersect(V::precompute(r), r.tfar, tri, h);
    a.t[0] = a.t[1] = h.t;
    return a;
  }
};

// --- Judging and timing -------------------------------------------------------

double fraction(std::size_t count, std::size_t total) { return total ? static_cast<double>(count) / total : 0.0; }

// Nearest-rank percentile of a sorted sample (as judge.cpp's).
double percentile(const std::vector<double>& sorted, double p) {
  if (sorted.empty()) return std::numeric_limits<double>::quiet_NaN();
  const auto rank = static_cast<std::size_t>(std::ceil(p * sorted.size()));
  return sorted[std::min(sorted.size() - 1, rank == 0 ? 0 : rank - 1)];
}

// The counting and t-error columns of a row (see kernel_accuracy.h).
void judge(const std::vector<Truth>& truth, const std::vector<Answer>& answers, AccuracyRow& row) {
  std::size_t invalid = 0, truth_hits = 0, ambiguous = 0, false_miss = 0, false_hit = 0;
  std::vector<double> ulps;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const Truth& v = truth[i];
    const Answer& a = answers[i];
    invalid += !v.valid;
    truth_hits += v.hit;
    ambiguous += v.ambiguous;
    false_miss += v.hit && !a.hit;
    false_hit += !v.hit && a.hit;
    if (v.hit && a.hit && std::fabs(v.t) <= FLT_MAX) {
      const float t = a.t[v.exit ? 1 : 0];
      ulps.push_back(std::isfinite(t) ? ulp_error(t, v.t) : std::numeric_limits<double>::infinity());
    }
  }
  row.rays = truth.size();
  row.invalid = fraction(invalid, truth.size());
  row.truth_hits = fraction(truth_hits, truth.size());
  row.ambiguous = fraction(ambiguous, truth.size());
  row.false_miss = fraction(false_miss, truth.size());
  row.false_hit = fraction(false_hit, truth.size());
  row.wrong_prim = 0.0;  // one primitive per ray: no other to pick
  std::sort(ulps.begin(), ulps.end());
  row.ulp_p50 = percentile(ulps, 0.5);
  row.ulp_p99 = percentile(ulps, 0.99);
  row.ulp_max = ulps.empty() ? std::numeric_limits<double>::quiet_NaN() : ulps.back();
}

// Million tests per second of `pass` (one loop over the set), per repetition.
// Each repetition repeats the loop for at least 2 ms so that the clock's
// resolution and call overhead do not matter; one untimed pass warms up.
template <typename F>
std::vector<double> time_mtests(std::size_t tests_per_pass, int repetitions, F&& pass) {
  using Clock = std::chrono::steady_clock;
  const auto seconds = [](Clock::duration d) { return std::chrono::duration<double>(d).count(); };
  pass();
  const auto start = Clock::now();
  pass();
  const double one = std::max(seconds(Clock::now() - start), 1e-9);
  const auto passes = static_cast<std::size_t>(std::ceil(2e-3 / one));
  std::vector<double> samples;
  for (int rep = 0; rep < repetitions; ++rep) {
    const auto t0 = Clock::now();
    for (std::size_t k = 0; k < passes; ++k) pass();
    const double s = seconds(Clock::now() - t0);
    samples.push_back(static_cast<double>(tests_per_pass * passes) / s * 1e-6);
  }
  return samples;
}

template <typename Family, typename V>
AccuracyRow measure(const PrimRaySet<typename Family::Prim>& set, const std::vector<Truth>& truth, int repetitions) {
  using Prepared = typename Family::template Prepared<V>;
  std::vector<Prepared> prepared;
  prepared.reserve(set.prims.size());
  for (const auto& p : set.prims) prepared.push_back(Family::template prepare<V>(p));
  const std::vector<Ray>& rays = set.rays;

  std::vector<Answer> answers(rays.size());
  for (std::size_t i = 0; i < rays.size(); ++i) answers[i] = Family::template answer<V>(rays[i], prepared[i]);
  AccuracyRow row;
  row.scene = set.scene;
  row.rayset = set.rayset;
  row.query = "intersect";
  row.backend = "kernel:" + std::string(V::name);
  row.accuracy_class = std::string(to_string(V::accuracy));
  judge(truth, answers, row);

  const std::vector<double> samples = time_mtests(rays.size(), repetitions, [&] {
    std::size_t hits = 0;
    float t_sum = 0.0f;  // keeps the t computation alive
    for (std::size_t i = 0; i < rays.size(); ++i) {
      const Answer a = Family::template answer<V>(rays[i], prepared[i]);
      hits += a.hit;
      t_sum += a.hit ? a.t[0] : 0.0f;
    }
    benchmark::DoNotOptimize(hits);
    benchmark::DoNotOptimize(t_sum);
    benchmark::ClobberMemory();
  });
  row.mrays_s = median(samples);
  row.mrays_s_min = *std::min_element(samples.begin(), samples.end());
  row.mrays_s_max = *std::max_element(samples.begin(), samples.end());
  return row;
}

std::string row_key(const std::string& scene, const std::string& rayset, std::string_view variant) {
  return fmt::format("{}/{}/kernel:{}", scene, rayset, variant);
}

// Stores a set as the header of KernelAccuracyOptions::rays_dir says; the
// file name keeps only [A-Za-z0-9._-] of the set's name.
template <typename Prim>
void store(const PrimRaySet<Prim>& set, const KernelAccuracyOptions& options) {
  static_assert(sizeof(Prim) % sizeof(float) == 0, "a primitive is a plain record of floats");
  constexpr std::size_t kFloats = sizeof(Prim) / sizeof(float);
  std::string name = fmt::format("{}.{}.n{}.seed{}", set.scene, set.rayset, set.rays.size(), options.seed);
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '-' && c != '_') c = '_';
  const std::string base = options.rays_dir + "/" + name;
  write_ray_file(base + ".rays.npy", set.rays);
  std::vector<double> prims(set.prims.size() * kFloats);
  for (std::size_t i = 0; i < set.prims.size(); ++i) {
    float f[kFloats];
    std::memcpy(f, &set.prims[i], sizeof(Prim));
    for (std::size_t k = 0; k < kFloats; ++k) prims[i * kFloats + k] = f[k];
  }
  write_npy_f64(base + ".prims.npy", prims, set.prims.size(), kFloats);
}

template <typename Family>
void run_family(const KernelAccuracyOptions& options, std::vector<AccuracyRow>& rows) {
  for (const auto& set : Family::raysets(options.rays, options.seed)) {
    const auto wanted = [&](std::string_view variant) {
      return options.filter.empty() || row_key(set.scene, set.rayset, variant).find(options.filter) != std::string::npos;
    };
    bool any = false;
    for_each_variant<typename Family::Variants>([&](auto v) { any = any || wanted(decltype(v)::name); });
    if (!any) continue;
    print_stderr_line(fmt::format("raybench: {} {}: judging {} rays", set.scene, set.rayset, set.rays.size()));
    if (!options.rays_dir.empty()) store(set, options);
    std::vector<Truth> truth(set.rays.size());
    for (std::size_t i = 0; i < set.rays.size(); ++i) truth[i] = Family::truth(set.rays[i], set.prims[i]);
    for_each_variant<typename Family::Variants>([&](auto v) {
      using V = decltype(v);
      if (wanted(V::name)) rows.push_back(measure<Family, V>(set, truth, options.repetitions));
    });
  }
}

}  // namespace

std::vector<AccuracyRow> run_kernel_accuracy(const KernelAccuracyOptions& options) {
  if (options.rays < 1) throw InputError("", "--rays must be at least 1");
  if (options.repetitions < 1) throw InputError("", "--reps must be at least 1");
  std::vector<AccuracyRow> rows;
  run_family<BoxFamily>(options, rows);
  run_family<ObbFamily>(options, rows);
  run_family<SphereFamily>(options, rows);
  run_family<TriangleFamily>(options, rows);
  if (rows.empty())
    throw InputError("", fmt::format("--filter '{}' matches no <scene>/<rayset>/<backend> of accuracy-kernels "
                                     "(e.g. prim:sphere/origin-inside/kernel:sphere_seed)",
                                     options.filter));
  if (!options.out_csv.empty()) {
    write_accuracy_csv(options.out_csv, rows);
    write_metadata(metadata_path_for(options.out_csv),
                   collect_metadata({{"command", options.command_line},
                                     {"rays_per_set", std::to_string(options.rays)},
                                     {"seed", std::to_string(options.seed)},
                                     {"repetitions", std::to_string(options.repetitions)},
                                     {"filter", options.filter}}));
  }
  return rows;
}

std::string format_kernel_accuracy_table(const std::vector<AccuracyRow>& rows) {
  std::string out = fmt::format("{:<14} {:<34} {:<24} {:>6} {:>7} {:>6} {:>6} {:>7} {:>7} {:>8} {:>8} {:>9} {:>8}\n", "scene",
                                "rayset", "backend", "rays", "invalid", "truth", "ambig", "f_miss", "f_hit", "ulp_p50",
                                "ulp_p99", "ulp_max", "Mtests/s");
  const auto number = [](double v) { return std::isnan(v) ? std::string("-") : fmt::format("{:.3g}", v); };
  for (const AccuracyRow& r : rows)
    out += fmt::format("{:<14} {:<34} {:<24} {:>6} {:>7.4f} {:>6.4f} {:>6.4f} {:>7.4f} {:>7.4f} {:>8} {:>8} {:>9} {:>8.1f}\n",
                       r.scene, r.rayset, r.backend, r.rays, r.invalid, r.truth_hits, r.ambiguous, r.false_miss,
                       r.false_hit, number(r.ulp_p50), number(r.ulp_p99), number(r.ulp_max), r.mrays_s);
  return out;
}

}  // namespace raybench
