// The LUT texture: one OpenEXR per material with everything a renderer or an OSL shader needs to
// evaluate and sample the fitted material with plain texture lookups. Layout: docs/lut-format.md.
#pragma once

#include <functional>
#include <optional>
#include <string>

#include "core/rgb_space.h"
#include "fit/fit.h"
#include "fit/recommend.h"
#include "model/parametric.h"
#include "model/tabulated.h"

namespace facetfit {

// Version 2 adds the body and the parametric fits on the whole measurement; version 1 LUTs (no body)
// still read, with a zero body. Version 3 is version 2 with the anisotropic lobe's rows appended (written
// only for a fit that has one: LUTs without it stay version 2, which readers of version 2 take).
// Version 4 adds facetfit:body_exponent (Minnaert's k of the tabulated body, model/body.h), with or
// without the anisotropic rows; it is written only when k is not 1, so a Lambertian body's LUT stays
// version 2 or 3 and earlier readers, which would render the body Lambertian, refuse the others.
// Version 5 is version 4 with the closure representation (facetfit:closures_*, model/closures.h): what
// the production shader renders. Version 6 is 5 with closure lobes that follow the view or with `closures`
// recommended. A bake writes 5 or 6 (a fit with closures); versions 1 to 4 still read, without closures.
constexpr int kLutFormatVersion = 2;
constexpr int kLutAnisotropicVersion = 3;
constexpr int kLutBodyExponentVersion = 4;
constexpr int kLutClosuresVersion = 5;
constexpr int kLutViewLobesVersion = 6;  // 5, with closure lobes that follow the view (model/closures.h)


struct LutMetadata {
  int format_version = kLutFormatVersion;
  std::string facetfit_version = FACETFIT_VERSION;
  std::string source;         // as named on the command line (file path or builtin:NAME)
  std::string source_sha256;  // of the source file's bytes (of the name, for built-ins)
  int resolution = 90;
  Smith smith = Smith::correlated;
  int iterations = 0;
  double residual = 0.0;
  double alpha_ggx = 0.0, alpha_beckmann = 0.0;  // moment estimates of the tabulated NDF
  Rgb f0{0.0}, f82{0.0};
  Rgb body{0.0};  // the tabulated representation's body albedo at normal incidence (model/body.h)
  double body_exponent = 1.0;  // and its Minnaert exponent
  // The parametric representations fitted on the whole measurement (alpha, body, F82-tint f0 and f82),
  // and the classical baseline (Lambert + GGX + Schlick).
  Coat coat;      // of the tabulated representation
  struct Parametric {
    double alpha = 0.0;
    Rgb body{0.0}, f0{0.0}, f82{0.0};
    Coat coat;
  };
  Parametric ggx, beckmann, lsq;
  // The fit named "ggx", "beckmann" or "lsq"; null for another name.
  const Parametric* fit(const std::string& family) const;
  // Distance of each representation from the measurement (fit/measurement.h), and of the paper's pure fit.
  double error = 0.0, error_ggx = 0.0, error_beckmann = 0.0, error_lsq = 0.0, error_extraction = 0.0;
  // Relative L1 distance (projected-area weighted) of each parametric NDF from the tabulated one.
  double ndf_error_ggx = 0.0, ndf_error_beckmann = 0.0;
  Representation representation = Representation::tabulated;  // which model a renderer should use (fit/recommend.h)
  double tolerance = 0.0;  // the --tolerance that chose it
  bool sampling = true;    // sampling tables present (absent with --eval-only)
  // The anisotropic lobe (version 3, or 4 where announced): its grid's resolution and azimuths (0: none), and the anisotropic
  // GGX fit (fit/fit.h, AnisotropicFit::ggx: principal alphas, axis, body, F82-tint Fresnel).
  int anisotropic_resolution = 0, anisotropic_phi_count = 0;
  AnisotropicParametricFit anisotropic_ggx;
  // The closure representation (version 5; empty before) and its distance from the measurement.
  Closures closures;
  double error_closures = 0.0;
  // The distance of the representation named `name` (tabulated, ggx, beckmann, lsq, closures); NaN for another name.
  double distance(const std::string& name) const;
  std::vector<std::string> warnings;  // implausible values found when fitting (fit/plausibility.h)
  // The linear space every colour above and every Fresnel row is in (core/rgb_space.h), and its matrix
  // from lin_rec709. Written only when it is another space (facetfit:colorspace, facetfit:colorspace_matrix).
  std::string colorspace = kRec709Space;
  ColorMatrix from_rec709{1.0};
};

// Row layout of the texture; texel x of row y is at s = (x + 0.5) / width, t = (y + 0.5) / height.
struct LutLayout {
  static constexpr int kNdfRow = 0;       // D at grid node x (x = 0..R), in every channel
  static constexpr int kSigmaRow = 1;     // sigma at grid node x
  static constexpr int kFresnelRow = 2;   // RGB Fresnel at theta_d = x pi/180 (x = 0..89)
  static constexpr int kSamplingRow = 3;  // + s: CDF of visible normals of view slice s at node x
  // Version 3, after the rows above: the anisotropic lobe's Fresnel curve (RGB, as row 2), then one row
  // per azimuth m with D(theta_x, phi_m) in R and sigma in G.
  int anisotropic_row = 0;
  int width = 0, height = 0;
  static LutLayout of(int resolution, bool sampling, int anisotropic_resolution = 0, int anisotropic_phi_count = 0);
};

struct Lut {
  MicrofacetTables tables;
  VisibleNormalTables sampling;  // empty when baked with --eval-only
  std::optional<AnisotropicTables> anisotropic;  // version 3, or 4 with facetfit:anisotropic_phi_count
  LutMetadata meta;

  TabulatedMicrofacet model() const { return TabulatedMicrofacet(tables, sampling); }
  // One of the parametric fits it carries ("ggx", "beckmann" or "lsq"): alpha, body, coat and its
  // F82-tint Fresnel (Schlick for lsq), evaluated with `smith`. nullopt for another name.
  std::optional<ParametricBrdf> parametric(const std::string& family, Smith smith) const;
  // The closure representation: version 5's, or for an older LUT its recommended family's fit as one
  // lobe (the anisotropic GGX fit where it has one), what the material shader rendered of it.
  Closures closures() const;
  // What the production material (osl/facetfit_material.osl) and the MaterialX export emit: the
  // recommended GGX or Beckmann fit as one lobe, else (closures or tabulated recommended) closures().
  Closures production_closures() const;

 private:
  Closures recommended_fit_closures() const;  // the recommended family's fit as one lobe
};

// Every number a LUT's metadata stores, with the range its reader accepts (a colour per channel): the one
// table the writer clamps to and the reader checks, so that a bake never writes what its reader refuses.
void visit_limits(LutMetadata& m, const std::function<void(const std::string& name, double& value, double lo, double hi)>& visit);
// The largest colour a LUT stores (a reflectance or body, per channel): an implausible measurement may give
// F > 1, baked with a warning; past this it is damage or an attack.
constexpr double kLutMaxColour = 1e3;
// Clamps every number of the metadata and the Fresnel rows into its range, one warning line per attribute
// clamped (its farthest value). make_lut and in_colorspace end with it.
void clamp_to_limits(Lut& lut);

// facetfit:representation_code of a representation: 0 tabulated, 1 ggx, 2 beckmann, 3 closures (the shaders read it).
int representation_code(Representation r);

// Builds the LUT of a fit, its representation recommended under `tolerance` (fit/recommend.h).
Lut make_lut(const FitResult& fit, const Quadrature& quadrature, const std::string& source, const std::string& source_sha256,
             double tolerance, bool with_sampling);
// The recommended representation's own parameters, as parameters_of() gives them for the fit it was baked from.
RepresentationParameters recommended_parameters(const LutMetadata& meta);

// The LUT with every colour (Fresnel curves, bodies, f0 and f82 of each fit, the closures' lobes) taken from
// its space to `space`, whose matrix from lin_rec709 is `from_rec709`; as it is when already there.
Lut in_colorspace(Lut lut, const std::string& space, const ColorMatrix& from_rec709);

// Writes through a temporary file renamed into place. Throws Error naming `path`.
void write_lut(const std::string& path, const Lut& lut);
// Throws Error("<path>: <problem>") for anything that is not a complete facetfit LUT this version reads.
Lut read_lut(const std::string& path);

}  // namespace facetfit
