// Orthonormal local frames: the shading frame (t, b, n) around a unit normal, and a frame turned about it.
#pragma once

#include <cmath>

#include "core/vec.h"

namespace facetfit {

struct Frame {
  Vec3 t, b, n;
  // Any tangents: the branchless basis of Duff et al. 2017 (continuous except across n.z = 0's sign).
  explicit Frame(const Vec3& normal) : n(normal) {
    const double sign = std::copysign(1.0, n.z), a = -1.0 / (sign + n.z), c = n.x * n.y * a;
    t = Vec3(1.0 + sign * n.x * n.x * a, sign * c, -sign * n.x);
    b = Vec3(c, sign + n.y * n.y * a, -n.y);
  }
  // With its x axis along the projection of a given direction on the surface (an anisotropic lobe's axes
  // follow it); the frame above where that projection vanishes.
  Frame(const Vec3& normal, const Vec3& along) : Frame(normal) {
    const Vec3 projected = along - glm::dot(along, n) * n;
    const double len = glm::length(projected);
    if (!(len > 1e-9)) return;
    t = projected / len;
    b = glm::cross(n, t);
  }
  Vec3 to_local(const Vec3& v) const { return {glm::dot(v, t), glm::dot(v, b), glm::dot(v, n)}; }
  Vec3 to_world(const Vec3& v) const { return v.x * t + v.y * b + v.z * n; }
};

// A local frame turned about its normal: the x axis at azimuth `angle`. Anisotropic lobes are written in
// the frame of their axes, which a measurement or a stretch places at some azimuth.
struct TurnedFrame {
  double c = 1.0, s = 0.0;  // cosine and sine of the angle, kept: callers turn every direction they evaluate
  TurnedFrame() = default;
  explicit TurnedFrame(double angle) : c(std::cos(angle)), s(std::sin(angle)) {}
  // From the angle's cosine and sine when a direction gives them (x / r, y / r), without the angle.
  static TurnedFrame of(double cosine, double sine) {
    TurnedFrame f;
    f.c = cosine, f.s = sine;
    return f;
  }
  // The frame whose x axis is w's azimuth, (w.x, w.y) / |w.xy| (the identity straight up): a view's own.
  static TurnedFrame of_azimuth(const Vec3& w) {
    const double r = std::sqrt(w.x * w.x + w.y * w.y);
    if (!(r > 0.0)) return TurnedFrame();
    const double per = 1.0 / r;
    return of(w.x * per, w.y * per);
  }
  Vec3 to_frame(const Vec3& v) const { return {c * v.x + s * v.y, -s * v.x + c * v.y, v.z}; }    // by -angle
  Vec3 from_frame(const Vec3& v) const { return {c * v.x - s * v.y, s * v.x + c * v.y, v.z}; }  // by +angle
};

}  // namespace facetfit
