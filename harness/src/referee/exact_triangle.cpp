#include "referee/exact_triangle.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <CGAL/FPU.h>
#include <CGAL/Gmpq.h>
#include <CGAL/Interval_nt.h>

namespace raybench {
namespace {

// The file: the exact ray-triangle judgement of referee/exact_triangle.h,
// filtered: each sign and t is first taken from interval arithmetic, and
// computed in GMP rationals (CGAL::Gmpq) only when the interval cannot
// decide (or for the nearest double and for ties), so every decision is
// exact and the common case fast.
// Interval_nt<false> assumes the FPU rounds upwards; Protect_FPU_rounding
// sets that for the scope of each judgement and restores it after.
using Interval = CGAL::Interval_nt<false>;
using Rational = CGAL::Gmpq;

template <typename T>
struct V3 {
  T x, y, z;
};
template <typename T>
V3<T> sub(const V3<T>& p, const V3<T>& q) {
  return {p.x - q.x, p.y - q.y, p.z - q.z};
}
template <typename T>
V3<T> cross(const V3<T>& p, const V3<T>& q) {
  return {p.y * q.z - p.z * q.y, p.z * q.x - p.x * q.z, p.x * q.y - p.y * q.x};
}
template <typename T>
T dot(const V3<T>& p, const V3<T>& q) {
  return p.x * q.x + p.y * q.y + p.z * q.z;
}
template <typename T>
V3<T> lift(Vec3f v) {
  return {T(static_cast<double>(v.x)), T(static_cast<double>(v.y)), T(static_cast<double>(v.z))};
}

// Everything the verdict needs, in number type T.
template <typename T>
struct Terms {
  T e0, e1, e2, den, num;  // t = num / den
};

template <typename T>
Terms<T> terms(const Ray& ray, const Triangle& tri) {
  const V3<T> o = lift<T>(ray.org), d = lift<T>(ray.dir);
  const V3<T> a = sub(lift<T>(tri.v0), o), b = sub(lift<T>(tri.v1), o), c = sub(lift<T>(tri.v2), o);
  const V3<T> n = cross(sub(lift<T>(tri.v1), lift<T>(tri.v0)), sub(lift<T>(tri.v2), lift<T>(tri.v0)));
  Terms<T> out{dot(d, cross(b, c)), dot(d, cross(c, a)), dot(d, cross(a, b)), dot(d, n), dot(a, n)};
  return out;
}

int sign_of(const Rational& q) { return CGAL::sign(q); }

// The sign of an interval, or 2 when it straddles zero.
int sign_of(const Interval& i) {
  if (i.inf() > 0) return 1;
  if (i.sup() < 0) return -1;
  if (i.inf() == 0 && i.sup() == 0) return 0;
  return 2;
}

constexpr int kUndecided = 2;

// The verdict from terms in T; kUndecided when a sign could not be decided.
// Returns 1 hit, 0 miss.
template <typename T>
int decide(const Ray& ray, const Terms<T>& k, bool& on_boundary) {
  const int s_den = sign_of(k.den);
  if (s_den == kUndecided) return kUndecided;
  if (s_den == 0) return 0;  // parallel, coplanar or degenerate: never a hit
  const int s[3] = {sign_of(k.e0), sign_of(k.e1), sign_of(k.e2)};
  bool undecided = false;
  on_boundary = false;
  for (int si : s) {
    if (si == kUndecided) undecided = true;
    else if (si == -s_den) return 0;  // a decided opposite sign: the line passes outside
    else if (si == 0) on_boundary = true;
  }
  if (undecided) return kUndecided;
  // t in (lo, tfar]: sign(num - lo den) == sign(den), and tfar den - num has
  // the sign of den or is zero.
  const double lo = std::max(static_cast<double>(ray.tnear), 0.0);
  const int s_lo = sign_of(T(k.num - T(lo) * k.den));
  if (s_lo == kUndecided) return kUndecided;
  if (s_lo != s_den) return 0;
  if (std::isfinite(ray.tfar)) {
    const int s_hi = sign_of(T(T(static_cast<double>(ray.tfar)) * k.den - k.num));
    if (s_hi == kUndecided) return kUndecided;
    if (s_hi == -s_den) return 0;
  } else if (ray.tfar < 0) {
    return 0;
  }
  return 1;
}

// The double nearest to q, and an enclosing interval.
void nearest_double(const Rational& q, double& nearest, double& lower, double& upper) {
  const std::pair<double, double> i = CGAL::to_interval(q);
  lower = i.first;
  upper = i.second;
  if (lower == upper) {
    nearest = lower;
    return;
  }
  const Rational mid = (Rational(lower) + Rational(upper)) / 2;
  nearest = q < mid ? lower : upper;
}

}  // namespace

ExactTriangleHit exact_intersect(const Ray& ray, const Triangle& tri, TValue t_value) {
  ExactTriangleHit out;
  out.min_barycentric = std::numeric_limits<double>::quiet_NaN();
  out.plane_t = std::numeric_limits<double>::quiet_NaN();
  if (!is_traceable(ray) || !std::isfinite(tri.v0.x + tri.v0.y + tri.v0.z + tri.v1.x + tri.v1.y + tri.v1.z + tri.v2.x +
                                           tri.v2.y + tri.v2.z))
    return out;
  int verdict;
  {
    CGAL::Protect_FPU_rounding<true> upward;
    const Terms<Interval> k = terms<Interval>(ray, tri);
    verdict = decide(ray, k, out.on_boundary);
    if (sign_of(k.den) != 0 && sign_of(k.den) != kUndecided) {
      const double den = CGAL::to_double(k.den);
      out.min_barycentric = std::min({CGAL::to_double(k.e0) / den, CGAL::to_double(k.e1) / den, CGAL::to_double(k.e2) / den});
      const Interval t = k.num / k.den;
      out.plane_t = CGAL::to_double(t);
      out.t_lower = t.inf();
      out.t_upper = t.sup();
      out.t = out.plane_t;
    }
  }
  // The interval of t is a few double ulps wide when the filter decided;
  // the nearest double, and hits on a boundary (ties), need rationals.
  if (verdict == kUndecided || (verdict == 1 && (out.on_boundary || t_value == TValue::kNearest))) {
    out.exact_fallback = verdict == kUndecided;
    const Terms<Rational> k = terms<Rational>(ray, tri);
    verdict = decide(ray, k, out.on_boundary);
    if (sign_of(k.den) != 0) {
      out.min_barycentric = CGAL::to_double(std::min({k.e0 / k.den, k.e1 / k.den, k.e2 / k.den}));
      nearest_double(k.num / k.den, out.t, out.t_lower, out.t_upper);
      out.plane_t = out.t;
    }
  }
  out.hit = verdict == 1;
  if (!out.hit) out.on_boundary = false;
  return out;
}

int compare_exact_t(const Ray& ray, const Triangle& a, const Triangle& b) {
  const Terms<Rational> ka = terms<Rational>(ray, a), kb = terms<Rational>(ray, b);
  return CGAL::compare(ka.num / ka.den, kb.num / kb.den);
}

bool same_exact_t(const Ray& ray, const Triangle& a, const Triangle& b) {
  const Terms<Rational> ka = terms<Rational>(ray, a), kb = terms<Rational>(ray, b);
  if (CGAL::is_zero(ka.den) || CGAL::is_zero(kb.den)) return false;
  return ka.num * kb.den == kb.num * ka.den;  // num_a / den_a == num_b / den_b, without dividing
}

}  // namespace raybench
