#include "model/builtin.h"

#include "model/analytic.h"

namespace facetfit {

namespace {

// Complex indices of refraction at about 650, 550 and 450 nm (red, green, blue).
Fresnel gold() { return Fresnel::conductor({0.143, 0.374, 1.442}, {3.983, 2.385, 1.603}); }
Fresnel copper() { return Fresnel::conductor({0.200, 0.924, 1.102}, {3.912, 2.452, 2.142}); }
Fresnel aluminium() { return Fresnel::conductor({1.657, 0.880, 0.521}, {9.224, 6.270, 4.837}); }
Fresnel silver() { return Fresnel::conductor({0.155, 0.117, 0.138}, {4.828, 3.122, 2.147}); }

std::shared_ptr<const Brdf> lobe(NdfType type, double alpha, const Fresnel& fresnel) {
  return std::make_shared<MicrofacetBrdf>(Ndf::isotropic(type, alpha), Smith::correlated, fresnel);
}

}  // namespace

std::vector<BuiltinMaterial> builtin_materials() {
  using std::make_shared;
  return {
      {"gold-ggx-0.15", "polished gold: GGX alpha 0.15, conductor Fresnel", lobe(NdfType::ggx, 0.15, gold())},
      {"copper-beckmann-0.30", "brushed-look copper: Beckmann alpha 0.30, conductor Fresnel",
       lobe(NdfType::beckmann, 0.30, copper())},
      {"aluminium-ggx-0.05", "mirror-like aluminium: GGX alpha 0.05, conductor Fresnel",
       lobe(NdfType::ggx, 0.05, aluminium())},
      {"silver-ggx-0.60", "rough silver: GGX alpha 0.60, conductor Fresnel", lobe(NdfType::ggx, 0.60, silver())},
      {"black-glossy-ggx-0.08", "black glossy dielectric: GGX alpha 0.08, Fresnel of index 1.5",
       lobe(NdfType::ggx, 0.08, Fresnel::dielectric(1.5))},
      {"red-plastic", "red plastic, diffuse plus specular: Lambert (0.5, 0.05, 0.03) + GGX alpha 0.12, index 1.5",
       make_shared<SumBrdf>(std::vector<std::shared_ptr<const Brdf>>{
           make_shared<LambertBrdf>(Rgb(0.5, 0.05, 0.03)), lobe(NdfType::ggx, 0.12, Fresnel::dielectric(1.5))})},
      {"blue-clearcoat-paint", "clear-coated metallic blue paint, two lobes: GGX 0.03 coat (index 1.5) + GGX 0.35 blue base",
       make_shared<SumBrdf>(std::vector<std::shared_ptr<const Brdf>>{
           lobe(NdfType::ggx, 0.03, Fresnel::dielectric(1.5)),
           lobe(NdfType::ggx, 0.35, Fresnel::schlick(Rgb(0.04, 0.12, 0.55)))})},
  };
}

std::optional<BuiltinMaterial> find_builtin(const std::string& name) {
  for (auto& m : builtin_materials())
    if (m.name == name) return m;
  return std::nullopt;
}

}  // namespace facetfit
