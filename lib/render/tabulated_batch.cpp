// Compiled once per SIMD target by Highway's foreach_target (this file includes itself), as
// render/ggx_batch.cpp.
#include "render/simd_targets.h"  // before any of Highway's headers
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "render/tabulated_batch.cpp"
#include <hwy/foreach_target.h>  // before highway.h

#include <hwy/highway.h>
#include <hwy/contrib/math/math-inl.h>

#include <limits>

#include "model/tabulated.h"
#include "model/visible_slopes.h"
#include "render/lanes-inl.h"
#include "render/tabulated_batch.h"

HWY_BEFORE_NAMESPACE();
namespace facetfit {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

namespace {

// Single precision throughout (TabulatedBatchModel): DF's lanes, int32 indices.
using lanes::DF;
using lanes::set;
using V = lanes::VF;
using DI = hn::RebindToSigned<DF>;
using I = hn::Vec<DI>;

// Interval j and fraction t of the theta grid at theta = acos(c), c in [0, 1] (ThetaGrid::locate), from c
// and 1 - c (lanes::acos: a peak's theta needs 1 - c to more than single precision's steps near 1).
struct GridPosition {
  I j;
  V t;
};
HWY_INLINE GridPosition locate(DF d, V c, V one_minus_c, int resolution) {
  const DI di;
  const V theta = lanes::acos(d, hn::Min(hn::Max(c, hn::Zero(d)), set(d, 1.0)), hn::Max(one_minus_c, hn::Zero(d)));
  const V x = hn::Min(lanes::sqrt(d, hn::Max(hn::Zero(d), theta) * set(d, 2.0 / kPi)), set(d, 1.0)) * set(d, double(resolution));
  const I j = hn::Min(hn::ConvertTo(di, x), hn::Set(di, resolution - 1));
  return {j, x - hn::ConvertTo(d, j)};
}

// The Catmull-Rom spline through D's nodes at p (ThetaGrid::interpolate): node j - 1 mirrored to node 1
// at j = 0, the ghost past the last node folded into the weights of the last two. `quads` holds interval
// j's four nodes (j - 1 or 1, j, j + 1, j + 2 or the last) together (TabulatedBatchModel::ndf).
V spline(DF d, const float* quads, const GridPosition& p, int resolution) {
  const DI di;
  const V t = p.t, t2 = t * t, t3 = t2 * t, half = set(d, 0.5);
  const V w0 = half * (hn::Neg(t) + set(d, 2.0) * t2 - t3);
  V w1 = half * (set(d, 2.0) - set(d, 5.0) * t2 + set(d, 3.0) * t3);
  V w2 = half * (t + set(d, 4.0) * t2 - set(d, 3.0) * t3);
  V w3 = half * (t3 - t2);
  const auto past = hn::RebindMask(d, p.j + hn::Set(di, 2) > hn::Set(di, resolution));
  w2 = hn::IfThenElse(past, w2 + set(d, 2.0) * w3, w2);
  w1 = hn::IfThenElse(past, w1 - w3, w1);
  w3 = hn::IfThenElseZero(hn::Not(past), w3);
  const lanes::Neighbours<DF> node = lanes::gather4(d, quads, p.j * hn::Set(di, 4));
  V v = w0 * node.v[0];
  v = v + w1 * node.v[1];
  v = v + w2 * node.v[2];
  return v + w3 * node.v[3];
}

// G1 of the table (G1Table::operator()) at c = cos(theta) > 0; lanes at or below the horizon read 0.
V g1(DF d, const TabulatedBatchModel& model, V c) {
  const DI di;
  const V zero = hn::Zero(d), one = set(d, 1.0), scale = set(d, double(model.g1_size));
  const V cz = hn::Max(c, zero);
  const V x = hn::Sqrt(cz) * scale;
  const I m = hn::Min(hn::ConvertTo(di, x), hn::Set(di, model.g1_size - 1));
  const V t = x - hn::ConvertTo(d, m);
  const lanes::Neighbours<DF> node = lanes::gather4(d, model.g1_ratios, m);
  const V lo = node.v[0], hi = node.v[1];
  const V ratio = hn::IfThenElse(x >= scale, hn::Set(d, model.g1_ratios[model.g1_size]), lo + t * (hi - lo));
  return hn::IfThenElseZero(c > zero, hn::Min(one, cz * ratio));
}

// The cell k of the running sums cdf[row + 0..n] in which u in [0, 1) falls (the last whose sum is <= u:
// sample_cdf, so cells without mass are never chosen), stepping on from the cell the row's guide gives
// for u (append_cdf_guide, at guide_row), and u's fraction in it.
struct CellDraw {
  I k;
  V t;
};
HWY_INLINE CellDraw draw_cell(DF d, const float* cdf, const std::int32_t* guide, I row, I guide_row, int n, V u) {
  const DI di;
  constexpr int entries = VisibleSlopes::kGuide;
  const I one_i = hn::Set(di, 1), last = hn::Set(di, n - 1), end = hn::Set(di, n);
  const I g = hn::Min(hn::Max(hn::ConvertTo(di, u * set(d, double(entries))), hn::Zero(di)), hn::Set(di, entries - 1));
  I k = lanes::gather(di, guide, guide_row + g);
  // The sum at cell k is <= u. Most draws end within two cells of it: the next three sums at once, then
  // steps one cell at a time for lanes that go further (a guide entry over several cells of little mass).
  // Where a lane reads a sum past the row's last (cdf[row + n]), the masks below do not use it; the
  // tables have room past their end (TabulatedBatchModel).
  const lanes::Neighbours<DF> sums = lanes::gather4(d, cdf, row + k);
  const V c0 = sums.v[0], c1 = sums.v[1], c2 = sums.v[2], c3 = sums.v[3];
  const auto a1 = hn::And(hn::RebindMask(d, k < last), c1 <= u);
  const auto a2 = hn::And(a1, hn::And(hn::RebindMask(d, k + one_i < last), c2 <= u));
  const auto a3 = hn::And(a2, hn::And(hn::RebindMask(d, k + hn::Set(di, 2) < last), c3 <= u));
  V lo = hn::IfThenElse(a2, c2, hn::IfThenElse(a1, c1, c0)), hi = hn::IfThenElse(a2, c3, hn::IfThenElse(a1, c2, c1));
  k = k + hn::IfThenElseZero(hn::RebindMask(di, a1), one_i) + hn::IfThenElseZero(hn::RebindMask(di, a2), one_i);
  if (HWY_UNLIKELY(!hn::AllFalse(d, a3))) {
    auto more = hn::RebindMask(di, a3);
    do {
      k = hn::IfThenElse(more, k + one_i, k);
      more = hn::And(more, hn::And(k < last, hn::RebindMask(di, lanes::gather(d, cdf, row + hn::Min(k + one_i, end)) <= u)));
    } while (!hn::AllFalse(di, more));
    lo = lanes::gather(d, cdf, row + k), hi = lanes::gather(d, cdf, row + k + one_i);
  }
  const V zero = hn::Zero(d), one = set(d, 1.0), mass = hi - lo;
  const auto some = mass > zero;
  const V t = hn::IfThenElse(some, hn::Min(hn::Max(lanes::divide(d, u - lo, hn::IfThenElse(some, mass, one)), zero), one), set(d, 0.5));
  return {k, t};
}

// The view slice s below o and the weight t of s + 1 (view_slice, model/visible_slopes.h); lanes whose o
// is below the horizon (discarded) read slice 0, inside the tables.
struct SliceLanes {
  I s;
  V t;
};
HWY_INLINE SliceLanes view_slice(DF d, V oz, V scale) {
  const DI di;
  const V one = set(d, 1.0);
  const V cos_o = hn::Min(hn::Max(oz, hn::Zero(d)), one), sin_o = hn::Sqrt(hn::Max(hn::Zero(d), one - cos_o * cos_o));
  const V x = lanes::divide(d, cos_o, cos_o + scale * sin_o) * set(d, double(VisibleSlopes::kSlices - 1));
  const I s = hn::Min(hn::Max(hn::ConvertTo(di, x), hn::Zero(di)), hn::Set(di, VisibleSlopes::kSlices - 2));
  return {s, x - hn::ConvertTo(d, s)};
}

// The cosine and sine of o's azimuth (o.xy / |o.xy|; 1 and 0 straight above).
HWY_INLINE lanes::CosSinOf<V> view_azimuth(DF d, V ox, V oy) {
  const V o_xy = hn::Sqrt(ox * ox + oy * oy), zero = hn::Zero(d), one = set(d, 1.0);
  const auto turned = o_xy > zero;
  const V per_xy = hn::IfThenElseZero(turned, lanes::reciprocal(d, hn::IfThenElse(turned, o_xy, one)));
  return {hn::IfThenElse(turned, ox * per_xy, one), oy * per_xy};
}

// |v| and w at most this: VisibleSlopes::kEdge is 1 to single precision, where the slopes would not stay
// finite.
constexpr double kEdge = 1.0 - 0x1.0p-24;

// o reflected about a normal drawn from the lobe's visible slopes (VisibleSlopes::sample), to be refused
// where i.z <= 0.
lanes::DirectionOf<V> lobe_direction(DF d, const TabulatedBatchModel& model, V ox, V oy, V oz, V u1, V u2) {
  const DI di;
  constexpr int cells = VisibleSlopes::kCells, side = VisibleSlopes::kSideCells;
  const V zero = hn::Zero(d), one = set(d, 1.0), half = set(d, 0.5), scale = set(d, model.scale);
  const V edge = set(d, kEdge);
  // One of the two view slices around o with the weights of the mixture, reusing u1.
  const SliceLanes view = view_slice(d, oz, scale);
  const V keep = one - view.t;
  const auto first = u1 < keep;
  V u = lanes::divide(d, hn::IfThenElse(first, u1, u1 - keep), hn::IfThenElse(first, keep, hn::IfThenElse(view.t > zero, view.t, one)));
  u = hn::Min(hn::Max(u, zero), set(d, lanes::kBelowOne<DF>));
  const I slice = hn::IfThenElse(hn::RebindMask(di, first), view.s, view.s + hn::Set(di, 1));
  const CellDraw cx = draw_cell(d, model.view_cdf, model.view_guide, slice * hn::Set(di, cells + 1),
                                slice * hn::Set(di, VisibleSlopes::kGuide + 1), cells, u);
  const V v = hn::Min(hn::Max(set(d, -1.0) + (hn::ConvertTo(d, cx.k) + cx.t) * set(d, 2.0 / cells), hn::Neg(edge)), edge);
  const V x = lanes::divide(d, scale * v, one - hn::Abs(v));
  // y~'s sign from u2's first half, its size from the rest.
  const auto lower = u2 < half;
  const V sign = hn::IfThenElse(lower, set(d, -1.0), one);
  u2 = hn::Min(hn::IfThenElse(lower, set(d, 2.0) * u2, set(d, 2.0) * u2 - one), set(d, lanes::kBelowOne<DF>));
  const CellDraw cy = draw_cell(d, model.side_cdf, model.side_guide, cx.k * hn::Set(di, side + 1),
                                cx.k * hn::Set(di, VisibleSlopes::kGuide + 1), side, u2);
  const V w = hn::Min((hn::ConvertTo(d, cy.k) + cy.t) * set(d, 1.0 / side), edge);
  const V y = sign * lanes::divide(d, scale * w, one - w);
  const V inv = lanes::reciprocal(d, hn::Sqrt(one + x * x + y * y));
  // From o's azimuth frame to the local one.
  const lanes::CosSinOf<V> turn = view_azimuth(d, ox, oy);
  const V vx = hn::Neg(x) * inv, vy = hn::Neg(y) * inv;
  const V hx = turn.c * vx - turn.s * vy, hy = turn.s * vx + turn.c * vy, hz = inv;
  return lanes::reflect(d, ox, oy, oz, hx, hy, hz);
}

}  // namespace

void SampleTabulatedBatch(const TabulatedBatchModel& model, SampleBatch& batch) {
  const DF d;
  lanes::sample_proposal(d, model.weights, model.coat, batch, false, [&](V ox, V oy, V oz, V u1, V u2, V, V) {
    return lobe_direction(d, model, ox, oy, oz, u1, u2);
  });
}

void EvalTabulatedBatch(const TabulatedBatchModel& model, EvaluationBatch& batch, bool with_f) {
  with_f = with_f && model.f;  // f's tables are null otherwise
  const DF d;
  const DI di;
  const std::size_t n = batch.padded_size();
  const V zero = hn::Zero(d), one = set(d, 1.0), four = set(d, 4.0), scale = set(d, model.scale);
  constexpr int cells = VisibleSlopes::kCells, side = VisibleSlopes::kSideCells;
  const int resolution = model.resolution;
  const V body[3] = {set(d, model.body.r * kInvPi), set(d, model.body.g * kInvPi), set(d, model.body.b * kInvPi)};
  const bool minnaert = model.body_exponent != 1.0;
  const V body_power = set(d, model.body_exponent - 1.0), body_scale = set(d, 0.5 * (model.body_exponent + 1.0));
  const bool coat = model.coat.present();
  double* out[3] = {batch.r.data(), batch.g.data(), batch.b.data()};
  for (std::size_t k = 0; k < n; k += hn::Lanes(d)) {
    const V ox = lanes::load(d, batch.ox.data() + k), oy = lanes::load(d, batch.oy.data() + k), oz = lanes::load(d, batch.oz.data() + k);
    const V ix = lanes::load(d, batch.ix.data() + k), iy = lanes::load(d, batch.iy.data() + k), iz = lanes::load(d, batch.iz.data() + k);
    const auto above = hn::And(iz > zero, oz > zero);
    // h = normalize(i + o)
    V hx = ix + ox, hy = iy + oy, hz = iz + oz;
    const V inv_len = lanes::inverse_sqrt(d, hx * hx + hy * hy + hz * hz);
    hx = hx * inv_len, hy = hy * inv_len, hz = hz * inv_len;
    const auto h_up = hz > zero;
    const V four_cos = four * iz * oz;
    const V cos_d = hn::Min(hn::Max(ix * hx + iy * hy + iz * hz, zero), one);
    const V o_dot_h = ox * hx + oy * hy + oz * hz;
    const auto o_faces_h = o_dot_h > zero;
    V coat_f = zero, coat_pdf = zero;
    if (coat) {
      const lanes::CoatTermsOf<V> terms = lanes::coat_terms(d, model.coat, ox, oy, oz, ix, iy, iz, hx, hy, hz, cos_d, four_cos, o_faces_h);
      coat_f = terms.f, coat_pdf = terms.pdf;
    }
    if (with_f) {
      // 1 - h.z = (h.x^2 + h.y^2) / (1 + h.z)
      const V one_minus = lanes::divide(d, hx * hx + hy * hy, one + hn::Max(hz, zero));
      const GridPosition normal = locate(d, hn::IfThenElse(h_up, hz, one), hn::IfThenElseZero(h_up, one_minus), resolution);
      const V dh = hn::IfThenElseZero(h_up, hn::Max(zero, spline(d, model.ndf, normal, resolution)));
      const V g1_i = g1(d, model, iz), g1_o = g1(d, model, oz);
      const V g2 = lanes::smith_formulas::g2_from_g1(lanes::LaneOps<DF>{d}, model.smith, g1_o, g1_i);
      V fresnel[3];
      lanes::fresnel_curve(d, model.curve, cos_d, fresnel);
      const V specular = lanes::divide(d, dh * g2, four_cos);
      // f where cos(theta_i) cos(theta_o) does not underflow (above_horizon, core/vec.h)
      const auto formed = hn::And(above, iz * oz > zero);
      // Minnaert's factor (k + 1) / 2 (cos_i cos_o)^(k - 1) (model/body.h)
      const V factor =
          minnaert ? body_scale * hn::Exp(d, body_power * hn::Log(d, hn::Max(iz * oz, hn::Set(d, std::numeric_limits<float>::min())))) : one;
      for (int c = 0; c < 3; ++c) lanes::store(d, hn::IfThenElseZero(formed, body[c] * factor + fresnel[c] * specular + coat_f), out[c] + k);
    }

    // The lobe's visible slopes (VisibleSlopes::pdf): h in o's azimuth frame, its cell, the cell's share
    // mixed between the two view slices around o, per steradian of h; reflected about h, d(omega_i) =
    // 4 (o.h) d(omega_h).
    // A light's slots take f alone (shading_batch.h): where no lane of the vector asks, no density.
    if (hn::AllFalse(d, lanes::load(d, batch.with_pdf.data() + k) != zero)) {
      lanes::store(d, zero, batch.pdf.data() + k);
      continue;
    }
    const lanes::CosSinOf<V> turn = view_azimuth(d, ox, oy);
    const auto visible = hn::And(o_faces_h, h_up);
    const V vx = turn.c * hx + turn.s * hy, vy = turn.c * hy - turn.s * hx;
    const V a = hn::IfThenElse(visible, scale * hz + hn::Abs(vx), one), b = hn::IfThenElse(visible, scale * hz + hn::Abs(vy), one);
    const V v = hn::Neg(lanes::divide(d, vx, a)), w = lanes::divide(d, hn::Abs(vy), b);
    const I i = hn::Min(hn::Max(hn::ConvertTo(di, (v + one) * set(d, 0.5 * cells)), hn::Zero(di)), hn::Set(di, cells - 1));
    const I j = hn::Min(hn::Max(hn::ConvertTo(di, w * set(d, double(side))), hn::Zero(di)), hn::Set(di, side - 1));
    const SliceLanes view = view_slice(d, oz, scale);
    const I at = view.s * hn::Set(di, cells) + i;
    const V mixed = (one - view.t) * lanes::gather(d, model.view_mass, at) + view.t * lanes::gather(d, model.view_mass, at + hn::Set(di, cells));
    const V cell = mixed * lanes::gather(d, model.side_mass, i * hn::Set(di, side) + j);
    const V ab = a * b;
    const V per_h = lanes::divide(d, cell * set(d, 0.25 * cells * side) * (set(d, model.scale * model.scale) * hz), ab * ab);
    const V lobe_pdf = hn::IfThenElseZero(visible, lanes::divide(d, per_h, four * o_dot_h));
    lanes::store(d, hn::IfThenElseZero(above, lanes::mixture_density(d, model.weights, coat, lobe_pdf, coat_pdf, iz)), batch.pdf.data() + k);
  }
}

// NOLINTNEXTLINE(google-readability-namespace-comments)
}  // namespace HWY_NAMESPACE
}  // namespace facetfit
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include "io/merl.h"
#include "render/shading.h"
#include "render/simd_dispatch.h"

namespace facetfit {

std::optional<TabulatedLanes> TabulatedLanes::recognise(const LanesInput& in) {
  const auto* slopes = dynamic_cast<const VisibleSlopeProposal*>(in.proposal);
  if (!slopes || !(in.lobe_weight > 0.0)) return std::nullopt;
  TabulatedLanes lanes{TabulatedBatchModel::of(*slopes, dynamic_cast<const TabulatedMicrofacet*>(&in.brdf), in.lobe_weight), {}};
  if (const auto* table = dynamic_cast<const HalfDiffTable*>(&in.brdf)) lanes.merl = MerlBatchModel::of(*table);
  return lanes;
}

void TabulatedLanes::eval(EvaluationBatch& batch, const ShadingModel& shading) const {
  eval_tabulated_batch(model, batch, SimdTarget::best, model.f);
  if (model.f) return;
  if (merl) return eval_merl_batch(*merl, batch);
  for (std::size_t k = 0; k < batch.size(); ++k) {
    const Rgb v = shading.f(batch.o(k), batch.i(k));
    batch.r[k] = v.r, batch.g[k] = v.g, batch.b[k] = v.b;
  }
}

TabulatedBatchModel TabulatedBatchModel::of(const VisibleSlopeProposal& proposal, const TabulatedMicrofacet* lobe, double lobe_weight) {
  TabulatedBatchModel m;
  const VisibleSlopes& slopes = proposal.slopes();
  const ProposalParts& parts = proposal.parts();
  m.scale = slopes.scale();
  m.coat = parts.coat;
  m.weights = {lobe_weight, parts.lobe, parts.body, parts.coat.present() ? parts.coat_weight() : 0.0};
  const MicrofacetTables* tables = lobe && lobe->stretch().unscaled() ? &lobe->tables() : nullptr;
  if (tables && (tables->fresnel.value.size() != std::size_t(FresnelCurve::kSize) || tables->coat.alpha != parts.coat.alpha ||
                 tables->coat.f0 != parts.coat.f0))
    tables = nullptr;
  // Every table rounded to float, one after the other; the pointers are set once all are in place.
  auto values = std::make_shared<std::vector<float>>();
  auto guides = std::make_shared<std::vector<std::int32_t>>();
  const auto put = [&values](const auto& table) {
    const std::size_t at = values->size();
    for (const double x : table) values->push_back(float(x));
    return at;
  };
  const auto put_guide = [&guides](const std::vector<std::int64_t>& guide) {
    const std::size_t at = guides->size();
    for (const std::int64_t g : guide) guides->push_back(std::int32_t(g));
    return at;
  };
  const std::size_t view_cdf = put(slopes.view_cdf()), view_mass = put(slopes.view_mass());
  const std::size_t side_cdf = put(slopes.side_cdf()), side_mass = put(slopes.side_mass());
  const std::size_t view_guide = put_guide(slopes.view_guide()), side_guide = put_guide(slopes.side_guide());
  std::size_t ndf = 0, g1_ratios = 0, curve = 0;
  if (tables) {
    // Interval j's four nodes of the spline together (spline()).
    const std::vector<double>& nodes = tables->ndf.ndf;
    const int resolution = tables->ndf.grid.resolution;
    std::vector<double> quads;
    for (int j = 0; j < resolution; ++j)
      for (const int at : {j == 0 ? 1 : j - 1, j, j + 1, std::min(j + 2, resolution)}) quads.push_back(nodes[std::size_t(at)]);
    ndf = put(quads);
    g1_ratios = put(std::vector<double>(lobe->g1_table().ratios(), lobe->g1_table().ratios() + lobe->g1_table().size() + 1));
    std::vector<double> rgb;
    for (const Rgb& e : tables->fresnel.value) rgb.insert(rgb.end(), {e.r, e.g, e.b});
    curve = put(rgb);
  }
  values->resize(values->size() + 4, 0.0f);  // room past the last table for the lanes' reads of four neighbours (lanes::gather4)
  m.view_cdf = values->data() + view_cdf, m.view_mass = values->data() + view_mass;
  m.side_cdf = values->data() + side_cdf, m.side_mass = values->data() + side_mass;
  m.view_guide = guides->data() + view_guide, m.side_guide = guides->data() + side_guide;
  if (tables) {
    m.f = true;
    m.resolution = tables->ndf.grid.resolution;
    m.ndf = values->data() + ndf;
    m.g1_ratios = values->data() + g1_ratios;
    m.g1_size = lobe->g1_table().size();
    m.smith = tables->smith;
    m.curve = values->data() + curve;
    m.body = tables->body;
    m.body_exponent = tables->body_exponent;
  }
  m.values = std::move(values), m.guides = std::move(guides);
  return m;
}

void eval_tabulated_batch(const TabulatedBatchModel& model, EvaluationBatch& batch, SimdTarget target, bool with_f) {
  FACETFIT_DISPATCH(target, EvalTabulatedBatch, model, batch, with_f);
}

void sample_tabulated_batch(const TabulatedBatchModel& model, SampleBatch& batch, SimdTarget target) {
  FACETFIT_DISPATCH(target, SampleTabulatedBatch, model, batch);
}

}  // namespace facetfit
#endif
