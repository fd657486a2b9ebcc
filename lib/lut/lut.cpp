#include "lut/lut.h"

#include <cmath>
#include <limits>
#include <map>
#include <sstream>
#include <string_view>

#include <glm/matrix.hpp>

#include "core/error.h"
#include "fit/representations.h"
#include "fit/roughness.h"
#include "io/image_file.h"

namespace facetfit {

namespace {

constexpr const char* kPrefix = "facetfit:";
std::string key(const char* name) { return std::string(kPrefix) + name; }

void set_color(ImageSpec& spec, const char* name, const Rgb& c) {
  spec.set(key(name), std::array<float, 3>{float(c.r), float(c.g), float(c.b)});
}

// The named float[3] attribute, or nullopt.
std::optional<Rgb> get_color(const ImageSpec& spec, const char* name) {
  const auto v = spec.get_vec3(key(name));
  if (!v) return std::nullopt;
  return Rgb((*v)[0], (*v)[1], (*v)[2]);
}

// Integer codes of the metadata choices, fixed by the LUT format (docs/lut-format.md), for readers that
// cannot read string attributes.
int smith_code(Smith s) {
  switch (s) {
    case Smith::masking: return 0;
    case Smith::correlated: return 1;
    case Smith::separable: return 2;
  }
  return -1;
}


// A closure lobe's family as an integer (Cycles' OSL reads no string attribute): 1 GGX, 2 Beckmann, as
// representation_code.
int family_code(NdfType type) { return type == NdfType::ggx ? 1 : 2; }

// The attribute of closure lobe k: facetfit:closures_lobe<k>_<name>.
std::string lobe_key(std::size_t k, const char* name) { return "closures_lobe" + std::to_string(k) + "_" + name; }

void write_closures(ImageSpec& spec, const LutMetadata& m) {
  const Closures& c = m.closures;
  spec.set(key("closures_lobes"), int(c.lobes.size()));
  set_color(spec, "closures_body", c.body);
  spec.set(key("closures_coat_alpha"), float(c.coat.alpha));
  spec.set(key("closures_coat_f0"), float(c.coat.f0));
  spec.set(key("closures_error"), float(m.error_closures));
  for (std::size_t k = 0; k < c.lobes.size(); ++k) {
    const ClosureLobe& l = c.lobes[k];
    spec.set(key(lobe_key(k, "family_code").c_str()), family_code(l.type));
    spec.set(key(lobe_key(k, "alpha_x").c_str()), float(l.alpha_x));
    spec.set(key(lobe_key(k, "alpha_y").c_str()), float(l.alpha_y));
    spec.set(key(lobe_key(k, "angle").c_str()), float(l.angle));
    spec.set(key(lobe_key(k, "weight").c_str()), float(l.weight));
    spec.set(key(lobe_key(k, "fresnel_code").c_str()), l.fresnel == ClosureLobe::Fresnel::f82_tint ? 1 : 2);
    set_color(spec, lobe_key(k, "f0").c_str(), l.f0);
    set_color(spec, lobe_key(k, "f82").c_str(), l.f82);
    set_color(spec, lobe_key(k, "f90").c_str(), l.f90);
    spec.set(key(lobe_key(k, "exponent").c_str()), float(l.exponent));
    if (m.format_version >= kLutViewLobesVersion) spec.set(key(lobe_key(k, "view_exponent").c_str()), float(l.view_exponent));
  }
}

// Version 5's closures, each attribute present and in range, or one line naming it.
void read_closures(const std::string& path, const ImageSpec& spec, LutMetadata& m) {
  // Missing numbers read as NaN, which validate() refuses by name with the ranges of visit_limits().
  const auto number = [&](const std::string& name) { return double(spec.get_float(key(name.c_str()), std::numeric_limits<float>::quiet_NaN())); };
  const auto colour = [&](const std::string& name) {
    const auto c = get_color(spec, name.c_str());
    if (!c) fail(path, "facetfit:" + name + " is missing or not a colour");
    return *c;
  };
  Closures& c = m.closures;
  const int lobes = spec.get_int(key("closures_lobes"), -1);
  if (lobes < 1 || lobes > Closures::kMaxLobes)
    fail(path, "facetfit:closures_lobes is " + std::to_string(lobes) + ": must be 1 to " + std::to_string(Closures::kMaxLobes));
  c.body = colour("closures_body");
  c.coat = {number("closures_coat_alpha"), number("closures_coat_f0")};
  m.error_closures = number("closures_error");
  for (std::size_t k = 0; k < std::size_t(lobes); ++k) {
    const int code = spec.get_int(key(lobe_key(k, "family_code").c_str()), -1);
    if (code != 1 && code != 2) fail(path, "facetfit:" + lobe_key(k, "family_code") + " is missing or not 1 (GGX) or 2 (Beckmann)");
    const int fresnel = spec.get_int(key(lobe_key(k, "fresnel_code").c_str()), -1);
    if (fresnel != 1 && fresnel != 2)
      fail(path, "facetfit:" + lobe_key(k, "fresnel_code") + " is missing or not 1 (F82-tint) or 2 (generalized Schlick)");
    c.lobes.push_back({code == 1 ? NdfType::ggx : NdfType::beckmann, number(lobe_key(k, "alpha_x")), number(lobe_key(k, "alpha_y")),
                       number(lobe_key(k, "angle")), number(lobe_key(k, "weight")),
                       fresnel == 1 ? ClosureLobe::Fresnel::f82_tint : ClosureLobe::Fresnel::schlick, colour(lobe_key(k, "f0")),
                       colour(lobe_key(k, "f82")), colour(lobe_key(k, "f90")), number(lobe_key(k, "exponent"))});
    if (m.format_version >= kLutViewLobesVersion) c.lobes.back().view_exponent = number(lobe_key(k, "view_exponent"));
  }
}

}  // namespace

int representation_code(Representation r) {
  switch (r) {
    case Representation::tabulated: return 0;
    case Representation::ggx: return 1;
    case Representation::beckmann: return 2;
    case Representation::closures: return 3;
  }
  return -1;
}

LutLayout LutLayout::of(int resolution, bool sampling, int anisotropic_resolution, int anisotropic_phi_count) {
  const int rows = kSamplingRow + (sampling ? resolution + 1 : 0);
  const int width = std::max({resolution + 1, FresnelCurve::kSize, anisotropic_phi_count > 0 ? anisotropic_resolution + 1 : 0});
  return {rows, width, rows + (anisotropic_phi_count > 0 ? 1 + anisotropic_phi_count : 0)};
}

Lut make_lut(const FitResult& fit, const Quadrature& quadrature, const std::string& source, const std::string& sha256,
             double tolerance, bool with_sampling) {
  if (!fit.ok()) fail(source, "no LUT for a meaningless fit: " + fit.problem);
  Lut lut;
  lut.tables = fit.lobe.tables(fit.smith);
  if (with_sampling) lut.sampling = VisibleNormalTables::build(fit.ndf());
  LutMetadata& m = lut.meta;
  m.source = source;
  m.source_sha256 = sha256;
  m.resolution = fit.ndf().grid.resolution;
  m.smith = fit.smith;
  m.iterations = fit.extraction.iterations;
  m.residual = fit.extraction.residual;
  m.alpha_ggx = fit.alpha_ggx;
  m.alpha_beckmann = fit.alpha_beckmann;
  m.f0 = fit.f0;
  m.f82 = fit.f82;
  m.body = fit.body();
  m.body_exponent = fit.lobe.body_exponent;
  m.coat = fit.lobe.coat;
  const auto parametric = [](const ParametricFit& p) { return LutMetadata::Parametric{p.alpha, p.body, p.f0, p.f82, p.coat}; };
  m.ggx = parametric(fit.ggx);
  m.beckmann = parametric(fit.beckmann);
  m.lsq = parametric(fit.lsq);
  m.error = fit.error;
  m.error_ggx = fit.ggx.error;
  m.error_beckmann = fit.beckmann.error;
  m.error_lsq = fit.lsq.error;
  m.error_extraction = fit.error_extraction;
  m.ndf_error_ggx = ndf_distance(quadrature, fit.ndf(), Ndf::isotropic(NdfType::ggx, fit.ggx.alpha));
  m.ndf_error_beckmann = ndf_distance(quadrature, fit.ndf(), Ndf::isotropic(NdfType::beckmann, fit.beckmann.alpha));
  m.tolerance = tolerance;
  m.representation = recommend(fit, tolerance);
  m.sampling = with_sampling;
  m.warnings = fit.warnings;
  if (fit.anisotropic) {
    lut.anisotropic = fit.anisotropic->tables;
    m.format_version = kLutAnisotropicVersion;
    m.anisotropic_resolution = lut.anisotropic->grid.resolution;
    m.anisotropic_phi_count = lut.anisotropic->phi_count;
    m.anisotropic_ggx = fit.anisotropic->ggx;
  }
  if (m.body_exponent != 1.0) m.format_version = kLutBodyExponentVersion;
  m.closures = fit.closures.closures;
  m.error_closures = fit.closures.error;
  if (!m.closures.empty()) m.format_version = kLutClosuresVersion;
  for (const ClosureLobe& l : m.closures.lobes)
    if (l.view_aligned()) m.format_version = kLutViewLobesVersion;
  // A reader of version 5 knows no closures representation.
  if (m.representation == Representation::closures) m.format_version = kLutViewLobesVersion;
  clamp_to_limits(lut);
  return lut;
}

void visit_limits(LutMetadata& m, const std::function<void(const std::string& name, double& value, double lo, double hi)>& visit) {
  constexpr double kAlpha = 10.0, kColour = kLutMaxColour, kDistance = 1e30;
  const auto colour = [&](const std::string& name, Rgb& c, double hi) {
    for (int k = 0; k < 3; ++k) visit(name, c[k], 0.0, hi);  // an implausible measurement may give F > 1: kept finite
  };
  const auto coat = [&](const std::string& prefix, Coat& c) {
    visit(prefix + "coat_alpha", c.alpha, 0.0, kAlpha);
    visit(prefix + "coat_f0", c.f0, 0.0, 1.0);
  };
  visit("alpha_ggx", m.alpha_ggx, 0.0, kAlpha);
  visit("alpha_beckmann", m.alpha_beckmann, 0.0, kAlpha);
  visit("anisotropic_ggx_alpha_x", m.anisotropic_ggx.alpha.alpha_x, 0.0, kAlpha);
  visit("anisotropic_ggx_alpha_y", m.anisotropic_ggx.alpha.alpha_y, 0.0, kAlpha);
  visit("anisotropic_ggx_angle", m.anisotropic_ggx.alpha.angle, -kPi, kPi);
  colour("anisotropic_ggx_body", m.anisotropic_ggx.body, kColour);
  colour("anisotropic_ggx_f0", m.anisotropic_ggx.f0, kColour);
  colour("anisotropic_ggx_f82", m.anisotropic_ggx.f82, kColour);
  colour("f0", m.f0, kColour);
  colour("f82", m.f82, kColour);
  colour("body", m.body, kColour);
  coat("", m.coat);
  for (const auto& [name, p] : {std::pair{"ggx_", &m.ggx}, {"beckmann_", &m.beckmann}, {"lsq_", &m.lsq}}) {
    const std::string n = name;
    visit(n + "alpha", p->alpha, 0.0, kAlpha);
    colour(n + "body", p->body, kColour);
    colour(n + "f0", p->f0, kColour);
    colour(n + "f82", p->f82, kColour);
    coat(n, p->coat);
  }
  for (const auto& [name, v] : {std::pair{"tolerance", &m.tolerance}, {"residual", &m.residual}, {"error", &m.error},
                                {"error_ggx", &m.error_ggx}, {"error_beckmann", &m.error_beckmann}, {"error_lsq", &m.error_lsq},
                                {"error_extraction", &m.error_extraction}, {"ndf_error_ggx", &m.ndf_error_ggx},
                                {"ndf_error_beckmann", &m.ndf_error_beckmann}, {"anisotropic_ggx_error", &m.anisotropic_ggx.error},
                                {"closures_error", &m.error_closures}})
    visit(name, *v, 0.0, kDistance);
  Closures& c = m.closures;
  colour("closures_body", c.body, kColour);
  coat("closures_", c.coat);
  for (std::size_t k = 0; k < c.lobes.size(); ++k) {
    ClosureLobe& l = c.lobes[k];
    visit(lobe_key(k, "alpha_x"), l.alpha_x, 1e-4, kAlpha);
    visit(lobe_key(k, "alpha_y"), l.alpha_y, 1e-4, kAlpha);
    visit(lobe_key(k, "angle"), l.angle, -kPi, kPi);
    visit(lobe_key(k, "weight"), l.weight, 0.0, 1.0);  // as the closure fit bounds it: the colours carry the rest
    colour(lobe_key(k, "f0"), l.f0, kColour);
    colour(lobe_key(k, "f82"), l.f82, kColour);
    colour(lobe_key(k, "f90"), l.f90, kColour);
    visit(lobe_key(k, "exponent"), l.exponent, 0.0, 100.0);
    visit(lobe_key(k, "view_exponent"), l.view_exponent, 0.0, 4.0);
  }
}

void clamp_to_limits(Lut& lut) {
  LutMetadata& m = lut.meta;
  std::map<std::string, std::pair<double, double>> clamped;  // name -> the farthest value, its limit
  const auto clamp = [&](const std::string& name, double& v, double lo, double hi) {
    if (!(v < lo || v > hi)) return;  // in range, or NaN: the reader refuses it by name, the fit never writes one
    const double limit = v < lo ? lo : hi;
    auto& [worst, at] = clamped[name];
    if (std::abs(v - limit) >= std::abs(worst - at)) worst = v, at = limit;
    v = limit;
  };
  visit_limits(m, [&](const std::string& name, double& v, double lo, double hi) { clamp("facetfit:" + name, v, lo, hi); });
  // The Fresnel rows, as the reader checks them (LutPixels::reflectance).
  for (FresnelCurve* curve : {&lut.tables.fresnel, lut.anisotropic ? &lut.anisotropic->fresnel : nullptr})
    if (curve)
      for (Rgb& f : curve->value)
        for (int c = 0; c < 3; ++c) clamp("the Fresnel curve", f[c], 0.0, kLutMaxColour);
  for (const auto& [name, value] : clamped) {
    std::ostringstream s;
    s << name << " was " << value.first << ", outside what a LUT stores: written as " << value.second;
    m.warnings.push_back(s.str());
  }
}

Lut in_colorspace(Lut lut, const std::string& space, const ColorMatrix& from_rec709) {
  LutMetadata& m = lut.meta;
  if (m.colorspace == space) return lut;
  const ColorMatrix to = from_rec709 * glm::inverse(m.from_rec709);
  const auto convert = [&](Rgb& c) { c = to * c; };
  for (Rgb& v : lut.tables.fresnel.value) convert(v);
  if (lut.anisotropic)
    for (Rgb& v : lut.anisotropic->fresnel.value) convert(v);
  for (Rgb* c : {&lut.tables.body, &m.f0, &m.f82, &m.body, &m.anisotropic_ggx.body, &m.anisotropic_ggx.f0, &m.anisotropic_ggx.f82,
                 &m.closures.body})
    convert(*c);
  for (LutMetadata::Parametric* p : {&m.ggx, &m.beckmann, &m.lsq})
    for (Rgb* c : {&p->body, &p->f0, &p->f82}) convert(*c);
  for (ClosureLobe& lobe : m.closures.lobes)
    for (Rgb* c : {&lobe.f0, &lobe.f82, &lobe.f90}) convert(*c);
  m.colorspace = space;
  m.from_rec709 = from_rec709;
  clamp_to_limits(lut);  // a space narrower than Rec.709 takes some colours below 0
  return lut;
}

RepresentationParameters recommended_parameters(const LutMetadata& m) {
  const Representation r = m.representation;
  if (r == Representation::tabulated) return {r, std::nullopt, m.f0, m.f82, m.body, m.coat, m.error};
  if (r == Representation::closures) return closures_parameters(m.closures, m.error_closures);
  const bool ggx = r == Representation::ggx;
  const LutMetadata::Parametric& p = ggx ? m.ggx : m.beckmann;
  return {r, p.alpha, p.f0, p.f82, p.body, p.coat, ggx ? m.error_ggx : m.error_beckmann};
}

void write_lut(const std::string& path, const Lut& lut) {
  const int r = lut.meta.resolution, nodes = r + 1;
  const LutLayout layout = LutLayout::of(r, lut.meta.sampling, lut.meta.anisotropic_resolution, lut.meta.anisotropic_phi_count);
  std::vector<float> pixels(std::size_t(layout.width) * layout.height * 3, 0.0f);
  const auto put = [&](int row, int x, const Rgb& v) {
    float* p = pixels.data() + (std::size_t(row) * layout.width + x) * 3;
    p[0] = float(v.r), p[1] = float(v.g), p[2] = float(v.b);
  };
  // Rows shorter than the image repeat their last value, so a clamped lookup past the end agrees.
  for (int x = 0; x < layout.width; ++x) {
    const int node = std::min(x, nodes - 1);
    put(LutLayout::kNdfRow, x, Rgb(lut.tables.ndf.ndf[std::size_t(node)]));
    put(LutLayout::kSigmaRow, x, Rgb(lut.tables.ndf.sigma[std::size_t(node)]));
    put(LutLayout::kFresnelRow, x, lut.tables.fresnel.value[std::size_t(std::min(x, FresnelCurve::kSize - 1))]);
    if (lut.meta.sampling)
      for (int s = 0; s < nodes; ++s) put(LutLayout::kSamplingRow + s, x, Rgb(lut.sampling.cdf_at(s, node)));
  }
  if (const auto& a = lut.anisotropic) {
    for (int x = 0; x < layout.width; ++x) {
      put(layout.anisotropic_row, x, a->fresnel.value[std::size_t(std::min(x, FresnelCurve::kSize - 1))]);
      const std::size_t node = std::size_t(std::min(x, a->grid.resolution));
      for (int m = 0; m < a->phi_count; ++m)
        put(layout.anisotropic_row + 1 + m, x, Rgb(a->ndf[node * a->phi_count + m], a->sigma[node * a->phi_count + m], 0.0));
    }
  }

  ImageSpec spec(layout.width, layout.height, {"R", "G", "B"});  // data, not colour: no transfer function
  const LutMetadata& m = lut.meta;
  spec.set(key("format_version"), m.format_version);
  spec.set(key("facetfit_version"), m.facetfit_version);
  spec.set(key("source"), m.source);
  spec.set(key("source_sha256"), m.source_sha256);
  spec.set(key("resolution"), m.resolution);
  spec.set(key("smith"), to_string(m.smith));
  spec.set(key("iterations"), m.iterations);
  spec.set(key("residual"), float(m.residual));
  spec.set(key("alpha_ggx"), float(m.alpha_ggx));
  spec.set(key("alpha_beckmann"), float(m.alpha_beckmann));
  set_color(spec, "f0", m.f0);
  set_color(spec, "f82", m.f82);
  spec.set(key("ndf_error_ggx"), float(m.ndf_error_ggx));
  spec.set(key("ndf_error_beckmann"), float(m.ndf_error_beckmann));
  spec.set(key("representation"), to_string(m.representation));
  // The same two choices as integers: Cycles' OSL (1.14) returns string attributes as empty strings.
  spec.set(key("smith_code"), smith_code(m.smith));
  spec.set(key("representation_code"), representation_code(m.representation));
  spec.set(key("tolerance"), float(m.tolerance));
  set_color(spec, "body", m.body);
  if (m.format_version >= kLutBodyExponentVersion) spec.set(key("body_exponent"), float(m.body_exponent));
  spec.set(key("coat_alpha"), float(m.coat.alpha));
  spec.set(key("coat_f0"), float(m.coat.f0));
  for (const auto& [name, p] : {std::pair{"ggx", &m.ggx}, {"beckmann", &m.beckmann}, {"lsq", &m.lsq}}) {
    const std::string n = name;
    spec.set(key((n + "_alpha").c_str()), float(p->alpha));
    spec.set(key((n + "_coat_alpha").c_str()), float(p->coat.alpha));
    spec.set(key((n + "_coat_f0").c_str()), float(p->coat.f0));
    set_color(spec, (n + "_body").c_str(), p->body);
    set_color(spec, (n + "_f0").c_str(), p->f0);
    set_color(spec, (n + "_f82").c_str(), p->f82);
  }
  spec.set(key("error"), float(m.error));
  spec.set(key("error_ggx"), float(m.error_ggx));
  spec.set(key("error_beckmann"), float(m.error_beckmann));
  spec.set(key("error_lsq"), float(m.error_lsq));
  spec.set(key("error_extraction"), float(m.error_extraction));
  spec.set(key("sampling"), m.sampling ? 1 : 0);
  if (lut.anisotropic) {
    spec.set(key("anisotropic_resolution"), m.anisotropic_resolution);
    spec.set(key("anisotropic_phi_count"), m.anisotropic_phi_count);
    // The anisotropic GGX fit, what an anisotropic closure takes (the OSL material shader).
    const AnisotropicParametricFit& g = m.anisotropic_ggx;
    spec.set(key("anisotropic_ggx_alpha_x"), float(g.alpha.alpha_x));
    spec.set(key("anisotropic_ggx_alpha_y"), float(g.alpha.alpha_y));
    spec.set(key("anisotropic_ggx_angle"), float(g.alpha.angle));
    set_color(spec, "anisotropic_ggx_body", g.body);
    set_color(spec, "anisotropic_ggx_f0", g.f0);
    set_color(spec, "anisotropic_ggx_f82", g.f82);
    spec.set(key("anisotropic_ggx_error"), float(g.error));
  }
  if (m.format_version >= kLutClosuresVersion) write_closures(spec, m);
  if (m.colorspace != kRec709Space) {
    spec.set(key("colorspace"), m.colorspace);
    spec.set(key("colorspace_matrix"), matrix_text(m.from_rec709));
  }
  // One line per warning; absent when there is none.
  if (!m.warnings.empty()) {
    std::string text;
    for (const std::string& w : m.warnings) text += (text.empty() ? "" : "\n") + w;
    spec.set(key("warnings"), text);
  }

  write_image_atomic(path, spec, pixels.data(), [](const std::string& temp) { read_lut(temp); });
}

namespace {

// Where the metadata keeps each parametric fit and its distance, by representation name.
struct StoredFit {
  const char* name;
  LutMetadata::Parametric LutMetadata::*fit;
  double LutMetadata::*error;
};
constexpr StoredFit kStoredFits[] = {{"ggx", &LutMetadata::ggx, &LutMetadata::error_ggx},
                                     {"beckmann", &LutMetadata::beckmann, &LutMetadata::error_beckmann},
                                     {"lsq", &LutMetadata::lsq, &LutMetadata::error_lsq}};

// Every parametric representation (fit/representations.h) has its place in the metadata: a new row without
// one is a compile error here, not a null fit in `info`.
constexpr bool every_parametric_stored() {
  for (const RepresentationRow& r : kRepresentations) {
    if (r.parametric == nullptr) continue;
    bool stored = false;
    for (const StoredFit& s : kStoredFits) stored = stored || std::string_view(r.name) == s.name;
    if (!stored) return false;
  }
  return true;
}
static_assert(every_parametric_stored(), "a parametric representation of kRepresentations has no kStoredFits entry");

}  // namespace

const LutMetadata::Parametric* LutMetadata::fit(const std::string& family) const {
  for (const StoredFit& s : kStoredFits)
    if (family == s.name) return &(this->*s.fit);
  return nullptr;
}

double LutMetadata::distance(const std::string& name) const {
  if (name == "tabulated") return error;
  if (name == "closures") return error_closures;
  for (const StoredFit& s : kStoredFits)
    if (name == s.name) return this->*s.error;
  return std::nan("");
}

std::optional<ParametricBrdf> Lut::parametric(const std::string& family, Smith smith) const {
  const LutMetadata::Parametric* p = meta.fit(family);
  if (!p) return std::nullopt;
  const NdfType type = family == "beckmann" ? NdfType::beckmann : NdfType::ggx;
  return ParametricBrdf(Ndf::isotropic(type, p->alpha), smith, p->f0, p->f82, p->body, p->coat);
}

Closures Lut::closures() const { return meta.closures.empty() ? recommended_fit_closures() : meta.closures; }

Closures Lut::production_closures() const {
  const bool one_lobe = meta.representation == Representation::ggx || meta.representation == Representation::beckmann;
  return one_lobe ? recommended_fit_closures() : closures();
}

Closures Lut::recommended_fit_closures() const {
  if (anisotropic && meta.representation != Representation::beckmann) return closures_of(meta.anisotropic_ggx);
  const bool beckmann = meta.representation == Representation::beckmann ||
                        (meta.representation == Representation::tabulated && meta.error_beckmann < meta.error_ggx);
  const LutMetadata::Parametric& p = beckmann ? meta.beckmann : meta.ggx;
  ParametricFit fit;
  fit.type = beckmann ? NdfType::beckmann : NdfType::ggx;
  fit.alpha = p.alpha, fit.body = p.body, fit.f0 = p.f0, fit.f82 = p.f82, fit.coat = p.coat;
  return closures_of(fit);
}

namespace {

// Every number of the metadata finite and in its range, or one line naming the attribute: a LUT edited by
// hand or damaged must not render NaN or negative light.
void validate(const std::string& path, LutMetadata m) {
  visit_limits(m, [&](const std::string& name, double& v, double lo, double hi) {
    // Against the limits as floats, as the attributes are stored: a value the writer clamped to 1e30, 1e-4 or
    // pi is written as the float nearest it, which lies just outside the double limit.
    if (v >= double(float(lo)) && v <= double(float(hi))) return;
    std::ostringstream s;
    s << "facetfit:" << name;
    if (std::isnan(v)) s << " is missing or not a number";
    else s << " is " << v;
    s << ": must be in [" << lo << ", " << hi << "]";
    fail(path, s.str());
  });
}

// facetfit:colorspace and its matrix from lin_rec709; lin_rec709 when absent.
void read_colorspace(const std::string& path, const ImageSpec& spec, LutMetadata& m) {
  const std::string name = spec.get_string(key("colorspace"));
  if (name.empty() || name == kRec709Space) return;
  const std::optional<ColorMatrix> from_rec709 = parse_matrix(spec.get_string(key("colorspace_matrix")));
  if (!from_rec709)
    fail(path, "facetfit:colorspace_matrix is missing or not nine numbers of an invertible matrix (from lin_rec709 to " +
                   excerpt(name, 40) + ")");
  // Every RGB colour space holds white as a positive colour; a matrix that does not (-I) would render negative light.
  const Rgb white = *from_rec709 * Rgb(1.0);
  if (!(white.r > 0.0 && white.g > 0.0 && white.b > 0.0))
    fail(path, "facetfit:colorspace_matrix takes white to a colour that is not positive: not a matrix between RGB spaces");
  m.colorspace = name;
  m.from_rec709 = *from_rec709;
}

// The format version, one this facetfit reads.
int read_format_version(const std::string& path, const ImageSpec& spec) {
  if (!spec.attributes.count(key("format_version"))) fail(path, "not a facetfit LUT (no facetfit:format_version attribute)");
  const int version = spec.get_int(key("format_version"), -1);
  if (version < 1 || version > kLutViewLobesVersion)
    fail(path, "LUT format version " + std::to_string(version) + "; this facetfit reads versions 1 to " +
                   std::to_string(kLutViewLobesVersion));
  return version;
}

// The attributes of every version that say what the tables are: provenance, resolution, the Smith model,
// the recommended representation and the Fresnel curve's f0 and f82.
void read_lut_header(const std::string& path, const ImageSpec& spec, LutMetadata& m) {
  m.facetfit_version = spec.get_string(key("facetfit_version"));
  m.source = spec.get_string(key("source"));
  m.source_sha256 = spec.get_string(key("source_sha256"));
  m.resolution = spec.get_int(key("resolution"), -1);
  const auto smith = parse_smith(spec.get_string(key("smith")));
  const auto representation = parse_representation(spec.get_string(key("representation")));
  const auto f0 = get_color(spec, "f0"), f82 = get_color(spec, "f82");
  if (!smith) fail(path, "facetfit:smith is missing or not masking, correlated or separable");
  if (!representation) fail(path, "facetfit:representation is missing or not tabulated, ggx, beckmann or closures");
  if (!f0 || !f82) fail(path, std::string("facetfit:") + (!f0 ? "f0" : "f82") + " is missing or not a colour");
  if (m.resolution < 4 || m.resolution > 4096)
    fail(path, "facetfit:resolution is " + std::to_string(m.resolution) + ": must be between 4 and 4096");
  m.smith = *smith;
  m.representation = *representation;
  // The integer codes, where present (LUTs of facetfit 0.1.0 before they were added have none), must agree.
  if (spec.get_int(key("smith_code"), smith_code(m.smith)) != smith_code(m.smith) ||
      spec.get_int(key("representation_code"), representation_code(m.representation)) != representation_code(m.representation))
    fail(path, "facetfit LUT whose smith_code or representation_code contradicts its smith or representation");
  m.f0 = *f0;
  m.f82 = *f82;
}

// The paper's fit (iterations, residual, moment alphas and NDF distances), the settings and the warnings,
// one a line: at most kMaxWarningBytes of them (a bake writes a few lines of some 100 bytes), split in one pass.
constexpr std::size_t kMaxWarningBytes = 64 * 1024;
void read_extraction_attributes(const std::string& path, const ImageSpec& spec, LutMetadata& m) {
  m.iterations = spec.get_int(key("iterations"));
  m.residual = spec.get_float(key("residual"));
  m.alpha_ggx = spec.get_float(key("alpha_ggx"));
  m.alpha_beckmann = spec.get_float(key("alpha_beckmann"));
  m.ndf_error_ggx = spec.get_float(key("ndf_error_ggx"));
  m.ndf_error_beckmann = spec.get_float(key("ndf_error_beckmann"));
  m.tolerance = spec.get_float(key("tolerance"));
  m.sampling = spec.get_int(key("sampling")) != 0;
  const std::string text = spec.get_string(key("warnings"));
  if (text.size() > kMaxWarningBytes)
    fail(path, "facetfit:warnings is " + std::to_string(text.size()) + " bytes: at most " + std::to_string(kMaxWarningBytes));
  for (std::size_t begin = 0; begin < text.size();) {
    const std::size_t end = std::min(text.find('\n', begin), text.size());
    m.warnings.push_back(text.substr(begin, end - begin));
    begin = end + 1;
  }
}

// Version 2 on: the body, its exponent (version 4 on), the coat, the three parametric fits and the errors.
void read_parametric_attributes(const std::string& path, const ImageSpec& spec, int version, LutMetadata& m) {
  const auto body = get_color(spec, "body");
  if (!body) fail(path, "facetfit LUT version 2 without facetfit:body");
  m.body = *body;
  if (version >= kLutBodyExponentVersion) {
    m.body_exponent = spec.get_float(key("body_exponent"), -1.0f);
    if (!(m.body_exponent >= 1.0 && m.body_exponent <= kMaxBodyExponent))
      fail(path, "facetfit:body_exponent is missing or outside [1, " + std::to_string(int(kMaxBodyExponent)) + "]");
  }
  m.coat = {spec.get_float(key("coat_alpha")), spec.get_float(key("coat_f0"))};
  for (const auto& [name, p] : {std::pair{"ggx", &m.ggx}, {"beckmann", &m.beckmann}, {"lsq", &m.lsq}}) {
    const std::string n = name;
    const auto pb = get_color(spec, (n + "_body").c_str()), pf0 = get_color(spec, (n + "_f0").c_str()),
               pf82 = get_color(spec, (n + "_f82").c_str());
    p->alpha = spec.get_float(key((n + "_alpha").c_str()), -1.0f);
    if (!pb || !pf0 || !pf82 || !(p->alpha > 0.0)) fail(path, "facetfit LUT without a valid facetfit:" + n + "_* fit");
    *p = {p->alpha, *pb, *pf0, *pf82,
          {spec.get_float(key((n + "_coat_alpha").c_str())), spec.get_float(key((n + "_coat_f0").c_str()))}};
  }
  m.error = spec.get_float(key("error"));
  m.error_ggx = spec.get_float(key("error_ggx"));
  m.error_beckmann = spec.get_float(key("error_beckmann"));
  m.error_lsq = spec.get_float(key("error_lsq"));
  m.error_extraction = spec.get_float(key("error_extraction"));
}

// Whether the LUT has the anisotropic rows: version 3 always; versions 4 and 5 where they say so.
bool has_anisotropic_rows(const ImageSpec& spec, int version) {
  return version == kLutAnisotropicVersion ||
         (version >= kLutBodyExponentVersion && spec.get_int(key("anisotropic_phi_count"), 0) > 0);
}

// The anisotropic rows' size and the anisotropic GGX fit.
void read_anisotropic_attributes(const std::string& path, const ImageSpec& spec, LutMetadata& m) {
  m.anisotropic_resolution = spec.get_int(key("anisotropic_resolution"), -1);
  m.anisotropic_phi_count = spec.get_int(key("anisotropic_phi_count"), -1);
  // Bounded before anything is sized from them; the quadrature's own limits.
  if (m.anisotropic_resolution < 4 || m.anisotropic_resolution > 4096 || m.anisotropic_phi_count < 4 ||
      m.anisotropic_phi_count > 4096 || m.anisotropic_phi_count % 2 != 0)
    fail(path, "facetfit:anisotropic_resolution or facetfit:anisotropic_phi_count is missing or out of range (" +
                   std::to_string(m.anisotropic_resolution) + ", " + std::to_string(m.anisotropic_phi_count) + ")");
  // The 2D extraction runs on min(resolution, 90) intervals (fit/fit.cpp): another count reads the rows'
  // texels as the wrong grid's nodes, a lobe of the right range and the wrong shape.
  if (m.anisotropic_resolution != std::min(m.resolution, 90))
    fail(path, "facetfit:anisotropic_resolution is " + std::to_string(m.anisotropic_resolution) + ", not min(facetfit:resolution, 90) = " +
                   std::to_string(std::min(m.resolution, 90)));
  AnisotropicParametricFit& g = m.anisotropic_ggx;
  g.alpha = {spec.get_float(key("anisotropic_ggx_alpha_x")), spec.get_float(key("anisotropic_ggx_alpha_y")),
             spec.get_float(key("anisotropic_ggx_angle"))};
  const auto g_body = get_color(spec, "anisotropic_ggx_body"), g_f0 = get_color(spec, "anisotropic_ggx_f0"),
             g_f82 = get_color(spec, "anisotropic_ggx_f82");
  if (!g_body || !g_f0 || !g_f82) fail(path, "facetfit LUT with an anisotropic lobe without facetfit:anisotropic_ggx_body, _f0 or _f82");
  g.body = *g_body, g.f0 = *g_f0, g.f82 = *g_f82;
  g.error = spec.get_float(key("anisotropic_ggx_error"));
}

// Every attribute of a LUT of `version`, checked as it is read.
LutMetadata read_lut_attributes(const std::string& path, const ImageSpec& spec, int version) {
  LutMetadata m;
  m.format_version = version;
  read_lut_header(path, spec, m);
  read_extraction_attributes(path, spec, m);
  if (version == 1) {  // no body; the parametric fits are the moment alphas with the curve's f0 and f82
    m.ggx = {m.alpha_ggx, Rgb(0.0), m.f0, m.f82, {}};
    m.beckmann = {m.alpha_beckmann, Rgb(0.0), m.f0, m.f82, {}};
    m.lsq = m.ggx;
  } else {
    read_parametric_attributes(path, spec, version, m);
  }
  if (version >= kLutClosuresVersion) read_closures(path, spec, m);
  if (m.representation == Representation::closures && (version < kLutViewLobesVersion || m.closures.empty()))
    fail(path, "facetfit:representation is closures in a LUT of version " + std::to_string(version) + " (closures are recommended from version " +
                   std::to_string(kLutViewLobesVersion) + ")");
  if (has_anisotropic_rows(spec, version)) read_anisotropic_attributes(path, spec, m);
  read_colorspace(path, spec, m);
  return m;
}

// The image is the size the metadata implies.
void check_image_size(const std::string& path, const ImageSpec& spec, const LutLayout& layout, int resolution) {
  if (spec.width != layout.width || spec.height != layout.height)
    fail(path, "image is " + std::to_string(spec.width) + " x " + std::to_string(spec.height) + ", expected " +
                   std::to_string(layout.width) + " x " + std::to_string(layout.height) + " for resolution " +
                   std::to_string(resolution));
}

// The LUT image's pixels, read by row, column and channel (R, G, B), each refused unless finite.
struct LutPixels {
  const std::string& path;
  const ImageSpec& spec;
  std::array<int, 3> channel;
  std::vector<float> values;

  double get(int row, int x, int c) const {
    const float v = values[(std::size_t(row) * spec.width + x) * spec.channels.size() + channel[std::size_t(c)]];
    if (!std::isfinite(v)) fail(path, "non-finite value in row " + std::to_string(row) + ", column " + std::to_string(x));
    return double(v);
  }

  // A Fresnel row's reflectance: a negative one (an edited file) would render negative pixels.
  Rgb reflectance(int row, int x) const {
    const Rgb f(get(row, x, 0), get(row, x, 1), get(row, x, 2));
    for (int c = 0; c < 3; ++c)
      if (!(f[c] >= 0.0 && f[c] <= kLutMaxColour))
        fail(path, "row " + std::to_string(row) + ", column " + std::to_string(x) + ": the Fresnel reflectance must be in [0, 1000]");
    return f;
  }
};

// A negative density or projected area is no lobe (an edited file): refused, in the isotropic and the
// anisotropic rows alike.
bool is_lobe_node(double d, double sigma) { return d >= 0.0 && sigma > 0.0; }

// The isotropic NDF and sigma rows.
void read_ndf_rows(const LutPixels& pixels, int resolution, TabulatedNdf& ndf) {
  ndf.grid = ThetaGrid{resolution};
  for (int x = 0; x <= resolution; ++x) {
    ndf.ndf.push_back(pixels.get(LutLayout::kNdfRow, x, 0));
    ndf.sigma.push_back(pixels.get(LutLayout::kSigmaRow, x, 0));
    if (!is_lobe_node(ndf.ndf.back(), ndf.sigma.back()))
      fail(pixels.path, "rows " + std::to_string(LutLayout::kNdfRow) + " and " + std::to_string(LutLayout::kSigmaRow) + ", column " +
                            std::to_string(x) + ": D must be >= 0 and sigma > 0");
  }
}

// A Fresnel curve's row.
void read_fresnel_row(const LutPixels& pixels, int row, FresnelCurve& fresnel) {
  for (int x = 0; x < FresnelCurve::kSize; ++x) fresnel.value[std::size_t(x)] = pixels.reflectance(row, x);
}

// The visible-normal sampling rows, one CDF per row.
void read_sampling_rows(const LutPixels& pixels, int resolution, VisibleNormalTables& sampling) {
  const int nodes = resolution + 1;
  sampling.resolution = resolution;
  sampling.cdf.resize(std::size_t(nodes) * nodes);
  for (int s = 0; s < nodes; ++s) {
    double* row = sampling.cdf.data() + std::size_t(s) * nodes;
    for (int x = 0; x < nodes; ++x) row[x] = pixels.get(LutLayout::kSamplingRow + s, x, 0);
    // The samplers search each row as running sums (sample_cdf, the lanes' guide): 0 to 1, never falling.
    for (int x = 1; x < nodes; ++x)
      if (!(row[x] >= row[x - 1]))
        fail(pixels.path, "row " + std::to_string(LutLayout::kSamplingRow + s) + ", column " + std::to_string(x) +
                              ": the sampling CDF falls (or is not a number)");
    if (row[0] != 0.0 || row[nodes - 1] != 1.0)
      fail(pixels.path, "row " + std::to_string(LutLayout::kSamplingRow + s) + ": the sampling CDF must run from 0 to 1");
  }
}

// The anisotropic rows from `first_row`: the Fresnel curve, then one row of D and sigma per azimuth.
AnisotropicTables read_anisotropic_rows(const LutPixels& pixels, const LutMetadata& m, int first_row) {
  AnisotropicTables a;
  a.grid = ThetaGrid{m.anisotropic_resolution};
  a.phi_count = m.anisotropic_phi_count;
  a.smith = m.smith;
  read_fresnel_row(pixels, first_row, a.fresnel);
  for (int x = 0; x <= m.anisotropic_resolution; ++x)
    for (int p = 0; p < a.phi_count; ++p) {
      a.ndf.push_back(pixels.get(first_row + 1 + p, x, 0));
      a.sigma.push_back(pixels.get(first_row + 1 + p, x, 1));
      if (!is_lobe_node(a.ndf.back(), a.sigma.back()))
        fail(pixels.path, "anisotropic row " + std::to_string(first_row + 1 + p) + ", column " + std::to_string(x) +
                              ": D must be >= 0 and sigma > 0");
    }
  a.axis = m.anisotropic_ggx.alpha.angle;
  return a;
}

}  // namespace

Lut read_lut(const std::string& path) {
  ImageReader image = ImageReader::open(path);
  const ImageSpec& spec = image.spec();
  Lut lut;
  lut.meta = read_lut_attributes(path, spec, read_format_version(path, spec));
  const LutMetadata& m = lut.meta;
  validate(path, m);
  const LutLayout layout = LutLayout::of(m.resolution, m.sampling, m.anisotropic_resolution, m.anisotropic_phi_count);
  check_image_size(path, spec, layout, m.resolution);
  const std::array<int, 3> channel = rgb_channels(spec, path, OneChannel::refused);
  const LutPixels pixels{path, spec, channel, image.read_pixels()};

  read_ndf_rows(pixels, m.resolution, lut.tables.ndf);
  read_fresnel_row(pixels, LutLayout::kFresnelRow, lut.tables.fresnel);
  lut.tables.smith = m.smith;
  lut.tables.body = m.body;
  lut.tables.body_exponent = m.body_exponent;
  lut.tables.coat = m.coat;
  if (m.sampling) read_sampling_rows(pixels, m.resolution, lut.sampling);
  if (m.anisotropic_phi_count > 0) lut.anisotropic = read_anisotropic_rows(pixels, m, layout.anisotropic_row);
  return lut;
}

}  // namespace facetfit
