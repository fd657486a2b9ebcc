// Smith's G2, the masking-shadowing of a microfacet lobe, over a number type F and its `Ops`
// (model/scalar_ops.h), from the two Lambdas or from the two G1 = 1 / (1 + Lambda). The three couplings
// are those of `Smith` (model/smith.h). No guard and no namespace: model/smith.h includes it in
// facetfit::smith_formulas for double, render/lanes-inl.h inside Highway's per-target region (as
// model/ggx_terms-inl.h).

// G2 from Lambda_o and Lambda_i:
//   masking     1 / (1 + max(Lambda_o, Lambda_i)) = min(G1(o), G1(i))
//   correlated  1 / (1 + Lambda_i + Lambda_o)
//   separable   1 / ((1 + Lambda_i) (1 + Lambda_o)) = G1(o) G1(i)
template <class Ops, class F>
inline F g2(const Ops& op, Smith smith, F lambda_o, F lambda_i) {
  const F one = op.constant(1.0);
  switch (smith) {
    case Smith::masking: return op.reciprocal(one + op.max(lambda_i, lambda_o));
    case Smith::correlated: return op.reciprocal(one + lambda_i + lambda_o);
    case Smith::separable: return op.reciprocal((one + lambda_i) * (one + lambda_o));
  }
  return op.constant(0.0);
}

// The same G2 from G1(o) and G1(i) in [0, 1] (0 at the horizon), for lobes that tabulate G1: the correlated
// 1 / (1/G1i + 1/G1o - 1) written as G1i G1o / (G1i + G1o - G1i G1o), 0 where the denominator is 0.
template <class Ops, class F>
inline F g2_from_g1(const Ops& op, Smith smith, F g1_o, F g1_i) {
  switch (smith) {
    case Smith::masking: return op.min(g1_i, g1_o);
    case Smith::correlated: {
      const F den = g1_i + g1_o - g1_i * g1_o;
      return op.where_positive(den, op.divide(g1_i * g1_o, op.positive_or(den, op.constant(1.0))));
    }
    case Smith::separable: return g1_i * g1_o;
  }
  return op.constant(0.0);
}
