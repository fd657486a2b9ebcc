// Parity with the RGL format's reference evaluation: Mitsuba 3's `measured` BSDF (PyPI wheel, scalar_rgb,
// in the venv of scripts/setup-mitsuba.sh) against facetfit's RglBsdf with view slices, on random
// direction pairs of every RGL material in the data folder and of anisotropic files written here, grazing pairs included.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>

#include "io/rgl.h"
#include "support/tensor_file.h"
#include "test_util.h"

namespace facetfit {
namespace {

namespace fs = std::filesystem;

std::string quoted(const std::string& s) { return "'" + s + "'"; }

// Uniform in cos(theta) up to 88 degrees, plus pairs near the horizon and near the mirror direction:
// (o: viewer side, i), written to `file` for scripts/mitsuba_eval.py.
std::vector<std::pair<Vec3, Vec3>> direction_pairs(const std::string& file) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<std::pair<Vec3, Vec3>> pairs;
  const auto direction = [&](double max_theta) {
    const double c = 1.0 - u(rng) * (1.0 - std::cos(max_theta));
    return spherical_direction(std::acos(c), 2.0 * kPi * u(rng));
  };
  for (int n = 0; n < 400; ++n) pairs.emplace_back(direction(88.0 * kPi / 180.0), direction(88.0 * kPi / 180.0));
  for (int n = 0; n < 50; ++n) {
    const Vec3 o = direction(89.5 * kPi / 180.0);
    pairs.emplace_back(o, glm::normalize(Vec3(-o.x, -o.y, o.z) + 0.05 * Vec3(u(rng) - 0.5, u(rng) - 0.5, 0.0)));
  }
  nlohmann::json j = nlohmann::json::array();
  for (const auto& [o, i] : pairs) j.push_back({{o.x, o.y, o.z}, {i.x, i.y, i.z}});
  std::ofstream(file) << j.dump();
  return pairs;
}

// facetfit's view-slice evaluation of `bsdf_file` against Mitsuba's on the pairs of `dir`/pairs.json.
void expect_parity(const std::string& bsdf_file, const std::vector<std::pair<Vec3, Vec3>>& pairs, const test::TempDir& dir) {
  const std::string name = fs::path(bsdf_file).stem().string();
  SCOPED_TRACE(name);
  const test::RunResult r = test::run_command(quoted(FACETFIT_MITSUBA_PYTHON) + " " +
                                              quoted(std::string(FACETFIT_SOURCE_DIR) + "/scripts/mitsuba_eval.py") + " " +
                                              quoted(bsdf_file) + " " + dir.file("pairs.json") + " " + dir.file("out.json"));
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json reference = nlohmann::json::parse(std::ifstream(dir.file("out.json")));
  ASSERT_EQ(reference.size(), pairs.size());
  RglBsdf bsdf = RglBsdf::read(bsdf_file);
  bsdf.set_slices(RglBsdf::Slices::view);
  // The material's scale: the median magnitude of Mitsuba's values over the pairs.
  std::vector<double> magnitudes;
  for (const auto& value : reference)
    for (int c = 0; c < 3; ++c) magnitudes.push_back(std::abs(value[std::size_t(c)].get<double>()));
  std::nth_element(magnitudes.begin(), magnitudes.begin() + std::ptrdiff_t(magnitudes.size() / 2), magnitudes.end());
  const double floor = std::max(1e-3 * magnitudes[magnitudes.size() / 2], 1e-9);
  double worst = 0.0;
  int negative = 0, beyond = 0, values = 0;
  for (std::size_t n = 0; n < pairs.size(); ++n) {
    const auto& [o, i] = pairs[n];
    const Rgb f = *bsdf.eval(o, i) * i.z;  // Mitsuba's eval carries cos(theta) of the non-viewer side
    for (int c = 0; c < 3; ++c) {
      const double m = reference[n][std::size_t(c)].get<double>();
      negative += m < 0.0;
      // Relative, with a floor of a thousandth of the material's median value. Mitsuba evaluates in float32
      // (facetfit in double): its chain of interpolations and the inversion of the VNDF warp leave ~1e-4 of
      // rounding on a few pairs, so 1e-4 is the bar for 99% of the values and 5e-4 for every one. That
      // rounding is relative to the table entries it interpolates, not to the result: where a value is
      // far below them (cardboard_rgb near 83 degrees: 4e-6 where its median is 1e-2), turning the
      // directions by 1e-7, float32's own rounding, moves Mitsuba's value by up to 8.5e-4 of itself.
      const double d = std::abs(f[c] - m) / std::max(std::abs(m), floor);
      worst = std::max(worst, d);
      beyond += d > 1e-4;
      ++values;
      EXPECT_LE(d, 5e-4) << "pair " << n << " channel " << c << ": facetfit " << f[c] << ", Mitsuba " << m;
    }
  }
  EXPECT_LE(beyond, values / 100) << beyond << " of " << values << " values differ by more than 1e-4";
  ::testing::Test::RecordProperty(name + "_worst_relative", std::to_string(worst));
  std::printf("%s: worst relative difference %.2e over %zu pairs (%d values beyond 1e-4), %d negative reference values\n",
              name.c_str(), worst, pairs.size(), beyond, negative);
}

TEST(MitsubaParity, ViewSlicesEqualMitsubasMeasuredEval) {
  if (!fs::is_directory(test::rgl_dir()))
    GTEST_SKIP() << "RGL data folder " << test::rgl_dir().string() << " is absent (set FACETFIT_RGL_DIR)";
  ASSERT_TRUE(fs::exists(FACETFIT_MITSUBA_PYTHON)) << FACETFIT_MITSUBA_PYTHON << ": run scripts/setup-mitsuba.sh (make test does)";
  test::TempDir dir;
  const auto pairs = direction_pairs(dir.file("pairs.json"));
  int files = 0;
  for (const auto& entry : fs::directory_iterator(test::rgl_dir())) {
    if (entry.path().extension() != ".bsdf") continue;
    ++files;
    expect_parity(entry.path().string(), pairs, dir);
  }
  EXPECT_GT(files, 0);
}

// Anisotropic files (no such file is in the database folder here): arbitrary tables whose slices span
// 2 pi, pi (a half-turn symmetry) and pi/2 (two mirrors), and an analytic anisotropic GGX turned 30
// degrees, written by the tests' tensor writer.
TEST(MitsubaParity, AnisotropicFiles) {
  ASSERT_TRUE(fs::exists(FACETFIT_MITSUBA_PYTHON)) << FACETFIT_MITSUBA_PYTHON << ": run scripts/setup-mitsuba.sh (make test does)";
  test::TempDir dir;
  const auto pairs = direction_pairs(dir.file("pairs.json"));
  const float pi = float(kPi);
  const std::vector<std::pair<std::string, std::vector<float>>> spans = {
      {"full_turn", {-pi, -2.0f, -0.5f, 0.3f, 1.5f, pi}},
      {"half_turn", {-pi, -2.2f, -1.0f, 0.0f}},
      {"two_mirrors", {-pi, -2.6f, -2.1f, -pi / 2}},
  };
  unsigned seed = 1;
  for (const auto& [name, phi_i] : spans) {
    const std::string path = dir.file("arbitrary_" + name + ".bsdf");
    const std::vector<unsigned char> bytes = test::serialize(test::arbitrary_tensor_fields(seed++, phi_i));
    std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    EXPECT_TRUE(RglBsdf::read(path).anisotropic());
    expect_parity(path, pairs, dir);
  }
  const std::string path = dir.file("ggx_anisotropic.bsdf");
  const std::vector<unsigned char> bytes =
      test::serialize(test::microfacet_tensor_fields(Ndf{NdfType::ggx, 0.45, 0.2}, Smith::correlated, 30.0 * kPi / 180.0, 13, 10, 24));
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  expect_parity(path, pairs, dir);
}

}  // namespace
}  // namespace facetfit
