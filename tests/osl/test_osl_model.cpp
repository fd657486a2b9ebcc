// The OSL shaders in a real OSL renderer: Blender's Cycles from the bpy wheel (OSL 1.14, CPU), driven by
// tests/osl/cycles_render.py (tests/osl/osl_fixtures.h). The shaders compile (and a broken one fails with
// the compiler's message); a missing LUT renders the error colour; facetfit.h's eval, sample and pdf equal
// the C++ library to 1e-4 on grids of directions and uniform numbers.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <iostream>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "io/image_file.h"
#include "lut/lut.h"
#include "model/analytic.h"
#include "model/ndf.h"
#include "model/theta_grid.h"
#include "osl_fixtures.h"
#include "test_util.h"

namespace facetfit {
namespace {

using test::facetfit;
using test::RunResult;
using test::TempDir;
using test::osl::compile_shaders;
using test::osl::cycles;
using test::osl::Image;
using test::osl::kSource;
using test::osl::make_luts;
using test::osl::osl_compile;
using test::osl::radians;
using test::osl::read_image;
using test::osl::SharedFolder;
using test::osl::str;

using glm::dot;
using glm::length;
using glm::normalize;

// A size x size float RGB image holding one vector per pixel, row-major from the top left.
void write_vectors(const std::string& path, int size, const std::vector<Vec3>& v) {
  std::vector<float> rgb;
  for (const Vec3& d : v) rgb.insert(rgb.end(), {float(d.x), float(d.y), float(d.z)});
  write_image_atomic(path, ImageSpec(size, size, {"R", "G", "B"}), rgb.data());
}

Vec3 as_float(const Vec3& v) { return {double(float(v.x)), double(float(v.y)), double(float(v.z))}; }

// ---- compilation ------------------------------------------------------------------------------------

TEST(OslCompile, EveryShaderCompiles) {
  TempDir out;
  const RunResult r = osl_compile(kSource + "/osl", out.path().string());
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  int shaders = 0;
  for (const auto& e : std::filesystem::directory_iterator(kSource + "/osl")) {
    if (e.path().extension() != ".osl") continue;
    ++shaders;
    EXPECT_NE(r.out.find("compiled " + e.path().string()), std::string::npos) << r.out;
    EXPECT_TRUE(std::filesystem::exists(out.file(e.path().stem().string() + ".oso"))) << e.path();
  }
  EXPECT_GE(shaders, 2);
  // The test probe too: it includes facetfit.h from its own folder.
  const RunResult probe = osl_compile(kSource + "/tests/osl", out.path().string());
  EXPECT_EQ(probe.status, 0) << probe.out << probe.err;
}

TEST(OslCompile, BrokenShaderFailsWithTheCompilersMessage) {
  TempDir dir;
  test::write_bytes(dir.file("broken.osl"),
                    "#include \"" + kSource + "/osl/facetfit.h\"\n"
                    "shader broken(output color c = 0) {\n"
                    "  c = facetfit_no_such_function(1.0);\n"
                    "}\n");
  const RunResult r = osl_compile(dir.path().string(), dir.path().string());
  EXPECT_EQ(r.status, 1) << r.out << r.err;
  EXPECT_NE(r.out.find("FAILED   " + dir.file("broken.osl")), std::string::npos) << r.out;
  // The compiler's own line: file, line number, and what is wrong.
  EXPECT_NE(r.err.find("broken.osl:3: error: function 'facetfit_no_such_function' was not declared"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("broken.oso")));
}

// A missing LUT renders the material's error colour, not the texture system's silent magenta, and the
// shader says why, naming the file.
TEST(OslMaterial, MissingLutRendersTheErrorColourAndWarns) {
  TempDir dir;
  compile_shaders(dir.path());
  const RunResult r = cycles("probe " + dir.file("facetfit_material.oso") + " " + dir.file("out.exr") + " 6 lut=" + dir.file("no-such-lut.exr"));
  const Image img = read_image(dir.file("out.exr"));
  const float* px = img.at(3, 3);
  EXPECT_FLOAT_EQ(px[0], 1.0f);
  EXPECT_FLOAT_EQ(px[1], 0.0f);
  EXPECT_FLOAT_EQ(px[2], 0.5f);
  EXPECT_NE((r.out + r.err).find("facetfit_material: " + dir.file("no-such-lut.exr") + " is missing or not a facetfit LUT"),
            std::string::npos) << r.out << r.err;
}

// ---- eval, sample and pdf against the library --------------------------------------------------------

constexpr int kGrid = 32;  // cases a side: 1024 cases per render
constexpr int kCell = 3;   // pixels a side per case: the centre pixel is read, far from the case's edges

// 1e-4 relative, with a floor for values that are zero in exact arithmetic (below the horizon of one
// side, outside the support) and come out as float round-off.
bool close(double osl, double cpp, double floor) { return std::abs(osl - cpp) <= 1e-4 * std::abs(cpp) + floor; }

// How much `value` (a function of two unit directions) moves when a coordinate of either moves by 4
// float ulps (a relative 2.4e-7): the OSL side reads its inputs from float images and computes in
// float, so it can agree with the double library only to about this. Large for a sharp coat, whose
// density changes by 1/alpha^2 per radian near its peak; negligible elsewhere.
template <class F>
double input_sensitivity(const Vec3& a, const Vec3& b, F value) {
  constexpr double kUlps = 2.4e-7;
  const double base = value(a, b);
  double worst = 0.0;
  for (int k = 0; k < 3; ++k)
    for (const double s : {-1.0, 1.0}) {
      Vec3 da = a, db = b;
      da[k] += s * kUlps * std::max(std::abs(a[k]), 1e-3);
      db[k] += s * kUlps * std::max(std::abs(b[k]), 1e-3);
      worst = std::max({worst, std::abs(value(normalize(da), b) - base), std::abs(value(a, normalize(db)) - base)});
    }
  return worst;
}

// The inputs of one render, as written to the input images (float). Float rounding leaves a direction
// off unit length by up to 1e-7, which the OSL side ignores (it takes angles from all three components)
// and the library, which reads theta from z alone, does not: the library gets them renormalised in double.
struct Cases {
  std::vector<Vec3> o, second;  // second: i (eval, pdf) or (u1, u2, 1) (sample)
  Vec3 unit_o(int k) const { return normalize(o[std::size_t(k)]); }
  Vec3 unit_i(int k) const { return normalize(second[std::size_t(k)]); }
};

// Directions that reach the edges: the normal, grazing (89.9 degrees), retro-reflection, near the
// mirror direction (the peak), and random pairs; all rounded to float as the OSL side reads them.
Cases direction_pairs(std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Cases c;
  for (int k = 0; k < kGrid * kGrid; ++k) {
    Vec3 o = test::random_direction(rng), i = test::random_direction(rng);
    switch (k % 8) {
      case 0: o = spherical_direction(0.0, 0.0); break;
      case 1: o = spherical_direction(radians(89.9), 2.0 * kPi * u(rng)); break;
      case 2: i = o; break;
      case 3:
      case 4: {  // near mirror: reflect o about a normal close to z
        const Vec3 h = spherical_direction(0.3 * u(rng) * u(rng), 2.0 * kPi * u(rng));
        i = 2.0 * dot(o, h) * h - o;
        if (i.z <= 0.0) i = test::random_direction(rng);
        break;
      }
      case 5: i = spherical_direction(radians(89.9), 2.0 * kPi * u(rng)); break;
      default: break;
    }
    c.o.push_back(as_float(normalize(as_float(o))));
    c.second.push_back(as_float(normalize(as_float(i))));
  }
  return c;
}

Cases sample_inputs(std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Cases c;
  for (int k = 0; k < kGrid * kGrid; ++k) {
    Vec3 o = test::random_direction(rng);
    if (k % 16 == 0) o = spherical_direction(0.0, 0.0);
    if (k % 16 == 1) o = spherical_direction(radians(89.0), 2.0 * kPi * u(rng));
    // Corners of the unit square as well as its inside.
    double u1 = k % 16 == 2 ? 0.0 : u(rng), u2 = k % 16 == 3 ? 0.999999 : u(rng);
    c.o.push_back(as_float(normalize(as_float(o))));
    c.second.push_back(as_float({u1, u2, 1.0}));
  }
  return c;
}

class OslModel : public ::testing::TestWithParam<std::string> {
 protected:
  static void SetUpTestSuite() { luts_ = new SharedFolder(FACETFIT_OSL_FIXTURE, make_luts); }
  static void TearDownTestSuite() {
    delete luts_;
    luts_ = nullptr;
  }

  // A parameter ending in "+stretch" is that LUT with the artist's stretch (model/stretch.h), which the
  // probe hands to facetfit_stretch.
  bool stretched() const { return GetParam().size() > 8 && GetParam().substr(GetParam().size() - 8) == "+stretch"; }
  std::string lut() const { return luts_->file((stretched() ? GetParam().substr(0, GetParam().size() - 8) : GetParam()) + ".exr"); }
  Stretch stretch() const { return stretched() ? Stretch{2.0, 0.5, 0.5235987755982988} : Stretch{}; }
  TabulatedMicrofacet model() const {
    Lut l = read_lut(lut());
    return TabulatedMicrofacet(std::move(l.tables), std::move(l.sampling), stretch());
  }

  // Renders the probe in `mode` over the cases; returns one pixel per case (kGrid x kGrid RGBA): the
  // centre of its kCell x kCell block, so that no sub-pixel offset of the renderer reaches a neighbour.
  Image probe(int mode, const Cases& cases) const {
    TempDir dir;
    write_vectors(dir.file("o.exr"), kGrid, cases.o);
    write_vectors(dir.file("second.exr"), kGrid, cases.second);
    const RunResult r = cycles("probe " + luts_->file("facetfit_probe.oso") + " " + dir.file("out.exr") + " " +
                               std::to_string(kGrid * kCell) + " lut=" + lut() + " directions_o=" + dir.file("o.exr") +
                               " inputs_2=" + dir.file("second.exr") + " mode=" + std::to_string(mode) +
                               (stretched() ? " stretch_x=2.0 stretch_y=0.5 rotation=0.5235987755982988" : ""));
    // The probe's warnings (an input or the LUT it could not read) fail the test with Cycles' messages.
    EXPECT_EQ(r.out.find("facetfit_probe:"), std::string::npos) << r.out;
    EXPECT_EQ(r.err.find("facetfit_probe:"), std::string::npos) << r.err;
    const Image full = read_image(dir.file("out.exr"));
    EXPECT_EQ(full.width, kGrid * kCell);
    EXPECT_EQ(full.height, kGrid * kCell);
    Image img{kGrid, kGrid, full.channels, {}};
    for (int y = 0; y < kGrid; ++y)
      for (int x = 0; x < kGrid; ++x) {
        const float* px = full.at(kCell * x + kCell / 2, kCell * y + kCell / 2);
        img.pixels.insert(img.pixels.end(), px, px + full.channels);
      }
    return img;
  }

  // probe(), rendered again once when pixels come back black where the library's value is not (`drawn`
  // says which cases carry a value). Cycles does that now and then: in about one run of the osl label in
  // five under a parallel ctest, one to three of the 1024 pixels of one probe render are exactly 0 while
  // every other pixel agrees to 1e-5, and the same render is right when repeated (inputs, LUT and shader
  // unchanged; the probe's input checks do not fire). A fault of ours would repeat; the second render
  // is then checked as strictly as the first.
  template <class Drawn>
  Image probe_checked(int mode, const Cases& cases, Drawn drawn) const {
    Image img = probe(mode, cases);
    int black = 0;
    for (int k = 0; k < kGrid * kGrid; ++k) {
      const float* px = img.at(k % kGrid, k / kGrid);
      if (px[0] == 0.0f && px[1] == 0.0f && px[2] == 0.0f && drawn(k)) ++black;
    }
    if (black > 0) {
      std::cout << "mode " << mode << ": " << black << " pixel(s) black where the library has a value; rendering again\n";
      img = probe(mode, cases);
    }
    return img;
  }

  static SharedFolder* luts_;
};
SharedFolder* OslModel::luts_ = nullptr;

TEST_P(OslModel, MetadataEqualsLibrary) {
  const Lut table = read_lut(lut());
  Cases cases;  // any valid inputs: the metadata do not depend on them
  cases.o.assign(kGrid * kGrid, Vec3(0.0, 0.0, 1.0));
  cases.second.assign(kGrid * kGrid, Vec3(0.0, 0.0, 1.0));
  const Image img = probe(5, cases);
  const int smith = table.meta.smith == Smith::masking ? 0 : (table.meta.smith == Smith::correlated ? 1 : 2);
  const int representation = representation_code(table.meta.representation);
  EXPECT_EQ(img.at(0, 0)[0], float(smith));
  EXPECT_EQ(img.at(0, 0)[1], float(representation));
  EXPECT_EQ(img.at(0, 0)[2], float(table.meta.resolution));
}

TEST_P(OslModel, EvalEqualsLibrary) {
  const TabulatedMicrofacet model = this->model();
  const Cases cases = direction_pairs(11);
  const Image img = probe_checked(0, cases, [&](int k) {
    const Rgb f = model.eval(cases.unit_o(k), cases.unit_i(k)).value_or(Rgb(0.0));
    return f.r > 1e-3 || f.g > 1e-3 || f.b > 1e-3;
  });
  ASSERT_EQ(img.width, kGrid);
  double worst = 0.0;
  int checked = 0;
  for (int k = 0; k < kGrid * kGrid; ++k) {
    const Rgb f = model.eval(cases.unit_o(k), cases.unit_i(k)).value_or(Rgb(0.0));
    const float* px = img.at(k % kGrid, k / kGrid);
    for (int c = 0; c < 3; ++c) {
      const double moved = 2.0 * input_sensitivity(cases.unit_i(k), cases.unit_o(k), [&](const Vec3& i, const Vec3& o) {
        return model.eval(o, i).value_or(Rgb(0.0))[c];
      });
      EXPECT_TRUE(close(px[c], f[c], 1e-6 + moved)) << "case " << k << " channel " << c << ": OSL " << px[c] << ", C++ " << f[c]
                                            << "; o " << str(cases.o[std::size_t(k)]) << ", i " << str(cases.second[std::size_t(k)]);
      if (f[c] > 1e-3) worst = std::max(worst, std::abs(px[c] - f[c]) / f[c]), ++checked;
    }
  }
  EXPECT_GT(checked, kGrid * kGrid);  // most cases carry energy
  std::cout << GetParam() << ": eval, worst relative difference " << worst << " over " << checked << " values\n";
}

TEST_P(OslModel, PdfAndTermsEqualLibrary) {
  const TabulatedMicrofacet model = this->model();
  const Cases cases = direction_pairs(12);
  const Image img = probe_checked(1, cases, [&](int k) { return model.g1(cases.unit_i(k)) > 1e-3; });
  double worst = 0.0;
  for (int k = 0; k < kGrid * kGrid; ++k) {
    const Vec3 o = cases.unit_o(k), i = cases.unit_i(k);
    const float* px = img.at(k % kGrid, k / kGrid);
    const double pdf = model.pdf(o, i), d = model.D(normalize(i + o)), g1 = model.g1(i);
    const double moved = 2.0 * input_sensitivity(o, i, [&](const Vec3& a, const Vec3& b) { return model.pdf(a, b); });
    EXPECT_TRUE(close(px[0], pdf, 1e-6 + moved)) << "pdf, case " << k << ": OSL " << px[0] << ", C++ " << pdf << "; o " << str(o) << ", i " << str(i);
    EXPECT_TRUE(close(px[1], d, 1e-6)) << "D, case " << k << ": OSL " << px[1] << ", C++ " << d;
    EXPECT_TRUE(close(px[2], g1, 1e-6)) << "G1, case " << k << ": OSL " << px[2] << ", C++ " << g1;
    if (pdf > 1e-3) worst = std::max(worst, std::abs(px[0] - pdf) / pdf);
  }
  std::cout << GetParam() << ": pdf, worst relative difference " << worst << "\n";
}

// How far sample() moves its direction when an input moves by a few float ulps (4, a relative 2.4e-7):
// u1, u2, or o's coordinate x = R sqrt(theta / (pi/2)) on the grid, whose fraction weighs the two view
// slices the sampler mixes. The OSL side computes in float, so it can agree with the double library only
// to about this. It exceeds 1e-4 where the map to i is steep: near the switch between the two slices
// (u1 close to 1 - t) and in the low-density tail of a slice.
double sample_sensitivity(const TabulatedMicrofacet& model, const Vec3& o, double u1, double u2) {
  constexpr double kUlps = 2.4e-7;
  const int r = model.tables().ndf.grid.resolution;
  const double theta = std::atan2(std::hypot(o.x, o.y), o.z), phi = std::atan2(o.y, o.x);
  const double x = ThetaGrid::u_of_theta(theta) * r;
  const auto view = [&](double dx) { return spherical_direction(ThetaGrid::theta_of_u((x + dx) / r), phi); };
  const auto at = [&](const Vec3& v, double a, double b) {
    return model.sample_direction(v, clamp(a, 0.0, 0.9999999), clamp(b, 0.0, 0.9999999));
  };
  double worst = 0.0;
  for (const auto& [a, b] : {std::pair{at(o, u1 * (1.0 - kUlps), u2), at(o, u1 * (1.0 + kUlps), u2)},
                             std::pair{at(o, u1, u2 * (1.0 - kUlps)), at(o, u1, u2 * (1.0 + kUlps))},
                             std::pair{at(view(-kUlps * r), u1, u2), at(view(kUlps * r), u1, u2)}})
    if (a && b) worst = std::max(worst, 0.5 * length(*a - *b));
  return worst;
}

TEST_P(OslModel, SampleEqualsLibrary) {
  const TabulatedMicrofacet model = this->model();
  const Cases cases = sample_inputs(13);
  const auto draws = [&](int k) {
    return model.sample(cases.unit_o(k), cases.second[std::size_t(k)].x, cases.second[std::size_t(k)].y).has_value();
  };
  const Image dirs = probe_checked(2, cases, draws), pdfs = probe_checked(3, cases, draws);
  double worst_dir = 0.0, worst_pdf = 0.0;
  int drawn = 0, beyond = 0;  // beyond: farther apart than 1e-4
  for (int k = 0; k < kGrid * kGrid; ++k) {
    const Vec3 o = cases.unit_o(k);
    const double u1 = cases.second[std::size_t(k)].x, u2 = cases.second[std::size_t(k)].y;
    const auto s = model.sample(o, u1, u2);
    const float* d = dirs.at(k % kGrid, k / kGrid);
    const float* p = pdfs.at(k % kGrid, k / kGrid);
    const bool osl_ok = p[1] > 0.5f;
    if (s.has_value() != osl_ok) {
      // Only a reflection that grazes the horizon may fall on either side of it in float.
      const double z = s ? s->i.z : 2.0 * d[2] - 1.0;
      EXPECT_LT(std::abs(z), 1e-4) << "case " << k << ": C++ " << (s ? "draws" : "draws nothing") << ", OSL does not";
      continue;
    }
    if (!s) continue;
    ++drawn;
    const Vec3 i_osl{2.0 * d[0] - 1.0, 2.0 * d[1] - 1.0, 2.0 * d[2] - 1.0};
    const double dist = length(i_osl - s->i);
    const double bound = std::max(1e-4, 2.0 * sample_sensitivity(model, o, u1, u2));
    if (dist > 1e-4) ++beyond;
    EXPECT_LE(dist, bound) << "case " << k << ": OSL " << str(i_osl) << ", C++ " << str(s->i) << "; o " << str(o) << ", u " << u1 << " " << u2;
    worst_dir = std::max(worst_dir, dist);
    // The pdf OSL returns with its sample is the library's pdf of that direction (the density is
    // piecewise smooth in theta_h: compared at the OSL direction, not the C++ one).
    const double pdf = model.pdf(o, i_osl);
    const double moved = 2.0 * input_sensitivity(o, i_osl, [&](const Vec3& a, const Vec3& b) { return model.pdf(a, b); });
    EXPECT_TRUE(close(p[0], pdf, 1e-6 + moved)) << "sample pdf, case " << k << ": OSL " << p[0] << ", C++ " << pdf;
    if (pdf > 0.0) worst_pdf = std::max(worst_pdf, std::abs(p[0] - pdf) / pdf);
  }
  EXPECT_GT(drawn, kGrid * kGrid / 2);
  // 99% within 1e-4; the rest where the map is steep, within twice what 4 float ulps of an input move it.
  // Stretched, the view the tables see is itself computed in float (rotated, scaled, normalized): 98%.
  EXPECT_LE(beyond, drawn / (stretched() ? 50 : 100));
  std::cout << GetParam() << ": sample, " << drawn << " directions drawn, " << beyond << " farther apart than 1e-4 (worst "
            << worst_dir << "), worst pdf relative difference " << worst_pdf << "\n";
}

INSTANTIATE_TEST_SUITE_P(Materials, OslModel,
                         ::testing::Values("gold-ggx-0.15", "silver-ggx-0.60", "copper-beckmann-0.30", "blue-clearcoat-paint",
                                           "minnaert-ggx-0.20", "masking/silver-ggx-0.60", "gold-ggx-0.15+stretch",
                                           "blue-clearcoat-paint+stretch"),
                         [](const ::testing::TestParamInfo<std::string>& param) {
                           std::string name = param.param;
                           std::replace_if(name.begin(), name.end(), [](char c) { return !std::isalnum(static_cast<unsigned char>(c)); }, '_');
                           return name;
                         });

}  // namespace
}  // namespace facetfit
