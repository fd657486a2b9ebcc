#include "render/materials.h"

#include <cmath>
#include <cstddef>
#include <iterator>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include "core/error.h"
#include "fit/fit.h"
#include "fit/representations.h"
#include "io/input.h"
#include "io/rgl.h"
#include "io/utia.h"
#include "lut/lut.h"
#include "model/analytic.h"
#include "model/builtin.h"
#include "model/closures.h"
#include "model/parametric.h"
#include "model/rotated.h"
#include "model/visible_slopes.h"
#include "render/scene.h"
#include "render/shading.h"

namespace facetfit {

// Each representation of a fit renders from a LUT as a material type (fit/representations.h): the report
// renders it so. A row whose type is missing here, or reads no LUT, does not compile.
static_assert(
    [] {
      for (const RepresentationRow& r : kRepresentations) {
        bool found = false;
        for (const MaterialType& t : kMaterialTypes) found = found || (std::string_view(t.name) == r.material_type && t.reads_lut);
        if (!found) return false;
      }
      return true;
    }(),
    "every row of kRepresentations renders as a material type of kMaterialTypes that reads a LUT");

namespace {

// A LUT's tabulated model, able to sample: an --eval-only LUT gets its sampling tables built here.
std::shared_ptr<const TabulatedMicrofacet> sampled_lut_model(Lut lut) {
  if (lut.sampling.empty()) return std::make_shared<TabulatedMicrofacet>(std::move(lut.tables));
  return std::make_shared<TabulatedMicrofacet>(std::move(lut.tables), std::move(lut.sampling));
}

// A parametric lobe's proposal, tabulated: the visible slopes (model/visible_slopes.h) of the isotropic
// `ndf` on the grid, with the parts of a flat Fresnel of f0, the body and the coat, so its draws are
// weighted by f0 and the body.
std::shared_ptr<const Proposal> tabulated_proposal(const Ndf& ndf, const Rgb& f0, const Rgb& body = Rgb(0.0), const Coat& coat = {}) {
  return std::make_shared<VisibleSlopeProposal>(tabulate_ndf(ndf), ProposalParts(f0, body, coat));
}

// A LUT of the scene, its colours in the scene's working space.
Lut scene_lut(const SceneDesc& scene, const std::string& file) {
  return in_colorspace(read_lut(resolve(scene, file)), scene.working_space, scene.from_rec709);
}

// A measurement's RGB (lin_rec709) in the working space: f = M f_rec709.
class InWorkingSpace final : public Brdf {
 public:
  InWorkingSpace(std::shared_ptr<const Brdf> measurement, const ColorMatrix& from_rec709)
      : measurement_(std::move(measurement)), from_rec709_(from_rec709) {}
  std::optional<Rgb> eval(const Vec3& o, const Vec3& i) const override {
    const std::optional<Rgb> f = measurement_->eval(o, i);
    return f ? std::optional<Rgb>(from_rec709_ * *f) : std::nullopt;
  }

 private:
  std::shared_ptr<const Brdf> measurement_;
  ColorMatrix from_rec709_;
};

// The shading model of a measurement, rendered in the scene's working space.
std::shared_ptr<const ShadingModel> measured_model(const SceneDesc& scene, std::shared_ptr<const Brdf> brdf,
                                                   std::shared_ptr<const Proposal> proposal) {
  if (scene.working_space != kRec709Space) brdf = std::make_shared<InWorkingSpace>(std::move(brdf), scene.from_rec709);
  return std::make_shared<ShadingModel>(std::move(brdf), std::move(proposal));
}

// What proposes directions for a measured material: the given LUT's fit (a bake already made it), or else
// the paper's fit of its `table` alone (a proposal needs the lobe's shape, not the refinement's
// accuracy); none where that fit fails.
std::shared_ptr<const Proposal> measured_proposal(const SceneDesc& scene, const MaterialDesc& m, const HalfDiffTable* table) {
  if (!m.proposal.empty()) return std::make_shared<VisibleSlopeProposal>(scene_lut(scene, m.proposal).tables);
  const FitResult fit = Fitter{FitOptions::paper()}.fit(*table);
  if (fit.ok()) return std::make_shared<VisibleSlopeProposal>(MicrofacetTables{fit.ndf(), fit.smith, fit.fresnel(), {}, {}});
  return nullptr;
}

// A closures material: the LUT's closure representation (`closures` of the Lut), or what the production
// shader emits of the LUT (osl/facetfit_material.osl: Lut::production_closures), the artist's scales along
// each lobe's axes, turned by the rotation. Unstretched, it is drawn by the LUT's own tabulated proposal,
// as the `lut` and `measured` materials of the LUT are: the same random numbers then give nearly the same
// directions, and most of the noise cancels in their differences (the report's; with its own proposal,
// the closures of gold at the report test's 4 spp stood 5.4 from the measurement where the ggx fit stood
// 0.3).
std::shared_ptr<const ShadingModel> closure_model(const SceneDesc& scene, const MaterialDesc& m, Closures (Lut::*closures_of)() const) {
  Lut lut = scene_lut(scene, m.file);
  const Closures closures = (lut.*closures_of)().stretched(m.stretch.x, m.stretch.y, m.stretch.rotation());
  const auto brdf = std::make_shared<ClosureBrdf>(closures);
  if (!m.stretch.unscaled()) return std::make_shared<ShadingModel>(brdf, std::make_shared<ClosureProposal>(closures));
  return std::make_shared<ShadingModel>(brdf, VisibleSlopeProposal::of(*sampled_lut_model(std::move(lut))));
}

}  // namespace

std::shared_ptr<const ShadingModel> lut_parametric_model(const Lut& lut, const std::string& family, Smith smith, bool fresnel_curve,
                                                         bool anisotropic) {
  const LutMetadata::Parametric* p = lut.meta.fit(family);
  if (!p) fail("family '" + family + "'", "must be " + parametric_names());
  if (anisotropic && family == "ggx" && lut.anisotropic) {
    // The anisotropic GGX fit with its body; the proposal is the isotropic GGX of the same area (alpha_x
    // alpha_y), tabulated like the one below: the axes change which directions are likely, not coverage.
    const AnisotropicParametricFit& g = lut.meta.anisotropic_ggx;
    const auto lobe = std::make_shared<ParametricBrdf>(Ndf{NdfType::ggx, g.alpha.alpha_x, g.alpha.alpha_y}, smith, g.f0, g.f82, g.body);
    return std::make_shared<ShadingModel>(
        std::make_shared<RotatedBrdf>(lobe, g.alpha.angle),
        tabulated_proposal(Ndf::isotropic(NdfType::ggx, std::sqrt(g.alpha.alpha_x * g.alpha.alpha_y)), g.f0, g.body));
  }
  // The LUT's fit of this family on the whole measurement: its alpha, body and coat, with its own F82-tint
  // (lsq: Schlick) Fresnel or the tabulated curve.
  const Ndf ndf = Ndf::isotropic(family == "beckmann" ? NdfType::beckmann : NdfType::ggx, p->alpha);
  const auto brdf = fresnel_curve ? std::make_shared<ParametricBrdf>(ndf, smith, lut.tables.fresnel, p->body, p->coat)
                                  : std::make_shared<ParametricBrdf>(*lut.parametric(family, smith));
  // The proposal samples the lobe, the body and the coat (model/tabulated.h), weighted by f0 and the body.
  // Tabulated even for GGX: the report compares this render with the measured material's and the LUT's,
  // whose proposals are tabulated too, so the same random numbers give nearly the same directions and
  // most of the noise cancels in their difference (at the report's 32 spp, and at 4 spp in its test).
  return std::make_shared<ShadingModel>(brdf, tabulated_proposal(ndf, p->f0, p->body, p->coat));
}

// A measurement rendered as it is, in its own evaluation where the file has one (RGL, UTIA), else as its
// MERL-layout table; a fit only proposes directions (measured_proposal).
std::shared_ptr<const ShadingModel> measured_material(const SceneDesc& scene, const MaterialDesc& m) {
  const std::string source = resolve(scene, m.file);
  // Read once: what is rendered (the file itself for RGL and UTIA, else its table) and what the fit
  // proposing directions sees (the table).
  const std::shared_ptr<const Brdf> measurement = load_brdf(source);
  const auto* rgl = dynamic_cast<const RglBsdf*>(measurement.get());
  const bool utia = dynamic_cast<const UtiaBrdf*>(measurement.get()) != nullptr;
  std::shared_ptr<const HalfDiffTable> table = std::dynamic_pointer_cast<const HalfDiffTable>(measurement);
  if (!table && (!(rgl || utia) || m.proposal.empty())) table = std::make_shared<HalfDiffTable>(table_of(*measurement));
  const std::shared_ptr<const Proposal> proposal = measured_proposal(scene, m, table.get());
  // RGL files render through their own evaluation (the renderer's o is the viewer's side), not the
  // MERL-layout table: with view slices this is Mitsuba's `measured` (tests/io/test_mitsuba.cpp).
  if (rgl) {
    auto brdf = std::make_shared<RglBsdf>(*rgl);  // a copy shares the file's tables; the slices are its own
    brdf->set_slices(*parse_slices(m.slices));
    return measured_model(scene, brdf, proposal);
  }
  // UTIA files too, anisotropic as they are (the table and the proposal's fit see their azimuthal mean).
  if (utia) return measured_model(scene, measurement, proposal);
  return measured_model(scene, table, proposal);
}

// A baked LUT's tabulated model: its anisotropic lobe where it has one (along the tangent), else its
// isotropic one; either reshaped by the artist's stretch.
std::shared_ptr<const ShadingModel> lut_material(const SceneDesc& scene, const MaterialDesc& m) {
  Lut lut = scene_lut(scene, m.file);
  if (m.anisotropic && lut.anisotropic) {
    const auto lobe = std::make_shared<TabulatedAnisotropic>(std::move(*lut.anisotropic), m.stretch);
    return std::make_shared<ShadingModel>(lobe, lobe);
  }
  if (!m.stretch.unscaled()) {  // a stretch reshapes the lobe, not the slopes' tables: its own visible normals
    const auto model = std::make_shared<TabulatedMicrofacet>(sampled_lut_model(std::move(lut))->stretched(m.stretch));
    return std::make_shared<ShadingModel>(model, model);
  }
  // Its own sampling tables too: a stretch_texture stretches it per point (render/integrator.cpp).
  const auto model = sampled_lut_model(std::move(lut));
  return std::make_shared<ShadingModel>(model, VisibleSlopeProposal::of(*model));
}

// ggx | beckmann | lsq (the LUT's classical baseline: Lambert + GGX + Schlick): with a LUT, its fit of that
// family; without, the family's lobe of the material's alpha, f0 and f82.
std::shared_ptr<const ShadingModel> parametric_material(const SceneDesc& scene, const MaterialDesc& m) {
  if (!m.file.empty()) return lut_parametric_model(scene_lut(scene, m.file), m.type, m.smith, m.fresnel == "curve", m.anisotropic);
  const Ndf ndf = Ndf::isotropic(m.type == "beckmann" ? NdfType::beckmann : NdfType::ggx, m.alpha);
  // The proposal samples the lobe, weighted by f0: GGX's visible normals in closed form (model/proposal.h),
  // Beckmann's tabulated.
  const Rgb f0 = scene.from_rec709 * m.f0, f82 = scene.from_rec709 * m.f82;
  const auto brdf = std::make_shared<ParametricBrdf>(ndf, m.smith, f0, f82);
  if (ndf.type == NdfType::ggx) return std::make_shared<ShadingModel>(brdf, std::make_shared<GgxProposal>(m.alpha, f0, Rgb(0.0), Coat{}));
  return std::make_shared<ShadingModel>(brdf, tabulated_proposal(ndf, f0));
}

// The closures, as closure_model says, of the LUT's closure representation or (production_material) of what
// the production material emits.
std::shared_ptr<const ShadingModel> closures_material(const SceneDesc& scene, const MaterialDesc& m) {
  return closure_model(scene, m, &Lut::closures);
}

std::shared_ptr<const ShadingModel> production_material(const SceneDesc& scene, const MaterialDesc& m) {
  return closure_model(scene, m, &Lut::production_closures);
}

// A Lambertian reflector of the material's albedo; cosine sampling alone.
std::shared_ptr<const ShadingModel> lambert_material(const SceneDesc& scene, const MaterialDesc& m) {
  return std::make_shared<ShadingModel>(std::make_shared<LambertBrdf>(scene.from_rec709 * m.albedo), nullptr);
}

// A built-in's analytic model itself: the ground truth.
std::shared_ptr<const ShadingModel> analytic_material(const SceneDesc& scene, const MaterialDesc& m) {
  const std::string name = is_builtin(m.file) ? source_name(m.file) : m.file;
  const auto builtin = find_builtin(name);
  if (!builtin) fail(m.file, "analytic materials are built-ins (builtin:NAME)");
  std::shared_ptr<const Proposal> proposal;  // tabulated, as lut_parametric_model says why
  if (const auto* mf = dynamic_cast<const MicrofacetBrdf*>(builtin->brdf.get()))
    proposal = std::make_shared<VisibleSlopeProposal>(tabulate_ndf(mf->ndf()), ProposalParts{});
  return measured_model(scene, builtin->brdf, proposal);
}

const MaterialType* find_material_type(const std::string& name) {
  for (const MaterialType& t : kMaterialTypes)
    if (name == t.name) return &t;
  return nullptr;
}

std::string material_type_list() {
  std::string list;
  const std::size_t n = std::size(kMaterialTypes);
  for (std::size_t k = 0; k < n; ++k) list += std::string(k == 0 ? "" : k + 1 == n ? " or " : ", ") + kMaterialTypes[k].name;
  return list;
}

std::shared_ptr<const ShadingModel> load_material(const SceneDesc& scene, const MaterialDesc& m) {
  const MaterialType* type = find_material_type(m.type);
  if (!type) fail("material type '" + m.type + "'", "must be " + material_type_list());
  return type->make(scene, m);
}

}  // namespace facetfit
