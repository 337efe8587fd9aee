// What the BVH2 builders share (private to kernels/src): the SAH's leaf
// cost, a total order on float keys for sorting, and the binned object split
// (binned SAH and SBVH builders). A triangle's box is triangle_bounds
// (prim/triangle.h).
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <span>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/partitioner.h>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include "raybench/bvh/bvh2.h"

namespace raybench::bvh2_build {

// Leaf tests for n triangles tested `granularity` at a time, in units of one
// triangle test (Bvh2BuildOptions::leaf_granularity).
inline float leaf_tests(std::size_t n, int granularity) {
  const auto g = static_cast<std::size_t>(std::max(1, granularity));
  return static_cast<float>((n + g - 1) / g);
}

// A float as an unsigned integer with the same order (negative values
// flipped), and every NaN ordered too: sorting by it is a strict weak order
// even for the NaN centroids of a broken mesh, which std::sort on float
// comparisons is not (undefined behaviour).
inline std::uint32_t ordered_key(float f) {
  const auto bits = std::bit_cast<std::uint32_t>(f);
  return (bits & 0x80000000u) ? ~bits : bits | 0x80000000u;
}

// Binned object split (Wald, "On fast construction of SAH-based bounding
// volume hierarchies", RT 2007): centroids binned into `bins` equal bins per
// axis, every bin boundary evaluated by the SAH.
inline constexpr int kMaxBins = 64;
// A range of at least two chunks of kBinningChunk references is binned in
// parallel, in at most kMaxBinningChunks chunks (more would only add bins
// to set up and merge: two cores here).
inline constexpr std::size_t kBinningChunk = 1024;
inline constexpr std::size_t kMaxBinningChunks = 8;

struct ObjectSplit {
  int axis = -1;  // -1: none (the centroids coincide on every axis)
  int bin = 0;    // centroids in bins [0, bin] go left (centroid_bin)
  float cost = std::numeric_limits<float>::infinity();  // area-weighted leaf tests, not yet divided by the node's area
  BBox left, right;  // the bounds of either side
};

// The bin of centroid coordinate c, bins of 1 / scale from lo; below lo, and
// NaN (the centroid of a broken triangle), fall in bin 0, beyond in the last.
inline int centroid_bin(float c, float lo, float scale, int bins) {
  const float f = (c - lo) * scale;
  if (!(f >= 0.0f)) return 0;
  return f < static_cast<float>(bins) ? static_cast<int>(f) : bins - 1;
}

// The SAH sweep over binned boxes: the plane before bin j (0 < j < bins)
// has bins [0, j) on its left, holding left_counts[0] + ... +
// left_counts[j - 1] primitives, and bins [j, bins) on its right, holding
// right_counts[j] + ... + right_counts[bins - 1]; calls
// consider(j, cost, left box, right box, left count, right count) for each,
// with cost the area-weighted leaf tests of both sides (in packs of
// `granularity`).
template <std::size_t MaxBins, typename Consider>
void sweep_bins(const std::array<BBox, MaxBins>& boxes, const std::array<std::size_t, MaxBins>& left_counts,
                const std::array<std::size_t, MaxBins>& right_counts, int bins, int granularity, Consider&& consider) {
  std::array<float, MaxBins> right_cost{};
  std::array<BBox, MaxBins> right_bounds{};
  std::array<std::size_t, MaxBins> right_count{};
  BBox acc;
  std::size_t n = 0;
  for (int j = bins - 1; j > 0; --j) {
    acc.extend(boxes[j]);
    n += right_counts[j];
    right_bounds[j] = acc;
    right_count[j] = n;
    right_cost[j] = acc.half_area() * leaf_tests(n, granularity);
  }
  acc = BBox{};
  n = 0;
  for (int j = 1; j < bins; ++j) {
    acc.extend(boxes[j - 1]);
    n += left_counts[j - 1];
    const float cost = acc.half_area() * leaf_tests(n, granularity) + right_cost[j];
    consider(j, cost, acc, right_bounds[j], n, right_count[j]);
  }
}

#if defined(__SSE2__)
// A Vec3f as the first three lanes of an SSE vector (lane 3 zero): exactly
// three floats read, never past the vector. x and y are read as one 8-byte
// load: through memcpy, because a Vec3f is only 4-byte aligned and reading
// it through a double* is undefined behaviour (UBSan: misaligned load).
// g++ 12 and clang 14 emit the same instructions as for the cast (one 8-byte
// load, movq or movsd), so the lanes hold the same bits and the trees built
// from them are the same.
inline __m128 load_vec3(const Vec3f& v) {
  static_assert(offsetof(Vec3f, y) == offsetof(Vec3f, x) + sizeof(float));
  double xy;
  std::memcpy(&xy, &v.x, sizeof xy);
  return _mm_movelh_ps(_mm_castpd_ps(_mm_load_sd(&xy)), _mm_load_ss(&v.z));
}

// The box whose corners are the first three lanes of `lower` and `upper`.
inline BBox bbox_from_lanes(__m128 lower, __m128 upper) {
  alignas(16) float l[4], u[4];
  _mm_store_ps(l, lower);
  _mm_store_ps(u, upper);
  return BBox{{l[0], l[1], l[2]}, {u[0], u[1], u[2]}};
}

// A box being gathered (a bin's, a range's, a range's centroids'), extended
// as BBox::extend would. With AVX, one vector: the lower corner in the low
// lanes, the upper corner negated in the high lanes, so one min extends
// both (max(u, x) is -min(-u, -x), for NaN, which neither takes up, and
// signed zeros alike): the binning loop's min, max and stores halved, the
// same bins (measured: docs/notes/kernels-builders.md). Without AVX, two
// SSE vectors.
struct BoxAccumulator {
#if defined(__AVX__)
  using Key = __m256;
  __m256 lower_and_negated_upper = _mm256_set1_ps(std::numeric_limits<float>::infinity());

  static Key key(__m128 lower, __m128 upper) { return _mm256_set_m128(_mm_xor_ps(upper, _mm_set1_ps(-0.0f)), lower); }
  // min_ps(x, y) is (x < y ? x : y), as std::min(y, x): BBox::extend's order.
  void extend(Key k) { lower_and_negated_upper = _mm256_min_ps(k, lower_and_negated_upper); }
  void extend(const BoxAccumulator& b) { extend(b.lower_and_negated_upper); }
  BBox bounds() const {
    return bbox_from_lanes(_mm256_castps256_ps128(lower_and_negated_upper),
                           _mm_xor_ps(_mm256_extractf128_ps(lower_and_negated_upper, 1), _mm_set1_ps(-0.0f)));
  }
#else
  struct Key {
    __m128 lower, upper;
  };
  __m128 lower = _mm_set1_ps(std::numeric_limits<float>::infinity());
  __m128 upper = _mm_set1_ps(-std::numeric_limits<float>::infinity());

  static Key key(__m128 l, __m128 u) { return {l, u}; }
  void extend(const Key& k) {
    lower = _mm_min_ps(k.lower, lower);
    upper = _mm_max_ps(k.upper, upper);
  }
  void extend(const BoxAccumulator& b) { extend(Key{b.lower, b.upper}); }
  BBox bounds() const { return bbox_from_lanes(lower, upper); }
#endif
};
#endif

#if defined(__AVX2__)
// A reference's box as one vector: the lower corner in lanes 0-2, the upper
// in lanes 4-6, lanes 3 and 7 finite (here zero). A builder whose reference
// type can be read faster gives it its own box_lanes (found by argument-
// dependent lookup).
template <typename Ref>
inline __m256 box_lanes(const Ref& r) {
  return _mm256_set_m128(load_vec3(r.bounds.upper), load_vec3(r.bounds.lower));
}
#endif

// Bins `refs` on all three axes in one pass: bin_bounds[axis][b] and
// bin_count[axis][b] for b < bins, a reference binned by its box's centre
// (BBox::center, the centroid every builder splits by). The build's hottest
// loop: each reference is read once, its centre and its three bins are
// computed as one SSE vector (the same operations as BBox::center and
// centroid_bin, so every reference lands in the bin the partition puts it
// in), its box extends the bins (BoxAccumulator: the same comparisons as
// BBox::extend, so NaN boxes bin as before). One set of bins: even and odd
// references had filled two sets, merged at the end, so that a run of
// references in one bin would not wait on its own stores; with the fewer
// bins of small ranges (bins_for) one set is faster and gives the same trees
// (measured: docs/notes/kernels-builders.md).
//
// With AVX2, a bin's count rides in lane 3 of its box vector (below): one
// load, min, integer add and store per axis instead of a box update and a
// separate increment in memory (measured: docs/notes/kernels-builders.md).
template <std::size_t MaxBins, typename Ref>
void bin_all_axes(std::span<const Ref> refs, const float lo[3], const float scale[3], int bins,
                  std::array<std::array<BBox, MaxBins>, 3>& bin_bounds,
                  std::array<std::array<std::size_t, MaxBins>, 3>& bin_count) {
#if defined(__AVX2__)
  // A bin as one vector: lanes 0-2 the lower corner, 4-6 the upper corner
  // negated (BoxAccumulator's layout, the same min), lane 3 the count as an
  // integer (below 2^32: a chunk's). The key's lanes 3 and 7 are
  // +infinity, so min_ps(key, bin) returns the bin's lane 3 whatever its
  // bits (inf < x is false, and a NaN x is returned too), and the add
  // counts the reference.
  const float inf = std::numeric_limits<float>::infinity();
  const __m256 empty_bin = _mm256_castsi256_ps(
      _mm256_blend_epi32(_mm256_castps_si256(_mm256_set1_ps(inf)), _mm256_setzero_si256(), 0x08));
  __m256 bin[3][MaxBins];
  for (int axis = 0; axis < 3; ++axis)
    for (int b = 0; b < bins; ++b) bin[axis][b] = empty_bin;
  const __m256 negate_upper = _mm256_setr_ps(0.0f, 0.0f, 0.0f, 0.0f, -0.0f, -0.0f, -0.0f, -0.0f);
  const __m256 infinities = _mm256_set1_ps(inf);
  const __m256i count_one = _mm256_setr_epi32(0, 0, 0, 1, 0, 0, 0, 0);
  const __m128 lo4 = _mm_setr_ps(lo[0], lo[1], lo[2], 0.0f), scale4 = _mm_setr_ps(scale[0], scale[1], scale[2], 0.0f);
  const __m128 half = _mm_set1_ps(0.5f), zero = _mm_setzero_ps(), last_bin = _mm_set1_ps(static_cast<float>(bins - 1));
  for (const Ref& r : refs) {
    const __m256 corners = box_lanes(r);  // lanes 0-2 lower, 4-6 upper, 3 and 7 finite
    const __m128 ref_lower = _mm256_castps256_ps128(corners), ref_upper = _mm256_extractf128_ps(corners, 1);
    // centroid_bin on three axes, as below.
    const __m128 centre = _mm_mul_ps(_mm_add_ps(ref_lower, ref_upper), half);
    const __m128i b = _mm_cvttps_epi32(_mm_min_ps(_mm_max_ps(_mm_mul_ps(_mm_sub_ps(centre, lo4), scale4), zero), last_bin));
    const __m256 key = _mm256_blend_ps(_mm256_xor_ps(corners, negate_upper), infinities, 0x88);
    const auto extend = [&](__m256& v) {
      v = _mm256_castsi256_ps(_mm256_add_epi32(_mm256_castps_si256(_mm256_min_ps(key, v)), count_one));
    };
    extend(bin[0][_mm_cvtsi128_si32(b)]);
    extend(bin[1][_mm_extract_epi32(b, 1)]);
    extend(bin[2][_mm_extract_epi32(b, 2)]);
  }
  for (int axis = 0; axis < 3; ++axis)
    for (int b = 0; b < bins; ++b) {
      const __m256 v = bin[axis][b];
      bin_bounds[axis][b] = bbox_from_lanes(_mm256_castps256_ps128(v),
                                            _mm_xor_ps(_mm256_extractf128_ps(v, 1), _mm_set1_ps(-0.0f)));
      bin_count[axis][b] = static_cast<std::uint32_t>(_mm256_extract_epi32(_mm256_castps_si256(v), 3));
    }
#elif defined(__SSE2__)
  BoxAccumulator box[3][MaxBins];
  std::size_t count[3][MaxBins];
  for (int axis = 0; axis < 3; ++axis)
    for (int b = 0; b < bins; ++b) {
      box[axis][b] = BoxAccumulator{};
      count[axis][b] = 0;
    }
  const __m128 lo4 = _mm_setr_ps(lo[0], lo[1], lo[2], 0.0f), scale4 = _mm_setr_ps(scale[0], scale[1], scale[2], 0.0f);
  const __m128 half = _mm_set1_ps(0.5f), zero = _mm_setzero_ps(), last_bin = _mm_set1_ps(static_cast<float>(bins - 1));
  for (const Ref& r : refs) {
    const __m128 ref_lower = load_vec3(r.bounds.lower), ref_upper = load_vec3(r.bounds.upper);
    // centroid_bin on three axes: max_ps(f, 0) is 0 for a NaN f, as below lo;
    // min with bins - 1 before truncation gives the last bin from bins - 1 on.
    const __m128 centre = _mm_mul_ps(_mm_add_ps(ref_lower, ref_upper), half);
    const __m128 f = _mm_mul_ps(_mm_sub_ps(centre, lo4), scale4);
    alignas(16) std::int32_t b[4];
    _mm_store_si128(reinterpret_cast<__m128i*>(b), _mm_cvttps_epi32(_mm_min_ps(_mm_max_ps(f, zero), last_bin)));
    const BoxAccumulator::Key key = BoxAccumulator::key(ref_lower, ref_upper);
    for (int axis = 0; axis < 3; ++axis) {
      box[axis][b[axis]].extend(key);
      ++count[axis][b[axis]];
    }
  }
  for (int axis = 0; axis < 3; ++axis)
    for (int b = 0; b < bins; ++b) {
      bin_bounds[axis][b] = box[axis][b].bounds();
      bin_count[axis][b] = count[axis][b];
    }
#else
  for (const Ref& r : refs) {
    const Vec3f c = r.bounds.center();
    for (int axis = 0; axis < 3; ++axis) {
      const int b = centroid_bin(c[axis], lo[axis], scale[axis], bins);
      bin_bounds[axis][b].extend(r.bounds);
      ++bin_count[axis][b];
    }
  }
#endif
}

// As bin_all_axes, in chunks binned as parallel tasks, then merged: the
// top levels' ranges, binned on one thread, held up a small mesh's parallel
// build (measured: docs/notes/kernels-builders.md). The same bins as one
// pass: min, max and counts are exact whatever
// the order (a NaN coordinate is never taken up, as in BBox::extend), and
// the chunks depend on the range's size alone.
template <std::size_t MaxBins, typename Ref>
void bin_all_axes_in_chunks(std::span<const Ref> refs, const float lo[3], const float scale[3], int bins,
                            std::array<std::array<BBox, MaxBins>, 3>& bin_bounds,
                            std::array<std::array<std::size_t, MaxBins>, 3>& bin_count) {
  struct Bins {
    std::array<std::array<BBox, MaxBins>, 3> bounds;
    std::array<std::array<std::size_t, MaxBins>, 3> count;
  };
  const std::size_t chunk = std::max(kBinningChunk, (refs.size() + kMaxBinningChunks - 1) / kMaxBinningChunks);
  const std::size_t chunks = (refs.size() + chunk - 1) / chunk;
  std::vector<Bins> chunk_bins(chunks);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, chunks, 1), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t c = r.begin(); c != r.end(); ++c)
      bin_all_axes<MaxBins>(refs.subspan(c * chunk, std::min(chunk, refs.size() - c * chunk)), lo, scale, bins,
                            chunk_bins[c].bounds, chunk_bins[c].count);
  }, tbb::simple_partitioner());
  for (int axis = 0; axis < 3; ++axis)
    for (int b = 0; b < bins; ++b) {
      bin_bounds[axis][b] = BBox{};
      bin_count[axis][b] = 0;
      for (const Bins& part : chunk_bins) {
        bin_bounds[axis][b].extend(part.bounds[axis][b]);
        bin_count[axis][b] += part.count[axis][b];
      }
    }
}

// The cheapest plane between the bins of the splittable axes (splittable[a])
// of `total` references, both sides non-empty, by sweep_bins axis after
// axis: of equal costs, the first axis's and then the first plane's.
template <std::size_t MaxBins>
ObjectSplit best_split_of_bins_by_axis(const std::array<std::array<BBox, MaxBins>, 3>& bin_bounds,
                                       const std::array<std::array<std::size_t, MaxBins>, 3>& bin_count,
                                       const bool splittable[3], int bins, int granularity, std::size_t total) {
  ObjectSplit best;
  for (int axis = 0; axis < 3; ++axis) {
    if (!splittable[axis]) continue;
    sweep_bins(bin_bounds[axis], bin_count[axis], bin_count[axis], bins, granularity,
               [&](int j, float cost, const BBox& left, const BBox& right, std::size_t n, std::size_t) {
                 if (n > 0 && n < total && cost < best.cost) best = {axis, j - 1, cost, left, right};
               });
  }
  return best;
}

// The same split, the three axes swept at once in the lanes of SSE vectors
// (as Embree's BinInfo::best does): the same operations in the same order
// per lane, so the same costs to the bit and the same choice. The scalar
// sweep was a tenth of the binned build (Conference, one thread), most of
// it mispredicted branches on "cheaper than the best so far". Leaf tests
// are counted with a shift, so `granularity` must be a power of two, and
// `total` below 2^31 (int32 lanes); else the scalar sweep runs.
template <std::size_t MaxBins>
ObjectSplit best_split_of_bins(const std::array<std::array<BBox, MaxBins>, 3>& bin_bounds,
                               const std::array<std::array<std::size_t, MaxBins>, 3>& bin_count, const bool splittable[3],
                               int bins, int granularity, std::size_t total) {
#if defined(__SSE2__)
  if (std::has_single_bit(static_cast<unsigned>(std::max(1, granularity))) && total < (std::size_t{1} << 31)) {
    const __m128i round_up = _mm_set1_epi32(std::max(1, granularity) - 1);
    const __m128i shift = _mm_cvtsi32_si128(std::countr_zero(static_cast<unsigned>(std::max(1, granularity))));
    const auto leaf_tests4 = [&](__m128i n) {  // leaf_tests, per lane
      return _mm_cvtepi32_ps(_mm_srl_epi32(_mm_add_epi32(n, round_up), shift));
    };
    // A box per lane: lane a the box of axis a's bins so far; BBox::extend's
    // and BBox::half_area's operations, empty boxes of area 0.
    struct Boxes {
      __m128 lx, ly, lz, ux, uy, uz;
      void extend(const Boxes& b) {  // min_ps(b, a) is std::min(a, b); max_ps likewise
        lx = _mm_min_ps(b.lx, lx), ly = _mm_min_ps(b.ly, ly), lz = _mm_min_ps(b.lz, lz);
        ux = _mm_max_ps(b.ux, ux), uy = _mm_max_ps(b.uy, uy), uz = _mm_max_ps(b.uz, uz);
      }
      __m128 half_area() const {
        const __m128 filled =
            _mm_and_ps(_mm_and_ps(_mm_cmple_ps(lx, ux), _mm_cmple_ps(ly, uy)), _mm_cmple_ps(lz, uz));
        const __m128 ex = _mm_sub_ps(ux, lx), ey = _mm_sub_ps(uy, ly), ez = _mm_sub_ps(uz, lz);
        return _mm_and_ps(filled, _mm_add_ps(_mm_add_ps(_mm_mul_ps(ex, ey), _mm_mul_ps(ey, ez)), _mm_mul_ps(ez, ex)));
      }
    };
    const auto bin = [&](int j) {
      const BBox &x = bin_bounds[0][j], &y = bin_bounds[1][j], &z = bin_bounds[2][j];
      return Boxes{_mm_setr_ps(x.lower.x, y.lower.x, z.lower.x, 0.0f), _mm_setr_ps(x.lower.y, y.lower.y, z.lower.y, 0.0f),
                   _mm_setr_ps(x.lower.z, y.lower.z, z.lower.z, 0.0f), _mm_setr_ps(x.upper.x, y.upper.x, z.upper.x, 0.0f),
                   _mm_setr_ps(x.upper.y, y.upper.y, z.upper.y, 0.0f), _mm_setr_ps(x.upper.z, y.upper.z, z.upper.z, 0.0f)};
    };
    const auto count = [&](int j) {
      return _mm_setr_epi32(static_cast<int>(bin_count[0][j]), static_cast<int>(bin_count[1][j]),
                            static_cast<int>(bin_count[2][j]), 0);
    };
    const __m128 inf = _mm_set1_ps(std::numeric_limits<float>::infinity());
    const Boxes empty{inf, inf, inf, _mm_sub_ps(_mm_setzero_ps(), inf), _mm_sub_ps(_mm_setzero_ps(), inf),
                      _mm_sub_ps(_mm_setzero_ps(), inf)};
    __m128 right_cost[MaxBins];
    Boxes acc = empty;
    __m128i n = _mm_setzero_si128();
    for (int j = bins - 1; j > 0; --j) {
      acc.extend(bin(j));
      n = _mm_add_epi32(n, count(j));
      right_cost[j] = _mm_mul_ps(acc.half_area(), leaf_tests4(n));
    }
    // Per lane, the cheapest plane so far and its j: "cheaper" is strictly
    // less, as in the scalar sweep, so a NaN cost is never taken.
    const __m128i lanes = _mm_setr_epi32(splittable[0] ? -1 : 0, splittable[1] ? -1 : 0, splittable[2] ? -1 : 0, 0);
    const __m128i all = _mm_set1_epi32(static_cast<int>(total));
    __m128 best_cost = inf;
    __m128i best_j = _mm_setzero_si128();
    acc = empty;
    n = _mm_setzero_si128();
    for (int j = 1; j < bins; ++j) {
      acc.extend(bin(j - 1));
      n = _mm_add_epi32(n, count(j - 1));
      const __m128 cost = _mm_add_ps(_mm_mul_ps(acc.half_area(), leaf_tests4(n)), right_cost[j]);
      const __m128i both_sides = _mm_and_si128(_mm_cmpgt_epi32(n, _mm_setzero_si128()), _mm_cmpgt_epi32(all, n));
      const __m128 better =
          _mm_and_ps(_mm_cmplt_ps(cost, best_cost), _mm_castsi128_ps(_mm_and_si128(both_sides, lanes)));
      best_cost = _mm_or_ps(_mm_and_ps(better, cost), _mm_andnot_ps(better, best_cost));
      const __m128i take = _mm_castps_si128(better);
      best_j = _mm_or_si128(_mm_and_si128(take, _mm_set1_epi32(j)), _mm_andnot_si128(take, best_j));
    }
    alignas(16) float costs[4];
    alignas(16) std::int32_t js[4];
    _mm_store_ps(costs, best_cost);
    _mm_store_si128(reinterpret_cast<__m128i*>(js), best_j);
    ObjectSplit best;
    for (int axis = 0; axis < 3; ++axis) {
      if (costs[axis] < best.cost) {
        best.axis = axis;
        best.bin = js[axis] - 1;
        best.cost = costs[axis];
      }
    }
    if (best.axis >= 0) {  // both sides' boxes, gathered in the scalar sweep's order
      for (int b = 0; b <= best.bin; ++b) best.left.extend(bin_bounds[best.axis][b]);
      for (int b = bins - 1; b > best.bin; --b) best.right.extend(bin_bounds[best.axis][b]);
    }
    return best;
  }
#endif
  return best_split_of_bins_by_axis<MaxBins>(bin_bounds, bin_count, splittable, bins, granularity, total);
}

template <std::size_t MaxBins, typename Ref>
ObjectSplit find_object_split_in(std::span<const Ref> refs, const BBox& centroid_bounds, int bins, int granularity) {
  float lo[3], scale[3];
  bool splittable[3];
  for (int axis = 0; axis < 3; ++axis) {
    lo[axis] = centroid_bounds.lower[axis];
    const float extent = centroid_bounds.upper[axis] - lo[axis];
    splittable[axis] = extent > 0.0f;
    scale[axis] = splittable[axis] ? static_cast<float>(bins) / extent : 0.0f;
  }
  std::array<std::array<BBox, MaxBins>, 3> bin_bounds{};
  std::array<std::array<std::size_t, MaxBins>, 3> bin_count{};
  if (refs.size() < 2 * kBinningChunk) bin_all_axes<MaxBins>(refs, lo, scale, bins, bin_bounds, bin_count);
  else bin_all_axes_in_chunks<MaxBins>(refs, lo, scale, bins, bin_bounds, bin_count);
  return best_split_of_bins<MaxBins>(bin_bounds, bin_count, splittable, bins, granularity, refs.size());
}

// The cheapest object split of `refs` (anything with a `bounds` box, split by
// its centre), counting leaf tests in packs of `granularity`; both sides
// non-empty. The bin arrays are sized for the bins asked for (16 by
// default), not kMaxBins: setting up 64 bins per node cost more than binning
// the few triangles of the deep nodes.
template <typename Ref>
ObjectSplit find_object_split(std::span<const Ref> refs, const BBox& centroid_bounds, int bins, int granularity) {
  if (bins <= 16) return find_object_split_in<16>(refs, centroid_bounds, bins, granularity);
  if (bins <= 32) return find_object_split_in<32>(refs, centroid_bounds, bins, granularity);
  return find_object_split_in<kMaxBins>(refs, centroid_bounds, bins, granularity);
}

// Builds both children of a split: as two TBB tasks when the range is large
// enough to be worth it (Bvh2BuildOptions::parallel_threshold), else in turn.
template <typename BuildLeft, typename BuildRight>
void build_children(std::size_t count, std::size_t parallel_threshold, BuildLeft&& left, BuildRight&& right) {
  if (count >= parallel_threshold) {
    tbb::parallel_invoke(left, right);
  } else {
    left();
    right();
  }
}

}  // namespace raybench::bvh2_build
