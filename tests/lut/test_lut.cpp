// LUT textures: bake -> write -> read gives back the same model; metadata round trip; bad files.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "core/error.h"
#include "fit/fit.h"
#include "io/input.h"
#include "io/utia.h"
#include "lut/lut.h"
#include "model/analytic.h"
#include "test_util.h"

namespace facetfit {
namespace {

using test::error_of;
using test::TempDir;

struct Baked {
  Fitter fitter{FitOptions::paper()};
  FitResult fit;
};

Baked fit_of(const Brdf& brdf, Smith smith = Smith::correlated) {
  FitOptions options = FitOptions::paper();
  options.smith = smith;
  Baked b{Fitter(options), {}};
  b.fit = b.fitter.fit(HalfDiffTable::tabulate(brdf));
  return b;
}

// The LUT of a fit, read back whole so that it can be written again with its attributes changed (the
// damaged-file tests).
class RewritableLut {
 public:
  RewritableLut(const std::string& path, const Baked& b) {
    write_lut(path, make_lut(b.fit, b.fitter.quadrature(), "x", "", 0.02, true));
    auto in = OIIO::ImageInput::open(path);
    spec = in->spec();
    pixels_.resize(std::size_t(spec.width) * std::size_t(spec.height) * std::size_t(spec.nchannels));
    EXPECT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels_.data()));
  }
  // The pixels as read, under `changed` (a copy of `spec` with attributes set or erased).
  void write(const std::string& path, const OIIO::ImageSpec& changed) const {
    auto out = OIIO::ImageOutput::create(path);
    EXPECT_TRUE(out->open(path, changed) && out->write_image(OIIO::TypeDesc::FLOAT, pixels_.data()) && out->close());
  }
  OIIO::ImageSpec spec;

 private:
  std::vector<float> pixels_;
};

TEST(Lut, RoundTripEvaluatesAsTheInMemoryModel) {
  const Baked b = fit_of(MicrofacetBrdf(Ndf::isotropic(NdfType::ggx, 0.25), Smith::separable,
                                        Fresnel::conductor({0.2, 0.9, 1.1}, {3.9, 2.4, 2.1})),
                         Smith::separable);
  const Lut lut = make_lut(b.fit, b.fitter.quadrature(), "builtin:test", "abc", 0.02, true);
  TempDir dir;
  write_lut(dir.file("m.exr"), lut);
  const Lut back = read_lut(dir.file("m.exr"));
  const TabulatedMicrofacet a = lut.model(), c = back.model();
  EXPECT_EQ(back.tables.smith, Smith::separable);
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int n = 0; n < 2000; ++n) {
    const Vec3 i = test::random_direction(rng), o = test::random_direction(rng);
    const Rgb fa = *a.eval(o, i), fc = *c.eval(o, i);
    for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(fc[ch], fa[ch], 1e-6 * std::max(fa[ch], 1e-6));
    const double pa = a.pdf(o, i), pc = c.pdf(o, i);
    EXPECT_NEAR(pc, pa, 1e-6 * std::max(pa, 1e-6));
  }
  // Same samples from the same numbers.
  for (int n = 0; n < 200; ++n) {
    const Vec3 o = test::random_direction(rng);
    const double u1 = u(rng), u2 = u(rng);
    const auto sa = a.sample(o, u1, u2), sc = c.sample(o, u1, u2);
    ASSERT_EQ(sa.has_value(), sc.has_value());
    if (sa) {
      EXPECT_NEAR(glm::length(sa->i - sc->i), 0.0, 1e-5);
    }
  }
}

// write_lut reads what it wrote as read_lut does before the file takes its name: a LUT its own reader
// refuses (here a GGX fit of alpha 0, as a failed fit would leave) is an error, and nothing is left.
TEST(Lut, AWriteItsReaderRefusesFailsAndLeavesNothing) {
  const Baked b = fit_of(MicrofacetBrdf(Ndf::isotropic(NdfType::ggx, 0.2), Smith::correlated, Fresnel::schlick(Rgb(0.9))));
  Lut lut = make_lut(b.fit, b.fitter.quadrature(), "x", "", 0.02, true);
  TempDir dir;
  write_lut(dir.file("good.exr"), lut);  // control: the same LUT with its fit intact
  EXPECT_NO_THROW(read_lut(dir.file("good.exr")));
  lut.meta.ggx.alpha = 0.0;
  const std::string error = error_of([&] { write_lut(dir.file("bad.exr"), lut); });
  EXPECT_EQ(error, dir.file("bad.exr") + ": cannot write: its reader refuses what was written: facetfit LUT without a valid facetfit:ggx_* fit");
  EXPECT_FALSE(std::filesystem::exists(dir.file("bad.exr")));
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), std::filesystem::directory_iterator()), 1);
}

TEST(Lut, MetadataRoundTrip) {
  const Baked b = fit_of(MicrofacetBrdf(Ndf::isotropic(NdfType::beckmann, 0.3), Smith::correlated, Fresnel::schlick(Rgb(0.9, 0.6, 0.3))));
  const Lut lut = make_lut(b.fit, b.fitter.quadrature(), "/data/copper.binary", std::string(64, 'f'), 0.02, true);
  TempDir dir;
  write_lut(dir.file("copper.exr"), lut);
  const LutMetadata m = read_lut(dir.file("copper.exr")).meta;
  EXPECT_EQ(m.format_version, kLutClosuresVersion);
  EXPECT_EQ(m.facetfit_version, FACETFIT_VERSION);
  EXPECT_EQ(m.source, "/data/copper.binary");
  EXPECT_EQ(m.source_sha256, std::string(64, 'f'));
  EXPECT_EQ(m.resolution, 90);
  EXPECT_EQ(m.smith, Smith::correlated);
  EXPECT_EQ(m.iterations, b.fit.extraction.iterations);
  EXPECT_FLOAT_EQ(float(m.alpha_beckmann), float(b.fit.alpha_beckmann));
  EXPECT_FLOAT_EQ(float(m.alpha_ggx), float(b.fit.alpha_ggx));
  EXPECT_FLOAT_EQ(float(m.f0.g), float(b.fit.f0.g));
  EXPECT_FLOAT_EQ(float(m.f82.b), float(b.fit.f82.b));
  EXPECT_FLOAT_EQ(float(m.ndf_error_ggx), float(lut.meta.ndf_error_ggx));
  // A Beckmann material: its Beckmann fit is within tolerance, its GGX fit is not.
  EXPECT_LT(m.ndf_error_beckmann, 0.002);
  EXPECT_GT(m.ndf_error_ggx, 0.05);
  EXPECT_EQ(m.representation, Representation::beckmann);
  EXPECT_TRUE(m.sampling);
  // The closures come back to float precision.
  const Closures &c = m.closures, &want = b.fit.closures.closures;
  ASSERT_EQ(c.lobes.size(), want.lobes.size());
  ASSERT_FALSE(c.empty());
  EXPECT_FLOAT_EQ(float(c.coat.alpha), float(want.coat.alpha));
  for (std::size_t k = 0; k < c.lobes.size(); ++k) {
    EXPECT_EQ(c.lobes[k].type, want.lobes[k].type);
    EXPECT_EQ(c.lobes[k].fresnel, want.lobes[k].fresnel);
    EXPECT_FLOAT_EQ(float(c.lobes[k].alpha_x), float(want.lobes[k].alpha_x));
    EXPECT_FLOAT_EQ(float(c.lobes[k].weight), float(want.lobes[k].weight));
    EXPECT_FLOAT_EQ(float(c.lobes[k].exponent), float(want.lobes[k].exponent));
    for (int e = 0; e < 3; ++e) {
      EXPECT_FLOAT_EQ(float(c.lobes[k].f0[e]), float(want.lobes[k].f0[e]));
      EXPECT_FLOAT_EQ(float(c.lobes[k].f82[e]), float(want.lobes[k].f82[e]));
      EXPECT_FLOAT_EQ(float(c.lobes[k].f90[e]), float(want.lobes[k].f90[e]));
    }
  }
}

// Closure lobes that follow the view make the LUT version 6, their exponents read back to float precision; a
// version 6 LUT without an exponent, or with one outside [0, 4], is refused with one line naming it.
TEST(Lut, ViewExponentsMakeVersionSix) {
  Baked b = fit_of(MicrofacetBrdf(Ndf::isotropic(NdfType::ggx, 0.2), Smith::correlated, Fresnel::schlick(Rgb(0.9, 0.6, 0.3))));
  ASSERT_EQ(b.fit.closures.closures.lobes.size(), 1u);
  b.fit.closures.closures.lobes[0].view_exponent = 1.25;
  TempDir dir;
  const RewritableLut original(dir.file("v.exr"), b);
  const Lut lut = read_lut(dir.file("v.exr"));
  EXPECT_EQ(lut.meta.format_version, kLutViewLobesVersion);
  EXPECT_FLOAT_EQ(float(lut.meta.closures.lobes[0].view_exponent), 1.25f);
  for (const float bad : {-0.5f, 4.5f, std::nanf("")}) {
    OIIO::ImageSpec spec = original.spec;
    spec.attribute("facetfit:closures_lobe0_view_exponent", bad);
    original.write(dir.file("bad.exr"), spec);
    const std::string e = error_of([&] { read_lut(dir.file("bad.exr")); });
    EXPECT_NE(e.find("bad.exr: facetfit:closures_lobe0_view_exponent is "), std::string::npos) << bad << ": " << e;
    EXPECT_NE(e.find(": must be in [0, 4]"), std::string::npos) << bad << ": " << e;
  }
  OIIO::ImageSpec spec = original.spec;
  spec.erase_attribute("facetfit:closures_lobe0_view_exponent");
  original.write(dir.file("bad.exr"), spec);
  EXPECT_NE(error_of([&] { read_lut(dir.file("bad.exr")); }).find("facetfit:closures_lobe0_view_exponent is missing"), std::string::npos);
  // The control: the same LUT with the exponent 0 is version 5's.
  b.fit.closures.closures.lobes[0].view_exponent = 0.0;
  const RewritableLut along(dir.file("t.exr"), b);
  EXPECT_EQ(read_lut(dir.file("t.exr")).meta.format_version, kLutClosuresVersion);
}

// Version 5's closures: each attribute is checked on reading, and a LUT without them (versions 1 to 4)
// gives its recommended family's fit as one lobe, what the material shader rendered of it.
TEST(Lut, ClosuresAreValidatedAndOlderLutsGetOneLobe) {
  const Baked b = fit_of(MicrofacetBrdf(Ndf::isotropic(NdfType::ggx, 0.2), Smith::correlated, Fresnel::schlick(Rgb(0.9, 0.6, 0.3))));
  TempDir dir;
  const RewritableLut original(dir.file("g.exr"), b);
  const auto damaged = [&](const char* name, float value, const std::string& expected) {
    OIIO::ImageSpec spec = original.spec;
    if (std::isinf(value))
      spec.erase_attribute(name);
    else if (std::string(name).find("code") != std::string::npos || std::string(name).find("lobes") != std::string::npos)
      spec.attribute(name, int(value));
    else
      spec.attribute(name, value);
    original.write(dir.file("bad.exr"), spec);
    const std::string e = error_of([&] { read_lut(dir.file("bad.exr")); });
    EXPECT_NE(e.find("bad.exr: facetfit:" + expected), std::string::npos) << name << " " << value << ": " << e;
  };
  const float kAbsent = std::numeric_limits<float>::infinity();
  damaged("facetfit:closures_lobes", 0, "closures_lobes is 0: must be 1 to 3");
  damaged("facetfit:closures_lobes", 4, "closures_lobes is 4");
  damaged("facetfit:closures_lobes", kAbsent, "closures_lobes is -1");
  damaged("facetfit:closures_lobe0_alpha_x", std::nanf(""), "closures_lobe0_alpha_x is missing or not a number: must be in [0.0001, 10]");
  damaged("facetfit:closures_lobe0_alpha_y", 0.0f, "closures_lobe0_alpha_y is 0: must be in [0.0001, 10]");
  damaged("facetfit:closures_lobe0_weight", -1.0f, "closures_lobe0_weight is -1: must be in [0, 1]");
  damaged("facetfit:closures_lobe0_weight", 900.0f, "closures_lobe0_weight is 900: must be in [0, 1]");  // pixels of 3.4e6
  damaged("facetfit:closures_lobe0_family_code", 3, "closures_lobe0_family_code is missing");
  damaged("facetfit:closures_lobe0_fresnel_code", 0, "closures_lobe0_fresnel_code is missing");
  damaged("facetfit:closures_lobe0_exponent", kAbsent, "closures_lobe0_exponent is missing");
  damaged("facetfit:closures_coat_f0", 2.0f, "closures_coat_f0 is 2: must be in [0, 1]");
  damaged("facetfit:closures_body", kAbsent, "closures_body is missing");

  FitResult old = b.fit;
  old.closures = {};
  write_lut(dir.file("old.exr"), make_lut(old, b.fitter.quadrature(), "x", "", 0.02, true));
  const Lut lut = read_lut(dir.file("old.exr"));
  EXPECT_EQ(lut.meta.format_version, kLutFormatVersion);
  const Closures c = lut.closures();
  ASSERT_EQ(c.lobes.size(), 1u);
  EXPECT_EQ(c.lobes[0].type, NdfType::ggx);
  EXPECT_FLOAT_EQ(float(c.lobes[0].alpha_x), float(lut.meta.ggx.alpha));
  EXPECT_EQ(c.lobes[0].weight, 1.0);
  EXPECT_EQ(c.lobes[0].fresnel, ClosureLobe::Fresnel::f82_tint);
}

// A LUT in another working space must carry a usable matrix from lin_rec709: anything else is one line
// naming the file and the attribute, never colours multiplied by garbage.
TEST(Lut, AWorkingSpaceWithoutAUsableMatrixIsRefused) {
  TempDir dir;
  const RewritableLut original(dir.file("g.exr"), fit_of(MicrofacetBrdf(Ndf::isotropic(NdfType::ggx, 0.2), Smith::correlated,
                                                                         Fresnel::schlick(Rgb(0.9, 0.6, 0.3)))));
  const auto with_matrix = [&](const std::string& file, const char* matrix) {
    OIIO::ImageSpec spec = original.spec;
    spec.attribute("facetfit:colorspace", "ACEScg");
    if (matrix) spec.attribute("facetfit:colorspace_matrix", matrix);
    original.write(dir.file(file), spec);
    return dir.file(file);
  };
  const char* kAcesCg = "0.61 0.34 0.05 0.07 0.92 0.01 0.02 0.11 0.87";
  const Lut good = read_lut(with_matrix("good.exr", kAcesCg));
  EXPECT_EQ(good.meta.colorspace, "ACEScg");
  EXPECT_NEAR(good.meta.from_rec709[1][0], 0.34, 1e-12);  // column 1, row 0: the text is row by row
  for (const char* bad : {static_cast<const char*>(nullptr), "", "0.61 0.34 0.05 0.07 0.92 0.01 0.02 0.11",
                          "0.61 0.34 0.05 0.07 0.92 0.01 0.02 0.11 0.87 1", "0.61 0.34 0.05 0.07 nan 0.01 0.02 0.11 0.87",
                          "1 2 3 2 4 6 0 0 1", "1e30 0 0 0 1 0 0 0 1", "1 0 0 0 1 0 0 0 inf", "one two three"}) {
    const std::string e = error_of([&] { read_lut(with_matrix("bad.exr", bad)); });
    EXPECT_NE(e.find("bad.exr: facetfit:colorspace_matrix is missing or not nine numbers"), std::string::npos)
        << (bad ? bad : "(absent)") << ": " << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
  // Invertible but not between RGB spaces: -I takes white to a negative colour (issue 61: negative pixels).
  EXPECT_NE(error_of([&] { read_lut(with_matrix("bad.exr", "-1 0 0 0 -1 0 0 0 -1")); }).find("takes white to a colour that is not positive"),
            std::string::npos);
}

TEST(Lut, ToleranceChoosesTheRepresentation) {
  const Baked two_lobes = fit_of(SumBrdf({std::make_shared<MicrofacetBrdf>(Ndf::isotropic(NdfType::ggx, 0.05), Smith::correlated, Fresnel::one()),
                                          std::make_shared<MicrofacetBrdf>(Ndf::isotropic(NdfType::ggx, 0.5), Smith::correlated, Fresnel::one())}));
  EXPECT_EQ(make_lut(two_lobes.fit, two_lobes.fitter.quadrature(), "x", "", 0.02, true).meta.representation, Representation::tabulated);
  EXPECT_EQ(make_lut(two_lobes.fit, two_lobes.fitter.quadrature(), "x", "", 10.0, true).meta.representation, Representation::ggx);
  const Baked ggx = fit_of(MicrofacetBrdf(Ndf::isotropic(NdfType::ggx, 0.2), Smith::correlated, Fresnel::one()));
  EXPECT_EQ(make_lut(ggx.fit, ggx.fitter.quadrature(), "x", "", 0.02, true).meta.representation, Representation::ggx);
  // The largest tolerance --tolerance takes, 1e30, is written as the float nearest it (just above 1e30) and read
  // back: the reader's limits are the floats the writer stores.
  TempDir dir;
  write_lut(dir.file("t.exr"), make_lut(ggx.fit, ggx.fitter.quadrature(), "x", "", 1e30, true));
  EXPECT_FLOAT_EQ(float(read_lut(dir.file("t.exr")).meta.tolerance), 1e30f);
}

TEST(Lut, EveryMeasurementThatFitsBakesWhatItsReaderAccepts) {
  // Valid measurements at the edges: a GGX of alpha 10 (moment alpha 10.15), a near mirror, a Lambert
  // table of albedo 2e4, reflection only at theta_h >= 88 degrees. Each either fails in the fit with its
  // problem or bakes a LUT its reader reads, what lies outside a stored range clamped with a warning
  // naming it (visit_limits: one table for the writer and the reader).
  std::vector<std::pair<std::string, HalfDiffTable>> tables;
  const auto ggx = [](double alpha) { return MicrofacetBrdf(Ndf::isotropic(NdfType::ggx, alpha), Smith::correlated, Fresnel::schlick(Rgb(0.9))); };
  tables.emplace_back("ggx-10", HalfDiffTable::tabulate(ggx(10.0)));
  tables.emplace_back("near-mirror", HalfDiffTable::tabulate(ggx(0.002)));
  tables.emplace_back("bright-lambert", HalfDiffTable::tabulate(LambertBrdf(Rgb(2e4))));
  HalfDiffTable grazing = HalfDiffTable::tabulate(ggx(0.5));
  for (int i = 0; i < HalfDiffTable::kThetaH - 1; ++i)
    for (int j = 0; j < HalfDiffTable::kThetaD; ++j)
      for (int k = 0; k < HalfDiffTable::kPhiD; ++k)
        for (int c = 0; c < 3; ++c) grazing.channel(c)[HalfDiffTable::index(i, j, k)] = 0.0f;
  tables.emplace_back("grazing-only", std::move(grazing));
  TempDir dir;
  int baked = 0;
  bool clamped_alpha = false;
  for (const auto& [name, table] : tables) {
    for (const FitOptions& options : {FitOptions::paper(), FitOptions{}}) {
      const Fitter fitter(options);
      const FitResult fit = fitter.fit(table);
      if (!fit.ok()) {
        EXPECT_FALSE(fit.problem.empty()) << name;
        continue;
      }
      const Lut lut = make_lut(fit, fitter.quadrature(), name, "", 0.02, true);
      const std::string path = dir.file(name + ".exr");
      ASSERT_NO_THROW(write_lut(path, lut)) << name << ": " << error_of([&] { write_lut(path, lut); });
      const Lut back = read_lut(path);
      ++baked;
      for (const std::string& w : back.meta.warnings) clamped_alpha |= name == "ggx-10" && w.rfind("facetfit:alpha_ggx was 10.", 0) == 0;
    }
  }
  EXPECT_GE(baked, 6);
  EXPECT_TRUE(clamped_alpha) << "the GGX of alpha 10 did not clamp its moment alpha";
}

// A format version this facetfit does not read is named as such, a missing one as missing (issue 61: -1 was
// reported as "no format_version attribute").
// The property behind the test above, on random valid measurements (seeded, so that CI draws the same): a
// GGX or Beckmann lobe of alpha log-uniform in [0.002, 10] with a random RGB Schlick Fresnel over a random
// Lambert body of albedo log-uniform in [1e-3, 2e4] (very bright tables included), some with only the pairs at
// theta_h past a random angle in [60, 89] degrees kept. Each either fails in the fit with its problem or bakes
// a LUT that its reader reads back.
TEST(Lut, RandomValidMeasurementsBakeOrFailInTheFit) {
  std::mt19937_64 rng(61);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const auto log_uniform = [&](double lo, double hi) { return lo * std::pow(hi / lo, u(rng)); };
  TempDir dir;
  int baked = 0, failed = 0;
  for (int draw = 0; draw < 8; ++draw) {
    const NdfType type = u(rng) < 0.5 ? NdfType::ggx : NdfType::beckmann;
    const double alpha = log_uniform(0.002, 10.0);
    const auto lobe = std::make_shared<MicrofacetBrdf>(Ndf::isotropic(type, alpha), Smith::correlated, Fresnel::schlick(Rgb(u(rng), u(rng), u(rng))));
    const Rgb albedo = log_uniform(1e-3, 2e4) * Rgb(u(rng), u(rng), u(rng));
    HalfDiffTable table = HalfDiffTable::tabulate(SumBrdf({std::make_shared<LambertBrdf>(albedo), lobe}));
    if (draw % 3 == 2) {  // only theta_h past a random angle: bins below it missing
      const int first = int(HalfDiffTable::kThetaH * std::sqrt(log_uniform(60.0, 89.0) / 90.0));
      for (int i = 0; i < first; ++i)
        for (int j = 0; j < HalfDiffTable::kThetaD; ++j)
          for (int k = 0; k < HalfDiffTable::kPhiD; ++k) table.set_missing(i, j, k);
    }
    const std::string what = std::string(to_string(type)) + " alpha " + std::to_string(alpha) + ", albedo " + std::to_string(albedo.r);
    const Fitter fitter{FitOptions{}};
    const FitResult fit = fitter.fit(table);
    if (!fit.ok()) {
      EXPECT_FALSE(fit.problem.empty()) << what;
      ++failed;
      continue;
    }
    const std::string path = dir.file("r" + std::to_string(draw) + ".exr");
    ASSERT_NO_THROW(write_lut(path, make_lut(fit, fitter.quadrature(), "x", "", 0.02, true))) << what;
    EXPECT_NO_THROW(read_lut(path)) << what;
    ++baked;
  }
  std::printf("[ random ] %d baked, %d failed in the fit\n", baked, failed);
  EXPECT_GE(baked, 4);
}

TEST(Lut, AFormatVersionIsNamedAsWritten) {
  const Baked b = fit_of(MicrofacetBrdf(Ndf::isotropic(NdfType::ggx, 0.2), Smith::correlated, Fresnel::schlick(Rgb(0.9))));
  TempDir dir;
  const RewritableLut original(dir.file("g.exr"), b);
  for (const int version : {-1, 0, 99}) {
    OIIO::ImageSpec spec = original.spec;
    spec.attribute("facetfit:format_version", version);
    original.write(dir.file("bad.exr"), spec);
    EXPECT_NE(error_of([&] { read_lut(dir.file("bad.exr")); }).find("LUT format version " + std::to_string(version) + "; this facetfit reads versions 1 to"),
              std::string::npos) << version;
  }
  OIIO::ImageSpec spec = original.spec;
  spec.erase_attribute("facetfit:format_version");
  original.write(dir.file("bad.exr"), spec);
  EXPECT_NE(error_of([&] { read_lut(dir.file("bad.exr")); }).find("no facetfit:format_version attribute"), std::string::npos);
}

TEST(Lut, ADarkChannelOfNegativeNoiseBakesAndReadsBack) {
  // Blue is noise around a slightly negative mean (RGL's dark channels): the paper's Fresnel ratio
  // would be negative there; the curve is clamped at zero and the LUT reads back (a negative f0 is
  // refused on reading).
  HalfDiffTable table = HalfDiffTable::tabulate(MicrofacetBrdf(Ndf::isotropic(NdfType::ggx, 0.2), Smith::correlated, Fresnel::one()));
  std::mt19937 rng(7);
  std::normal_distribution<float> noise(-0.002f, 0.01f);
  float* blue = table.channel(2);
  for (std::size_t n = 0; n < HalfDiffTable::kBins; ++n) blue[n] = noise(rng);
  for (const FitOptions& options : {FitOptions::paper(), FitOptions{}}) {
    const FitResult fit = Fitter(options).fit(table);
    ASSERT_TRUE(fit.ok()) << fit.problem;
    for (int j = 0; j < FresnelCurve::kSize; ++j) EXPECT_GE(fit.fresnel().value[std::size_t(j)].b, 0.0) << j;
    TempDir dir;
    write_lut(dir.file("dark.exr"), make_lut(fit, Fitter(options).quadrature(), "x", "", 0.02, false));
    const Lut back = read_lut(dir.file("dark.exr"));
    EXPECT_GE(back.meta.f0.b, 0.0);
  }
}

TEST(Lut, EvalOnlyLeavesOutTheSamplingTables) {
  const Baked b = fit_of(MicrofacetBrdf(Ndf::isotropic(NdfType::ggx, 0.2), Smith::correlated, Fresnel::one()));
  TempDir dir;
  write_lut(dir.file("full.exr"), make_lut(b.fit, b.fitter.quadrature(), "x", "", 0.02, true));
  write_lut(dir.file("eval.exr"), make_lut(b.fit, b.fitter.quadrature(), "x", "", 0.02, false));
  const Lut full = read_lut(dir.file("full.exr")), eval = read_lut(dir.file("eval.exr"));
  EXPECT_TRUE(full.model().can_sample());
  EXPECT_FALSE(eval.model().can_sample());
  EXPECT_LT(std::filesystem::file_size(dir.file("eval.exr")), std::filesystem::file_size(dir.file("full.exr")));
  const Vec3 i = spherical_direction(0.3, 0.0), o = spherical_direction(0.5, 2.0);
  EXPECT_EQ(full.model().eval(o, i)->r, eval.model().eval(o, i)->r);
}

// An anisotropic input (a UTIA file) bakes version 3: the 2D extraction's tables come back to float
// precision and evaluate as in memory; the same material's isotropic LUT stays version 2.
TEST(Lut, AnisotropicLobeRoundTrip) {
  TempDir dir;
  UtiaBrdf::tabulate(MicrofacetBrdf(Ndf{NdfType::ggx, 0.5, 0.25}, Smith::correlated, Fresnel::schlick(Rgb(0.9, 0.6, 0.3))))
      .write(dir.file("a.bin"));
  const Fitter fitter{FitOptions::paper()};
  FitResult fit = fitter.fit(load_table(dir.file("a.bin")));
  ASSERT_TRUE(fit.ok() && fit.anisotropic) << fit.problem;
  // With its closures, version 5 with the same rows: its closure is the anisotropic GGX fit.
  write_lut(dir.file("a5.exr"), make_lut(fit, fitter.quadrature(), "a.bin", "", 0.02, true));
  const Lut five = read_lut(dir.file("a5.exr"));
  EXPECT_EQ(five.meta.format_version, kLutClosuresVersion);
  ASSERT_TRUE(five.anisotropic);
  ASSERT_EQ(five.meta.closures.lobes.size(), 1u);
  EXPECT_NEAR(five.meta.closures.lobes[0].alpha_x, fit.anisotropic->ggx.alpha.alpha_x, 1e-6);
  EXPECT_NEAR(five.meta.closures.lobes[0].alpha_y, fit.anisotropic->ggx.alpha.alpha_y, 1e-6);
  EXPECT_NEAR(five.meta.closures.lobes[0].angle, fit.anisotropic->ggx.alpha.angle, 1e-6);
  // Without closures (what earlier facetfits wrote), the versions below.
  fit.closures = {};
  const Lut baked = make_lut(fit, fitter.quadrature(), "a.bin", "", 0.02, true);
  write_lut(dir.file("a.exr"), baked);
  const Lut lut = read_lut(dir.file("a.exr"));
  EXPECT_EQ(lut.meta.format_version, kLutAnisotropicVersion);
  ASSERT_TRUE(lut.anisotropic);
  EXPECT_EQ(lut.anisotropic->phi_count, 48);
  const AnisotropicParametricFit &g = lut.meta.anisotropic_ggx, &want = fit.anisotropic->ggx;
  EXPECT_NEAR(g.alpha.alpha_x, want.alpha.alpha_x, 1e-6);
  EXPECT_NEAR(g.alpha.alpha_y, want.alpha.alpha_y, 1e-6);
  EXPECT_NEAR(g.alpha.angle, want.alpha.angle, 1e-6);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(g.body[c], want.body[c], 1e-6);
    EXPECT_NEAR(g.f0[c], want.f0[c], 1e-6);
    EXPECT_NEAR(g.f82[c], want.f82[c], 1e-6);
  }
  const TabulatedAnisotropic in_memory(*baked.anisotropic), read_back(*lut.anisotropic);
  for (const auto& [o, i] : {std::pair{spherical_direction(0.3, 0.2), spherical_direction(0.5, 3.0)},
                            {spherical_direction(1.1, 1.0), spherical_direction(0.9, 4.5)}}) {
    const Rgb a = *in_memory.eval(o, i), b = *read_back.eval(o, i);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(b[c], a[c], 1e-5 * std::max(1.0, a[c]));
    EXPECT_NEAR(read_back.pdf(o, i), in_memory.pdf(o, i), 1e-5 * std::max(1.0, in_memory.pdf(o, i)));
  }
  // With a Minnaert body too, version 4, which announces its anisotropic rows.
  FitResult minnaert = fit;
  minnaert.lobe.body_exponent = 1.5;
  write_lut(dir.file("k.exr"), make_lut(minnaert, fitter.quadrature(), "a.bin", "", 0.02, true));
  const Lut with_k = read_lut(dir.file("k.exr"));
  EXPECT_EQ(with_k.meta.format_version, kLutBodyExponentVersion);
  EXPECT_NEAR(with_k.tables.body_exponent, 1.5, 1e-6);
  ASSERT_TRUE(with_k.anisotropic);
  EXPECT_EQ(with_k.anisotropic->ndf, lut.anisotropic->ndf);
  EXPECT_NEAR(with_k.meta.anisotropic_ggx.alpha.alpha_x, want.alpha.alpha_x, 1e-6);
  // Without the anisotropic fit, version 2 as before.
  FitResult isotropic = fit;
  isotropic.anisotropic.reset();
  write_lut(dir.file("iso.exr"), make_lut(isotropic, fitter.quadrature(), "a.bin", "", 0.02, true));
  EXPECT_EQ(read_lut(dir.file("iso.exr")).meta.format_version, kLutFormatVersion);
  // A damaged azimuth count is refused before anything is sized from it.
  {
    auto in = OIIO::ImageInput::open(dir.file("a.exr"));
    OIIO::ImageSpec spec = in->spec();
    std::vector<float> px(std::size_t(spec.width) * std::size_t(spec.height) * std::size_t(spec.nchannels));
    ASSERT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, px.data()));
    spec.attribute("facetfit:anisotropic_phi_count", 1 << 30);
    auto out = OIIO::ImageOutput::create(dir.file("bad.exr"));
    ASSERT_TRUE(out->open(dir.file("bad.exr"), spec) && out->write_image(OIIO::TypeDesc::FLOAT, px.data()) && out->close());
  }
  EXPECT_NE(error_of([&] { read_lut(dir.file("bad.exr")); }).find("bad.exr: facetfit:anisotropic_resolution or facetfit:anisotropic_phi_count"),
            std::string::npos);
  // A resolution in range but not the one the rows were written on: refused, not read as another grid.
  {
    auto in = OIIO::ImageInput::open(dir.file("a.exr"));
    OIIO::ImageSpec spec = in->spec();
    std::vector<float> px(std::size_t(spec.width) * std::size_t(spec.height) * std::size_t(spec.nchannels));
    ASSERT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, px.data()));
    spec.attribute("facetfit:anisotropic_resolution", 10);
    auto out = OIIO::ImageOutput::create(dir.file("grid.exr"));
    ASSERT_TRUE(out->open(dir.file("grid.exr"), spec) && out->write_image(OIIO::TypeDesc::FLOAT, px.data()) && out->close());
  }
  EXPECT_NE(error_of([&] { read_lut(dir.file("grid.exr")); }).find("grid.exr: facetfit:anisotropic_resolution is 10, not min(facetfit:resolution, 90)"),
            std::string::npos);
}

TEST(Lut, ABodyExponentMakesVersionFour) {
  // A Minnaert body (model/body.h) is carried by version 4 only: a Lambertian body's LUT stays version 2,
  // which earlier readers take; they refuse version 4 rather than render its body as Lambert's.
  TempDir dir;
  Baked b = fit_of(MicrofacetBrdf(Ndf::isotropic(NdfType::ggx, 0.2), Smith::correlated, Fresnel::one()));
  b.fit.closures = {};  // without them, as earlier facetfits wrote (with them, version 5)
  b.fit.lobe.body = Rgb(0.4, 0.3, 0.2);
  b.fit.lobe.body_exponent = 1.6;
  write_lut(dir.file("k.exr"), make_lut(b.fit, b.fitter.quadrature(), "x", "", 0.02, true));
  const Lut lut = read_lut(dir.file("k.exr"));
  EXPECT_EQ(lut.meta.format_version, kLutBodyExponentVersion);
  EXPECT_FALSE(lut.anisotropic);
  EXPECT_NEAR(lut.tables.body_exponent, 1.6, 1e-6);
  const TabulatedMicrofacet in_memory(b.fit.lobe.tables(b.fit.smith)), read_back = lut.model();
  const Vec3 o = spherical_direction(1.2, 0.0), i = spherical_direction(1.3, 2.0);
  const Rgb a = *in_memory.eval(o, i), c = *read_back.eval(o, i);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(c[k], a[k], 1e-5 * a[k]);
  // The body's part: 0.4 / pi ((k + 1) / 2 (cos_o cos_i)^(k - 1) - 1) more than a Lambertian body's.
  MicrofacetTables lambert = b.fit.lobe.tables(b.fit.smith);
  lambert.body_exponent = 1.0;
  const double body_part = a.r - TabulatedMicrofacet(lambert).eval(o, i)->r;
  EXPECT_NEAR(body_part, 0.4 / kPi * (1.3 * std::pow(std::cos(1.2) * std::cos(1.3), 0.6) - 1.0), 1e-9);
  // An exponent outside [1, 3], or none, is refused naming the attribute.
  auto in = OIIO::ImageInput::open(dir.file("k.exr"));
  OIIO::ImageSpec spec = in->spec();
  std::vector<float> px(std::size_t(spec.width) * std::size_t(spec.height) * std::size_t(spec.nchannels));
  ASSERT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, px.data()));
  for (const float value : {0.5f, std::nanf(""), 3.5f, -1.0f}) {
    if (value == -1.0f)  // none at all
      spec.erase_attribute("facetfit:body_exponent");
    else
      spec.attribute("facetfit:body_exponent", value);
    auto out = OIIO::ImageOutput::create(dir.file("bad.exr"));
    ASSERT_TRUE(out->open(dir.file("bad.exr"), spec) && out->write_image(OIIO::TypeDesc::FLOAT, px.data()) && out->close());
    const std::string e = error_of([&] { read_lut(dir.file("bad.exr")); });
    EXPECT_NE(e.find("bad.exr: facetfit:body_exponent is missing or outside [1, 3]"), std::string::npos) << value << ": " << e;
  }
  b.fit.lobe.body_exponent = 1.0;
  write_lut(dir.file("one.exr"), make_lut(b.fit, b.fitter.quadrature(), "x", "", 0.02, true));
  EXPECT_EQ(read_lut(dir.file("one.exr")).meta.format_version, kLutFormatVersion);
}

// LUTs are written and read through OpenEXR itself (io/image_file.h); OpenImageIO, an independent reader
// and writer, must see the same file: the same pixels and attributes of the same types, and a LUT it
// writes back must read as the same LUT.
TEST(Lut, OpenImageIoReadsAndWritesTheSameFile) {
  TempDir dir;
  const Baked b = fit_of(MicrofacetBrdf(Ndf::isotropic(NdfType::ggx, 0.2), Smith::correlated, Fresnel::schlick(Rgb(0.9, 0.6, 0.3))));
  Lut lut = make_lut(b.fit, b.fitter.quadrature(), "x", "", 0.02, true);
  lut.meta.warnings = {"first warning", "second warning"};
  write_lut(dir.file("ours.exr"), lut);
  const Lut ours = read_lut(dir.file("ours.exr"));

  auto in = OIIO::ImageInput::open(dir.file("ours.exr"));
  ASSERT_TRUE(in) << OIIO::geterror();
  const OIIO::ImageSpec spec = in->spec();
  EXPECT_EQ(spec.channelnames, (std::vector<std::string>{"R", "G", "B"}));
  EXPECT_EQ(spec.get_int_attribute("facetfit:format_version", -1), ours.meta.format_version);
  EXPECT_EQ(spec.get_string_attribute("facetfit:smith"), "correlated");
  EXPECT_EQ(spec.get_string_attribute("facetfit:warnings"), "first warning\nsecond warning");
  EXPECT_FLOAT_EQ(spec.get_float_attribute("facetfit:ggx_alpha"), float(ours.meta.ggx.alpha));
  const OIIO::ParamValue* f0 = spec.find_attribute("facetfit:f0");
  ASSERT_TRUE(f0 && f0->type().basetype == OIIO::TypeDesc::FLOAT && f0->type().basevalues() == 3);
  for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(static_cast<const float*>(f0->data())[c], float(ours.meta.f0[c]));
  std::vector<float> px(std::size_t(spec.width) * std::size_t(spec.height) * std::size_t(spec.nchannels));
  ASSERT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, px.data()));
  EXPECT_FLOAT_EQ(px[0], float(ours.tables.ndf.ndf[0]));  // row 0, column 0: D at theta_h = 0

  auto out = OIIO::ImageOutput::create(dir.file("theirs.exr"));
  ASSERT_TRUE(out->open(dir.file("theirs.exr"), spec) && out->write_image(OIIO::TypeDesc::FLOAT, px.data()) && out->close());
  const Lut theirs = read_lut(dir.file("theirs.exr"));
  EXPECT_EQ(theirs.meta.warnings, ours.meta.warnings);
  EXPECT_EQ(theirs.meta.smith, ours.meta.smith);
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(theirs.meta.f0[c], ours.meta.f0[c]);
    EXPECT_EQ(theirs.meta.ggx.body[c], ours.meta.ggx.body[c]);
  }
  EXPECT_EQ(theirs.tables.ndf.ndf, ours.tables.ndf.ndf);
  EXPECT_EQ(theirs.tables.ndf.sigma, ours.tables.ndf.sigma);
  EXPECT_EQ(theirs.sampling.cdf, ours.sampling.cdf);
}

TEST(Lut, BadFilesGetOneClearLine) {
  TempDir dir;
  test::write_bytes(dir.file("garbage.exr"), "not an image at all");
  EXPECT_NE(error_of([&] { read_lut(dir.file("garbage.exr")); }).find("garbage.exr: "), std::string::npos);
  EXPECT_NE(error_of([&] { read_lut(dir.file("missing.exr")); }).find("missing.exr: "), std::string::npos);
  // A valid EXR that is not a LUT.
  {
    OIIO::ImageSpec spec(4, 4, 3, OIIO::TypeDesc::FLOAT);
    auto out = OIIO::ImageOutput::create(dir.file("plain.exr"));
    std::vector<float> px(48, 0.5f);
    ASSERT_TRUE(out->open(dir.file("plain.exr"), spec) && out->write_image(OIIO::TypeDesc::FLOAT, px.data()) && out->close());
  }
  EXPECT_NE(error_of([&] { read_lut(dir.file("plain.exr")); }).find("not a facetfit LUT"), std::string::npos);
  // A truncated LUT.
  const Baked b = fit_of(MicrofacetBrdf(Ndf::isotropic(NdfType::ggx, 0.2), Smith::correlated, Fresnel::one()));
  write_lut(dir.file("good.exr"), make_lut(b.fit, b.fitter.quadrature(), "x", "", 0.02, true));
  const std::string bytes = test::read_bytes(dir.file("good.exr"));
  test::write_bytes(dir.file("cut.exr"), bytes.substr(0, bytes.size() / 2));
  const std::string cut = error_of([&] { read_lut(dir.file("cut.exr")); });
  EXPECT_NE(cut.find("cut.exr: "), std::string::npos) << cut;
  EXPECT_EQ(cut.find('\n'), std::string::npos) << cut;
  // The integer code of the Smith model contradicting its name (OSL shaders read the code).
  {
    auto in = OIIO::ImageInput::open(dir.file("good.exr"));
    ASSERT_TRUE(in);
    OIIO::ImageSpec spec = in->spec();
    std::vector<float> px(std::size_t(spec.width) * std::size_t(spec.height) * std::size_t(spec.nchannels));
    ASSERT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, px.data()));
    EXPECT_EQ(spec.get_int_attribute("facetfit:smith_code", -1), 1);  // correlated
    spec.attribute("facetfit:smith_code", 0);
    auto out = OIIO::ImageOutput::create(dir.file("contradicts.exr"));
    ASSERT_TRUE(out->open(dir.file("contradicts.exr"), spec) && out->write_image(OIIO::TypeDesc::FLOAT, px.data()) && out->close());
  }
  EXPECT_NE(error_of([&] { read_lut(dir.file("contradicts.exr")); }).find("contradicts.exr: facetfit LUT whose smith_code"),
            std::string::npos);
  // Metadata numbers that are not finite or out of range are refused, naming the attribute (a LUT with
  // a NaN or negative alpha, f0 or tolerance used to render without complaint).
  const auto tampered = [&](const char* name, float value) {
    auto in = OIIO::ImageInput::open(dir.file("good.exr"));
    OIIO::ImageSpec spec = in->spec();
    std::vector<float> px(std::size_t(spec.width) * std::size_t(spec.height) * std::size_t(spec.nchannels));
    EXPECT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, px.data()));
    spec.attribute(std::string("facetfit:") + name, value);
    const std::string file = dir.file(std::string("tampered-") + name + ".exr");
    auto out = OIIO::ImageOutput::create(file);
    EXPECT_TRUE(out->open(file, spec) && out->write_image(OIIO::TypeDesc::FLOAT, px.data()) && out->close());
    return error_of([&] { read_lut(file); });
  };
  for (const auto& [name, value] : {std::pair{"alpha_ggx", std::nanf("")}, {"alpha_beckmann", -0.2f}, {"tolerance", -1.0f},
                                    {"coat_f0", 2.0f}, {"ggx_alpha", std::numeric_limits<float>::infinity()}, {"error", std::nanf("")}}) {
    const std::string e = tampered(name, value);
    EXPECT_NE(e.find(std::string("facetfit:") + name + " is "), std::string::npos) << name << ": " << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
  // Negative NDF entries (pixels scaled by -1, as an audit's oiiotool --mulc -1) are no lobe.
  {
    auto in = OIIO::ImageInput::open(dir.file("good.exr"));
    OIIO::ImageSpec spec = in->spec();
    std::vector<float> px(std::size_t(spec.width) * std::size_t(spec.height) * std::size_t(spec.nchannels));
    ASSERT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, px.data()));
    for (float& v : px) v = -v;
    auto out = OIIO::ImageOutput::create(dir.file("negative.exr"));
    ASSERT_TRUE(out->open(dir.file("negative.exr"), spec) && out->write_image(OIIO::TypeDesc::FLOAT, px.data()) && out->close());
  }
  EXPECT_NE(error_of([&] { read_lut(dir.file("negative.exr")); }).find("column 0: D must be >= 0 and sigma > 0"), std::string::npos);
  // A sampling row that is no CDF (falling, or not from 0 to 1): the samplers search it as running sums,
  // the SIMD one from a guide built on that order, and would disagree.
  for (const bool falls : {true, false}) {
    auto in = OIIO::ImageInput::open(dir.file("good.exr"));
    OIIO::ImageSpec spec = in->spec();
    std::vector<float> px(std::size_t(spec.width) * std::size_t(spec.height) * std::size_t(spec.nchannels));
    ASSERT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, px.data()));
    const auto at = [&](int row, int x) { return (std::size_t(row) * std::size_t(spec.width) + std::size_t(x)) * std::size_t(spec.nchannels); };
    const int row = LutLayout::kSamplingRow + 5;
    ASSERT_LT(px[at(row, 10)], px[at(row, 40)]);
    if (falls) {
      px[at(row, 11)] = px[at(row, 10)] * 0.5f;
    } else {  // running to 0.5
      for (int x = 0; x < spec.width; ++x) px[at(row, x)] *= 0.5f;
    }
    const std::string file = dir.file(falls ? "falling-cdf.exr" : "cdf-to-half.exr");
    auto out = OIIO::ImageOutput::create(file);
    ASSERT_TRUE(out->open(file, spec) && out->write_image(OIIO::TypeDesc::FLOAT, px.data()) && out->close());
    const std::string e = error_of([&] { read_lut(file); });
    EXPECT_NE(e.find(falls ? "row 8, column 11: the sampling CDF falls" : "row 8: the sampling CDF must run from 0 to 1"), std::string::npos) << e;
  }
  // A negative Fresnel reflectance (issue 47: accepted, it rendered negative pixels), and one of 3e38 (issue 61:
  // pixels of 2.5e38).
  for (const float bad : {-0.25f, 3e38f}) {
    {
      auto in = OIIO::ImageInput::open(dir.file("good.exr"));
      OIIO::ImageSpec spec = in->spec();
      std::vector<float> px(std::size_t(spec.width) * std::size_t(spec.height) * std::size_t(spec.nchannels));
      ASSERT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, px.data()));
      px[(std::size_t(LutLayout::kFresnelRow) * std::size_t(spec.width) + 7) * std::size_t(spec.nchannels) + 1] = bad;
      auto out = OIIO::ImageOutput::create(dir.file("bad-fresnel.exr"));
      ASSERT_TRUE(out->open(dir.file("bad-fresnel.exr"), spec) && out->write_image(OIIO::TypeDesc::FLOAT, px.data()) && out->close());
    }
    const std::string fresnel = error_of([&] { read_lut(dir.file("bad-fresnel.exr")); });
    EXPECT_NE(fresnel.find("row " + std::to_string(LutLayout::kFresnelRow) + ", column 7: the Fresnel reflectance must be in [0, 1000]"),
              std::string::npos)
        << bad << ": " << fresnel;
  }
}

}  // namespace
}  // namespace facetfit

namespace facetfit {
namespace {

// The bytes of `file` with the 32-bit size of header attribute `name` (after its name and type) set.
std::string with_attribute_size(std::string bytes, const std::string& name, std::int32_t size) {
  const std::size_t at = bytes.find(name + '\0');
  EXPECT_NE(at, std::string::npos) << name;
  const std::size_t type_end = bytes.find('\0', at + name.size() + 1);
  std::memcpy(&bytes[type_end + 1], &size, 4);
  return bytes;
}

// The bytes of `file` with the data window's xMax set (fuzz_env's finding: OpenEXR sizes buffers by it).
std::string wider(std::string bytes, std::int32_t x_max) {
  const std::size_t at = bytes.find(std::string("dataWindow") + '\0' + "box2i" + '\0');
  std::memcpy(&bytes[at + 11 + 6 + 4 + 8], &x_max, 4);
  return bytes;
}

TEST(Lut, HostileOpenExrHeadersAreRefusedBeforeOpenExrAllocates) {
  // fuzz_lut's findings: OpenEXR 3.1 allocates what a header claims (a string attribute of 1.6 GB in a
  // 6 KB file took 1.7 GB), and parses fixed-size values and channel lists by their own rules, so a header
  // whose stated sizes disagree is read differently by it. Each is one line now, before OpenEXR runs.
  const Baked b = fit_of(MicrofacetBrdf(Ndf::isotropic(NdfType::ggx, 0.2), Smith::correlated, Fresnel::schlick(Rgb(0.9))));
  TempDir dir;
  write_lut(dir.file("good.exr"), make_lut(b.fit, b.fitter.quadrature(), "builtin:test", "abc", 0.02, false));
  const std::string good = test::read_bytes(dir.file("good.exr"));
  const std::pair<std::string, std::string> cases[] = {
      {with_attribute_size(good, "facetfit:smith", 1677721610), "attribute 'facetfit:smith' claims 1677721610 bytes"},
      {with_attribute_size(good, "compression", 513), "attribute 'compression' of type compression has 513 bytes, not 1"},
      {with_attribute_size(good, "channels", 40), "attribute 'channels' of type chlist does not match its size"},
      {with_attribute_size(good, "dataWindow", -5), "attribute 'dataWindow' claims -5 bytes"},
      {wider(good, 8388623), "a 8388624 x 3 image; at most 65536 x 65536"},
  };
  for (const auto& [bytes, message] : cases) {
    test::write_bytes(dir.file("bad.exr"), bytes);
    const std::string e = error_of([&] { read_lut(dir.file("bad.exr")); });
    EXPECT_NE(e.find(dir.file("bad.exr") + ": OpenEXR header: " + message), std::string::npos) << e;
  }
  // A data window changed after writing implies an offset table of another length; OpenEXR would decode
  // the chunks as if they matched it, without an error (an audit's 512 x 256 map read as 65536 x 1).
  std::string taller = good;
  const std::int32_t y_max = 39;  // 40 rows: three chunks of 16 where the file has one
  std::memcpy(&taller[taller.find(std::string("dataWindow") + '\0' + "box2i" + '\0') + 11 + 6 + 4 + 12], &y_max, 4);
  test::write_bytes(dir.file("taller.exr"), taller);
  const std::string e = error_of([&] { read_lut(dir.file("taller.exr")); });
  EXPECT_NE(e.find(dir.file("taller.exr") + ": OpenEXR: chunk"), std::string::npos) << e;
  EXPECT_NO_THROW(read_lut(dir.file("good.exr")));
}

}  // namespace
}  // namespace facetfit
