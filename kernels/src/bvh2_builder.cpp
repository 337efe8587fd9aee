// Binned SAH BVH2 builder: Wald, "On fast Construction of SAH-based Bounding
// Volume Hierarchies", IEEE RT 2007. Subtrees are built in parallel with TBB.
// The tree's shape and leaf contents depend only on the input; with several
// threads the nodes' positions in the array may differ between builds, which
// changes no traversal result. NaN boxes bin as BBox::extend takes them (a
// NaN coordinate is never taken up); coincident centroids and ranges past
// max_sah_depth are halved, so the depth stays bounded.
// measured (constants, passes): docs/notes/kernels-builders.md
#include <algorithm>
#include <array>
#include <cstddef>
#include <atomic>
#include <limits>
#include <memory>
#include <type_traits>
#include <utility>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_reduce.h>

#if defined(__SSE2__)
#include <immintrin.h>
#endif


#include "raybench/bvh/bvh2.h"
#include "build_buffer.h"
#include "bvh2_build_util.h"

namespace raybench {
namespace {

// The centroid is the box's centre, computed where needed rather than
// stored. 32 bytes, 32-aligned: the box is one aligned load and one lane
// permute (box_lanes), where 28 bytes took six loads and shuffles, and a
// reference never straddles a cache line (measured:
// docs/notes/kernels-builders.md).
struct alignas(32) PrimRef {
  BBox bounds;
  std::uint32_t id;
  std::uint32_t unused = 0;
};
static_assert(sizeof(PrimRef) == 32 && offsetof(PrimRef, bounds) == 0 && sizeof(BBox) == 24);

#if defined(__AVX2__)
// bvh2_build::box_lanes for a PrimRef: lanes 0-2 the lower corner, 4-6 the
// upper, lanes 3 and 7 copies of lower.z and upper.z (finite wherever the
// box is, never the id's bits, which as a float would be a denormal).
inline __m256 box_lanes(const PrimRef& r) {
  return _mm256_permutevar8x32_ps(_mm256_load_ps(&r.bounds.lower.x), _mm256_setr_epi32(0, 1, 2, 2, 3, 4, 5, 5));
}
#endif

using bvh2_build::BuildBuffer;
using bvh2_build::centroid_bin;
using bvh2_build::kMaxBins;
using bvh2_build::ObjectSplit;

// The box and the centroid box of a range of references, gathered in SIMD
// registers (the same min/max and centre as BBox::extend and BBox::center).
struct RangeBounds {
#if defined(__SSE2__)
  bvh2_build::BoxAccumulator box, centroid_box;

  void extend(const PrimRef& r) {
#if defined(__AVX2__)
    extend(box_lanes(r));
#else
    using Box = bvh2_build::BoxAccumulator;
    const __m128 l = bvh2_build::load_vec3(r.bounds.lower), u = bvh2_build::load_vec3(r.bounds.upper);
    const __m128 c = _mm_mul_ps(_mm_add_ps(l, u), _mm_set1_ps(0.5f));
    box.extend(Box::key(l, u));
    centroid_box.extend(Box::key(c, c));
#endif
  }
#if defined(__AVX2__)
  // A reference's box_lanes: Box::key's operations, on one vector.
  void extend(__m256 corners) {
    const __m256 negate_upper = _mm256_setr_ps(0.0f, 0.0f, 0.0f, 0.0f, -0.0f, -0.0f, -0.0f, -0.0f);
    const __m128 c = centre(corners);
    box.extend(_mm256_xor_ps(corners, negate_upper));
    centroid_box.extend(bvh2_build::BoxAccumulator::key(c, c));
  }
  // BBox::center's operations, lanes 0-2.
  static __m128 centre(__m256 corners) {
    return _mm_mul_ps(_mm_add_ps(_mm256_castps256_ps128(corners), _mm256_extractf128_ps(corners, 1)), _mm_set1_ps(0.5f));
  }
#endif
  void extend(const RangeBounds& b) {
    box.extend(b.box);
    centroid_box.extend(b.centroid_box);
  }
  BBox bounds() const { return box.bounds(); }
  BBox centroids() const { return centroid_box.bounds(); }
#else
  BBox box, centroid_box;
  void extend(const PrimRef& r) {
    box.extend(r.bounds);
    centroid_box.extend(r.bounds.center());
  }
  void extend(const RangeBounds& b) {
    box.extend(b.box);
    centroid_box.extend(b.centroid_box);
  }
  BBox bounds() const { return box; }
  BBox centroids() const { return centroid_box; }
#endif
};

RangeBounds range_bounds(const PrimRef* first, const PrimRef* last) {
  RangeBounds b;
  for (; first != last; ++first) b.extend(*first);
  return b;
}

// References per task in the passes over all of them: small enough that a
// small mesh's (Wuson's 3,732 triangles) are made on both threads.
constexpr std::size_t kGrain = 1024;

// Ranges of at least this many references are partitioned in two halves at
// once (Builder::partition_in_halves). measured: docs/notes/kernels-builders.md
constexpr std::size_t kHalvedPartition = std::size_t{1} << 15;

// Ranges of fewer references are built into one thread's scratch
// (Builder::build_locally), whatever the parallel threshold: at most 4,093
// nodes, 128 KiB per thread.
constexpr std::size_t kMostLocalReferences = 2048;
// A local build must spawn no task: waiting for one, its thread could take
// up another range's local build, which would overwrite its scratch. Its
// ranges are binned and partitioned in one pass each.
static_assert(kMostLocalReferences <= 2 * bvh2_build::kBinningChunk && kMostLocalReferences <= kHalvedPartition);

class Builder {
 public:
  Builder(BuildBuffer<PrimRef>& refs, BuildBuffer<Bvh2Node>& nodes, const Bvh2BuildOptions& options)
      : refs_(refs), nodes_(nodes), options_(options), bins_(std::clamp(options.bin_count, 2, kMaxBins)) {}

  // Builds the subtree for refs_[begin, end), whose boxes are `range`, into
  // nodes_[node_index]. The children's boxes come out of the partition, so
  // no node reads its references more than twice (to bin, to partition).
  void build(std::uint32_t node_index, std::size_t begin, std::size_t end, const RangeBounds& range, int depth) {
    if (end - begin < local_below_) return build_locally(node_index, begin, end, range, depth);
    SharedSlots slots{*this};
    build(slots, node_index, begin, end, range, depth);
  }

  std::uint32_t node_count() const { return next_node_.load(); }

 private:
  // Node slots taken from the tree's array by every thread, one pair at a
  // time (the ranges built as parallel tasks).
  struct SharedSlots {
    Builder& builder;
    Bvh2Node* at(std::uint32_t i) { return &builder.nodes_[i]; }
    std::uint32_t take_pair() { return builder.next_node_.fetch_add(2, std::memory_order_relaxed); }
  };
  // Node slots in one thread's scratch array, local index 0 the subtree's
  // root (a range built on one thread, below the parallel threshold).
  struct LocalSlots {
    Bvh2Node* scratch;
    std::uint32_t used = 1;
    Bvh2Node* at(std::uint32_t i) { return scratch + i; }
    std::uint32_t take_pair() { return std::exchange(used, used + 2); }
  };

  // Builds a range that no task will share into this thread's scratch, then
  // takes all its slots from the tree's array at once and moves it there.
  // Taking every pair from the shared counter sent its cache line back and
  // forth between the cores (measured: docs/notes/kernels-builders.md). On
  // one thread the nodes land where they did, in depth-first order.
  void build_locally(std::uint32_t node_index, std::size_t begin, std::size_t end, const RangeBounds& range, int depth) {
    std::unique_ptr<BuildBuffer<Bvh2Node>>& scratch = scratch_.local();
    const std::size_t most = 2 * (end - begin) - 1;  // every leaf one reference
    if (scratch == nullptr || scratch->size() < most) scratch = std::make_unique<BuildBuffer<Bvh2Node>>(most);
    LocalSlots slots{scratch->data()};
    build(slots, 0, begin, end, range, depth);
    // Local index i > 0 goes to first + i - 1; the root to node_index.
    const std::uint32_t first = next_node_.fetch_add(slots.used - 1, std::memory_order_relaxed);
    const auto placed = [&](Bvh2Node n) {
      if (!n.is_leaf()) n.first_index += first - 1;  // an inner node's children (no leaf is empty here)
      return n;
    };
    std::construct_at(&nodes_[node_index], placed(slots.scratch[0]));
    for (std::uint32_t i = 1; i < slots.used; ++i) std::construct_at(&nodes_[first + i - 1], placed(slots.scratch[i]));
  }

  template <typename Slots>
  void build(Slots& slots, std::uint32_t node_index, std::size_t begin, std::size_t end, const RangeBounds& range,
             int depth) {
    Bvh2Node& node = *std::construct_at(slots.at(node_index), Bvh2Node{range.bounds()});
    const BBox centroids = range.centroids();
    const std::size_t count = end - begin;
    const auto make_leaf = [&] {
      node.first_index = static_cast<std::uint32_t>(begin);
      node.prim_count = static_cast<std::uint32_t>(count);
    };
    if (count <= 1) return make_leaf();
    const float leaf_cost = bvh2_build::leaf_tests(count, options_.leaf_granularity);
    // A split costs at least the traversal step: no need to bin a range
    // whose leaf costs no more (every range of at most 8 with 8-wide leaves).
    if (count <= static_cast<std::size_t>(options_.max_leaf_size) && leaf_cost <= options_.traversal_cost)
      return make_leaf();

    const ObjectSplit split = depth < options_.max_sah_depth
                                  ? bvh2_build::find_object_split(std::span<const PrimRef>(refs_.data() + begin, count),
                                                                  centroids, bins_for(count), options_.leaf_granularity)
                                  : ObjectSplit{};
    PrimRef* const first = refs_.data() + begin;
    PrimRef* const last = refs_.data() + end;
    PrimRef* middle = nullptr;
    RangeBounds left, right;
    if (split.axis >= 0) {
      const float split_cost = options_.traversal_cost + split.cost / node.bounds.half_area();
      if (split_cost >= leaf_cost && count <= static_cast<std::size_t>(options_.max_leaf_size)) return make_leaf();
      middle = partition_in_halves(first, last, centroids, split, bins_for(count), left, right);
      if (middle == first || middle == last) middle = nullptr;  // float rounding put all on one side
    } else if (count <= static_cast<std::size_t>(options_.max_leaf_size)) {
      return make_leaf();
    }
    if (middle == nullptr) {
      // All centroids coincide (e.g. duplicated or degenerate triangles), or the
      // tree is already max_sah_depth deep: halve the range.
      middle = first + count / 2;
      left = range_bounds(first, middle);
      right = range_bounds(middle, last);
    }

    const auto mid = static_cast<std::size_t>(middle - refs_.data());
    const std::uint32_t left_node = slots.take_pair();
    node.first_index = left_node;
    node.prim_count = 0;
    if constexpr (std::is_same_v<Slots, LocalSlots>) {
      build(slots, left_node, begin, mid, left, depth + 1);
      build(slots, left_node + 1, mid, end, right, depth + 1);
    } else {
      bvh2_build::build_children(
          count, options_.parallel_threshold, [&] { build(left_node, begin, mid, left, depth + 1); },
          [&] { build(left_node + 1, mid, end, right, depth + 1); });
    }
  }

  // Moves the references whose centroid bin (the bins find_object_split used)
  // is at most split.bin before the others, as std::partition, and returns
  // the first of the others; gathers both sides' boxes on the way.
  static PrimRef* partition(PrimRef* first, PrimRef* last, const BBox& centroids, const ObjectSplit& split, int bins,
                            RangeBounds& left, RangeBounds& right) {
    const int axis = split.axis;
    const float lo = centroids.lower[axis];
    const float scale = static_cast<float>(bins) / (centroids.upper[axis] - lo);
    // The boxes gather in locals, written out once: gathered in `left` and
    // `right` themselves, they lived in memory, as the swaps' float stores
    // may alias a SIMD vector, and every extend waited on the one before
    // it through a store and a load (measured: docs/notes/kernels-builders.md).
    RangeBounds l, r;
#if defined(__AVX2__)
    // centroid_bin as bin_all_axes computes it (the same lanes, the same
    // bins), the split axis's lane compared: one load and permute per
    // reference, shared with its box's extend.
    const __m128 lo4 = _mm_set1_ps(lo), scale4 = _mm_set1_ps(scale);
    const __m128 zero = _mm_setzero_ps(), last_bin = _mm_set1_ps(static_cast<float>(bins - 1));
    const __m128i split_bin = _mm_set1_epi32(split.bin);
    const int axis_bit = 1 << axis;
    const auto goes_left = [&](__m256 corners) {
      const __m128 f = _mm_mul_ps(_mm_sub_ps(RangeBounds::centre(corners), lo4), scale4);
      const __m128i b = _mm_cvttps_epi32(_mm_min_ps(_mm_max_ps(f, zero), last_bin));
      return (_mm_movemask_ps(_mm_castsi128_ps(_mm_cmpgt_epi32(b, split_bin))) & axis_bit) == 0;
    };
    for (;;) {
      __m256 front, back;
      while (first != last && goes_left(front = box_lanes(*first))) l.extend(front), ++first;
      while (first != last && !goes_left(back = box_lanes(*(last - 1)))) r.extend(back), --last;
      if (first == last) break;
      // *first goes right, *(last - 1) left: swapped, their boxes already read.
      std::swap(*first, *--last);
      l.extend(back);
      r.extend(front);
      ++first;
    }
#else
    const auto goes_left = [&](const PrimRef& r) {
      return centroid_bin(r.bounds.center()[axis], lo, scale, bins) <= split.bin;
    };
    for (;;) {
      while (first != last && goes_left(*first)) l.extend(*first++);
      while (first != last && !goes_left(*(last - 1))) r.extend(*--last);
      if (first == last) break;
      std::swap(*first, *--last);
      l.extend(*first++);
      r.extend(*last);
    }
#endif
    left = l;
    right = r;
    return first;
  }

  // As partition, for a range of at least kHalvedPartition references: its
  // halves are partitioned (the same way) as two parallel tasks, then the
  // right side of the first half and the left side of the second trade
  // places, as many as the smaller of them holds. The root's partition alone
  // left the other thread idle (measured: docs/notes/kernels-builders.md).
  // The halves depend on the range's size alone, so
  // the references' order, and the tree, are the same on any thread count;
  // each side holds the references it held, in another order.
  static PrimRef* partition_in_halves(PrimRef* first, PrimRef* last, const BBox& centroids, const ObjectSplit& split,
                                      int bins, RangeBounds& left, RangeBounds& right) {
    const auto count = static_cast<std::size_t>(last - first);
    if (count < kHalvedPartition) return partition(first, last, centroids, split, bins, left, right);
    PrimRef* const half = first + count / 2;
    PrimRef *left_end = nullptr, *right_end = nullptr;  // of the first half's left side, of the second's
    RangeBounds left0, right0, left1, right1;
    tbb::parallel_invoke(
        [&] { left_end = partition_in_halves(first, half, centroids, split, bins, left0, right0); },
        [&] { right_end = partition_in_halves(half, last, centroids, split, bins, left1, right1); });
    // [first, left_end) left, [left_end, half) right, [half, right_end) left, [right_end, last) right.
    const auto trade = static_cast<std::ptrdiff_t>(std::min(half - left_end, right_end - half));
    tbb::parallel_for(tbb::blocked_range<std::ptrdiff_t>(0, trade, kGrain), [&](const tbb::blocked_range<std::ptrdiff_t>& r) {
      std::swap_ranges(left_end + r.begin(), left_end + r.end(), right_end - trade + r.begin());
    });
    left0.extend(left1);
    right0.extend(right1);
    left = left0;
    right = right0;
    return left_end + (right_end - half);
  }

  // Fewer bins for small ranges, where evaluating 16 bins costs more than
  // binning the few triangles: one bin per two triangles, at least 8
  // (Bvh2BuildOptions::bin_count at most); the tree's SAH cost is
  // unchanged (measured: docs/notes/kernels-builders.md).
  int bins_for(std::size_t count) const {
    return std::min(bins_, std::max(8, static_cast<int>(std::min<std::size_t>(count / 2, kMaxBins))));
  }

  BuildBuffer<PrimRef>& refs_;
  BuildBuffer<Bvh2Node>& nodes_;
  const Bvh2BuildOptions& options_;
  const int bins_;
  const std::size_t local_below_ = std::min(options_.parallel_threshold, kMostLocalReferences);
  tbb::enumerable_thread_specific<std::unique_ptr<BuildBuffer<Bvh2Node>>> scratch_;
  // On a cache line of its own: the members above are read at every node.
  alignas(64) std::atomic<std::uint32_t> next_node_{1};
};

}  // namespace

namespace {

// The build over n primitives whose boxes bounds_of(i) gives.
template <typename BoundsOf>
Bvh2 build_binned_sah(std::size_t n, BoundsOf bounds_of, const Bvh2BuildOptions& options) {
  Bvh2 bvh;
  if (n == 0) {
    bvh.nodes.resize(1);  // an empty leaf whose empty box no ray enters
    return bvh;
  }
  BuildBuffer<PrimRef> refs(n);
  const RangeBounds all = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, n, kGrain), RangeBounds{},
      [&](const tbb::blocked_range<std::size_t>& r, RangeBounds b) {
        for (std::size_t i = r.begin(); i != r.end(); ++i)
          b.extend(*std::construct_at(&refs[i], PrimRef{bounds_of(i), static_cast<std::uint32_t>(i)}));
        return b;
      },
      [](RangeBounds a, const RangeBounds& b) {
        a.extend(b);
        return a;
      });
  BuildBuffer<Bvh2Node> nodes(2 * n - 1);  // at most: every leaf one primitive
  Builder builder(refs, nodes, options);
  builder.build(0, 0, refs.size(), all, 0);
  bvh.nodes.assign(nodes.data(), nodes.data() + builder.node_count());
  bvh.prim_ids.resize(refs.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, refs.size(), kGrain), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) bvh.prim_ids[i] = refs[i].id;
  });
  return bvh;
}

}  // namespace

Bvh2 build_bvh2_binned_sah(std::span<const Triangle> triangles, const Bvh2BuildOptions& options) {
  return build_binned_sah(triangles.size(), [&](std::size_t i) { return triangle_bounds(triangles[i]); }, options);
}

Bvh2 build_bvh2_binned_sah(std::span<const BBox> prim_bounds, const Bvh2BuildOptions& options) {
  return build_binned_sah(prim_bounds.size(), [&](std::size_t i) { return prim_bounds[i]; }, options);
}

double Bvh2::sah_cost(int leaf_granularity) const {
  const double root_area = nodes.empty() ? 0.0 : nodes[0].bounds.half_area();
  if (!(root_area > 0.0)) return 0.0;
  const auto g = static_cast<std::uint32_t>(std::max(1, leaf_granularity));
  double cost = 0.0;
  for (const Bvh2Node& n : nodes) {
    const double area = n.bounds.half_area();
    cost += n.is_leaf() ? area * ((n.prim_count + g - 1) / g) : area;  // traversal and intersection cost 1
  }
  return cost / root_area;
}

}  // namespace raybench
