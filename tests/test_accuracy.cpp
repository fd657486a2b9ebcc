// Ground truth: analytic GGX and Beckmann materials written as MERL files and fitted back, with each
// Smith model extracted by the matching --smith. The same figures make docs/accuracy.md.
#include <gtest/gtest.h>

#include "fit/ground_truth.h"
#include "test_util.h"

namespace facetfit {
namespace {

}  // namespace

// Readable test parameters in failure messages.
void PrintTo(const GroundTruthCase& c, std::ostream* os) {
  *os << to_string(c.type) << " alpha " << c.alpha << " smith " << to_string(c.smith);
}

namespace {

class GroundTruth : public testing::TestWithParam<GroundTruthCase> {};

void expect_within_the_bar(const GroundTruthCase& c, FitOptions::Refine refine) {
  FitOptions options;
  options.smith = c.smith;
  options.refine = refine;
  const Fitter fitter(options);
  test::TempDir dir;
  const GroundTruthError e = measure_ground_truth(c, fitter, dir.file("case.binary"));
  ASSERT_TRUE(e.problem.empty()) << e.problem;
  const double alpha_bar = c.alpha <= 0.02 ? 0.015 : 0.005;
  EXPECT_LT(std::abs(e.alpha_relative), alpha_bar) << "alpha " << e.alpha;
  EXPECT_LT(e.ndf_l1, 0.01);
  EXPECT_LT(e.fresnel_abs, 0.005);
}

// The paper's method alone, and the default fit (refinement on the whole measurement).
TEST_P(GroundTruth, WithinTheBar) { expect_within_the_bar(GetParam(), FitOptions::Refine::none); }
TEST_P(GroundTruth, WithinTheBarRefined) { expect_within_the_bar(GetParam(), FitOptions::Refine::full); }

std::string case_name(const testing::TestParamInfo<GroundTruthCase>& info) {
  std::string alpha = std::to_string(int(info.param.alpha * 1000 + 0.5));
  return std::string(to_string(info.param.type)) + "_" + to_string(info.param.smith) + "_alpha" + alpha;
}

INSTANTIATE_TEST_SUITE_P(Standard, GroundTruth, testing::ValuesIn(standard_ground_truth_cases()), case_name);

}  // namespace
}  // namespace facetfit
