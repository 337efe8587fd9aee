// my_kernel: a ray-tracing kernel as a user writes one in their own
// repository, against raybench's installed plugin header and nothing else of
// raybench. A plain Möller–Trumbore triangle test and a BVH2 built with
// binned SAH (or median splits), traced closest-first with a stack.
//
// Options (the text after "plugin:PATH:", ':'-separated), checked before any
// scene is loaded:
//   leaf=N           at most N triangles per leaf, 1..64 (default 4)
//   builder=sah      binned surface area heuristic, 16 bins (the default)
//   builder=median   split the largest centroid axis at the median
//
// Thread safety: build runs on one thread (it ignores input->threads);
// intersect and occluded only read the accel, so raybench may call them
// concurrently. Degenerate triangles (zero area, repeated vertices) are kept
// in the tree and never hit: Möller–Trumbore's determinant is 0 for them.
//
// MY_KERNEL_DROP_EVERY=N (a compile definition, off by default) makes the
// kernel wrong on purpose: it reports a miss for about one ray in N. It is a
// demonstration of what `raybench gate` catches; see README.md.
#include <raybench/plugin.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <new>
#include <string>
#include <vector>

namespace {

struct Vec3 {
  float x, y, z;
};
inline Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3 cross(Vec3 a, Vec3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
inline float dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline float axis(const Vec3& v, int a) { return a == 0 ? v.x : a == 1 ? v.y : v.z; }

struct Box {
  Vec3 lo{std::numeric_limits<float>::infinity(), std::numeric_limits<float>::infinity(), std::numeric_limits<float>::infinity()};
  Vec3 hi{-std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity()};
  void grow(Vec3 p) {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }
  void grow(const Box& b) { grow(b.lo), grow(b.hi); }
  float area() const {
    if (!(lo.x <= hi.x)) return 0.0f;
    const Vec3 e = hi - lo;
    return 2.0f * (e.x * e.y + e.y * e.z + e.z * e.x);
  }
};

// A node of the tree: a leaf when count > 0 (triangles first .. first+count
// of the reordered array), otherwise an inner node whose children are nodes
// first and first + 1.
struct Node {
  Box box;
  uint32_t first = 0;
  uint32_t count = 0;
};

// A triangle as Möller–Trumbore wants it, with the scene's index.
struct Tri {
  Vec3 v0, e1, e2;
  int32_t prim;
};

struct Options {
  unsigned leaf = 4;
  bool median = false;
};

struct Accel {
  std::vector<Node> nodes;
  std::vector<Tri> tris;
};

void write_error(char* error, size_t size, const std::string& message) {
  if (error && size) std::snprintf(error, size, "%s", message.c_str());
}

// Parses "leaf=N:builder=sah"; returns "" when valid, else the problem.
std::string parse_options(const char* text, Options& out) {
  std::string s = text ? text : "";
  size_t start = 0;
  while (start <= s.size()) {
    const size_t end = std::min(s.find(':', start), s.size());
    const std::string item = s.substr(start, end - start);
    start = end + 1;
    if (item.empty()) continue;
    if (item.rfind("leaf=", 0) == 0) {
      const std::string value = item.substr(5);
      char* rest = nullptr;
      const long n = value.empty() ? 0 : std::strtol(value.c_str(), &rest, 10);
      if (value.empty() || *rest != '\0' || n < 1 || n > 64) return "leaf=" + value + ": want an integer from 1 to 64";
      out.leaf = static_cast<unsigned>(n);
    } else if (item == "builder=sah") {
      out.median = false;
    } else if (item == "builder=median") {
      out.median = true;
    } else {
      return "unknown option '" + item + "' (known: leaf=N, builder=sah, builder=median)";
    }
  }
  return "";
}

// The centroid's bin along an axis; non-finite coordinates go to bin 0.
inline int bin_of(float c, float lo, float scale, int bins) {
  const float f = (c - lo) * scale;
  if (!(f >= 0.0f)) return 0;
  return std::min(bins - 1, static_cast<int>(f));
}

// Builds the tree over prims (indices into boxes/centroids) in place.
void build_tree(Accel& accel, const std::vector<Box>& boxes, const std::vector<Vec3>& centroids, std::vector<uint32_t>& prims,
                const Options& options) {
  constexpr int kBins = 16;
  struct Task {
    uint32_t node, begin, end;
  };
  accel.nodes.reserve(2 * prims.size() / std::max(1u, options.leaf) + 1);
  accel.nodes.push_back({});
  std::vector<Task> tasks{{0, 0, static_cast<uint32_t>(prims.size())}};
  while (!tasks.empty()) {
    const Task task = tasks.back();
    tasks.pop_back();
    Box box, cbox;
    for (uint32_t i = task.begin; i < task.end; ++i) box.grow(boxes[prims[i]]), cbox.grow(centroids[prims[i]]);
    accel.nodes[task.node].box = box;
    const uint32_t count = task.end - task.begin;
    if (count <= options.leaf) {
      accel.nodes[task.node].first = task.begin;
      accel.nodes[task.node].count = count;
      continue;
    }
    const Vec3 extent = cbox.hi - cbox.lo;
    int split_axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : extent.y >= extent.z ? 1 : 2;
    uint32_t mid = task.begin + count / 2;
    bool split_found = false;
    if (!options.median) {
      // Binned SAH: the cheapest of the 3 x 15 bin boundaries.
      float best_cost = std::numeric_limits<float>::infinity();
      int best_axis = -1, best_bin = 0;
      for (int a = 0; a < 3; ++a) {
        const float lo = axis(cbox.lo, a), width = axis(cbox.hi, a) - lo;
        if (!(width > 0.0f) || !std::isfinite(width)) continue;
        const float scale = kBins / width;
        Box bin_box[kBins];
        uint32_t bin_count[kBins] = {};
        for (uint32_t i = task.begin; i < task.end; ++i) {
          const int b = bin_of(axis(centroids[prims[i]], a), lo, scale, kBins);
          bin_box[b].grow(boxes[prims[i]]);
          ++bin_count[b];
        }
        float right_area[kBins];
        uint32_t right_count[kBins];
        Box acc;
        uint32_t n = 0;
        for (int b = kBins - 1; b > 0; --b) {
          acc.grow(bin_box[b]);
          n += bin_count[b];
          right_area[b] = acc.area();
          right_count[b] = n;
        }
        acc = Box{};
        n = 0;
        for (int b = 0; b < kBins - 1; ++b) {
          acc.grow(bin_box[b]);
          n += bin_count[b];
          if (n == 0 || right_count[b + 1] == 0) continue;
          const float cost = acc.area() * n + right_area[b + 1] * right_count[b + 1];
          if (cost < best_cost) best_cost = cost, best_axis = a, best_bin = b;
        }
      }
      if (best_axis >= 0) {
        const float lo = axis(cbox.lo, best_axis), scale = kBins / (axis(cbox.hi, best_axis) - lo);
        const auto it = std::partition(prims.begin() + task.begin, prims.begin() + task.end, [&](uint32_t p) {
          return bin_of(axis(centroids[p], best_axis), lo, scale, kBins) <= best_bin;
        });
        mid = static_cast<uint32_t>(it - prims.begin());
        split_found = mid > task.begin && mid < task.end;
      }
    }
    if (!split_found) {
      // Median split (builder=median, or SAH found no boundary: every
      // centroid in one bin): halves by index order along the largest axis.
      mid = task.begin + count / 2;
      std::nth_element(prims.begin() + task.begin, prims.begin() + mid, prims.begin() + task.end,
                       [&](uint32_t p, uint32_t q) { return axis(centroids[p], split_axis) < axis(centroids[q], split_axis); });
    }
    const uint32_t left = static_cast<uint32_t>(accel.nodes.size());
    accel.nodes.push_back({});
    accel.nodes.push_back({});
    accel.nodes[task.node].first = left;
    accel.nodes[task.node].count = 0;
    tasks.push_back({left + 1, mid, task.end});
    tasks.push_back({left, task.begin, mid});
  }
}

// Slab test; the entry distance when the ray's interval meets the box, else
// +infinity. NaNs (origin on a slab plane with a zero direction component)
// are dropped by the argument order of min/max; the far distance is widened
// by 3 ulps-worth so rounding never culls a box the ray grazes.
inline float box_entry(const Box& b, Vec3 org, Vec3 inv, float tnear, float tfar) {
  const float tx0 = (b.lo.x - org.x) * inv.x, tx1 = (b.hi.x - org.x) * inv.x;
  const float ty0 = (b.lo.y - org.y) * inv.y, ty1 = (b.hi.y - org.y) * inv.y;
  const float tz0 = (b.lo.z - org.z) * inv.z, tz1 = (b.hi.z - org.z) * inv.z;
  float t0 = std::max(tnear, std::min(tx0, tx1));
  t0 = std::max(t0, std::min(ty0, ty1));
  t0 = std::max(t0, std::min(tz0, tz1));
  float t1 = std::min(tfar, std::max(tx0, tx1));
  t1 = std::min(t1, std::max(ty0, ty1));
  t1 = std::min(t1, std::max(tz0, tz1));
  return t0 <= t1 * 1.0000004f ? t0 : std::numeric_limits<float>::infinity();
}

// Möller–Trumbore: true and t, u, v when the ray hits the triangle within
// (tnear, tfar]. A zero determinant (a degenerate triangle, or a ray in the
// triangle's plane) is a miss.
inline bool intersect_triangle(const Tri& tri, Vec3 org, Vec3 dir, float tnear, float tfar, float& t, float& u, float& v) {
  const Vec3 p = cross(dir, tri.e2);
  const float det = dot(tri.e1, p);
  if (det == 0.0f || !std::isfinite(det)) return false;
  const float inv_det = 1.0f / det;
  const Vec3 s = org - tri.v0;
  u = dot(s, p) * inv_det;
  if (!(u >= 0.0f && u <= 1.0f)) return false;
  const Vec3 q = cross(s, tri.e1);
  v = dot(dir, q) * inv_det;
  if (!(v >= 0.0f && u + v <= 1.0f)) return false;
  t = dot(tri.e2, q) * inv_det;
  return t > tnear && t <= tfar;
}

#ifdef MY_KERNEL_DROP_EVERY
// The deliberate bug: about one ray in MY_KERNEL_DROP_EVERY, chosen by its
// bits (so the same rays whatever the batching), is reported as a miss.
inline bool dropped(const raybench_ray& r) {
  uint32_t h = 2166136261u;
  const unsigned char* bytes = reinterpret_cast<const unsigned char*>(&r);
  for (size_t i = 0; i < sizeof r; ++i) h = (h ^ bytes[i]) * 16777619u;
  return h % (MY_KERNEL_DROP_EVERY) == 0;
}
#else
inline bool dropped(const raybench_ray&) { return false; }
#endif

// Closest hit (any_hit false) or any hit (true) of one ray.
template <bool any_hit>
inline bool trace(const Accel& accel, const raybench_ray& r, raybench_hit* hit) {
  const Vec3 org{r.org_x, r.org_y, r.org_z}, dir{r.dir_x, r.dir_y, r.dir_z};
  const Vec3 inv{1.0f / dir.x, 1.0f / dir.y, 1.0f / dir.z};
  const float tnear = r.tnear;
  float tfar = r.tfar;
  bool found = false;
  if (box_entry(accel.nodes[0].box, org, inv, tnear, tfar) == std::numeric_limits<float>::infinity()) return false;
  uint32_t stack[128];
  int top = 0;
  uint32_t node = 0;
  for (;;) {
    const Node& n = accel.nodes[node];
    if (n.count > 0) {
      for (uint32_t i = n.first; i < n.first + n.count; ++i) {
        float t, u, v;
        if (intersect_triangle(accel.tris[i], org, dir, tnear, tfar, t, u, v)) {
          found = true;
          if (any_hit) return true;
          tfar = t;
          hit->t = t, hit->prim = accel.tris[i].prim, hit->u = u, hit->v = v;
        }
      }
    } else {
      const float d0 = box_entry(accel.nodes[n.first].box, org, inv, tnear, tfar);
      const float d1 = box_entry(accel.nodes[n.first + 1].box, org, inv, tnear, tfar);
      constexpr float kMiss = std::numeric_limits<float>::infinity();
      if (d0 != kMiss && d1 != kMiss) {  // both: the nearer first
        const bool swap = d1 < d0;
        stack[top++] = n.first + (swap ? 0 : 1);
        node = n.first + (swap ? 1 : 0);
        continue;
      }
      if (d0 != kMiss) { node = n.first; continue; }
      if (d1 != kMiss) { node = n.first + 1; continue; }
    }
    if (top == 0) break;
    node = stack[--top];
  }
  return found;
}

// The tree's depth is at most the triangle count over ... in theory; the
// builder's splits always separate at least one triangle, so check it fits
// the traversal stack once, at build time.
unsigned depth(const Accel& accel, uint32_t node) {
  const Node& n = accel.nodes[node];
  if (n.count > 0) return 1;
  return 1 + std::max(depth(accel, n.first), depth(accel, n.first + 1));
}

// ---- the plugin table ----

int check_options(const char* options, char* error, size_t error_size) {
  Options parsed;
  const std::string problem = parse_options(options, parsed);
  if (problem.empty()) return 0;
  write_error(error, error_size, problem);
  return 1;
}

void* build(const raybench_build_input* input, char* error, size_t error_size) {
  Options options;
  const std::string problem = parse_options(input->options, options);
  if (!problem.empty()) {
    write_error(error, error_size, problem);
    return nullptr;
  }
  try {
    auto* accel = new Accel;
    const size_t n = input->triangle_count;
    std::vector<Box> boxes(n);
    std::vector<Vec3> centroids(n);
    std::vector<uint32_t> prims(n);
    for (size_t i = 0; i < n; ++i) {
      const float* f = input->triangles + 9 * i;
      for (int k = 0; k < 3; ++k) boxes[i].grow(Vec3{f[3 * k], f[3 * k + 1], f[3 * k + 2]});
      centroids[i] = {(boxes[i].lo.x + boxes[i].hi.x) * 0.5f, (boxes[i].lo.y + boxes[i].hi.y) * 0.5f,
                      (boxes[i].lo.z + boxes[i].hi.z) * 0.5f};
      prims[i] = static_cast<uint32_t>(i);
    }
    build_tree(*accel, boxes, centroids, prims, options);
    if (depth(*accel, 0) > 120) {
      delete accel;
      write_error(error, error_size, "the tree is deeper than the traversal stack (120)");
      return nullptr;
    }
    accel->tris.reserve(n);
    for (uint32_t p : prims) {
      const float* f = input->triangles + 9 * static_cast<size_t>(p);
      const Vec3 v0{f[0], f[1], f[2]}, v1{f[3], f[4], f[5]}, v2{f[6], f[7], f[8]};
      accel->tris.push_back({v0, v1 - v0, v2 - v0, static_cast<int32_t>(p)});
    }
    return accel;
  } catch (const std::bad_alloc&) {
    write_error(error, error_size, "out of memory");
    return nullptr;
  }
}

size_t memory_bytes(const void* accel) {
  const auto* a = static_cast<const Accel*>(accel);
  return a->nodes.capacity() * sizeof(Node) + a->tris.capacity() * sizeof(Tri);
}

int intersect(const void* accel, const raybench_ray* rays, size_t count, raybench_hit* hits) {
  const auto& a = *static_cast<const Accel*>(accel);
  for (size_t i = 0; i < count; ++i) {
    hits[i] = {std::numeric_limits<float>::infinity(), RAYBENCH_NO_HIT, 0.0f, 0.0f};
    if (!trace<false>(a, rays[i], &hits[i]) || dropped(rays[i]))
      hits[i] = {std::numeric_limits<float>::infinity(), RAYBENCH_NO_HIT, 0.0f, 0.0f};
  }
  return 0;
}

int occluded(const void* accel, const raybench_ray* rays, size_t count, uint8_t* out) {
  const auto& a = *static_cast<const Accel*>(accel);
  for (size_t i = 0; i < count; ++i) out[i] = trace<true>(a, rays[i], nullptr) && !dropped(rays[i]) ? 1 : 0;
  return 0;
}

void destroy(void* accel) { delete static_cast<Accel*>(accel); }

const raybench_plugin_table kTable = {
    RAYBENCH_PLUGIN_ABI_VERSION,
    "my_kernel",
    "Moller-Trumbore triangles in a binned-SAH BVH2 (the raybench example plugin)",
    "fast",
    check_options,
    build,
    memory_bytes,
    intersect,
    occluded,
    destroy,
};

}  // namespace

extern "C" RAYBENCH_PLUGIN_EXPORT const raybench_plugin_table* raybench_plugin(void) { return &kTable; }
