// MERL tables: layout, lookups, missing bins, and every kind of bad file.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "core/error.h"
#include "core/halfdiff.h"
#include "io/merl.h"
#include "model/analytic.h"
#include "test_util.h"

namespace facetfit {
namespace {

using test::error_of;
using test::TempDir;

HalfDiffTable gold_table() {
  return HalfDiffTable::tabulate(MicrofacetBrdf(Ndf::isotropic(NdfType::ggx, 0.3), Smith::correlated,
                                            Fresnel::conductor({0.143, 0.374, 1.442}, {3.983, 2.385, 1.603})));
}

TEST(Merl, WriteReadRoundTripIsExactToFloat) {
  TempDir dir;
  const HalfDiffTable table = gold_table();
  table.write(dir.file("gold.binary"));
  EXPECT_EQ(std::filesystem::file_size(dir.file("gold.binary")), HalfDiffTable::kFileBytes);
  const HalfDiffTable back = HalfDiffTable::read(dir.file("gold.binary"));
  for (int c = 0; c < 3; ++c)
    for (std::size_t n = 0; n < HalfDiffTable::kBins; n += 97) {
      const float a = table.channel(c)[n], b = back.channel(c)[n];
      if (HalfDiffTable::missing(a)) {
        EXPECT_TRUE(HalfDiffTable::missing(b));
      } else {
        EXPECT_NEAR(a, b, 1e-6f * std::max(1.0f, a));
      }
    }
  // No temporary left behind.
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 1);
}

TEST(Merl, ChannelScalesAndLayoutFollowTheReferenceReader) {
  TempDir dir;
  HalfDiffTable table;
  table.set(10, 20, 30, Rgb(1.0, 2.0, 3.0));
  table.write(dir.file("t.binary"));
  const std::string bytes = test::read_bytes(dir.file("t.binary"));
  const std::size_t n = HalfDiffTable::index(10, 20, 30);
  EXPECT_EQ(n, std::size_t(30 + 180 * 20 + 180 * 90 * 10));
  double stored[3];
  for (int c = 0; c < 3; ++c)
    std::memcpy(&stored[c], bytes.data() + 12 + (std::size_t(c) * HalfDiffTable::kBins + n) * 8, 8);
  EXPECT_NEAR(stored[0], 1.0 * 1500.0, 1e-9);
  EXPECT_NEAR(stored[1], 2.0 * 1500.0 / 1.15, 1e-9);
  EXPECT_NEAR(stored[2], 3.0 * 1500.0 / 1.66, 1e-9);
}

TEST(Merl, NearestLookupTruncatesLikeTheReferenceReader) {
  HalfDiffTable table;
  for (int i = 0; i < HalfDiffTable::kThetaH; ++i)
    for (int j = 0; j < HalfDiffTable::kThetaD; ++j)
      for (int k = 0; k < HalfDiffTable::kPhiD; ++k) table.set(i, j, k, Rgb(i, j, k));
  table.set_lookup(HalfDiffTable::Lookup::nearest);
  // Just inside bin (12, 34, 56) of each axis.
  const double th = std::pow((12 + 0.9) / 90.0, 2) * 0.5 * kPi, td = (34 + 0.9) / 90.0 * 0.5 * kPi,
               pd = (56 + 0.9) / 180.0 * kPi;
  const auto [o, i] = from_half_diff(th, td, pd);
  const Rgb v = *table.eval(o, i);
  EXPECT_EQ(v, Rgb(12, 34, 56));
  // phi_d and phi_d + pi are the same bin (reciprocity).
  EXPECT_EQ(*table.eval(i, o), Rgb(12, 34, 56));
}

TEST(Merl, LinearLookupInterpolatesAndSkipsMissingBins) {
  HalfDiffTable table;
  for (int i = 0; i < HalfDiffTable::kThetaH; ++i)
    for (int j = 0; j < HalfDiffTable::kThetaD; ++j)
      for (int k = 0; k < HalfDiffTable::kPhiD; ++k) table.set(i, j, k, Rgb(i + 2.0 * j + 0.5 * k));
  // Halfway along theta_d between bins 40 and 41: the mean of the two.
  const double th = std::pow(30.0 / 90.0, 2) * 0.5 * kPi, pd = 50.0 / 180.0 * kPi;
  auto [o, i] = from_half_diff(th, 40.5 / 90.0 * 0.5 * kPi, pd);
  EXPECT_NEAR(table.eval(o, i)->r, 30 + 81.0 + 25, 1e-3);
  // With bin 41 missing, only bin 40 remains.
  table.set_missing(30, 41, 50);
  EXPECT_NEAR(table.eval(o, i)->r, 30 + 80.0 + 25, 1e-3);
  // All neighbours missing: no value, never zero. (Clear a block around the point: after the round
  // trip through directions its coordinates are only near the bin centres.)
  for (int a = 29; a <= 31; ++a)
    for (int b = 40; b <= 41; ++b)
      for (int c = 49; c <= 51; ++c) table.set_missing(a, b, c);
  EXPECT_FALSE(table.eval(o, i).has_value());
}

// MERL files mark missing bins with negative numbers; in memory a missing bin is NaN.
TEST(Merl, NegativeFileEntriesAreMissing) {
  TempDir dir;
  HalfDiffTable table = gold_table();
  table.write(dir.file("a.binary"));
  std::string bytes = test::read_bytes(dir.file("a.binary"));
  const double minus_one = -1.0;
  std::memcpy(bytes.data() + 12 + HalfDiffTable::index(5, 6, 7) * 8, &minus_one, 8);
  test::write_bytes(dir.file("b.binary"), bytes);
  const HalfDiffTable back = HalfDiffTable::read(dir.file("b.binary"));
  EXPECT_TRUE(HalfDiffTable::missing(back.value(0, 5, 6, 7)));
  EXPECT_FALSE(HalfDiffTable::missing(back.value(1, 5, 6, 7)));
}

// A negative value tabulated in memory (RGL noise) is a measurement: kept, read back by eval.
TEST(Merl, NegativeMeasurementsStay) {
  HalfDiffTable table = gold_table();
  table.set(5, 6, 7, Rgb(-0.01, 0.2, -0.02));
  EXPECT_FALSE(HalfDiffTable::missing(table.value(0, 5, 6, 7)));
  EXPECT_FLOAT_EQ(table.value(0, 5, 6, 7), -0.01f);
  EXPECT_FLOAT_EQ(table.value(2, 5, 6, 7), -0.02f);
}

class MerlBadFile : public testing::Test {
 protected:
  // Reads `bytes` as a MERL file and returns the error message.
  std::string read_error(const std::string& bytes) {
    const std::string path = dir.file("bad.binary");
    test::write_bytes(path, bytes);
    return error_of([&] { HalfDiffTable::read(path); });
  }
  TempDir dir;
};

TEST_F(MerlBadFile, Missing) {
  const std::string msg = error_of([&] { HalfDiffTable::read(dir.file("nope.binary")); });
  EXPECT_NE(msg.find("nope.binary: cannot open"), std::string::npos) << msg;
}

TEST_F(MerlBadFile, Folder) {
  const std::string msg = error_of([&] { HalfDiffTable::read(dir.path().string()); });
  EXPECT_NE(msg.find("is a folder"), std::string::npos) << msg;
}

TEST_F(MerlBadFile, Empty) { EXPECT_NE(read_error("").find("bad.binary: file is empty"), std::string::npos); }

TEST_F(MerlBadFile, TruncatedHeader) { EXPECT_NE(read_error("abcde").find("truncated header"), std::string::npos); }

TEST_F(MerlBadFile, WrongDimensions) {
  EXPECT_NE(read_error(test::merl_header(90, 90, 360) + std::string(64, '\0')).find("90 x 90 x 360"), std::string::npos);
}

TEST_F(MerlBadFile, HugeHeaderAllocatesNothing) {
  // 10^9 entries claimed: rejected from the header alone.
  const std::string msg = read_error(test::merl_header(1000, 1000, 1000));
  EXPECT_NE(msg.find("1000 x 1000 x 1000"), std::string::npos) << msg;
}

TEST_F(MerlBadFile, Truncated) {
  const std::string msg = read_error(test::merl_header(90, 90, 180) + std::string(1000, '\0'));
  EXPECT_NE(msg.find("(truncated)"), std::string::npos) << msg;
}

TEST_F(MerlBadFile, TrailingData) {
  const std::string msg = read_error(test::merl_header(90, 90, 180) + std::string(3 * HalfDiffTable::kBins * 8 + 8, '\0'));
  EXPECT_NE(msg.find("(trailing data)"), std::string::npos) << msg;
}

TEST_F(MerlBadFile, NanPayloadNamesTheOffset) {
  std::string bytes = test::merl_header(90, 90, 180) + std::string(3 * HalfDiffTable::kBins * 8, '\0');
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::size_t bin = HalfDiffTable::index(3, 4, 5);
  std::memcpy(bytes.data() + 12 + (HalfDiffTable::kBins + bin) * 8, &nan, 8);
  const std::string msg = read_error(bytes);
  EXPECT_NE(msg.find("NaN at byte offset " + std::to_string(12 + (HalfDiffTable::kBins + bin) * 8)), std::string::npos) << msg;
  EXPECT_NE(msg.find("green channel, bin theta_h 3, theta_d 4, phi_d 5"), std::string::npos) << msg;
  EXPECT_EQ(msg.find('\n'), std::string::npos);
}

TEST_F(MerlBadFile, InfPayloadInTheLastChannel) {
  std::string bytes = test::merl_header(90, 90, 180) + std::string(3 * HalfDiffTable::kBins * 8, '\0');
  const double inf = -std::numeric_limits<double>::infinity();
  const std::size_t last = 3 * HalfDiffTable::kBins - 1;
  std::memcpy(bytes.data() + 12 + last * 8, &inf, 8);
  const std::string msg = read_error(bytes);
  EXPECT_NE(msg.find("Inf at byte offset " + std::to_string(12 + last * 8) + " (blue channel, bin theta_h 89, theta_d 89, phi_d 179)"),
            std::string::npos)
      << msg;
}

TEST_F(MerlBadFile, WriteIntoMissingFolderNamesTheTarget) {
  const std::string target = dir.file("no/such/folder/x.binary");
  const std::string msg = error_of([&] { HalfDiffTable().write(target); });
  EXPECT_NE(msg.find(target), std::string::npos) << msg;
}

}  // namespace
}  // namespace facetfit
