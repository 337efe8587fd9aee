// The exact box, OBB and sphere referees: every decision in GMP rationals
// (CGAL::Gmpq), t rounded from rationals or from 256-bit MPFR. The semantics
// and the accuracy of t are documented in exact_primitives.h.
#include "referee/exact_primitives.h"

#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include <CGAL/Gmpq.h>
#include <mpfr.h>

namespace raybench {
namespace {

using Rational = CGAL::Gmpq;

// Every float is a dyadic rational; the double conversion is exact, and so
// is mpq_set_d behind Gmpq(double).
Rational exact(float x) { return Rational(static_cast<double>(x)); }

struct Vec3q {
  Rational x, y, z;
};
Vec3q exact(Vec3f v) { return {exact(v.x), exact(v.y), exact(v.z)}; }
Vec3q operator-(const Vec3q& a, const Vec3q& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
Rational dot(const Vec3q& a, const Vec3q& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

// An MPFR number that frees itself.
class Mpfr {
 public:
  explicit Mpfr(mpfr_prec_t bits) { mpfr_init2(x_, bits); }
  Mpfr(mpfr_prec_t bits, const Rational& q) : Mpfr(bits) { mpfr_set_q(x_, q.mpq(), MPFR_RNDN); }
  ~Mpfr() { mpfr_clear(x_); }
  Mpfr(const Mpfr&) = delete;
  Mpfr& operator=(const Mpfr&) = delete;
  mpfr_ptr get() { return x_; }
  double to_double() const { return mpfr_get_d(x_, MPFR_RNDN); }

 private:
  mpfr_t x_;
};

// The double nearest q: rounding to a 53-bit MPFR number is the correct
// rounding, and reading it back as a double is exact (t is never subnormal
// in double: |t| >= 2^-149 / FLT_MAX > 2^-1022).
double nearest_double(const Rational& q) { return Mpfr(53, q).to_double(); }

void require_finite(bool finite, const char* what) {
  if (!finite) throw std::invalid_argument(std::string("exact referee: non-finite ") + what);
}

// The ray's parameter range [lo, tfar] as rationals, lo = max(tnear, 0);
// `empty` when not even t = lo is in it. Hits need t > lo (see decide()).
struct RayInterval {
  bool empty = false;
  Rational lo;
  std::optional<Rational> hi;  // none: tfar = +inf
};

RayInterval ray_interval(const Ray& r) {
  RayInterval iv;
  if (r.tnear == std::numeric_limits<float>::infinity()) {
    iv.empty = true;
    return iv;
  }
  iv.lo = r.tnear > 0.0f ? exact(r.tnear) : Rational(0);  // -inf and negatives: 0
  if (std::isinf(r.tfar)) {
    iv.empty = r.tfar < 0.0f;
  } else {
    iv.hi = exact(r.tfar);
    iv.empty = *iv.hi < iv.lo;
  }
  return iv;
}

// The t-range [E, X] of the ray inside an intersection of slabs; a missing
// bound is unbounded (every slab so far was parallel and contained the ray).
struct SlabRange {
  bool empty = false;
  std::optional<Rational> entry, exit;

  // The slab lower <= e + t f <= upper along the ray (e, f: the origin's and
  // the direction's coordinate across the slab). f = 0 (either sign of zero:
  // the rational has none) keeps every t or none, by the closed slab.
  void clip(const Rational& e, const Rational& f, const Rational& lower, const Rational& upper) {
    if (empty) return;
    if (CGAL::sign(f) == CGAL::ZERO) {
      empty = !(lower <= e && e <= upper);
      return;
    }
    Rational t1 = (lower - e) / f, t2 = (upper - e) / f;
    if (CGAL::sign(f) == CGAL::NEGATIVE) std::swap(t1, t2);
    if (!entry || t1 > *entry) entry = std::move(t1);
    if (!exit || t2 < *exit) exit = std::move(t2);
    empty = *entry > *exit;
  }
};

// A solid occupying [E, X] along the ray, against the interval (lo, tfar].
ExactPrimitiveHit decide(const SlabRange& range, const RayInterval& iv) {
  ExactPrimitiveHit out;
  if (range.empty || iv.empty) return out;
  // [E, X] meets (lo, tfar] iff X > lo, E <= tfar and tfar > lo.
  const bool exit_after_lo = !range.exit || *range.exit > iv.lo;
  const bool entry_by_tfar = !range.entry || !iv.hi || *range.entry <= *iv.hi;
  const bool open_interval_nonempty = !iv.hi || *iv.hi > iv.lo;
  out.hit = exit_after_lo && entry_by_tfar && open_interval_nonempty;
  if (!out.hit) {
    // Touched at t = lo only (lo <= tfar holds: the interval is not empty).
    out.start_contact = (!range.entry || *range.entry <= iv.lo) && (!range.exit || iv.lo <= *range.exit);
    return out;
  }
  if (range.entry && *range.entry > iv.lo) {
    out.t = nearest_double(*range.entry);
    return out;
  }
  // Starting in or on the solid: the first surface point in (lo, tfar] is
  // the exit, or tfar when the segment ends inside.
  out.exit = true;
  if (range.exit && (!iv.hi || *range.exit <= *iv.hi)) out.t = nearest_double(*range.exit);
  else out.t = iv.hi ? nearest_double(*iv.hi) : std::numeric_limits<double>::infinity();
  return out;
}

// A boundary occupying the ends of [E, X] along the ray, against the
// interval (lo, tfar]: the first of E, X inside it (exact_intersect_surface).
ExactPrimitiveHit decide_surface(const SlabRange& range, const RayInterval& iv) {
  ExactPrimitiveHit out;
  if (range.empty || iv.empty) return out;
  const bool open_interval_nonempty = !iv.hi || *iv.hi > iv.lo;
  const auto inside = [&](const std::optional<Rational>& t) {
    return open_interval_nonempty && t && *t > iv.lo && (!iv.hi || *t <= *iv.hi);
  };
  out.start_contact = (range.entry && *range.entry == iv.lo) || (range.exit && *range.exit == iv.lo);
  if (inside(range.entry)) {
    out.hit = true;
    out.t = nearest_double(*range.entry);
  } else if (inside(range.exit)) {
    out.hit = true;
    out.exit = true;
    out.t = nearest_double(*range.exit);
  }
  return out;
}

// sign(w + s sqrt(D)) for s = +1 or -1, D >= 0, without a square root.
int sign_with_root(const Rational& w, const Rational& D, int s) {
  const int sw = CGAL::sign(w);
  if (s > 0) {
    if (sw >= 0) return (sw == 0 && CGAL::sign(D) == CGAL::ZERO) ? 0 : 1;
    return CGAL::sign(D - w * w);  // sqrt(D) against -w > 0
  }
  if (sw <= 0) return (sw == 0 && CGAL::sign(D) == CGAL::ZERO) ? 0 : -1;
  return CGAL::sign(w * w - D);  // w > 0 against sqrt(D)
}

// The root (-b + s sqrt(D)) / a (s = -1: t0, s = +1: t1) to 256 bits, then
// to double; see the accuracy note in the header.
double sphere_root(const Rational& a, const Rational& b, const Rational& C, const Rational& D, int s) {
  constexpr mpfr_prec_t kBits = 256;
  Mpfr ma(kBits, a), mb(kBits, b), mc(kBits, C), md(kBits, D), root(kBits), q(kBits), t(kBits);
  mpfr_sqrt(root.get(), md.get(), MPFR_RNDN);
  // q = -(b + sign(b) sqrt(D)) adds two numbers of one sign: no cancellation.
  const bool b_negative = CGAL::sign(b) == CGAL::NEGATIVE;
  if (b_negative) {
    mpfr_sub(q.get(), root.get(), mb.get(), MPFR_RNDN);  // sqrt(D) - b > 0
  } else {
    mpfr_add(q.get(), mb.get(), root.get(), MPFR_RNDN);
    mpfr_neg(q.get(), q.get(), MPFR_RNDN);  // <= 0
  }
  if (mpfr_zero_p(q.get())) return 0.0;  // b = 0 and D = 0, so C = 0: a double root at 0
  // With b >= 0, q / a = (-b - sqrt(D)) / a = t0 and C / q = t1 (their
  // product is C / a); with b < 0 the other way round.
  const bool q_over_a = (s < 0) != b_negative;
  if (q_over_a) mpfr_div(t.get(), q.get(), ma.get(), MPFR_RNDN);
  else mpfr_div(t.get(), mc.get(), q.get(), MPFR_RNDN);
  return t.to_double();
}

}  // namespace

bool is_exact_ray(const Ray& ray) {
  return is_finite(ray.org) && is_finite(ray.dir) && !std::isnan(ray.tnear) && !std::isnan(ray.tfar) &&
         !(ray.dir.x == 0.0f && ray.dir.y == 0.0f && ray.dir.z == 0.0f);
}

namespace {

// The box's [E, X] along the ray; none for the empty box or an exact-invalid ray.
std::optional<SlabRange> slab_range(const Ray& ray, const BBox& box) {
  for (int i = 0; i < 3; ++i) require_finite(!std::isnan(box.lower[i]) && !std::isnan(box.upper[i]), "box (NaN)");
  for (int i = 0; i < 3; ++i)
    if (box.lower[i] > box.upper[i]) return std::nullopt;  // the empty box
  require_finite(is_finite(box.lower) && is_finite(box.upper), "box");
  if (!is_exact_ray(ray)) return std::nullopt;
  SlabRange range;
  for (int i = 0; i < 3; ++i) range.clip(exact(ray.org[i]), exact(ray.dir[i]), exact(box.lower[i]), exact(box.upper[i]));
  return range;
}

std::optional<SlabRange> slab_range(const Ray& ray, const OrientedBox& box) {
  require_finite(is_finite(box.center) && is_finite(box.axis[0]) && is_finite(box.axis[1]) && is_finite(box.axis[2]) &&
                     is_finite(box.half_extent),
                 "oriented box");
  if (!is_exact_ray(ray)) return std::nullopt;
  for (int i = 0; i < 3; ++i)
    if (box.half_extent[i] < 0.0f) return std::nullopt;  // an empty box
  const Vec3q offset = exact(ray.org) - exact(box.center), dir = exact(ray.dir);
  SlabRange range;
  for (int i = 0; i < 3; ++i) {
    const Vec3q axis = exact(box.axis[i]);
    const Rational h = exact(box.half_extent[i]);
    range.clip(dot(offset, axis), dot(dir, axis), -h, h);
  }
  return range;
}

}  // namespace

ExactPrimitiveHit exact_intersect(const Ray& ray, const BBox& box) {
  const std::optional<SlabRange> range = slab_range(ray, box);
  return range ? decide(*range, ray_interval(ray)) : ExactPrimitiveHit{};
}

ExactPrimitiveHit exact_intersect(const Ray& ray, const OrientedBox& box) {
  const std::optional<SlabRange> range = slab_range(ray, box);
  return range ? decide(*range, ray_interval(ray)) : ExactPrimitiveHit{};
}

ExactPrimitiveHit exact_intersect_surface(const Ray& ray, const BBox& box) {
  const std::optional<SlabRange> range = slab_range(ray, box);
  return range ? decide_surface(*range, ray_interval(ray)) : ExactPrimitiveHit{};
}

ExactPrimitiveHit exact_intersect_surface(const Ray& ray, const OrientedBox& box) {
  const std::optional<SlabRange> range = slab_range(ray, box);
  return range ? decide_surface(*range, ray_interval(ray)) : ExactPrimitiveHit{};
}

namespace {

// Both sphere referees; `contact_on_hits`: set start_contact for hits as
// well (exact_intersect_surface's meaning of it).
ExactPrimitiveHit sphere_hit(const Ray& ray, const Sphere& sphere, bool contact_on_hits) {
  require_finite(is_finite(sphere.center) && std::isfinite(sphere.radius), "sphere");
  ExactPrimitiveHit out;
  if (!is_exact_ray(ray)) return out;
  const RayInterval iv = ray_interval(ray);
  if (iv.empty) return out;
  const Vec3q f = exact(ray.org) - exact(sphere.center), d = exact(ray.dir);
  const Rational r = exact(sphere.radius);
  const Rational a = dot(d, d), b = dot(f, d), C = dot(f, f) - r * r;
  const Rational D = b * b - a * C;
  if (CGAL::sign(D) == CGAL::NEGATIVE) return out;
  // sign(root_s - v) = sign(-b - a v + s sqrt(D)), as a > 0.
  const auto compare_root = [&](int s, const Rational& v) { return sign_with_root(-b - a * v, D, s); };
  const auto in_interval = [&](int s) { return compare_root(s, iv.lo) > 0 && (!iv.hi || compare_root(s, *iv.hi) <= 0); };
  const bool in0 = in_interval(-1), in1 = in_interval(+1);
  const auto contact = [&] { return compare_root(-1, iv.lo) == 0 || compare_root(+1, iv.lo) == 0; };
  if (!in0 && !in1) {
    out.start_contact = contact();
    return out;
  }
  out.hit = true;
  out.exit = !in0;
  out.t = sphere_root(a, b, C, D, in0 ? -1 : +1);
  if (contact_on_hits) out.start_contact = contact();
  return out;
}

}  // namespace

ExactPrimitiveHit exact_intersect(const Ray& ray, const Sphere& sphere) { return sphere_hit(ray, sphere, false); }

ExactPrimitiveHit exact_intersect_surface(const Ray& ray, const Sphere& sphere) { return sphere_hit(ray, sphere, true); }

}  // namespace raybench
