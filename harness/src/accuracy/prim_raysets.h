// The extreme ray sets of ../shared/EXTREMES.md at the level of one
// primitive: each ray is paired with the box, OBB, sphere or triangle it is
// tested against, so that a kernel variant can be judged alone, with no BVH
// in between (`raybench accuracy-kernels`, accuracy/kernel_accuracy.h).
//
// Every set is a pure function of (set name, ray count, seed): ray i comes
// from the counter-based Rng(seed, hash of "<scene>/<rayset>", i), so the
// rays are bit-identical on every machine. A set whose construction sweeps a
// parameter (EXTREMES.md: G05, G07, G12, G13, G16) is one set per value,
// named with a suffix ("far-small-sphere:D=1e3", "direction-scaling:|d|=1e-20").
// The sets, per family (the construction of each is commented at its maker):
//   box, obb   G09 axis-parallel-signed-zero, G10 origin-inside,
//              G11 origin-on-surface:{outward,inward}, G15 invalid-rays,
//              invalid-rays:extreme-d, G16 direction-scaling, G20 control-random
//   sphere     G10, G12 far-small-sphere, G13 tiny-sphere, G15, G16, G20
//   triangle   G05 tiny-triangles, G07 grazing, G08 degenerate-triangles,
//              G14 behind-origin, G15, G16, G19 coplanar, G20
// Every ray has tnear = 0 and tfar = +inf except where G15 corrupts them.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "raybench/math/bbox.h"
#include "raybench/math/ray.h"
#include "raybench/prim/obb.h"
#include "raybench/prim/sphere.h"
#include "raybench/prim/triangle.h"

namespace raybench {

template <typename Prim>
struct PrimRaySet {
  std::string scene;   // prim:box, prim:obb, prim:sphere or prim:triangle
  std::string rayset;  // the EXTREMES.md name, with a parameter suffix where the catalogue sweeps one
  std::vector<Ray> rays;
  std::vector<Prim> prims;  // prims[i] is the primitive rays[i] is tested against
};

// The direction lengths of G16: powers of two, so that scaling a unit
// direction is exact and every length gives the same geometric ray (the
// exact hit/miss is identical across the sets, t scales exactly). Named
// after the nearest power of ten: 2^-66 ~ 1.4e-20 is "|d|=1e-20".
inline constexpr int kDirectionScaleExponents[] = {-66, -23, 0, 23, 66};

std::vector<PrimRaySet<BBox>> box_raysets(std::size_t rays, std::uint64_t seed);
std::vector<PrimRaySet<OrientedBox>> obb_raysets(std::size_t rays, std::uint64_t seed);
std::vector<PrimRaySet<Sphere>> sphere_raysets(std::size_t rays, std::uint64_t seed);
std::vector<PrimRaySet<Triangle>> triangle_raysets(std::size_t rays, std::uint64_t seed);

}  // namespace raybench
