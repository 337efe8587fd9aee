// W float or int lanes in one register, for the wide kernels written once for
// every width: FloatLanes<8>/IntLanes<8> are AVX2's __m256/__m256i,
// FloatLanes<4>/IntLanes<4> SSE's __m128/__m128i (with AVX2's variable
// shifts and permutes). Thin wrappers: each operation is one intrinsic, so
// the wide box and triangle tests compile as if written with intrinsics.
// Comparisons are ordered and non-signalling (false for NaN), and min/max
// return their second operand when either is NaN, as the scalar kernels'
// comparisons do. Only with AVX2 (raybench::kHaveAvx2); without it the wide
// kernels run their scalar forms. fmadd is one fused multiply-add, as
// std::fma: every AVX2 CPU has FMA3, and a build that targets AVX2 without
// it is refused rather than given a slower or differently rounded form.
// With AVX-512F and VL (raybench::simd::kHaveAvx512; chosen at compile time,
// -march=native on such a host) the same widths gain comparisons into a lane
// mask (vcmpps k, chained under a mask for an and), for the leaf tests; they
// answer bit for bit as compare-and-movemask; FloatLanes<16> is AVX-512's
// __m512, for the packet traversal (two of them: LanePair below). What
// AVX-512 paid and did not:
// docs/notes/kernels-wide-traversal.md
#pragma once

#include <cstdint>

#if defined(__AVX2__) && defined(__AVX512F__) && defined(__AVX512VL__)
#define RAYBENCH_AVX512 1
#endif
namespace raybench::simd {
inline constexpr bool kHaveAvx512 =
#if defined(RAYBENCH_AVX512)
    true;
#else
    false;
#endif
}  // namespace raybench::simd

#if defined(__AVX2__)
#if !defined(__FMA__)
#error "raybench's wide kernels need FMA3 with AVX2: compile with -march=native or -mavx2 -mfma"
#endif
#include <immintrin.h>

namespace raybench::simd {

template <int W>
struct FloatLanes;
template <int W>
struct IntLanes;

template <>
struct IntLanes<8> {
  __m256i v;
  static IntLanes set1(std::uint32_t x) { return {_mm256_set1_epi32(static_cast<int>(x))}; }
  static IntLanes load(const std::uint32_t* p) { return {_mm256_load_si256(reinterpret_cast<const __m256i*>(p))}; }
  static IntLanes iota(int step) { return {_mm256_setr_epi32(0, step, 2 * step, 3 * step, 4 * step, 5 * step, 6 * step, 7 * step)}; }
  void storeu(std::uint32_t* p) const { _mm256_storeu_si256(reinterpret_cast<__m256i*>(p), v); }
  IntLanes shift_right(IntLanes by) const { return {_mm256_srlv_epi32(v, by.v)}; }
  IntLanes operator&(IntLanes o) const { return {_mm256_and_si256(v, o.v)}; }
  // Lane i of the result is lane index[i] of this.
  IntLanes permute(IntLanes index) const { return {_mm256_permutevar8x32_epi32(v, index.v)}; }
  // Bit i set when lane i's sign bit is.
  unsigned sign_mask() const { return static_cast<unsigned>(_mm256_movemask_ps(_mm256_castsi256_ps(v))); }
};

template <>
struct FloatLanes<8> {
  __m256 v;
  static FloatLanes set1(float x) { return {_mm256_set1_ps(x)}; }
  static FloatLanes load(const float* p) { return {_mm256_load_ps(p)}; }
  // The 8 rows of 8 floats at `rows` transposed: lane i of out[k] is rows[i * 8 + k].
  // Row loads and in-register shuffles (transpose4_in_lanes below), no gather.
  static void load_transposed8(const float* rows, FloatLanes (&out)[8]);
  // All bits set in lane i when bit i of `bits` is: a lane mask, as the comparisons give.
  static FloatLanes from_bits(unsigned bits) {
    const __m256i bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    const __m256i set = _mm256_and_si256(_mm256_set1_epi32(static_cast<int>(bits)), bit);
    return {_mm256_castsi256_ps(_mm256_cmpeq_epi32(set, bit))};
  }
  void storeu(float* p) const { _mm256_storeu_ps(p, v); }
  FloatLanes operator+(FloatLanes o) const { return {_mm256_add_ps(v, o.v)}; }
  FloatLanes operator-(FloatLanes o) const { return {_mm256_sub_ps(v, o.v)}; }
  FloatLanes operator*(FloatLanes o) const { return {_mm256_mul_ps(v, o.v)}; }
  FloatLanes operator/(FloatLanes o) const { return {_mm256_div_ps(v, o.v)}; }
  FloatLanes operator&(FloatLanes o) const { return {_mm256_and_ps(v, o.v)}; }
  FloatLanes operator|(FloatLanes o) const { return {_mm256_or_ps(v, o.v)}; }
  FloatLanes operator^(FloatLanes o) const { return {_mm256_xor_ps(v, o.v)}; }
  FloatLanes operator<=(FloatLanes o) const { return {_mm256_cmp_ps(v, o.v, _CMP_LE_OQ)}; }
  FloatLanes operator<(FloatLanes o) const { return {_mm256_cmp_ps(v, o.v, _CMP_LT_OQ)}; }
  FloatLanes operator>=(FloatLanes o) const { return {_mm256_cmp_ps(v, o.v, _CMP_GE_OQ)}; }
  FloatLanes operator>(FloatLanes o) const { return {_mm256_cmp_ps(v, o.v, _CMP_GT_OQ)}; }
  FloatLanes operator!=(FloatLanes o) const { return {_mm256_cmp_ps(v, o.v, _CMP_NEQ_OQ)}; }
  FloatLanes abs() const { return {_mm256_andnot_ps(_mm256_set1_ps(-0.0f), v)}; }
  // The sign bits alone (x ^ y.sign() flips x's sign where y is negative).
  FloatLanes sign() const { return {_mm256_and_ps(_mm256_set1_ps(-0.0f), v)}; }
  FloatLanes permute(IntLanes<8> index) const { return {_mm256_permutevar8x32_ps(v, index.v)}; }
  unsigned mask() const { return static_cast<unsigned>(_mm256_movemask_ps(v)); }
#if defined(RAYBENCH_AVX512)
  // Bit i set when lane i compares true by `Predicate` and bit i of `within`
  // is set: one compare into a mask register (the and comes free). The
  // named forms, for every width, follow the specialisations (le_mask, ...).
  template <int Predicate>
  unsigned cmp_mask(FloatLanes o, unsigned within) const {
    return _mm256_mask_cmp_ps_mask(static_cast<__mmask8>(within), v, o.v, Predicate);
  }
#endif
};
// max(a, b) / min(a, b): b when either is NaN.
inline FloatLanes<8> max(FloatLanes<8> a, FloatLanes<8> b) { return {_mm256_max_ps(a.v, b.v)}; }
inline FloatLanes<8> min(FloatLanes<8> a, FloatLanes<8> b) { return {_mm256_min_ps(a.v, b.v)}; }
// a * b + c, rounded once (std::fma).
inline FloatLanes<8> fmadd(FloatLanes<8> a, FloatLanes<8> b, FloatLanes<8> c) { return {_mm256_fmadd_ps(a.v, b.v, c.v)}; }
// a * b - c, rounded once (std::fma(a, b, -c)).
inline FloatLanes<8> fmsub(FloatLanes<8> a, FloatLanes<8> b, FloatLanes<8> c) { return {_mm256_fmsub_ps(a.v, b.v, c.v)}; }

template <>
struct IntLanes<4> {
  __m128i v;
  static IntLanes set1(std::uint32_t x) { return {_mm_set1_epi32(static_cast<int>(x))}; }
  static IntLanes load(const std::uint32_t* p) { return {_mm_load_si128(reinterpret_cast<const __m128i*>(p))}; }
  static IntLanes iota(int step) { return {_mm_setr_epi32(0, step, 2 * step, 3 * step)}; }
  void storeu(std::uint32_t* p) const { _mm_storeu_si128(reinterpret_cast<__m128i*>(p), v); }
  IntLanes shift_right(IntLanes by) const { return {_mm_srlv_epi32(v, by.v)}; }
  IntLanes operator&(IntLanes o) const { return {_mm_and_si128(v, o.v)}; }
  IntLanes permute(IntLanes index) const {
    return {_mm_castps_si128(_mm_permutevar_ps(_mm_castsi128_ps(v), index.v))};
  }
  unsigned sign_mask() const { return static_cast<unsigned>(_mm_movemask_ps(_mm_castsi128_ps(v))); }
};

template <>
struct FloatLanes<4> {
  __m128 v;
  static FloatLanes set1(float x) { return {_mm_set1_ps(x)}; }
  static FloatLanes load(const float* p) { return {_mm_load_ps(p)}; }
  void storeu(float* p) const { _mm_storeu_ps(p, v); }
  FloatLanes operator+(FloatLanes o) const { return {_mm_add_ps(v, o.v)}; }
  FloatLanes operator-(FloatLanes o) const { return {_mm_sub_ps(v, o.v)}; }
  FloatLanes operator*(FloatLanes o) const { return {_mm_mul_ps(v, o.v)}; }
  FloatLanes operator/(FloatLanes o) const { return {_mm_div_ps(v, o.v)}; }
  FloatLanes operator&(FloatLanes o) const { return {_mm_and_ps(v, o.v)}; }
  FloatLanes operator|(FloatLanes o) const { return {_mm_or_ps(v, o.v)}; }
  FloatLanes operator^(FloatLanes o) const { return {_mm_xor_ps(v, o.v)}; }
  FloatLanes operator<=(FloatLanes o) const { return {_mm_cmp_ps(v, o.v, _CMP_LE_OQ)}; }
  FloatLanes operator<(FloatLanes o) const { return {_mm_cmp_ps(v, o.v, _CMP_LT_OQ)}; }
  FloatLanes operator>=(FloatLanes o) const { return {_mm_cmp_ps(v, o.v, _CMP_GE_OQ)}; }
  FloatLanes operator>(FloatLanes o) const { return {_mm_cmp_ps(v, o.v, _CMP_GT_OQ)}; }
  FloatLanes operator!=(FloatLanes o) const { return {_mm_cmp_ps(v, o.v, _CMP_NEQ_OQ)}; }
  FloatLanes abs() const { return {_mm_andnot_ps(_mm_set1_ps(-0.0f), v)}; }
  // The sign bits alone (x ^ y.sign() flips x's sign where y is negative).
  FloatLanes sign() const { return {_mm_and_ps(_mm_set1_ps(-0.0f), v)}; }
  FloatLanes permute(IntLanes<4> index) const { return {_mm_permutevar_ps(v, index.v)}; }
  unsigned mask() const { return static_cast<unsigned>(_mm_movemask_ps(v)); }
#if defined(RAYBENCH_AVX512)
  // Bit i set when lane i compares true by `Predicate` and bit i of `within`
  // is set: one compare into a mask register (the and comes free). The
  // named forms, for every width, follow the specialisations (le_mask, ...).
  template <int Predicate>
  unsigned cmp_mask(FloatLanes o, unsigned within) const {
    return _mm_mask_cmp_ps_mask(static_cast<__mmask8>(within), v, o.v, Predicate);
  }
#endif
};
#if defined(RAYBENCH_AVX512)
// a <= b (and so on) in the lanes of `within`, as a lane mask: the same
// ordered, non-signalling predicates as the operators above, for the widths
// that have cmp_mask.
template <int W>
unsigned le_mask(FloatLanes<W> a, FloatLanes<W> b, unsigned within = 0xff) { return a.template cmp_mask<_CMP_LE_OQ>(b, within); }
template <int W>
unsigned ge_mask(FloatLanes<W> a, FloatLanes<W> b, unsigned within = 0xff) { return a.template cmp_mask<_CMP_GE_OQ>(b, within); }
template <int W>
unsigned gt_mask(FloatLanes<W> a, FloatLanes<W> b, unsigned within = 0xff) { return a.template cmp_mask<_CMP_GT_OQ>(b, within); }
template <int W>
unsigned ne_mask(FloatLanes<W> a, FloatLanes<W> b, unsigned within = 0xff) { return a.template cmp_mask<_CMP_NEQ_OQ>(b, within); }
#endif

inline FloatLanes<4> max(FloatLanes<4> a, FloatLanes<4> b) { return {_mm_max_ps(a.v, b.v)}; }
inline FloatLanes<4> min(FloatLanes<4> a, FloatLanes<4> b) { return {_mm_min_ps(a.v, b.v)}; }
// a * b + c, rounded once (std::fma).
inline FloatLanes<4> fmadd(FloatLanes<4> a, FloatLanes<4> b, FloatLanes<4> c) { return {_mm_fmadd_ps(a.v, b.v, c.v)}; }
// a * b - c, rounded once (std::fma(a, b, -c)).
inline FloatLanes<4> fmsub(FloatLanes<4> a, FloatLanes<4> b, FloatLanes<4> c) { return {_mm_fmsub_ps(a.v, b.v, c.v)}; }

// Lane i of a where lane i of `m` is set (all ones), else of b.
inline FloatLanes<8> select(FloatLanes<8> m, FloatLanes<8> a, FloatLanes<8> b) { return {_mm256_blendv_ps(b.v, a.v, m.v)}; }
// The smallest and the largest lane (lanes without NaN).
inline float reduce_min(FloatLanes<8> x) {
  __m128 a = _mm_min_ps(_mm256_castps256_ps128(x.v), _mm256_extractf128_ps(x.v, 1));
  a = _mm_min_ps(a, _mm_movehl_ps(a, a));
  return _mm_cvtss_f32(_mm_min_ss(a, _mm_movehdup_ps(a)));
}
inline float reduce_max(FloatLanes<8> x) {
  __m128 a = _mm_max_ps(_mm256_castps256_ps128(x.v), _mm256_extractf128_ps(x.v, 1));
  a = _mm_max_ps(a, _mm_movehl_ps(a, a));
  return _mm_cvtss_f32(_mm_max_ss(a, _mm_movehdup_ps(a)));
}

// Eight reductions at once: lane k of the result is the smallest (largest)
// lane of rows[k] (lanes without NaN): 21 shuffles and compares where eight
// reduce_min take 48, and the result stays in a register.
template <class Op>
inline FloatLanes<8> reduce_each(const FloatLanes<8> (&rows)[8], Op op) {
  __m256 pairs[4], quads[2];
  for (int k = 0; k < 4; ++k)  // lanes: row 2k, 2k+1, 2k, 2k+1 in each 128-bit half
    pairs[k] = op(_mm256_unpacklo_ps(rows[2 * k].v, rows[2 * k + 1].v), _mm256_unpackhi_ps(rows[2 * k].v, rows[2 * k + 1].v));
  for (int k = 0; k < 2; ++k)  // lanes: rows 4k .. 4k+3 in each 128-bit half
    quads[k] = op(_mm256_shuffle_ps(pairs[2 * k], pairs[2 * k + 1], _MM_SHUFFLE(1, 0, 1, 0)),
                  _mm256_shuffle_ps(pairs[2 * k], pairs[2 * k + 1], _MM_SHUFFLE(3, 2, 3, 2)));
  return {op(_mm256_permute2f128_ps(quads[0], quads[1], 0x20), _mm256_permute2f128_ps(quads[0], quads[1], 0x31))};
}
inline FloatLanes<8> reduce_min_each(const FloatLanes<8> (&rows)[8]) {
  return reduce_each(rows, [](__m256 a, __m256 b) { return _mm256_min_ps(a, b); });
}
inline FloatLanes<8> reduce_max_each(const FloatLanes<8> (&rows)[8]) {
  return reduce_each(rows, [](__m256 a, __m256 b) { return _mm256_max_ps(a, b); });
}
// Lane `k` of x in every lane.
inline FloatLanes<8> broadcast_lane(FloatLanes<8> x, int k) { return x.permute(IntLanes<8>::set1(static_cast<std::uint32_t>(k))); }

// The first two steps of the 8 x 8 transpose (the classic unpack and
// shuffle): from rows r[0..4), tt[k]'s low 128 bits hold element k of the
// four rows and its high 128 bits element k + 4 (each half of a wider
// register alike, for the 16-lane form below).
template <class V, class Unpacklo, class Unpackhi, class Shuffle>
inline void transpose4_in_lanes(const V (&r)[4], V (&tt)[4], Unpacklo unpacklo, Unpackhi unpackhi, Shuffle shuffle) {
  const V t0 = unpacklo(r[0], r[1]), t1 = unpackhi(r[0], r[1]), t2 = unpacklo(r[2], r[3]), t3 = unpackhi(r[2], r[3]);
  tt[0] = shuffle.template operator()<_MM_SHUFFLE(1, 0, 1, 0)>(t0, t2);
  tt[1] = shuffle.template operator()<_MM_SHUFFLE(3, 2, 3, 2)>(t0, t2);
  tt[2] = shuffle.template operator()<_MM_SHUFFLE(1, 0, 1, 0)>(t1, t3);
  tt[3] = shuffle.template operator()<_MM_SHUFFLE(3, 2, 3, 2)>(t1, t3);
}

inline void FloatLanes<8>::load_transposed8(const float* rows, FloatLanes (&out)[8]) {
  const auto unpacklo = [](__m256 a, __m256 b) { return _mm256_unpacklo_ps(a, b); };
  const auto unpackhi = [](__m256 a, __m256 b) { return _mm256_unpackhi_ps(a, b); };
  const auto shuffle = []<int Imm>(__m256 a, __m256 b) { return _mm256_shuffle_ps(a, b, Imm); };
  __m256 lo[4], hi[4], tlo[4], thi[4];  // rows 0-3 and 4-7
  // A row as two 16-byte loads into one register: what GCC makes of an
  // unaligned 256-bit load under its AMD tunings anyway, but written so it
  // stays a register value. From _mm256_loadu_ps, GCC copied the rows to
  // the stack in 16-byte pieces, and each 32-byte reload for the shuffles
  // waited for both pieces (a failed store-to-load forward; measured:
  // docs/notes/kernels-packets.md).
  const auto row = [](const float* p) {
    return _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(p)), _mm_loadu_ps(p + 4), 1);
  };
  for (int i = 0; i < 4; ++i) lo[i] = row(rows + 8 * i), hi[i] = row(rows + 8 * (i + 4));
  transpose4_in_lanes(lo, tlo, unpacklo, unpackhi, shuffle);
  transpose4_in_lanes(hi, thi, unpacklo, unpackhi, shuffle);
  for (int k = 0; k < 4; ++k) {
    out[k] = {_mm256_permute2f128_ps(tlo[k], thi[k], 0x20)};
    out[k + 4] = {_mm256_permute2f128_ps(tlo[k], thi[k], 0x31)};
  }
}

#if defined(RAYBENCH_AVX512)
// 16 float lanes in one AVX-512 register, for the packet traversal's 16
// rays (bvh/wide_bvh_packet.h). Comparisons give a LaneMask16 (a mask
// register), with the same ordered, non-signalling predicates as above.
struct LaneMask16 {
  __mmask16 k;
  static LaneMask16 from_bits(unsigned bits) { return {static_cast<__mmask16>(bits)}; }
  unsigned mask() const { return k; }
  LaneMask16 operator&(LaneMask16 o) const { return {static_cast<__mmask16>(k & o.k)}; }
};

template <>
struct FloatLanes<16> {
  __m512 v;
  static FloatLanes set1(float x) { return {_mm512_set1_ps(x)}; }
  static FloatLanes load(const float* p) { return {_mm512_load_ps(p)}; }
  // The 16 rows of 8 floats at `rows` transposed: lane i of out[k] is rows[i * 8 + k].
  static void load_transposed8(const float* rows, FloatLanes (&out)[8]);
  void storeu(float* p) const { _mm512_storeu_ps(p, v); }
  FloatLanes operator+(FloatLanes o) const { return {_mm512_add_ps(v, o.v)}; }
  FloatLanes operator-(FloatLanes o) const { return {_mm512_sub_ps(v, o.v)}; }
  FloatLanes operator*(FloatLanes o) const { return {_mm512_mul_ps(v, o.v)}; }
  FloatLanes operator/(FloatLanes o) const { return {_mm512_div_ps(v, o.v)}; }
  // xor and and in their integer forms: AVX-512F alone (the float forms need DQ).
  FloatLanes operator^(FloatLanes o) const {
    return {_mm512_castsi512_ps(_mm512_xor_si512(_mm512_castps_si512(v), _mm512_castps_si512(o.v)))};
  }
  LaneMask16 operator<=(FloatLanes o) const { return {_mm512_cmp_ps_mask(v, o.v, _CMP_LE_OQ)}; }
  LaneMask16 operator<(FloatLanes o) const { return {_mm512_cmp_ps_mask(v, o.v, _CMP_LT_OQ)}; }
  LaneMask16 operator>=(FloatLanes o) const { return {_mm512_cmp_ps_mask(v, o.v, _CMP_GE_OQ)}; }
  LaneMask16 operator>(FloatLanes o) const { return {_mm512_cmp_ps_mask(v, o.v, _CMP_GT_OQ)}; }
  LaneMask16 operator!=(FloatLanes o) const { return {_mm512_cmp_ps_mask(v, o.v, _CMP_NEQ_OQ)}; }
  FloatLanes abs() const { return {_mm512_abs_ps(v)}; }
  FloatLanes sign() const {
    return {_mm512_castsi512_ps(_mm512_and_si512(_mm512_set1_epi32(INT32_MIN), _mm512_castps_si512(v)))};
  }
};
// max/min in their zero-masking form under a full mask: the same instruction
// (GCC 12's plain _mm512_max_ps/_mm512_min_ps warn of an undefined operand).
inline FloatLanes<16> max(FloatLanes<16> a, FloatLanes<16> b) { return {_mm512_maskz_max_ps(0xffff, a.v, b.v)}; }
inline FloatLanes<16> min(FloatLanes<16> a, FloatLanes<16> b) { return {_mm512_maskz_min_ps(0xffff, a.v, b.v)}; }
inline FloatLanes<16> fmadd(FloatLanes<16> a, FloatLanes<16> b, FloatLanes<16> c) { return {_mm512_fmadd_ps(a.v, b.v, c.v)}; }
inline FloatLanes<16> fmsub(FloatLanes<16> a, FloatLanes<16> b, FloatLanes<16> c) { return {_mm512_fmsub_ps(a.v, b.v, c.v)}; }
inline FloatLanes<16> select(LaneMask16 m, FloatLanes<16> a, FloatLanes<16> b) { return {_mm512_mask_blend_ps(m.k, b.v, a.v)}; }
// The lower or upper 8 lanes (AVX-512F alone: through the 64-bit form,
// zero-masked under a full mask for GCC 12's sake as above).
template <int Half>
inline FloatLanes<8> half_of(FloatLanes<16> x) {
  return {_mm256_castpd_ps(_mm512_maskz_extractf64x4_pd(0xff, _mm512_castps_pd(x.v), Half))};
}
inline float reduce_min(FloatLanes<16> x) { return reduce_min(min(half_of<0>(x), half_of<1>(x))); }
inline float reduce_max(FloatLanes<16> x) { return reduce_max(max(half_of<0>(x), half_of<1>(x))); }
// Lane `k` of x in each of 8 lanes (one permute, zero-masked under a full
// mask for GCC 12's sake as above).
inline FloatLanes<8> broadcast_lane8(FloatLanes<16> x, int k) {
  return half_of<0>(FloatLanes<16>{_mm512_maskz_permutexvar_ps(0xffff, _mm512_set1_epi32(k), x.v)});
}

// Register j holds row j in its low 256 bits and row j + 8 in its high ones,
// so the 8-lane transpose's first two steps run on both halves at once; one
// two-source permute per field then interleaves the 128-bit quarters.
// (Zero-masked forms under a full mask for GCC 12's sake, as above.)
inline void FloatLanes<16>::load_transposed8(const float* rows, FloatLanes (&out)[8]) {
  const auto unpacklo = [](__m512 a, __m512 b) { return _mm512_maskz_unpacklo_ps(0xffff, a, b); };
  const auto unpackhi = [](__m512 a, __m512 b) { return _mm512_maskz_unpackhi_ps(0xffff, a, b); };
  const auto shuffle = []<int Imm>(__m512 a, __m512 b) { return _mm512_maskz_shuffle_ps(0xffff, a, b, Imm); };
  const auto two_rows = [&](int j) {
    const __m512d low = _mm512_castpd256_pd512(_mm256_castps_pd(_mm256_loadu_ps(rows + 8 * j)));
    return _mm512_castpd_ps(_mm512_maskz_insertf64x4(0xff, low, _mm256_castps_pd(_mm256_loadu_ps(rows + 8 * (j + 8))), 1));
  };
  __m512 lo[4], hi[4], tlo[4], thi[4];  // rows 0-3 (and 8-11) and 4-7 (and 12-15)
  for (int j = 0; j < 4; ++j) lo[j] = two_rows(j), hi[j] = two_rows(j + 4);
  transpose4_in_lanes(lo, tlo, unpacklo, unpackhi, shuffle);
  transpose4_in_lanes(hi, thi, unpacklo, unpackhi, shuffle);
  // tlo[k]'s quarters: element k of rows 0-3, element k + 4 of rows 0-3, element k of rows 8-11, k + 4 of 8-11;
  // thi[k]'s the same of rows 4-7 and 12-15.
  const __m512i even = _mm512_setr_epi32(0, 1, 2, 3, 16, 17, 18, 19, 8, 9, 10, 11, 24, 25, 26, 27);
  const __m512i odd = _mm512_setr_epi32(4, 5, 6, 7, 20, 21, 22, 23, 12, 13, 14, 15, 28, 29, 30, 31);
  for (int k = 0; k < 4; ++k) {
    out[k] = {_mm512_permutex2var_ps(tlo[k], even, thi[k])};
    out[k + 4] = {_mm512_permutex2var_ps(tlo[k], odd, thi[k])};
  }
}
#endif

// Lane `k` of x in each of 8 lanes (AVX2's form of broadcast_lane8).
inline FloatLanes<8> broadcast_lane8(FloatLanes<8> x, int k) { return broadcast_lane(x, k); }

// Twice a register's lanes in two registers (lanes 0 to H - 1 in lo, H to
// 2H - 1 in hi), every operation the register's own on either half, so each
// lane computes exactly what it computes in one: the packet traversal's 32
// rays with AVX-512 (two FloatLanes<16>), 16 with AVX2 (two FloatLanes<8>).
// A packet of twice the rays shares each node's fetch, frustum test and
// branches among them (docs/notes/kernels-packets.md, "32-ray packets").
template <typename Half, int H>
struct LanePair {
  using HalfMask = decltype(Half::set1(0.0f) <= Half::set1(0.0f));
  // The comparisons' answer: bit i of mask() for lane i.
  struct Mask {
    HalfMask lo, hi;
    Mask() = default;
    Mask(HalfMask l, HalfMask h) : lo(l), hi(h) {}
    Mask(const Mask& o) : lo(o.lo), hi(o.hi) {}  // half by half, as LanePair below
    Mask& operator=(const Mask& o) {
      lo = o.lo;
      hi = o.hi;
      return *this;
    }
    static Mask from_bits(unsigned bits) { return {HalfMask::from_bits(bits & ((1u << H) - 1u)), HalfMask::from_bits(bits >> H)}; }
    unsigned mask() const { return lo.mask() | hi.mask() << H; }
    Mask operator&(Mask o) const { return {lo & o.lo, hi & o.hi}; }
  };
  Half lo, hi;
  LanePair() = default;
  LanePair(Half l, Half h) : lo(l), hi(h) {}
  // Copied half by half, each half one register's move. The implicit copy
  // moves the pair as 2H floats of memory, which GCC does in 16-byte pieces
  // where its tuning has no wider moves by pieces (generic, AMD Zen): a
  // register-wide load of such a copy then waits for the pieces to reach
  // the cache (a failed store-to-load forward; measured in the AVX2
  // packets: docs/notes/kernels-packets.md).
  LanePair(const LanePair& o) : lo(o.lo), hi(o.hi) {}
  LanePair& operator=(const LanePair& o) {
    lo = o.lo;
    hi = o.hi;
    return *this;
  }
  static LanePair set1(float x) {
    const Half h = Half::set1(x);
    return {h, h};
  }
  static LanePair load(const float* p) { return {Half::load(p), Half::load(p + H)}; }
  // The 2H rows of 8 floats at `rows` transposed: lane i of out[k] is rows[i * 8 + k].
  static void load_transposed8(const float* rows, LanePair (&out)[8]) {
    Half lo[8], hi[8];
    Half::load_transposed8(rows, lo);
    Half::load_transposed8(rows + H * 8, hi);
    for (int k = 0; k < 8; ++k) out[k] = {lo[k], hi[k]};
  }
  void storeu(float* p) const {
    lo.storeu(p);
    hi.storeu(p + H);
  }
  LanePair operator+(LanePair o) const { return {lo + o.lo, hi + o.hi}; }
  LanePair operator-(LanePair o) const { return {lo - o.lo, hi - o.hi}; }
  LanePair operator*(LanePair o) const { return {lo * o.lo, hi * o.hi}; }
  LanePair operator/(LanePair o) const { return {lo / o.lo, hi / o.hi}; }
  LanePair operator^(LanePair o) const { return {lo ^ o.lo, hi ^ o.hi}; }
  Mask operator<=(LanePair o) const { return {lo <= o.lo, hi <= o.hi}; }
  Mask operator<(LanePair o) const { return {lo < o.lo, hi < o.hi}; }
  Mask operator>=(LanePair o) const { return {lo >= o.lo, hi >= o.hi}; }
  Mask operator>(LanePair o) const { return {lo > o.lo, hi > o.hi}; }
  Mask operator!=(LanePair o) const { return {lo != o.lo, hi != o.hi}; }
  LanePair abs() const { return {lo.abs(), hi.abs()}; }
  LanePair sign() const { return {lo.sign(), hi.sign()}; }
};
template <typename Half, int H>
inline LanePair<Half, H> max(LanePair<Half, H> a, LanePair<Half, H> b) { return {max(a.lo, b.lo), max(a.hi, b.hi)}; }
template <typename Half, int H>
inline LanePair<Half, H> min(LanePair<Half, H> a, LanePair<Half, H> b) { return {min(a.lo, b.lo), min(a.hi, b.hi)}; }
template <typename Half, int H>
inline LanePair<Half, H> fmadd(LanePair<Half, H> a, LanePair<Half, H> b, LanePair<Half, H> c) {
  return {fmadd(a.lo, b.lo, c.lo), fmadd(a.hi, b.hi, c.hi)};
}
template <typename Half, int H>
inline LanePair<Half, H> fmsub(LanePair<Half, H> a, LanePair<Half, H> b, LanePair<Half, H> c) {
  return {fmsub(a.lo, b.lo, c.lo), fmsub(a.hi, b.hi, c.hi)};
}
template <typename Half, int H>
inline LanePair<Half, H> select(typename LanePair<Half, H>::Mask m, LanePair<Half, H> a, LanePair<Half, H> b) {
  return {select(m.lo, a.lo, b.lo), select(m.hi, a.hi, b.hi)};
}
// Lane `k` of x (0 to 2H - 1) in each of 8 lanes.
template <typename Half, int H>
inline FloatLanes<8> broadcast_lane8(LanePair<Half, H> x, int k) {
  return k < H ? broadcast_lane8(x.lo, k) : broadcast_lane8(x.hi, k - H);
}

}  // namespace raybench::simd
#endif
