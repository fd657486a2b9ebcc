// Schlick's Fresnel and Hoffman's F82-tint over a number type F and its `Ops` (model/scalar_ops.h), at
// mu = cos(theta_d). No guard and no namespace: model/fresnel.h includes it in facetfit::fresnel_formulas
// for double, render/lanes-inl.h inside Highway's per-target region (as model/ggx_terms-inl.h).

// Schlick's weight (1 - mu)^5, with 1 - mu clamped to [0, 1]; three products.
template <class Ops, class F>
inline F schlick_weight(const Ops& op, F mu) {
  const F m = op.min(op.max(op.constant(1.0) - mu, op.constant(0.0)), op.constant(1.0));
  return (m * m) * (m * m) * m;
}

// The generalized Schlick F = f0 + (f90 - f0) w, with w = (1 - mu)^e (Cycles' and MaterialX's
// generalized_schlick_bsdf). F0 and F90 may be colours (Rgb) over a number w.
template <class F0, class F90, class F>
inline F0 generalized_schlick(F0 f0, F90 f90, F w) {
  return f0 + (f90 - f0) * w;
}

// Schlick's F = f0 + (1 - f0) w, w = schlick_weight(mu).
template <class Ops, class F0, class F>
inline F0 schlick(const Ops& op, F0 f0, F w) {
  return generalized_schlick(f0, op.constant(1.0), w);
}

// mu (1 - mu)^6, the shape of F82-tint's correction, the sixth power multiplied out (four products).
template <class Ops, class F>
inline F f82_basis(const Ops& op, F mu) {
  const F m = op.constant(1.0) - mu, m2 = m * m;
  return mu * m2 * m2 * m2;
}

// F82-tint (Hoffman 2019): F = max(0, Schlick(f0, mu) - a mu (1 - mu)^6), from Schlick's weight w and the
// basis at mu, per channel; a = (Schlick(f0, 1/7) - f82) / f82_basis(1/7) pins F(acos(1/7)) = f82
// (F82Tint, model/fresnel.h).
template <class Ops, class F>
inline F f82_tint(const Ops& op, F f0, F a, F w, F basis) {
  return op.max(schlick(op, f0, w) - a * basis, op.constant(0.0));
}
