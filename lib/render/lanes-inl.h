// The terms the renderer's SIMD kernels share (render/ggx_batch.cpp, tabulated_batch.cpp, merl_batch.cpp),
// compiled into each kernel file once per SIMD target: Highway's per-target header pattern (the guard
// toggles with HWY_TARGET_TOGGLE). Include after <hwy/highway.h> and <hwy/contrib/math/math-inl.h>.
#if defined(FACETFIT_RENDER_LANES_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef FACETFIT_RENDER_LANES_INL_H_
#undef FACETFIT_RENDER_LANES_INL_H_
#else
#define FACETFIT_RENDER_LANES_INL_H_
#endif

#include <array>
#include <cstddef>
#include <cstdint>

#include "core/vec.h"
#include "model/coat.h"
#include "model/fresnel_curve.h"
#include "model/smith.h"
#include "render/shading_batch.h"

HWY_BEFORE_NAMESPACE();
namespace facetfit {
namespace HWY_NAMESPACE {
namespace lanes {
namespace hn = hwy::HWY_NAMESPACE;

using D = hn::ScalableTag<double>;
using V = hn::Vec<D>;
// Single precision: twice a double vector's lanes (one on the scalar baseline). The tabulated lobe's
// kernels run in it (render/tabulated_batch.cpp); every helper below takes either.
using DF = hn::ScalableTag<float>;
using VF = hn::Vec<DF>;

template <class DT>
constexpr bool kSingle = sizeof(hn::TFromD<DT>) == 4;

// A column's (double) lanes from p in DT's precision: hn::Lanes(dt) entries.
template <class DT>
HWY_INLINE hn::Vec<DT> load(DT dt, const double* p) {
  if constexpr (!kSingle<DT>) {
    return hn::LoadU(dt, p);
  } else {
    const D d;
#if HWY_TARGET == HWY_SCALAR
    return hn::DemoteTo(dt, hn::LoadU(d, p));
#else
    const hn::Half<DT> dh;
    return hn::Combine(dt, hn::DemoteTo(dh, hn::LoadU(d, p + hn::Lanes(d))), hn::DemoteTo(dh, hn::LoadU(d, p)));
#endif
  }
}

// v's lanes into a column of doubles at p.
template <class DT>
HWY_INLINE void store(DT dt, hn::Vec<DT> v, double* p) {
  if constexpr (!kSingle<DT>) {
    hn::StoreU(v, dt, p);
  } else {
    const D d;
#if HWY_TARGET == HWY_SCALAR
    hn::StoreU(hn::PromoteTo(d, v), d, p);
#else
    const hn::Half<DT> dh;
    hn::StoreU(hn::PromoteTo(d, hn::LowerHalf(dh, v)), d, p);
    hn::StoreU(hn::PromoteTo(d, hn::UpperHalf(dh, v)), d, p + hn::Lanes(d));
#endif
  }
}

// 1 / x, as the division gives it to a few ulp. AVX-512 has a 14-bit estimate that two Newton steps,
// y += y (1 - x y), make 56 bits in about half the division's time (vdivpd on 8 doubles issues once per
// 16 cycles, and a GGX sample divides about twenty times). Where x is 0, infinite, NaN or so small that
// 1/x overflows, the first step's error is not finite: those lanes divide. Elsewhere the division: AVX2
// has no estimate for doubles.
inline V reciprocal(D d, V x) {
#if HWY_TARGET == HWY_AVX3
  const V one = hn::Set(d, 1.0);
  const V y0{_mm512_rcp14_pd(x.raw)};
  const V e0 = hn::NegMulAdd(x, y0, one), y1 = hn::MulAdd(y0, e0, y0);
  const V y2 = hn::MulAdd(y1, hn::NegMulAdd(x, y1, one), y1);
  const auto special = hn::Not(hn::IsFinite(e0));
  if (HWY_UNLIKELY(!hn::AllFalse(d, special))) return hn::IfThenElse(special, one / x, y2);
  return y2;
#else
  return hn::Set(d, 1.0) / x;
#endif
}

// a / b, as the division gives it to a few ulp: a times b's reciprocal, except in the lanes where that is
// infinite (b zero or so small that 1/b overflows), which divide: 0 / b is 0 and a denormal over a
// denormal is finite, a times infinity is not.
inline V divide(D d, V a, V b) {
#if HWY_TARGET == HWY_AVX3
  const V r = reciprocal(d, b);
  const auto overflows = hn::Not(hn::IsFinite(r));
  if (HWY_UNLIKELY(!hn::AllFalse(d, overflows))) return hn::IfThenElse(overflows, a / b, a * r);
  return a * r;
#else
  (void)d;
  return a / b;
#endif
}

// 1 / sqrt(x), as reciprocal: two Newton steps y *= 3/2 - x/2 y^2 on AVX-512's 14-bit estimate; the lanes
// where x is 0, infinite, NaN, negative or so small that the estimate's square overflows take 1 / sqrt(x).
inline V inverse_sqrt(D d, V x) {
#if HWY_TARGET == HWY_AVX3
  const V half_x = hn::Set(d, 0.5) * x, three_halves = hn::Set(d, 1.5);
  const V y0{_mm512_rsqrt14_pd(x.raw)};
  const V e0 = half_x * (y0 * y0), y1 = y0 * (three_halves - e0);
  const V y2 = y1 * hn::NegMulAdd(half_x, y1 * y1, three_halves);
  const auto special = hn::Not(hn::IsFinite(e0));
  if (HWY_UNLIKELY(!hn::AllFalse(d, special))) return hn::IfThenElse(special, hn::Set(d, 1.0) / hn::Sqrt(x), y2);
  return y2;
#else
  return hn::Set(d, 1.0) / hn::Sqrt(x);
#endif
}

// sqrt(x) for finite x >= 0 (outside that, what it gives depends on the target): x times inverse_sqrt on
// AVX-512, whose estimate and Newton steps issue in a quarter of vsqrtpd's time (once per 16 cycles on
// eight doubles); 0 at 0. Elsewhere the square root.
inline V sqrt(D d, V x) {
#if HWY_TARGET == HWY_AVX3
  const auto positive = x > hn::Zero(d);
  return hn::IfThenElseZero(positive, x * inverse_sqrt(d, hn::IfThenElse(positive, x, hn::Set(d, 1.0))));
#else
  (void)d;
  return hn::Sqrt(x);
#endif
}

// The same in single precision: the division and the square root themselves (AVX2's and AVX-512's
// single-precision estimates would each need a Newton step to reach it).
inline VF reciprocal(DF d, VF x) { return hn::Set(d, 1.0f) / x; }
inline VF divide(DF, VF a, VF b) { return a / b; }
inline VF inverse_sqrt(DF d, VF x) { return hn::Set(d, 1.0f) / hn::Sqrt(x); }
inline VF sqrt(DF, VF x) { return hn::Sqrt(x); }

// base[index] in each lane: Highway's gather, except for AVX2's eight 32-bit lanes, which load one by one:
// AMD's Zen (family 23) microcodes vgatherdps, and a gather is eight loads on other x86 cores too.
template <class DT, typename T>
HWY_INLINE hn::Vec<DT> gather(DT d, const T* base, hn::Vec<hn::RebindToSigned<DT>> index) {
#if HWY_TARGET == HWY_AVX2
  if constexpr (sizeof(T) == 4 && hn::MaxLanes(DT()) == 8) {
    alignas(32) std::int32_t at[8];
    hn::Store(index, hn::RebindToSigned<DT>(), at);
    alignas(32) const T v[8] = {base[at[0]], base[at[1]], base[at[2]], base[at[3]], base[at[4]], base[at[5]], base[at[6]], base[at[7]]};
    return hn::Load(d, v);
  }
#endif
  return hn::GatherIndex(d, base, index);
}

// base[index + c], c = 0..3, in each lane: four neighbouring entries of a table at once. AVX2's eight
// single-precision lanes load each lane's four together and transpose them (two 4 x 4 transposes),
// where four gathers would load 32 floats one by one; elsewhere four gathers. Reads up to base[index + 3]
// whether or not the caller uses it: the table needs three entries of room past the last index.
template <class DT>
struct Neighbours {
  hn::Vec<DT> v[4];
};
template <class DT>
HWY_INLINE Neighbours<DT> gather4(DT d, const float* base, hn::Vec<hn::RebindToSigned<DT>> index) {
  const hn::RebindToSigned<DT> di;
#if HWY_TARGET == HWY_AVX2
  if constexpr (hn::MaxLanes(DT()) == 8) {
    alignas(32) std::int32_t at[8];
    hn::Store(index, di, at);
    __m128 r0 = _mm_loadu_ps(base + at[0]), r1 = _mm_loadu_ps(base + at[1]), r2 = _mm_loadu_ps(base + at[2]), r3 = _mm_loadu_ps(base + at[3]);
    __m128 r4 = _mm_loadu_ps(base + at[4]), r5 = _mm_loadu_ps(base + at[5]), r6 = _mm_loadu_ps(base + at[6]), r7 = _mm_loadu_ps(base + at[7]);
    _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
    _MM_TRANSPOSE4_PS(r4, r5, r6, r7);
    using VT = hn::Vec<DT>;
    return {{VT{_mm256_set_m128(r4, r0)}, VT{_mm256_set_m128(r5, r1)}, VT{_mm256_set_m128(r6, r2)}, VT{_mm256_set_m128(r7, r3)}}};
  }
#endif
  return {{gather(d, base, index), gather(d, base, index + hn::Set(di, 1)), gather(d, base, index + hn::Set(di, 2)),
           gather(d, base, index + hn::Set(di, 3))}};
}

// x in DT's precision (a double constant rounded to single where DT is).
template <class DT>
HWY_INLINE hn::Vec<DT> set(DT d, double x) {
  return hn::Set(d, static_cast<hn::TFromD<DT>>(x));
}

// acos(c), c in [-1, 1], as Highway's Acos (asin's polynomial on [0, 1/2] at |c| or at sqrt((1 - |c|) / 2))
// with sqrt above for the square root. The polynomial is Highway's internal AsinImpl (hwy 1.0.3, Debian
// bookworm's): the lanes tests compare the result with std::acos's to 1e-10 on every target (double).
// `one_minus_c`, where given, is 1 - c for c >= 1/2 from the caller's own terms: single precision rounds
// c = cos(theta) near 1 to steps of 6e-8, which leaves a theta of 0.005 with 0.5% of error; 1 - c =
// sin^2 / (1 + c) keeps it to the sine's rounding.
template <class DT, class VT = hn::Vec<DT>>
HWY_INLINE VT acos(DT d, VT c, VT one_minus_c) {
  const VT a = hn::Abs(c), half = set(d, 0.5), half_pi = set(d, 0.5 * kPi);
  const auto near_zero = a < half;
  const VT yy = hn::IfThenElse(near_zero, a * a, half * one_minus_c);
  const VT y = hn::IfThenElse(near_zero, a, sqrt(d, yy));
  hn::impl::AsinImpl<hn::TFromD<DT>> poly;
  const VT asin_y = hn::MulAdd(poly.AsinPoly(d, yy, y), y * yy, y);
  const VT z = hn::IfThenElse(near_zero, half_pi - hn::CopySign(asin_y, c), asin_y + asin_y);
  return hn::IfThenElse(hn::Or(near_zero, c >= hn::Zero(d)), z, set(d, kPi) - z);
}
template <class DT, class VT = hn::Vec<DT>>
HWY_INLINE VT acos(DT d, VT c) {
  const VT one = set(d, 1.0);
  return acos(d, c, one - hn::Abs(c));
}

template <class VT>
struct CosSinOf {
  VT c, s;
};
using CosSin = CosSinOf<V>;

// (-1)^k / n! for n = 2k and 2k + 1, k = 0..10: the coefficients of cos_sin's series.
constexpr std::array<double, 22> kCosSinSeries = [] {
  std::array<double, 22> c{};
  double inverse_factorial = 1.0;
  for (int n = 0; n < 22; ++n) {
    if (n > 0) inverse_factorial /= n;
    c[std::size_t(n)] = (n / 2) % 2 == 0 ? inverse_factorial : -inverse_factorial;
  }
  return c;
}();

// cos and sin of phi in [-pi, pi] in one: cos is even, sin odd, and on [0, pi], with x = |phi| - pi/2 in
// [-pi/2, pi/2], cos = -sin(x) and sin = cos(x), their Taylor series to x^21 and x^20, whose remainders at
// pi/2 (1e-18, 2e-17) are below double rounding; Estrin's scheme, half Horner's dependent chain. Accurate
// to double rounding of 1 (absolute, as a direction's components need; sin(0) is 6e-17). Highway's Sin and
// Cos reduce any argument, each on its own.
template <class DT, class VT = hn::Vec<DT>>
HWY_INLINE CosSinOf<VT> cos_sin(DT d, VT phi) {
  const VT x = hn::Abs(phi) - set(d, 0.5 * kPi), x2 = x * x;
  const auto c = [&](std::size_t n) { return set(d, kCosSinSeries[n]); };
  const VT cos_x = hn::impl::Estrin(x2, c(0), c(2), c(4), c(6), c(8), c(10), c(12), c(14), c(16), c(18), c(20));
  const VT sin_x = hn::impl::Estrin(x2, c(1), c(3), c(5), c(7), c(9), c(11), c(13), c(15), c(17), c(19), c(21));
  return {hn::Neg(sin_x * x), hn::CopySign(cos_x, phi)};
}

// cos and sin of 2 pi u, u in [0, 1): the angle taken in [-pi, pi) (u - 1 is exact for u >= 1/2).
template <class DT, class VT = hn::Vec<DT>>
HWY_INLINE CosSinOf<VT> cos_sin_turn(DT d, VT u) {
  const VT one = set(d, 1.0);
  return cos_sin(d, set(d, 2.0 * kPi) * hn::IfThenElse(u >= set(d, 0.5), u - one, u));
}

// The library's formulas written once over a number type (model/ggx_terms-inl.h: GGX's D and Lambda;
// model/smith_terms-inl.h: Smith's G2; model/fresnel_terms-inl.h: Schlick and F82-tint), compiled for
// this target.
namespace ggx {
#include "model/ggx_terms-inl.h"
#include "model/ggx_visible-inl.h"
}  // namespace ggx
namespace smith_formulas {
#include "model/smith_terms-inl.h"
}  // namespace smith_formulas
namespace fresnel_formulas {
#include "model/fresnel_terms-inl.h"
}  // namespace fresnel_formulas
namespace warps {
#include "model/warps-inl.h"
}  // namespace warps

// What those formulas need of DT's vectors (ScalarOps, model/scalar_ops.h, for double): the lanes'
// division and reciprocal, the square root, constants, min and max, and choices by sign.
template <class DT, class VT = hn::Vec<DT>>
struct LaneOps {
  DT d;
  VT divide(VT a, VT b) const { return lanes::divide(d, a, b); }
  VT reciprocal(VT x) const { return lanes::reciprocal(d, x); }
  VT sqrt(VT x) const { return hn::Sqrt(x); }
  VT constant(double c) const { return set(d, c); }
  VT min(VT a, VT b) const { return hn::Min(a, b); }
  VT max(VT a, VT b) const { return hn::Max(a, b); }
  VT where_positive(VT x, VT v) const { return hn::IfThenElseZero(x > hn::Zero(d), v); }
  VT positive_or(VT x, VT otherwise) const { return hn::IfThenElse(x > hn::Zero(d), x, otherwise); }
  VT negate(VT x) const { return hn::Neg(x); }
  VT inverse_sqrt(VT x) const { return lanes::inverse_sqrt(d, x); }
  VT divide_by_sqrt(VT a, VT b) const { return a * lanes::inverse_sqrt(d, b); }
  VT select_positive(VT x, VT a, VT b) const { return hn::IfThenElse(x > hn::Zero(d), a, b); }
};

// Smith's Lambda of GGX for w above the horizon (ggx::lambda).
template <class DT, class VT = hn::Vec<DT>>
HWY_INLINE VT ggx_lambda(DT d, VT wx, VT wy, VT wz, VT ax2, VT ay2) {
  return ggx::lambda(LaneOps<DT>{d}, wx, wy, wz, ax2, ay2);
}

// D(h) of GGX for h above the horizon (ggx::D).
template <class DT, class VT = hn::Vec<DT>>
HWY_INLINE VT ggx_ndf(DT d, VT hx, VT hy, VT hz, VT ax2, VT ay2, VT numerator_over_pi) {
  return ggx::D(LaneOps<DT>{d}, hx, hy, hz, ax2, ay2, numerator_over_pi);
}

// The tabulated Fresnel curve at cos(theta_d) in [0, 1]: linear between its entries, one per degree of
// theta_d (FresnelCurve::eval); `curve` holds its r, g, b entry by entry, in DT's precision.
template <class DT, class VT = hn::Vec<DT>>
HWY_INLINE void fresnel_curve(DT d, const hn::TFromD<DT>* curve, VT cos_d, VT out[3]) {
  constexpr int size = FresnelCurve::kSize;
  const hn::RebindToSigned<DT> di;
  using Index = hn::TFromD<decltype(di)>;
  const VT zero = hn::Zero(d), one = set(d, 1.0);
  const VT x = hn::Min(hn::Max(lanes::acos(d, cos_d) * set(d, size / (0.5 * kPi)), zero), set(d, size - 1.0));
  const auto j = hn::Min(hn::ConvertTo(di, x), hn::Set(di, Index{size - 2}));
  const VT t = x - hn::ConvertTo(d, j);
  const auto j3 = j + j + j;  // three values per entry
  if constexpr (kSingle<DT>) {
    // Entries j and j + 1, r g b r and r g b r (the curve has room past its end: TabulatedBatchModel).
    const Neighbours<DT> lo = gather4(d, curve, j3), hi = gather4(d, curve + 3, j3);
    for (int c = 0; c < 3; ++c) out[c] = lo.v[c] * (one - t) + hi.v[c] * t;
  } else {
    for (int c = 0; c < 3; ++c) {
      const VT lo = gather(d, curve + c, j3), hi = gather(d, curve + 3 + c, j3);
      out[c] = lo * (one - t) + hi * t;
    }
  }
}

// A clear coat's f (the same in R, G and B) and its visible normals' density of i (model/coat.h), from the
// half vector h, cos(theta_d), 4 cos(theta_i) cos(theta_o) and whether o faces h; the caller masks the
// pairs below the horizon.
template <class VT>
struct CoatTermsOf {
  VT f, pdf;
};
using CoatTerms = CoatTermsOf<V>;
template <class DT, class VT = hn::Vec<DT>>
HWY_INLINE CoatTermsOf<VT> coat_terms(DT d, const Coat& coat, VT ox, VT oy, VT oz, VT ix, VT iy, VT iz, VT hx, VT hy, VT hz, VT cos_d,
                                      VT four_cos, hn::Mask<DT> o_faces_h) {
  const double a = coat.alpha;
  const VT a2 = set(d, a * a), numerator = set(d, a * a * a * a * a * a / kPi), one = set(d, 1.0);
  const VT dc = ggx_ndf(d, hx, hy, hz, a2, a2, numerator);
  const VT lc_o = ggx_lambda(d, ox, oy, oz, a2, a2), lc_i = ggx_lambda(d, ix, iy, iz, a2, a2);
  // The coat's G2 and G1(o) divide, where the lobes' kernels take AVX-512's reciprocal estimate (LaneOps).
  struct DividingOps : LaneOps<DT> {
    VT reciprocal(VT x) const { return set(this->d, 1.0) / x; }
  };
  const DividingOps op{{d}};
  const VT fc = fresnel_formulas::schlick(op, set(d, coat.f0), fresnel_formulas::schlick_weight(op, cos_d));
  const VT g2 = smith_formulas::g2(op, Smith::correlated, lc_o, lc_i);
  return {fc * dc * g2 / four_cos, hn::IfThenElseZero(o_faces_h, (one / (one + lc_o)) * dc / (set(d, 4.0) * oz))};
}

template <class VT>
struct DirectionOf {
  VT x, y, z;
};
using Direction = DirectionOf<V>;

// o reflected about the unit normal h, 2 (o.h) h - o (reflect_about, core/vec.h).
template <class DT, class VT = hn::Vec<DT>>
HWY_INLINE DirectionOf<VT> reflect(DT d, VT ox, VT oy, VT oz, VT hx, VT hy, VT hz) {
  const VT two_o_h = set(d, 2.0) * (ox * hx + oy * hy + oz * hz);
  return {two_o_h * hx - ox, two_o_h * hy - oy, two_o_h * hz - oz};
}

// Visible normals of GGX (model/ggx_visible.h, Heitz 2018) for o above the horizon, with u1, u2 in [0, 1)
// and (cos, sin) of phi = 2 pi u2: i, to be refused where i.z <= 0.
template <class DT, class VT = hn::Vec<DT>>
HWY_INLINE DirectionOf<VT> ggx_visible_direction(DT d, VT ox, VT oy, VT oz, VT alpha, VT u1, VT cos_phi, VT sin_phi) {
  VT hx, hy, hz;
  ggx::visible_normal(LaneOps<DT>{d}, ox, oy, oz, alpha, alpha, hn::Sqrt(u1), cos_phi, sin_phi, hx, hy, hz);
  return reflect(d, ox, oy, oz, hx, hy, hz);
}

// The density of i for a shading model that draws with `weights` (ShadingModel::pdf), from the lobe's and
// the coat's densities (the body's is the cosine's).
template <class DT, class VT = hn::Vec<DT>>
HWY_INLINE VT mixture_density(DT d, const ProposalWeights& weights, bool coat, VT lobe_pdf, VT coat_pdf, VT iz) {
  const VT inv_pi = set(d, kInvPi);
  VT parts = set(d, weights.part_lobe) * lobe_pdf + set(d, weights.part_body) * iz * inv_pi;
  if (coat) parts = parts + set(d, weights.part_coat) * coat_pdf;
  return set(d, weights.lobe_weight) * parts + set(d, 1.0 - weights.lobe_weight) * (iz * inv_pi);
}

// The largest number below 1 in DT's precision: where a number drawn in [0, 1) is clamped.
template <class DT>
constexpr double kBelowOne = kSingle<DT> ? 1.0 - 0x1.0p-24 : 1.0 - 1e-16;

// Fills the batch's i and found for its padded_size() entries, drawn with `weights`
// (ShadingModel::sample_direction). `lobe(ox, oy, oz, u1, u2, cos_phi, sin_phi)` draws the lobe's
// direction (to be refused where i.z <= 0) with u1 rescaled to the lobe's part and (cos, sin) of
// phi = 2 pi u2 (where `lobe_turns`; zeros otherwise: the series costs as much as a tabulated lobe's
// cell draw, and only GGX lobes, the body, the coat and the cosine part read it; the cosine part turns its own
// where nothing else did and a lane draws it); it runs on every lane, the lanes that pick another part
// discard it.
template <class DT, class Lobe>
void sample_proposal(DT d, const ProposalWeights& weights, const Coat& coat, SampleBatch& batch, bool lobe_turns, const Lobe& lobe) {
  using VT = hn::Vec<DT>;
  const std::size_t n = batch.padded_size();
  const VT zero = hn::Zero(d), one = set(d, 1.0);
  const VT coat_alpha = set(d, coat.alpha), lobe_weight = set(d, weights.lobe_weight);
  const VT part_lobe = set(d, weights.part_lobe), part_body = set(d, weights.part_body);
  // Their reciprocals once (a part the model lacks gives infinity; no lane that picks it reads the result).
  const VT per_lobe = set(d, 1.0 / weights.part_lobe), per_body = set(d, 1.0 / weights.part_body);
  const VT per_coat = set(d, 1.0 / weights.part_coat);
  const bool with_coat = coat.present(), body = weights.part_body > 0.0, cosine_part = weights.lobe_weight < 1.0;
  const bool turns = lobe_turns || with_coat || body;
  for (std::size_t k = 0; k < n; k += hn::Lanes(d)) {
    const VT ox = load(d, batch.ox.data() + k), oy = load(d, batch.oy.data() + k), oz = load(d, batch.oz.data() + k);
    const VT u1 = load(d, batch.u1.data() + k), u2 = load(d, batch.u2.data() + k), u3 = load(d, batch.u3.data() + k);
    const CosSinOf<VT> turn = turns ? cos_sin_turn(d, u2) : CosSinOf<VT>{zero, zero};
    const VT cos_phi = turn.c, sin_phi = turn.s;
    // The proposal (u3 < lobe_weight): u1 picks its part and is rescaled within it (ProposalParts::sample).
    const auto in_lobe = u1 < part_lobe;
    DirectionOf<VT> i = lobe(ox, oy, oz, u1 * per_lobe, u2, cos_phi, sin_phi);
    const VT rest = u1 - part_lobe;
    auto refused = hn::Not(in_lobe);  // parts past the lobe that this model lacks
    if (body) {
      const auto in_body = hn::AndNot(in_lobe, rest < part_body);
      VT x, y, z;
      warps::cosine_hemisphere(LaneOps<DT>{d}, rest * per_body, cos_phi, sin_phi, x, y, z);
      i.x = hn::IfThenElse(in_body, x, i.x), i.y = hn::IfThenElse(in_body, y, i.y), i.z = hn::IfThenElse(in_body, z, i.z);
      refused = hn::AndNot(in_body, refused);
    }
    if (with_coat) {
      const auto in_coat = hn::AndNot(in_lobe, rest >= part_body);
      const VT u = hn::Min(hn::Max((rest - part_body) * per_coat, zero), set(d, kBelowOne<DT>));
      const DirectionOf<VT> c = ggx_visible_direction(d, ox, oy, oz, coat_alpha, u, cos_phi, sin_phi);
      i.x = hn::IfThenElse(in_coat, c.x, i.x), i.y = hn::IfThenElse(in_coat, c.y, i.y), i.z = hn::IfThenElse(in_coat, c.z, i.z);
      refused = hn::AndNot(in_coat, refused);
    }
    // Cosine sampling otherwise (ShadingModel::sample_direction), by the same warp as the body's; skipped
    // where no lane draws it.
    const auto cosine = u3 >= lobe_weight;
    if (cosine_part && !hn::AllFalse(d, cosine)) {
      const CosSinOf<VT> t = turns ? turn : cos_sin_turn(d, u2);
      VT x, y, z;
      warps::cosine_hemisphere(LaneOps<DT>{d}, u1, t.c, t.s, x, y, z);
      i.x = hn::IfThenElse(cosine, x, i.x), i.y = hn::IfThenElse(cosine, y, i.y), i.z = hn::IfThenElse(cosine, z, i.z);
      refused = hn::AndNot(cosine, refused);
    }
    // Every part refuses i on or below the horizon (cosine_direction too, at u1 = 1 in DT's precision).
    const auto found = hn::AndNot(refused, hn::And(oz > zero, i.z > zero));
    store(d, i.x, batch.ix.data() + k), store(d, i.y, batch.iy.data() + k), store(d, i.z, batch.iz.data() + k);
    store(d, hn::IfThenElseZero(found, one), batch.found.data() + k);
  }
}

}  // namespace lanes
// NOLINTNEXTLINE(google-readability-namespace-comments)
}  // namespace HWY_NAMESPACE
}  // namespace facetfit
HWY_AFTER_NAMESPACE();

#endif  // FACETFIT_RENDER_LANES_INL_H_
