// Spatial-split BVH (SBVH) builder: Stich, Friedrich & Dietrich, "Spatial
// splits in bounding volume hierarchies", HPG 2009. Top-down as the binned
// SAH builder, over references (a triangle and a box holding the part of it
// that the reference stands for). At each node the best binned object split
// is found; where its two sides overlap by more than alpha = 1e-5 of the
// root's area (the paper's restriction), binned spatial splits are
// evaluated too: bin_count planes per axis across the node, each reference
// chopped into the bins it spans by clipping its triangle (not its box) at
// the bin planes. A spatial split sends a reference that straddles the plane
// to both sides with its two clipped boxes, or, where that is cheaper by the
// SAH, whole to one side (the paper's reference unsplitting).
//
// What holds, for every triangle: each reference's box contains the part of
// the triangle it stands for, the union of those parts is the triangle (so
// the union of the boxes of the leaves that hold it covers it), and the
// triangle is in at least one leaf, degenerate ones included. Clipped boxes
// are rounded outward: the crossing of an edge with a plane is computed in
// double with an error bound and widened to the enclosing floats, so a box
// is never smaller than the exact clipped part, and at most about one ulp
// larger. A triangle with a non-finite coordinate is never clipped.
//
// Reference growth is bounded: the references live in one array of
// (1 + spatial_split_budget) * n slots; a node owns the slots of its range
// and the free ones after it, and splits at most as many references as it
// has free slots. Spatial splits whose straddlers fit are preferred; where
// none fit, the one made splits the straddlers that gain most and sends the
// rest whole to their cheaper side, and is taken only if the split so made
// still beats the object split. A split hands the free slots to its
// children in proportion to their references, so the budget's share of each
// subtree depends only on the input: the tree does too (its nodes are
// renumbered depth-first at the end), whether or not the subtrees were
// built in parallel (TBB, as the binned builder).
//
// Depth: past max_sah_depth ranges are halved, as in the other builders, so
// the depth stays within max_sah_depth + 32.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "bvh2_build_util.h"

namespace raybench {
namespace {

using bvh2_build::kMaxBins;
using bvh2_build::leaf_tests;
using bvh2_build::ObjectSplit;

// 1e-5: Stich et al. 2009 (their alpha, relative to the root's surface area).
constexpr float kAlpha = 1e-5f;

struct Ref {
  BBox bounds;  // contains the part of triangle `id` that this reference stands for
  std::uint32_t id;
};

Vec3f centroid_of(const Ref& r) { return r.bounds.center(); }

// a ∩ b, or the canonical empty box (which extends nothing).
BBox intersection(const BBox& a, const BBox& b) {
  const BBox c{max(a.lower, b.lower), min(a.upper, b.upper)};
  return c.empty() ? BBox{} : c;
}

// The largest float not above x, and the smallest float not below it.
float float_below(double x) {
  const float f = static_cast<float>(x);
  return static_cast<double>(f) > x ? std::nextafter(f, -std::numeric_limits<float>::infinity()) : f;
}
float float_above(double x) {
  const float f = static_cast<float>(x);
  return static_cast<double>(f) < x ? std::nextafter(f, std::numeric_limits<float>::infinity()) : f;
}

// Where edge ab crosses the plane x[axis] = plane (a and b on opposite
// sides of it). Conservative: a box that contains the exact point. In
// double, on float inputs (exact in double), the crossing's coordinate is
// within about 9.2 u (|a| + |b|) of exact, u = 2^-53 (three roundings for
// the parameter t, three for a + t (b - a), one for the widening), so
// widening by 16 u (|a| + |b|) = 2^-49 (|a| + |b|) and rounding outward to
// floats encloses it; it lies between a and b, which bounds the box too.
// Not conservative: the point in float arithmetic, for the SAH estimates of
// the binning, which only the partition's boxes must not undercut.
template <bool Conservative>
BBox edge_crossing(Vec3f a, Vec3f b, int axis, float plane) {
  BBox p;
  if constexpr (!Conservative) {
    const float t = (plane - a[axis]) / (b[axis] - a[axis]);
    p.lower = p.upper = a + (b - a) * t;
    p.lower[axis] = p.upper[axis] = plane;
    return p;
  }
  const double t =
      std::clamp((static_cast<double>(plane) - a[axis]) / (static_cast<double>(b[axis]) - a[axis]), 0.0, 1.0);
  for (int j = 0; j < 3; ++j) {
    if (j == axis) {
      p.lower[j] = p.upper[j] = plane;
      continue;
    }
    const double aj = a[j], bj = b[j];
    const double x = aj + t * (bj - aj);
    const double err = 0x1p-49 * (std::fabs(aj) + std::fabs(bj));
    p.lower[j] = std::max(float_below(x - err), std::min(a[j], b[j]));
    p.upper[j] = std::min(float_above(x + err), std::max(a[j], b[j]));
  }
  return p;
}

bool is_finite(const Triangle& t) { return is_finite(t.v0) && is_finite(t.v1) && is_finite(t.v2); }

// Splits the part of finite triangle t inside `box` at the plane
// x[axis] = plane: left contains t ∩ box ∩ {x[axis] <= plane}, right
// contains t ∩ box ∩ {x[axis] >= plane} (Conservative; else up to float
// rounding); a side the triangle does not reach is the empty box. The part
// of t on one side is the convex hull of its vertices on that side and the
// crossings of its edges with the plane.
template <bool Conservative>
void split_triangle(const Triangle& t, const BBox& box, int axis, float plane, BBox& left, BBox& right) {
  const Vec3f v[3] = {t.v0, t.v1, t.v2};
  BBox l, r;
  for (int e = 0; e < 3; ++e) {
    const Vec3f a = v[e], b = v[(e + 1) % 3];
    if (a[axis] <= plane) l.extend(a);
    if (a[axis] >= plane) r.extend(a);
    if ((a[axis] < plane && plane < b[axis]) || (b[axis] < plane && plane < a[axis])) {
      const BBox p = edge_crossing<Conservative>(a, b, axis, plane);
      l.extend(p);
      r.extend(p);
    }
  }
  BBox left_slab = box, right_slab = box;
  left_slab.upper[axis] = std::min(left_slab.upper[axis], plane);
  right_slab.lower[axis] = std::max(right_slab.lower[axis], plane);
  left = intersection(l, left_slab);
  right = intersection(r, right_slab);
}

// bins equal slabs across a node's bounds on one axis; planes[0] and
// planes[bins] are the bounds, and the planes never decrease.
struct SpatialBins {
  int axis;
  int bins;
  float lo, scale;
  float planes[kMaxBins + 1];

  SpatialBins(int axis_, int bins_, float lower, float upper) : axis(axis_), bins(bins_), lo(lower) {
    const float extent = upper - lower;
    scale = static_cast<float>(bins) / extent;
    for (int i = 0; i < bins; ++i) planes[i] = lower + extent * (static_cast<float>(i) / static_cast<float>(bins));
    planes[bins] = upper;
  }

  // The bin i with planes[i] <= x < planes[i + 1] (the first or last bin
  // beyond the bounds; bin 0 for NaN).
  int bin_of(float x) const {
    int i = bvh2_build::centroid_bin(x, lo, scale, bins);
    while (i > 0 && x < planes[i]) --i;
    while (i < bins - 1 && x >= planes[i + 1]) ++i;
    return i;
  }

  // The bins a reference spans: first .. last, where the plane between bins
  // j - 1 and j cuts it (first < j <= last) only if its box reaches across.
  // A triangle that cannot be clipped (a non-finite coordinate) spans the
  // one bin of its centroid.
  std::pair<int, int> span(const Ref& r, std::span<const Triangle> triangles) const {
    const float lower = r.bounds.lower[axis], upper = r.bounds.upper[axis];
    const int first = bin_of(lower);
    int last = bin_of(upper);
    while (last > first && upper <= planes[last]) --last;
    if (first < last && !is_finite(triangles[r.id])) {
      const int b = bin_of(r.bounds.center()[axis]);
      return {b, b};
    }
    return {first, last};
  }
};

struct SpatialSplit {
  int axis = -1;                                        // -1: none
  int plane = 0;                                        // SpatialBins::planes[plane] splits
  float cost = std::numeric_limits<float>::infinity();  // area-weighted, as ObjectSplit::cost
  BBox left, right;                                     // the two sides' bounds with every straddling reference split
  std::size_t left_count = 0, right_count = 0;
};

class SbvhBuilder {
 public:
  SbvhBuilder(std::span<const Triangle> triangles, std::vector<Ref>& refs, std::vector<Bvh2Node>& nodes,
              const Bvh2BuildOptions& options, float root_area)
      : triangles_(triangles),
        refs_(refs),
        nodes_(nodes),
        options_(options),
        bins_(std::clamp(options.bin_count, 2, kMaxBins)),
        min_overlap_(kAlpha * root_area) {}

  // Builds the subtree for refs_[begin, end) into nodes_[node_index]; the
  // slots [end, capacity) are free for the references its splits add.
  void build(std::uint32_t node_index, std::size_t begin, std::size_t end, std::size_t capacity, int depth) {
    BBox bounds, centroid_bounds;
    for (std::size_t i = begin; i < end; ++i) {
      bounds.extend(refs_[i].bounds);
      centroid_bounds.extend(centroid_of(refs_[i]));
    }
    Bvh2Node& node = nodes_[node_index];
    node.bounds = bounds;
    const std::size_t count = end - begin;
    const bool may_be_leaf = count <= static_cast<std::size_t>(options_.max_leaf_size);
    const auto make_leaf = [&] {
      node.first_index = static_cast<std::uint32_t>(begin);
      node.prim_count = static_cast<std::uint32_t>(count);
    };
    if (count <= 1) return make_leaf();

    ObjectSplit object;
    SpatialSplit spatial;
    if (depth < options_.max_sah_depth) {
      object = bvh2_build::find_object_split(std::span<const Ref>(refs_.data() + begin, count), centroid_bounds, bins_,
                                             options_.leaf_granularity);
      // Spatial splits only where the object split leaves the children
      // overlapping (or finds none: the centroids coincide).
      if (object.axis < 0 || intersection(object.left, object.right).half_area() > min_overlap_)
        spatial = find_spatial_split(begin, end, bounds, capacity - end);
    }
    // The spatial split as it can be made within the budget, if its
    // estimate beats the object split; the cheaper one is taken.
    SpatialPlan plan;
    if (spatial.axis >= 0 && spatial.cost < object.cost)
      plan = plan_spatial_split(begin, end, capacity, bounds, spatial);
    const bool use_spatial = plan.cost < object.cost;
    if (object.axis >= 0 || use_spatial) {
      const float split_cost = options_.traversal_cost + (use_spatial ? plan.cost : object.cost) / bounds.half_area();
      if (split_cost >= leaf_tests(count, options_.leaf_granularity) && may_be_leaf) return make_leaf();
    } else if (may_be_leaf) {
      return make_leaf();  // no split (coincident centroids, or max_sah_depth reached)
    }

    // Children: refs_[begin, left_end) and refs_[right_begin, right_end).
    std::size_t left_end = 0, right_begin = 0, right_end = 0;
    if (use_spatial) {
      std::copy(plan.left.begin(), plan.left.end(), refs_.begin() + static_cast<std::ptrdiff_t>(begin));
      std::copy(plan.right.begin(), plan.right.end(),
                refs_.begin() + static_cast<std::ptrdiff_t>(begin + plan.left.size()));
      // At most as many references were split as there were free slots.
      const std::size_t middle = begin + plan.left.size(), made_end = middle + plan.right.size();
      plan = SpatialPlan{};  // not held while the subtrees are built
      place_children(begin, middle, made_end, capacity, left_end, right_begin, right_end);
    } else if (object.axis < 0 ||
               !object_partition(begin, end, capacity, centroid_bounds, object, left_end, right_begin, right_end)) {
      // Past max_sah_depth, or no split that leaves both sides non-empty:
      // halve the range, which bounds the depth.
      place_children(begin, begin + count / 2, end, capacity, left_end, right_begin, right_end);
    }

    const std::uint32_t left = next_node_.fetch_add(2);
    node.first_index = left;
    node.prim_count = 0;
    bvh2_build::build_children(
        count, options_.parallel_threshold, [&] { build(left, begin, left_end, right_begin, depth + 1); },
        [&] { build(left + 1, right_begin, right_end, capacity, depth + 1); });
  }

  std::uint32_t node_count() const { return next_node_.load(); }

 private:
  // The left child holds refs_[begin, middle) and the right one
  // refs_[middle, end); the free slots [end, capacity) are shared between
  // them in proportion to their references: the right range moves up by the
  // left child's share. Sets the children's ranges.
  void place_children(std::size_t begin, std::size_t middle, std::size_t end, std::size_t capacity,
                      std::size_t& left_end, std::size_t& right_begin, std::size_t& right_end) {
    const std::size_t free = capacity - end;
    const std::size_t left_free = free * (middle - begin) / (end - begin);
    std::copy_backward(refs_.begin() + static_cast<std::ptrdiff_t>(middle),
                       refs_.begin() + static_cast<std::ptrdiff_t>(end),
                       refs_.begin() + static_cast<std::ptrdiff_t>(end + left_free));
    left_end = middle;
    right_begin = middle + left_free;
    right_end = end + left_free;
  }

  bool object_partition(std::size_t begin, std::size_t end, std::size_t capacity, const BBox& centroid_bounds,
                        const ObjectSplit& split, std::size_t& left_end, std::size_t& right_begin,
                        std::size_t& right_end) {
    const int axis = split.axis;
    const float lo = centroid_bounds.lower[axis];
    const float scale = static_cast<float>(bins_) / (centroid_bounds.upper[axis] - lo);
    Ref* mid = std::partition(refs_.data() + begin, refs_.data() + end, [&](const Ref& r) {
      return bvh2_build::centroid_bin(centroid_of(r)[axis], lo, scale, bins_) <= split.bin;
    });
    const auto middle = static_cast<std::size_t>(mid - refs_.data());
    if (middle == begin || middle == end) return false;  // float rounding put all on one side
    place_children(begin, middle, end, capacity, left_end, right_begin, right_end);
    return true;
  }

  // The cheapest spatial split of refs_[begin, end) as estimated with every
  // straddling reference split, both sides non-empty: among those that
  // split no more references than the `free` slots, or if there is none,
  // among all (plan_spatial_split then splits what it can).
  SpatialSplit find_spatial_split(std::size_t begin, std::size_t end, const BBox& bounds, std::size_t free) const {
    const std::size_t count = end - begin;
    const int g = options_.leaf_granularity;
    SpatialSplit best, best_over_budget;
    for (int axis = 0; axis < 3; ++axis) {
      const float lo = bounds.lower[axis], hi = bounds.upper[axis];
      if (!(hi > lo) || !std::isfinite(hi - lo)) continue;
      const SpatialBins bins(axis, bins_, lo, hi);
      std::array<BBox, kMaxBins> bin_bounds{};
      std::array<std::size_t, kMaxBins> entries{}, exits{};  // references whose first / last bin this is
      for (std::size_t i = begin; i < end; ++i) {
        const Ref& r = refs_[i];
        const auto [first, last] = bins.span(r, triangles_);
        ++entries[first];
        ++exits[last];
        // Chop the reference at each plane inside it, left to right.
        BBox rest = r.bounds;
        for (int b = first; b < last; ++b) {
          BBox left, right;
          split_triangle<false>(triangles_[r.id], rest, axis, bins.planes[b + 1], left, right);
          bin_bounds[b].extend(left);
          rest = right;
        }
        bin_bounds[last].extend(rest);
      }
      // The plane before bin j: references that start left of it go left,
      // those that end right of it go right (straddlers both ways).
      bvh2_build::sweep_bins(bin_bounds, entries, exits, bins_, g,
                             [&](int j, float cost, const BBox& left, const BBox& right, std::size_t n, std::size_t m) {
                               if (n == 0 || m == 0) return;
                               SpatialSplit& to_improve = n + m - count <= free ? best : best_over_budget;
                               if (cost < to_improve.cost) to_improve = {axis, j, cost, left, right, n, m};
                             });
    }
    return best.axis >= 0 ? best : best_over_budget;
  }

  // The references of either side of a spatial split as made, and the
  // area-weighted cost of the two sides (infinite if a side is empty).
  struct SpatialPlan {
    std::vector<Ref> left, right;
    float cost = std::numeric_limits<float>::infinity();
  };

  // Splits refs_[begin, end) at the spatial split's plane, into a plan. A
  // straddling reference goes to both sides clipped, or whole to one side
  // where the SAH of the split's sides says that is cheaper (reference
  // unsplitting, Stich et al.). Only as many references as the
  // node has free slots can be split: those that gain most by it (ties by
  // triangle index); the others go whole to their cheaper side.
  SpatialPlan plan_spatial_split(std::size_t begin, std::size_t end, std::size_t capacity, const BBox& bounds,
                                 const SpatialSplit& split) const {
    const int g = options_.leaf_granularity;
    const SpatialBins bins(split.axis, bins_, bounds.lower[split.axis], bounds.upper[split.axis]);
    const float plane = bins.planes[split.plane];
    const float nl = leaf_tests(split.left_count, g), nr = leaf_tests(split.right_count, g);
    const float nl1 = leaf_tests(split.left_count - 1, g), nr1 = leaf_tests(split.right_count - 1, g);
    const float al = split.left.half_area(), ar = split.right.half_area();
    const float split_cost = al * nl + ar * nr;
    struct Straddler {
      Ref whole, left, right;
      bool whole_left;  // the cheaper side for it whole
      float gain;       // cost whole on that side minus cost split
    };
    SpatialPlan plan;
    std::vector<Ref>& left = plan.left;
    std::vector<Ref>& right = plan.right;
    std::vector<Straddler> straddlers;
    for (std::size_t i = begin; i < end; ++i) {
      const Ref& r = refs_[i];
      const auto [first, last] = bins.span(r, triangles_);
      if (last < split.plane) {
        left.push_back(r);
        continue;
      }
      if (first >= split.plane) {
        right.push_back(r);
        continue;
      }
      Straddler s{r, r, r, false, 0.0f};
      split_triangle<true>(triangles_[r.id], r.bounds, split.axis, plane, s.left.bounds, s.right.bounds);
      if (s.left.bounds.empty()) {
        right.push_back(s.right);
      } else if (s.right.bounds.empty()) {
        left.push_back(s.left);
      } else {
        BBox left_with = split.left, right_with = split.right;
        left_with.extend(r.bounds);
        right_with.extend(r.bounds);
        const float all_left = left_with.half_area() * nl + ar * nr1;
        const float all_right = al * nl1 + right_with.half_area() * nr;
        s.whole_left = all_left <= all_right;
        s.gain = std::min(all_left, all_right) - split_cost;
        if (std::isnan(s.gain)) s.gain = -std::numeric_limits<float>::infinity();  // infinite areas: keep it whole
        straddlers.push_back(s);
      }
    }
    std::sort(straddlers.begin(), straddlers.end(), [](const Straddler& a, const Straddler& b) {
      return a.gain != b.gain ? a.gain > b.gain : a.whole.id < b.whole.id;
    });
    std::size_t free = capacity - end;
    for (const Straddler& s : straddlers) {
      if (s.gain > 0.0f && free > 0) {
        --free;
        left.push_back(s.left);
        right.push_back(s.right);
      } else {
        (s.whole_left ? left : right).push_back(s.whole);
      }
    }
    if (left.empty() || right.empty()) return plan;
    BBox left_bounds, right_bounds;
    for (const Ref& r : left) left_bounds.extend(r.bounds);
    for (const Ref& r : right) right_bounds.extend(r.bounds);
    plan.cost =
        left_bounds.half_area() * leaf_tests(left.size(), g) + right_bounds.half_area() * leaf_tests(right.size(), g);
    return plan;
  }

  std::span<const Triangle> triangles_;
  std::vector<Ref>& refs_;
  std::vector<Bvh2Node>& nodes_;
  const Bvh2BuildOptions& options_;
  const int bins_;
  const float min_overlap_;  // half area of the children's overlap above which spatial splits are tried
  std::atomic<std::uint32_t> next_node_{1};
};

}  // namespace

Bvh2 build_bvh2_sbvh(std::span<const Triangle> triangles, const Bvh2BuildOptions& options) {
  Bvh2 bvh;
  const std::size_t n = triangles.size();
  if (n == 0) {
    bvh.nodes.resize(1);  // an empty leaf whose empty box no ray enters
    return bvh;
  }
  const double budget = std::max(0.0, static_cast<double>(options.spatial_split_budget));
  const auto capacity = static_cast<std::size_t>(static_cast<double>(n) * (1.0 + budget));
  std::vector<Ref> refs(std::max(capacity, n));
  BBox root;
  for (std::size_t i = 0; i < n; ++i) {
    refs[i] = {triangle_bounds(triangles[i]), static_cast<std::uint32_t>(i)};
    root.extend(refs[i].bounds);
  }
  std::vector<Bvh2Node> nodes(2 * refs.size());
  SbvhBuilder builder(triangles, refs, nodes, options, root.half_area());
  builder.build(0, 0, n, refs.size(), 0);

  // Depth first from the root, children side by side: the node order and the
  // leaves' references (prim_ids) then depend only on the tree.
  bvh.nodes.reserve(builder.node_count());
  bvh.nodes.push_back(nodes[0]);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> stack{{0, 0}};  // (built node, its copy)
  while (!stack.empty()) {
    const auto [from, to] = stack.back();
    stack.pop_back();
    const Bvh2Node& node = nodes[from];
    if (node.is_leaf()) {
      bvh.nodes[to].first_index = static_cast<std::uint32_t>(bvh.prim_ids.size());
      for (std::uint32_t i = 0; i < node.prim_count; ++i) bvh.prim_ids.push_back(refs[node.first_index + i].id);
      continue;
    }
    const auto children = static_cast<std::uint32_t>(bvh.nodes.size());
    bvh.nodes[to].first_index = children;
    bvh.nodes.push_back(nodes[node.first_index]);
    bvh.nodes.push_back(nodes[node.first_index + 1]);
    stack.push_back({node.first_index + 1, children + 1});
    stack.push_back({node.first_index, children});
  }
  return bvh;
}

}  // namespace raybench
