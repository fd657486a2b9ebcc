// GGX's visible normals (Heitz 2018, "Sampling the GGX Distribution of Visible Normals") over a number type F
// and its `Ops` (model/scalar_ops.h). No guard and no namespace: model/ggx_visible.h includes it in
// facetfit::ggx for double, render/lanes-inl.h inside Highway's per-target region (as model/ggx_terms-inl.h).

// The visible normal h of GGX (alpha_x, alpha_y along the frame's axes) seen from o (above the horizon), at
// the point (r cos phi, r sin phi) of the unit disc: o is taken to the unit-roughness frame (v), where the
// visible part of the hemisphere projects to a disc and a half-disc; the disc point is warped onto them
// (s = (1 + v.z) / 2 blends the half-disc in), lifted onto the hemisphere and stretched back.
template <class Ops, class F>
inline void visible_normal(const Ops& op, F ox, F oy, F oz, F alpha_x, F alpha_y, F r, F cos_phi, F sin_phi, F& hx, F& hy, F& hz) {
  const F zero = op.constant(0.0), one = op.constant(1.0);
  F vx = alpha_x * ox, vy = alpha_y * oy, vz = oz;
  const F inv_v = op.inverse_sqrt(vx * vx + vy * vy + vz * vz);
  vx = vx * inv_v, vy = vy * inv_v, vz = vz * inv_v;
  // t1 = (-v.y, v.x, 0) / |.|, or the x axis where v is the normal; t2 = v x t1 (written out as glm::cross).
  const F len2 = vx * vx + vy * vy, safe_len2 = op.positive_or(len2, one);
  const F t1x = op.select_positive(len2, op.divide_by_sqrt(op.negate(vy), safe_len2), one);
  const F t1y = op.where_positive(len2, op.divide_by_sqrt(vx, safe_len2));
  const F t2x = vy * zero - t1y * vz, t2y = vz * t1x - zero * vx, t2z = vx * t1y - t1x * vy;
  const F p1 = r * cos_phi, s = op.constant(0.5) * (one + vz);
  const F p2 = (one - s) * op.sqrt(op.max(zero, one - p1 * p1)) + s * r * sin_phi;
  const F w = op.sqrt(op.max(zero, one - p1 * p1 - p2 * p2));
  const F nx = p1 * t1x + p2 * t2x + w * vx, ny = p1 * t1y + p2 * t2y + w * vy, nz = p1 * zero + p2 * t2z + w * vz;
  hx = alpha_x * nx, hy = alpha_y * ny, hz = op.max(zero, nz);
  const F inv_h = op.inverse_sqrt(hx * hx + hy * hy + hz * hz);
  hx = hx * inv_h, hy = hy * inv_h, hz = hz * inv_h;
}
