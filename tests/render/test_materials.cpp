// Materials in the reference renderer: measured tables, UTIA and RGL files against the analytic models and
// their LUTs, the artist's stretch (uniform, from a texture, along the plane's texture axes), and the
// textures' lookup.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "color/image_diff.h"
#include "fit/fit.h"
#include "io/input.h"
#include "io/utia.h"
#include "lut/lut.h"
#include "model/analytic.h"
#include "render/renderer.h"
#include "render/scene.h"
#include "render/texture.h"
#include "render_fixtures.h"
#include "support/tensor_file.h"
#include "test_util.h"

namespace facetfit {
namespace {

// `measured` (builtin:gold-ggx-0.15 as a measurement) and the analytic model rendered in the same
// small scene with the same seeds, compared over the sphere.
ImageDiff measured_against_analytic_gold(const MaterialDesc& measured) {
  MaterialDesc analytic;
  analytic.type = "analytic";
  analytic.file = "builtin:gold-ggx-0.15";
  SceneDesc a = default_scene(measured), b = default_scene(analytic);
  for (SceneDesc* s : {&a, &b}) {
    s->camera.width = s->camera.height = 64;
    s->spp = 64;
  }
  const RenderedImage ia = render(a), ib = render(b);
  std::vector<bool> mask(std::size_t(ia.width) * ia.height);
  for (std::size_t p = 0; p < mask.size(); ++p) mask[p] = ia.rgba[4 * p + 3] >= 1.0f;
  return image_delta_e(ia.rgb(), false, ib.rgb(), false, mask, DisplayTransform());
}

TEST(Render, MeasuredGgxTableMatchesTheAnalyticGgx) {
  // The analytic gold GGX, tabulated into a MERL table and rendered from it (trilinear lookup), against
  // the analytic model itself: mean Delta E 2000 over the sphere < 0.5.
  MaterialDesc measured;
  measured.type = "measured";
  measured.file = "builtin:gold-ggx-0.15";
  const ImageDiff d = measured_against_analytic_gold(measured);
  EXPECT_GT(d.pixels, 1000u);
  EXPECT_LT(d.mean, 0.5);
  std::printf("measured vs analytic GGX: mean Delta E 2000 %.4f, max %.4f over %zu pixels\n", d.mean, d.max, d.pixels);
}

TEST(Render, MeasuredMaterialSampledByAGivenLutRendersTheSameImage) {
  // A measured material sampled by a bake's LUT (the report hands its bake over rather than fitting
  // again) still renders the measurement: the same bar against the analytic model.
  test::TempDir dir;
  test::write_gold_lut(dir.file("gold.exr"));
  MaterialDesc measured;
  measured.type = "measured";
  measured.file = "builtin:gold-ggx-0.15";
  measured.proposal = dir.file("gold.exr");
  const ImageDiff d = measured_against_analytic_gold(measured);
  EXPECT_GT(d.pixels, 1000u);
  EXPECT_LT(d.mean, 0.5);
  // A missing proposal is an error naming it, not a silent refit.
  measured.proposal = dir.file("none.exr");
  EXPECT_NE(test::error_of([&] { render(default_scene(measured)); }).find("none.exr"), std::string::npos);
}

TEST(Render, StretchedLutMaterials) {
  // The scene's stretch reaches the model (tests/model/test_stretch.cpp checks the model against the analytic
  // anisotropic GGX): the identity renders the LUT as it is, a stretch changes the image, and bad values
  // get one line.
  test::TempDir dir;
  test::write_gold_lut(dir.file("gold.exr"));
  const auto scene = [&](const std::string& extra) {
    SceneDesc s = parse_scene_text(R"({"camera": {"width": 32, "height": 32}, "render": {"spp": 8},
      "environment": {"builtin": "sky"},
      "materials": {"m": {"type": "lut", "file": "gold.exr")" + extra + R"(}},
      "objects": [{"type": "sphere", "material": "m"}]})", "s.json", dir.path().string());
    return s;
  };
  const RenderedImage plain = render(scene("")), identity = render(scene(R"(, "stretch": [1, 1], "rotation": 40)"));
  EXPECT_EQ(plain.rgba, identity.rgba);
  const RenderedImage stretched = render(scene(R"(, "stretch": [3, 0.5], "rotation": 30)"));
  double diff = 0.0;
  for (std::size_t k = 0; k < plain.rgba.size(); ++k) diff += std::abs(plain.rgba[k] - stretched.rgba[k]);
  EXPECT_GT(diff / double(plain.rgba.size()), 1e-3);
  EXPECT_NE(test::error_of([&] { scene(R"(, "stretch": [0, 1])"); }).find("stretch must be in [0.01, 100]"), std::string::npos);
  EXPECT_NE(test::error_of([&] { scene(R"(, "stretch": 2)"); }).find("stretch must be [x, y]"), std::string::npos);
  EXPECT_NE(test::error_of([&] {
              parse_scene_text(R"({"materials": {"m": {"type": "ggx", "alpha": 0.2, "stretch": [2, 1]}},
                                   "objects": [{"type": "sphere", "material": "m"}]})", "t.json", ".");
            }).find("are for lut, closures and material materials"), std::string::npos);
}

TEST(Render, StretchTextureDrivesTheStretchPerPoint) {
  // A uniform texture (2, 0.5) times a stretch (1.5, 1) is the stretch (3, 0.5) everywhere: the same image,
  // sample for sample. A texture that varies changes the image where it departs from that value.
  test::TempDir dir;
  test::write_gold_lut(dir.file("gold.exr"));
  test::write_texture(dir.file("uniform.exr"), 4, 2, [](int, int) { return Rgb(2.0, 0.5, 7.0); });
  // The bottom row as the top: v is periodic, so the top pole reads both.
  test::write_texture(dir.file("bands.exr"), 16, 8, [](int, int y) { return y < 4 || y == 7 ? Rgb(2.0, 0.5, 0.0) : Rgb(0.5, 2.0, 0.0); });
  const auto scene = [&](const std::string& material, const std::string& object) {
    return parse_scene_text(R"({"camera": {"width": 32, "height": 32}, "render": {"spp": 8},
      "environment": {"builtin": "sky"},
      "materials": {"m": {"type": "lut", "file": "gold.exr", "rotation": 30, "tangent": [0, 1, 0])" + material + R"(}},
      "objects": [)" + object + R"(]})", "s.json", dir.path().string());
  };
  const std::string sphere = R"({"type": "sphere", "material": "m"})";
  const std::string plane = R"({"type": "plane", "point": [0, 0, 0], "normal": [0, 0.6, 4], "size": 2, "material": "m"})";
  for (const std::string& object : {sphere, plane}) {
    const RenderedImage fixed = render(scene(R"(, "stretch": [3, 0.5])", object));
    const RenderedImage textured = render(scene(R"(, "stretch": [1.5, 1], "stretch_texture": "uniform.exr")", object));
    EXPECT_EQ(fixed.rgba, textured.rgba) << object;
    // Bands: the upper half of the texture (v > 1/2: the upper hemisphere, or half the plane) is (2, 0.5),
    // most of the lower (0.5, 2).
    const RenderedImage bands = render(scene(R"(, "stretch": [1.5, 1], "stretch_texture": "bands.exr")", object));
    EXPECT_NE(fixed.rgba, bands.rgba) << object;
  }
  // On the sphere the upper rows see the upper texture band: identical to the uniform stretch where the
  // whole bilinear footprint lies in that band (the top rows of the sphere, well above its equator).
  const RenderedImage fixed = render(scene(R"(, "stretch": [3, 0.5])", sphere));
  const RenderedImage bands = render(scene(R"(, "stretch": [1.5, 1], "stretch_texture": "bands.exr")", sphere));
  int same = 0, covered = 0;
  for (int y = 0; y < 10; ++y)
    for (int x = 0; x < 32; ++x) {
      const std::size_t k = (std::size_t(y) * 32 + std::size_t(x)) * 4;
      if (fixed.rgba[k + 3] < 1.0f) continue;
      ++covered;
      same += fixed.rgba[k] == bands.rgba[k] && fixed.rgba[k + 1] == bands.rgba[k + 1];
    }
  EXPECT_GT(covered, 20);
  EXPECT_EQ(same, covered);
  EXPECT_NE(test::error_of([&] { render(scene(R"(, "stretch_texture": "missing.exr")", sphere)); }).find("missing.exr"), std::string::npos);
  test::write_texture(dir.file("nan.exr"), 2, 2, [](int x, int y) { return x == 1 && y == 1 ? Rgb(1.0, std::nan(""), 1.0) : Rgb(1.0); });
  EXPECT_NE(test::error_of([&] { render(scene(R"(, "stretch_texture": "nan.exr")", sphere)); }).find("nan.exr: non-finite G value at pixel (1, 1)"),
            std::string::npos);
  EXPECT_NE(test::error_of([&] { scene(R"(, "stretch_texture": "uniform.exr")", R"({"type": "mesh", "file": "x.obj", "material": "m"})"); })
                .find("a mesh has no texture coordinates"),
            std::string::npos);
}

// A unit sphere of `material` (scene-format JSON) under the built-in sky, size x size pixels, files
// resolved in `dir`.
RenderedImage sphere_under_sky(const test::TempDir& dir, const std::string& material, int size, int spp) {
  return render(parse_scene_text(R"({"camera": {"width": )" + std::to_string(size) + R"(, "height": )" + std::to_string(size) +
                                     R"(}, "render": {"spp": )" + std::to_string(spp) + R"(}, "environment": {"builtin": "sky"},
      "materials": {"m": )" + material + R"(}, "objects": [{"type": "sphere", "material": "m"}]})",
                                 "s.json", dir.path().string()));
}

// Sum of |a - b| over the sum of a, every channel.
double relative_difference(const RenderedImage& a, const RenderedImage& b) {
  double d = 0.0, sum = 0.0;
  for (std::size_t k = 0; k < a.rgba.size(); ++k) d += std::abs(a.rgba[k] - b.rgba[k]), sum += a.rgba[k];
  return d / sum;
}

// A UTIA file renders as itself, anisotropic (its fit, of the azimuthal mean, only proposes directions):
// the material's tangent turns the highlight, which it cannot do to an isotropic file.
TEST(Render, MeasuredUtiaFilesRenderAnisotropicAlongTheirTangent) {
  test::TempDir dir;
  const MicrofacetBrdf aniso(Ndf{NdfType::ggx, 0.5, 0.2}, Smith::correlated, Fresnel::schlick(Rgb(0.9, 0.7, 0.4)));
  const MicrofacetBrdf iso(Ndf::isotropic(NdfType::ggx, 0.35), Smith::correlated, Fresnel::schlick(Rgb(0.9, 0.7, 0.4)));
  UtiaBrdf::tabulate(aniso).write(dir.file("aniso.bin"));
  UtiaBrdf::tabulate(iso).write(dir.file("iso.bin"));
  const auto image = [&](const std::string& file, const std::string& tangent) {
    return sphere_under_sky(dir, R"({"type": "measured", "file": ")" + file + R"(", "tangent": )" + tangent + "}", 32, 16);
  };
  const double turned_aniso = relative_difference(image("aniso.bin", "[0, 1, 0]"), image("aniso.bin", "[1, 0, 0]"));
  const double turned_iso = relative_difference(image("iso.bin", "[0, 1, 0]"), image("iso.bin", "[1, 0, 0]"));
  std::cout << "relative change when the tangent turns: anisotropic " << turned_aniso << ", isotropic " << turned_iso << "\n";
  EXPECT_GT(turned_aniso, 4.0 * turned_iso);  // 0.087 against 0.012 when written
}

// A LUT baked from an anisotropic file carries the anisotropic lobe (LUT version 3): rendered along the
// tangent, it is nearer the file itself than the LUT's isotropic lobe of the azimuthal mean. The file is
// an RGL one (the tests' tensor writer: GGX 0.45 x 0.2 turned 30 degrees, F = 1), whose evaluation is
// accurate to the model; a UTIA file's 15-degree grid blurs such a lobe more than the fit misses it.
TEST(Render, AnisotropicLutRendersNearerItsMeasurementThanTheIsotropicLobe) {
  test::TempDir dir;
  const std::vector<unsigned char> bytes =
      test::serialize(test::microfacet_tensor_fields(Ndf{NdfType::ggx, 0.45, 0.2}, Smith::correlated, 30.0 * kPi / 180.0, 25, 32, 64));
  test::write_bytes(dir.file("aniso.bsdf"), std::string(bytes.begin(), bytes.end()));
  const FitResult fit = Fitter{FitOptions{}}.fit(load_table(dir.file("aniso.bsdf")));
  ASSERT_TRUE(fit.ok() && fit.anisotropic.has_value()) << fit.problem;
  write_lut(dir.file("aniso.exr"), make_lut(fit, Quadrature(90), "aniso.bsdf", "", 0.05, true));
  const Lut lut = read_lut(dir.file("aniso.exr"));
  ASSERT_TRUE(lut.anisotropic.has_value());
  // Version 5 (the closures), with the anisotropic rows.
  EXPECT_EQ(lut.meta.format_version, kLutClosuresVersion);
  const auto image = [&](const std::string& material) { return sphere_under_sky(dir, material, 32, 1024); };
  const std::string tangent = R"("tangent": [0.6, 0.8, 0])";
  const RenderedImage measured = image(R"({"type": "measured", "file": "aniso.bsdf", "proposal": "aniso.exr", )" + tangent + "}");
  const double anisotropic = relative_difference(image(R"({"type": "lut", "file": "aniso.exr", )" + tangent + "}"), measured);
  const double isotropic = relative_difference(image(R"({"type": "lut", "file": "aniso.exr", "anisotropic": false, )" + tangent + "}"), measured);
  const double turned = relative_difference(image(R"({"type": "lut", "file": "aniso.exr", "tangent": [-0.8, 0.6, 0]})"), measured);
  // The anisotropic GGX fit (a ggx material with the LUT) too, and its isotropic GGX.
  const double ggx = relative_difference(image(R"({"type": "ggx", "file": "aniso.exr", )" + tangent + "}"), measured);
  const double ggx_isotropic = relative_difference(image(R"({"type": "ggx", "file": "aniso.exr", "anisotropic": false, )" + tangent + "}"), measured);
  std::cout << "relative difference from the measured file: anisotropic lobe " << anisotropic << ", isotropic " << isotropic
            << ", anisotropic turned a quarter " << turned << "; anisotropic GGX fit " << ggx << ", isotropic GGX fit " << ggx_isotropic << "\n";
  EXPECT_LT(anisotropic, 0.5 * isotropic);
  EXPECT_LT(anisotropic, 0.5 * turned);
  EXPECT_LT(ggx, 0.5 * ggx_isotropic);
  // The artist's stretch reshapes the anisotropic lobe too (the lobe's own test: model/tabulated_anisotropic.h,
  // tests/model/test_anisotropic.cpp), uniformly or from a texture: a uniform texture (2, 0.5) times (1.5, 1) is
  // (3, 0.5) everywhere, sample for sample.
  test::write_texture(dir.file("uniform.exr"), 4, 2, [](int, int) { return Rgb(2.0, 0.5, 7.0); });
  const auto quick = [&](const std::string& material) { return sphere_under_sky(dir, material, 24, 8); };
  const RenderedImage plain = quick(R"({"type": "lut", "file": "aniso.exr", )" + tangent + "}");
  const RenderedImage fixed = quick(R"({"type": "lut", "file": "aniso.exr", "stretch": [3, 0.5], "rotation": 20, )" + tangent + "}");
  const RenderedImage textured =
      quick(R"({"type": "lut", "file": "aniso.exr", "stretch": [1.5, 1], "rotation": 20, "stretch_texture": "uniform.exr", )" + tangent + "}");
  EXPECT_EQ(fixed.rgba, textured.rgba);
  EXPECT_GT(relative_difference(fixed, plain), 0.05);
}

// The plane's texture axes as docs/scene-format.md states them: facing +y, u along +x and v along -z. Seen
// from above (image right +x, image top -z), a texture split in two halves renders each half of the image as
// the uniform stretch of that half does.
TEST(Render, PlaneTextureAxesAreAsDocumented) {
  test::TempDir dir;
  test::write_gold_lut(dir.file("gold.exr"));
  constexpr int kTexels = 64;
  const auto write_halves = [&](const std::string& name, bool along_u) {
    test::write_texture(dir.file(name), kTexels, kTexels, [&](int x, int y) {
      // u >= 1/2 (right columns), or v >= 1/2 (top rows): the rough half.
      const bool rough = along_u ? x >= kTexels / 2 : y < kTexels / 2;
      return rough ? Rgb(4.0, 4.0, 0.0) : Rgb(0.25, 0.25, 0.0);
    });
  };
  write_halves("u.exr", true);
  write_halves("v.exr", false);
  constexpr int kSize = 32;
  const auto image = [&](const std::string& material) {
    return render(parse_scene_text(R"({"camera": {"position": [0, 4, 0], "look_at": [0, 0, 0], "up": [0, 0, -1], "width": 32, "height": 32},
      "render": {"spp": 4}, "environment": {"builtin": "sky"},
      "materials": {"m": {"type": "lut", "file": "gold.exr")" + material + R"(}},
      "objects": [{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "size": 2, "material": "m"}]})",
                                   "s.json", dir.path().string()));
  };
  const RenderedImage sharp = image(R"(, "stretch": [0.25, 0.25])"), rough = image(R"(, "stretch": [4, 4])");
  // Pixel (x, y) sees the plane at world x or -z = (2 (p + 0.5) / 32 - 1) tan(15 deg) 4: compare the pixels
  // well inside one half (0.1 to 0.9 from the middle line), away from the texture's seams.
  const auto world = [](int p) { return (2.0 * (p + 0.5) / kSize - 1.0) * std::tan(15.0 * kPi / 180.0) * 4.0; };
  for (const bool along_u : {true, false}) {
    const RenderedImage textured = image(R"(, "stretch_texture": ")" + std::string(along_u ? "u.exr" : "v.exr") + "\"");
    int checked = 0;
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x) {
        // Column x sees world x = world(x), along which u grows; row y sees world z = world(y), against which v grows.
        const double from_middle = along_u ? world(x) : -world(y);  // > 0: the rough half
        if (std::abs(from_middle) < 0.1 || std::abs(from_middle) > 0.9) continue;
        const RenderedImage& want = from_middle > 0.0 ? rough : sharp;
        const std::size_t k = (std::size_t(y) * kSize + std::size_t(x)) * 4;
        for (int c = 0; c < 3; ++c)
          EXPECT_NEAR(textured.rgba[k + std::size_t(c)], want.rgba[k + std::size_t(c)], 1e-5 * (1.0 + want.rgba[k + std::size_t(c)]))
              << (along_u ? "u" : "v") << " at pixel " << x << ", " << y;
        ++checked;
      }
    EXPECT_GT(checked, 300);
  }
}

TEST(Texture, BilinearBetweenPixelCentresWithVFromTheBottomAndBothAxesPeriodic) {
  // 4 x 2: row 0 (top) 0, 1, 2, 3 in red; row 1 (bottom) 10, 11, 12, 13.
  const Texture t(4, 2, {0, 0, 0, 1, 0, 0, 2, 0, 0, 3, 0, 0, 10, 0, 0, 11, 0, 0, 12, 0, 0, 13, 0, 0});
  EXPECT_DOUBLE_EQ(t.lookup({0.125, 0.25}).r, 10.0);  // centre of the bottom-left pixel
  EXPECT_DOUBLE_EQ(t.lookup({0.375, 0.75}).r, 1.0);   // centre of the top row's second pixel
  EXPECT_DOUBLE_EQ(t.lookup({0.25, 0.75}).r, 0.5);    // between two centres
  EXPECT_DOUBLE_EQ(t.lookup({0.0, 0.75}).r, 1.5);     // across the u seam: (3 + 0) / 2
  EXPECT_DOUBLE_EQ(t.lookup({0.125, 0.5}).r, 5.0);    // halfway between the rows
  EXPECT_DOUBLE_EQ(t.lookup({1.125, -0.75}).r, 10.0); // periodic
  // The sphere's coordinates: the top pole v = 1, the bottom 0, the point facing +z (the default camera) u = 0.
  EXPECT_NEAR(sphere_texture_coordinates({0, 1, 0}).v, 1.0, 1e-12);
  EXPECT_NEAR(sphere_texture_coordinates({0, -1, 0}).v, 0.0, 1e-12);
  EXPECT_NEAR(sphere_texture_coordinates({1, 0, 0}).v, 0.5, 1e-12);
  EXPECT_NEAR(sphere_texture_coordinates({1, 0, 0}).u, 0.25, 1e-12);
}

}  // namespace
}  // namespace facetfit
