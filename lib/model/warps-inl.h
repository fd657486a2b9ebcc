// The cosine-weighted hemisphere warp, over a number type F and its `Ops` (model/scalar_ops.h). No guard and
// no namespace: model/proposal.h includes it in facetfit::warps for double, render/lanes-inl.h inside
// Highway's per-target region (as model/ggx_terms-inl.h).

// A direction of density cos(theta) / pi (Malley's method): a point of the unit disc, r = sqrt(u1) at
// phi = 2 pi u2 (given as its cosine and sine, which callers share with the other parts they draw), lifted to
// the hemisphere, z = sqrt(1 - r^2).
template <class Ops, class F>
inline void cosine_hemisphere(const Ops& op, F u1, F cos_phi, F sin_phi, F& x, F& y, F& z) {
  const F r = op.sqrt(u1);
  x = r * cos_phi;
  y = r * sin_phi;
  z = op.sqrt(op.max(op.constant(0.0), op.constant(1.0) - r * r));
}
