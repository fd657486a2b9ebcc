// Parity with the RGL format's reference evaluation: Mitsuba 3's `measured` BSDF (PyPI wheel, scalar_rgb,
// in the venv of scripts/setup-mitsuba.sh) against facetfit's RglBsdf with view slices, on random
// direction pairs of the six RGL materials, grazing ones included.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>

#include "io/rgl.h"
#include "test_util.h"

namespace facetfit {
namespace {

namespace fs = std::filesystem;

std::string quoted(const std::string& s) { return "'" + s + "'"; }

TEST(MitsubaParity, ViewSlicesEqualMitsubasMeasuredEval) {
  if (!fs::is_directory(test::rgl_dir()))
    GTEST_SKIP() << "RGL data folder " << test::rgl_dir().string() << " is absent (set FACETFIT_RGL_DIR)";
  ASSERT_TRUE(fs::exists(FACETFIT_MITSUBA_PYTHON)) << FACETFIT_MITSUBA_PYTHON << ": run scripts/setup-mitsuba.sh (make test does)";
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  // Uniform in cos(theta) up to 88 degrees, plus pairs near the horizon and near the mirror direction.
  std::vector<std::pair<Vec3, Vec3>> pairs;  // (o: viewer side, i)
  const auto direction = [&](double max_theta) {
    const double c = 1.0 - u(rng) * (1.0 - std::cos(max_theta));
    return spherical_direction(std::acos(c), 2.0 * kPi * u(rng));
  };
  for (int n = 0; n < 400; ++n) pairs.emplace_back(direction(88.0 * kPi / 180.0), direction(88.0 * kPi / 180.0));
  for (int n = 0; n < 50; ++n) {
    const Vec3 o = direction(89.5 * kPi / 180.0);
    pairs.emplace_back(o, glm::normalize(Vec3(-o.x, -o.y, o.z) + 0.05 * Vec3(u(rng) - 0.5, u(rng) - 0.5, 0.0)));
  }
  test::TempDir dir;
  nlohmann::json j = nlohmann::json::array();
  for (const auto& [o, i] : pairs) j.push_back({{o.x, o.y, o.z}, {i.x, i.y, i.z}});
  std::ofstream(dir.file("pairs.json")) << j.dump();

  int files = 0;
  for (const auto& entry : fs::directory_iterator(test::rgl_dir())) {
    if (entry.path().extension() != ".bsdf") continue;
    ++files;
    SCOPED_TRACE(entry.path().filename().string());
    const test::RunResult r = test::run_command(quoted(FACETFIT_MITSUBA_PYTHON) + " " +
                                                quoted(std::string(FACETFIT_SOURCE_DIR) + "/scripts/mitsuba_eval.py") + " " +
                                                quoted(entry.path().string()) + " " + dir.file("pairs.json") + " " + dir.file("out.json"));
    ASSERT_EQ(r.status, 0) << r.err;
    const nlohmann::json reference = nlohmann::json::parse(std::ifstream(dir.file("out.json")));
    ASSERT_EQ(reference.size(), pairs.size());
    RglBsdf bsdf = RglBsdf::read(entry.path().string());
    bsdf.set_slices(RglBsdf::Slices::view);
    double worst = 0.0;
    int negative = 0, beyond = 0, values = 0;
    for (std::size_t n = 0; n < pairs.size(); ++n) {
      const auto& [o, i] = pairs[n];
      const Rgb f = *bsdf.eval(o, i) * i.z;  // Mitsuba's eval carries cos(theta) of the non-viewer side
      for (int c = 0; c < 3; ++c) {
        const double m = reference[n][std::size_t(c)].get<double>();
        negative += m < 0.0;
        // Relative, with a floor of 1e-6. Mitsuba evaluates in float32 (facetfit in double): its chain of
        // interpolations and the inversion of the VNDF warp leave ~1e-4 of rounding on a few pairs, so
        // 1e-4 is the bar for 99% of the values and 5e-4 for every one.
        const double d = std::abs(f[c] - m) / std::max(std::abs(m), 1e-6);
        worst = std::max(worst, d);
        beyond += d > 1e-4;
        ++values;
        EXPECT_LE(d, 5e-4) << "pair " << n << " channel " << c << ": facetfit " << f[c] << ", Mitsuba " << m;
      }
    }
    EXPECT_LE(beyond, values / 100) << beyond << " of " << values << " values differ by more than 1e-4";
    RecordProperty(entry.path().stem().string() + "_worst_relative", std::to_string(worst));
    std::printf("%s: worst relative difference %.2e over %zu pairs (%d values beyond 1e-4), %d negative reference values\n",
                entry.path().stem().c_str(), worst, pairs.size(), beyond, negative);
  }
  EXPECT_GT(files, 0);
}

}  // namespace
}  // namespace facetfit
