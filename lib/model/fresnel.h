// Fresnel reflectance models, evaluated at cos(theta_d) = i.h = o.h.
#pragma once

#include <cmath>

#include "core/vec.h"
#include "model/scalar_ops.h"

namespace facetfit {

// Schlick's and F82-tint's formulas, which the renderer's SIMD lanes compile too.
namespace fresnel_formulas {
#include "model/fresnel_terms-inl.h"
}  // namespace fresnel_formulas

// Schlick's approximation with normal-incidence reflectance f0.
Rgb fresnel_schlick(const Rgb& f0, double cos_d);
// Conductor with complex index of refraction eta + i k per channel (unpolarized, exact).
Rgb fresnel_conductor(const Rgb& eta, const Rgb& k, double cos_d);
// Dielectric with real relative index eta (unpolarized, exact; total internal reflection gives 1).
double fresnel_dielectric(double eta, double cos_d);
// Hoffman's F82-tint model: Schlick plus a correction term that makes F(acos(1/7)) = f82 exactly,
// F(mu) = Schlick(f0, mu) - a mu (1 - mu)^6. The term's scale `a` is the material's: computed once.
struct F82Tint {
  Rgb f0{0.0}, a{0.0};
  F82Tint() = default;
  F82Tint(const Rgb& f0, const Rgb& f82);
  Rgb eval(double cos_d) const;
};
inline Rgb fresnel_f82_tint(const Rgb& f0, const Rgb& f82, double cos_d) { return F82Tint(f0, f82).eval(cos_d); }

// The angle at which the F82-tint model is pinned: acos(1/7), about 81.79 degrees.
inline double f82_theta() { return std::acos(1.0 / 7.0); }

// A Fresnel term for analytic models: one of the above, chosen by kind.
struct Fresnel {
  enum class Kind { one, schlick, conductor, dielectric };
  Kind kind = Kind::one;
  Rgb f0{1.0};        // schlick
  Rgb eta{1.5}, k{0}; // conductor: eta, k; dielectric: eta.x

  static Fresnel one() { return {}; }
  static Fresnel schlick(const Rgb& f0) { Fresnel f; f.kind = Kind::schlick; f.f0 = f0; return f; }
  static Fresnel conductor(const Rgb& eta, const Rgb& k) {
    Fresnel f; f.kind = Kind::conductor; f.eta = eta; f.k = k; return f;
  }
  static Fresnel dielectric(double eta) { Fresnel f; f.kind = Kind::dielectric; f.eta = Rgb(eta); return f; }

  Rgb eval(double cos_d) const;
};

}  // namespace facetfit
