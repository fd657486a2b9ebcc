// GGX's D and Smith's Lambda over a number type F and its `Ops` (model/ggx_terms.h). No guard and no
// namespace: model/ggx_terms.h includes it in facetfit::ggx for double, and render/lanes-inl.h inside
// Highway's per-target region, so that each SIMD target compiles the same text with its own instructions
// (a template defined outside that region cannot inline the target's operators).

// D(h) for h above the horizon, ax^3 ay^3 / (pi e^2) with e = hx^2 ay^2 + hy^2 ax^2 + hz^2 ax^2 ay^2:
// slope_pdf / cos^4 with the slopes multiplied out, one division instead of four. Homogeneous of degree
// -4 in h, it stays finite where hz^4 underflows. `numerator_over_pi`: ax^3 ay^3 / pi, fixed per lobe.
template <class Ops, class F>
inline F D(const Ops& op, F hx, F hy, F hz, F ax2, F ay2, F numerator_over_pi) {
  const F e = hx * hx * ay2 + hy * hy * ax2 + hz * hz * ax2 * ay2;
  return op.divide(numerator_over_pi, e * e);
}

// Lambda(w) for w above the horizon: (sqrt(1 + alpha^2 tan^2) - 1) / 2, with alpha^2 sin^2 =
// wx^2 ax^2 + wy^2 ay^2; zero where alpha^2 tan^2 is not positive (also 0 / 0 at a denormal normal).
template <class Ops, class F>
inline F lambda(const Ops& op, F wx, F wy, F wz, F ax2, F ay2) {
  const F a2t2 = op.divide(wx * wx * ax2 + wy * wy * ay2, wz * wz);
  const F one = op.constant(1.0);
  return op.where_positive(a2t2, op.constant(0.5) * (op.sqrt(one + a2t2) - one));
}
