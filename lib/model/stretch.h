// Artistic control of a tabulated lobe (Dupuy et al. 2015, section 6): its slopes stretched by (x, y)
// along axes turned by `rotation` about the normal,
//   D_s(h) = P(x~ / s_x, y~ / s_y) / (s_x s_y cos^4 theta_h),
// P the measured slope distribution: roughness grows in proportion to the stretch, so a stretch below 1
// sharpens. Smith masking is stretch-invariant (Heitz 2014): Lambda_s(w) = Lambda(w') for w' = (s_x w_x,
// s_y w_y, w_z) normalized, so masking, sigma and the visible normals are read from the isotropic tables
// at transformed directions; the tables themselves never change. A normal h of the stretched lobe is the
// normal h' = (h_x / s_x, h_y / s_y, h_z) normalized of the measured one, and densities per steradian of
// normals pick up d(omega_h') / d(omega_h) = cos^3(theta_h') / (s_x s_y cos^3(theta_h)).
#pragma once

#include <cmath>

#include "core/frame.h"
#include "core/vec.h"

namespace facetfit {

class Stretch {
 public:
  // What a scene or a texture may ask along either axis: roughness from 1/100 to 100 times the measured.
  static constexpr double kMin = 0.01, kMax = 100.0;

  // Slopes scaled by (x, y) along axes whose x axis lies at azimuth `rotation` (radians).
  Stretch(double along_x = 1.0, double along_y = 1.0, double rotation = 0.0)
      : x(along_x), y(along_y), rotation_(rotation), axes_(rotation) {}

  double x, y;
  double rotation() const { return rotation_; }

  // Scales nothing: an isotropic lobe does not change under a rotation alone, an anisotropic one turns.
  bool unscaled() const { return x == 1.0 && y == 1.0; }
  bool identity() const { return unscaled() && rotation_ == 0.0; }

  // Into and out of the frame whose x axis is the stretch's.
  Vec3 to_frame(const Vec3& v) const { return axes_.to_frame(v); }
  Vec3 from_frame(const Vec3& v) const { return axes_.from_frame(v); }
  // A direction as the measured lobe sees it (masking, the view of visible normals); frame coordinates.
  Vec3 direction(const Vec3& w) const { return glm::normalize(Vec3(x * w.x, y * w.y, w.z)); }
  // A normal of the stretched lobe as a normal of the measured one, and back; frame coordinates.
  Vec3 measured_normal(const Vec3& h) const { return glm::normalize(Vec3(h.x / x, h.y / y, h.z)); }
  Vec3 stretched_normal(const Vec3& m) const { return glm::normalize(Vec3(x * m.x, y * m.y, m.z)); }
  // d(omega_h') / d(omega_h) for h' = measured_normal(h), given both cosines.
  double normal_jacobian(double cos_h, double cos_measured) const {
    const double r = cos_measured / cos_h;
    return r * r * r / (x * y);
  }

 private:
  double rotation_;
  TurnedFrame axes_;
};

}  // namespace facetfit
