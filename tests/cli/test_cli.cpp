// The facetfit command as users run it: bad inputs, batches, JSON output.
#include <gtest/gtest.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <sstream>

#include "fit/fit.h"
#include "io/merl.h"
#include "lut/lut.h"
#include "io/utia.h"
#include "model/analytic.h"
#include "support/tensor_file.h"
#include "test_util.h"

namespace facetfit {
namespace {

using test::TempDir;

using test::facetfit;
using test::RunResult;
using test::run_command;

int lines(const std::string& s) { return int(std::count(s.begin(), s.end(), '\n')); }

class CliBadFile : public testing::TestWithParam<std::pair<std::string, std::string>> {};

// Each bad file: exactly one error line naming the file and the problem, exit status 1, no crash.
TEST_P(CliBadFile, OneClearLine) {
  TempDir dir;
  const auto& [name, expected] = GetParam();
  const std::string path = dir.file(name);
  if (name == "empty.binary") test::write_bytes(path, "");
  if (name == "truncated.binary") test::write_bytes(path, test::merl_header(90, 90, 180) + std::string(4096, '\0'));
  if (name == "dims.binary") test::write_bytes(path, test::merl_header(90, 90, 90) + std::string(4096, '\0'));
  if (name == "huge.binary") test::write_bytes(path, test::merl_header(1000, 1000, 1000));
  if (name == "nan.binary") {
    std::string bytes = test::merl_header(90, 90, 180) + std::string(3 * HalfDiffTable::kBins * 8, '\0');
    std::memset(bytes.data() + 12 + 8 * 1000, 0xff, 8);  // all ones: a NaN
    test::write_bytes(path, bytes);
  }
  if (name == "big.binary") {  // a single 1e308, finite as a double, not as the table's float (issue 47)
    std::string bytes = test::merl_header(90, 90, 180) + std::string(3 * HalfDiffTable::kBins * 8, '\0');
    const double big = 1e308;
    std::memcpy(bytes.data() + 12 + 8 * 1000, &big, 8);
    test::write_bytes(path, bytes);
  }
  if (name == "folder.binary") std::filesystem::create_directory(path);
  const RunResult r = facetfit("fit " + path);
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(lines(r.err), 2) << r.err;  // the error, then the batch summary
  EXPECT_NE(r.err.find("facetfit: error: " + path + ": "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(expected), std::string::npos) << r.err;
}

INSTANTIATE_TEST_SUITE_P(
    Merl, CliBadFile,
    testing::Values(std::make_pair("missing.binary", "no such file"), std::make_pair("empty.binary", "file is empty"),
                    std::make_pair("truncated.binary", "truncated"), std::make_pair("dims.binary", "90 x 90 x 90"),
                    std::make_pair("huge.binary", "1000 x 1000 x 1000"),
                    std::make_pair("nan.binary", "NaN at byte offset 8012"),
                    std::make_pair("big.binary", "1e+308 (out of float's range) at byte offset 8012"), std::make_pair("folder.binary", "is a folder")),
    [](const testing::TestParamInfo<std::pair<std::string, std::string>>& param) {
      return param.param.first.substr(0, param.param.first.find('.'));
    });

TEST(Cli, FittingLoadsNoImageLibrary) {
  // fit, convert and list-builtins run in an executable linked with the core library alone; image I/O,
  // colour management and ray tracing (some 250 shared libraries) load only with the command plugin.
  const RunResult needed = run_command("readelf -d " + std::string(FACETFIT_CLI));
  ASSERT_EQ(needed.status, 0) << needed.err;
  EXPECT_NE(needed.out.find("NEEDED"), std::string::npos);
  for (const char* heavy : {"OpenImageIO", "OpenColorIO", "embree"}) EXPECT_EQ(needed.out.find(heavy), std::string::npos) << heavy;
}

TEST(Cli, WithoutThePluginCoreCommandsRunAndOthersFailInOneLine) {
  TempDir dir;
  std::filesystem::copy_file(FACETFIT_CLI, dir.file("facetfit"));
  std::filesystem::permissions(dir.file("facetfit"), std::filesystem::perms::owner_all);
  const RunResult fit = run_command(dir.file("facetfit") + " fit builtin:gold-ggx-0.15 --refine none --json");
  EXPECT_EQ(fit.status, 0) << fit.err;
  EXPECT_NE(fit.out.find("\"alpha_ggx\""), std::string::npos);
  const RunResult bake = run_command(dir.file("facetfit") + " bake builtin:gold-ggx-0.15 -o " + dir.file("luts"));
  EXPECT_EQ(bake.status, 1);
  EXPECT_EQ(lines(bake.err), 1) << bake.err;
  EXPECT_NE(bake.err.find("facetfit: error: cannot load the command plugin facetfit-commands.so"), std::string::npos) << bake.err;
}

// `lut` written again to `out` with string attributes set (a crafted LUT).
void with_attributes(const std::string& lut, const std::string& out, const std::vector<std::pair<std::string, std::string>>& attributes) {
  auto in = OIIO::ImageInput::open(lut);
  ASSERT_TRUE(in);
  OIIO::ImageSpec spec = in->spec();
  std::vector<float> pixels(std::size_t(spec.width) * std::size_t(spec.height) * std::size_t(spec.nchannels));
  ASSERT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels.data()));
  for (const auto& [name, value] : attributes) spec.attribute(name, value);
  auto o = OIIO::ImageOutput::create(out);
  ASSERT_TRUE(o && o->open(out, spec) && o->write_image(OIIO::TypeDesc::FLOAT, pixels.data()) && o->close());
}

// A LUT's source holding a newline and a terminal escape (an edited file): info prints them as text
// (issue 47: they reached the terminal).
TEST(Cli, InfoPrintsMetadataAsText) {
  TempDir dir;
  const Fitter fitter{FitOptions::paper()};
  write_lut(dir.file("evil.exr"), make_lut(fitter.fit(HalfDiffTable::tabulate(LambertBrdf(Rgb(0.5)))), fitter.quadrature(),
                                           "evil\x1b[2J\nforged line", "x", 0.02, false));
  const RunResult r = facetfit("info " + dir.file("evil.exr"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out.find('\x1b'), std::string::npos);
  EXPECT_NE(r.out.find("source          evil?[2J?forged line\n"), std::string::npos) << r.out;
  // Its warnings too (issue 61: they were printed raw).
  with_attributes(dir.file("evil.exr"), dir.file("evil2.exr"), {{"facetfit:warnings", "odd\x1b[31m red"}});
  const RunResult w = facetfit("info " + dir.file("evil2.exr"));
  EXPECT_EQ(w.out.find('\x1b'), std::string::npos) << w.out;
  EXPECT_NE(w.out.find("warning         odd?[31m red"), std::string::npos) << w.out;
}

// LUT metadata is read in one pass with a size bound: 2 MB of warning lines (a crafted LUT) took 40 s in info
// when each line copied the rest; now such a LUT is refused at once with one line, and 60 KB of them read.
TEST(Cli, ManyWarningLinesAreReadInOnePassWithABound) {
  TempDir dir;
  const Fitter fitter{FitOptions::paper()};
  write_lut(dir.file("l.exr"), make_lut(fitter.fit(HalfDiffTable::tabulate(LambertBrdf(Rgb(0.5)))), fitter.quadrature(), "l", "x", 0.02, false));
  const auto with_warnings = [&](std::size_t bytes, const std::string& out) {
    std::string lines;
    while (lines.size() + 2 <= bytes) lines += "w\n";
    with_attributes(dir.file("l.exr"), out, {{"facetfit:warnings", lines}});
  };
  with_warnings(2 << 20, dir.file("big.exr"));
  const RunResult big = facetfit("info " + dir.file("big.exr"));
  EXPECT_EQ(big.status, 1);
  EXPECT_NE(big.err.find("facetfit:warnings is 2097"), std::string::npos) << big.err;
  with_warnings(60 << 10, dir.file("many.exr"));
  const RunResult many = facetfit("info " + dir.file("many.exr"));
  ASSERT_EQ(many.status, 0) << many.err;
  EXPECT_GT(std::count(many.out.begin(), many.out.end(), '\n'), 30000);
}

TEST(Cli, InfoOnAMeasurementSaysWhatToRun) {
  // Every input format (x.bin, UTIA, was left out of a list of its own and got the image reader's complaint).
  for (const std::string input : {"builtin:gold-ggx-0.15", "x.bsdf", "x.binary", "x.bin"}) {
    const RunResult r = facetfit("info " + input);
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(input + ": a measurement, not a LUT"), std::string::npos) << r.err;
  }
}

TEST(Cli, BatchGoesOnPastABadFile) {
  TempDir dir;
  test::write_bytes(dir.file("bad.binary"), "garbage");
  const RunResult r = facetfit("fit builtin:gold-ggx-0.15 " + dir.file("bad.binary") + " builtin:aluminium-ggx-0.05 --json");
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(lines(r.out), 2) << r.out;
  EXPECT_NE(r.err.find("bad.binary"), std::string::npos);
  EXPECT_NE(r.err.find("1 of 3 inputs failed"), std::string::npos) << r.err;
}

// export: each LUT's closures as a MaterialX document; a batch goes on past a bad LUT (exit 1, one line
// naming it). MaterialX's own validation accepts every document where the Python venv has MaterialX
// (make python installs it); the anisotropic lobe's tangent is turned by rotate3d.
TEST(Cli, ExportWritesMaterialXDocumentsThatValidate) {
  TempDir dir;
  ASSERT_EQ(facetfit("bake builtin:gold-ggx-0.15 builtin:blue-clearcoat-paint builtin:red-plastic -o " + dir.file("luts")).status, 0);
  const std::vector<unsigned char> bytes =
      test::serialize(test::microfacet_tensor_fields(Ndf{NdfType::ggx, 0.45, 0.2}, Smith::correlated, 0.5, 25, 32, 64));
  test::write_bytes(dir.file("aniso.bsdf"), std::string(bytes.begin(), bytes.end()));
  ASSERT_EQ(facetfit("bake " + dir.file("aniso.bsdf") + " -o " + dir.file("luts")).status, 0);
  test::write_bytes(dir.file("luts/broken.exr"), "not a LUT");
  const std::string luts = dir.file("luts/gold-ggx-0.15.exr") + " " + dir.file("luts/broken.exr") + " " + dir.file("luts/blue-clearcoat-paint.exr") +
                           " " + dir.file("luts/red-plastic.exr") + " " + dir.file("luts/aniso.exr");
  const RunResult r = facetfit("export --usd " + luts + " -o " + dir.file("mtlx/out"));
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("broken.exr"), std::string::npos) << r.err;
  std::string documents, stages;
  for (const char* name : {"gold_ggx_0_15", "blue_clearcoat_paint", "red_plastic", "aniso"}) {
    const std::string path = dir.file(std::string("mtlx/out/") + name + ".mtlx");
    ASSERT_TRUE(std::filesystem::exists(path)) << path;
    std::ifstream in(path);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find("<surfacematerial name=\"" + std::string(name) + "\""), std::string::npos) << text;
    EXPECT_NE(text.find("generalized_schlick_bsdf"), std::string::npos);
    documents += " " + path;
    stages += " " + dir.file(std::string("mtlx/out/") + name + ".usda");
  }
  EXPECT_FALSE(std::filesystem::exists(dir.file("mtlx/out/broken.usda")));
  std::ifstream aniso(dir.file("mtlx/out/aniso.mtlx"));
  EXPECT_NE(std::string((std::istreambuf_iterator<char>(aniso)), std::istreambuf_iterator<char>()).find("rotate3d"), std::string::npos);
  const std::string python = FACETFIT_PY_PYTHON;
  if (run_command("'" + python + "' -c 'import MaterialX' 2>/dev/null").status != 0)
    GTEST_SKIP() << "no MaterialX in " << python << " (run: make python): documents written, not validated";
  const RunResult valid = run_command("'" + python + "' " + std::string(FACETFIT_SOURCE_DIR) + "/tests/materialx/validate.py" + documents);
  EXPECT_EQ(valid.status, 0) << valid.out << valid.err;
  // The USD stages (export --usd) through usd-core: open, bind, reference resolved, validators.
  if (run_command("'" + python + "' -c 'import pxr.UsdValidation' 2>/dev/null").status != 0)
    GTEST_SKIP() << "no usd-core in " << python << " (run: make python): USD files written, not validated";
  const std::string usd_check = "'" + python + "' " + std::string(FACETFIT_SOURCE_DIR) + "/tests/usd/validate.py";
  const RunResult usd = run_command(usd_check + stages + " 2>&1");
  EXPECT_EQ(usd.status, 0) << usd.out << usd.err;
  std::cout << usd.out;
  // The control: a stage whose MaterialX document is gone fails.
  std::filesystem::remove(dir.file("mtlx/out/red_plastic.mtlx"));
  EXPECT_NE(run_command(usd_check + " " + dir.file("mtlx/out/red_plastic.usda") + " 2>&1").status, 0);
}

// Names that clean to one MaterialX name (a/x and b/x; a-b and "a b"): the first is written, the second
// refused with a line naming both; the same LUT given twice is written once.
TEST(Cli, ExportRefusesTwoLutsOfOneName) {
  TempDir dir;
  ASSERT_EQ(facetfit("bake builtin:gold-ggx-0.15 -o " + dir.file("luts")).status, 0);
  const std::string lut = dir.file("luts/gold-ggx-0.15.exr");
  for (const char* copy : {"a/x.exr", "b/x.exr", "c/a-b.exr", "c/a b.exr"}) {
    std::filesystem::create_directories(std::filesystem::path(dir.file(copy)).parent_path());
    std::filesystem::copy_file(lut, dir.file(copy));
  }
  const RunResult r = facetfit("export " + dir.file("a/x.exr") + " " + dir.file("b/x.exr") + " " + dir.file("c/a-b.exr") + " '" +
                               dir.file("c/a b.exr") + "' " + dir.file("a/x.exr") + " -o " + dir.file("mtlx"));
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 2) << r.err;
  EXPECT_NE(r.err.find(dir.file("b/x.exr") + ": its MaterialX name x is " + dir.file("a/x.exr") + "'s in this export"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("its MaterialX name a_b is"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 2) << r.out;  // x.mtlx and a_b.mtlx, once each
}

TEST(Cli, JsonHasExactlyTheDocumentedKeys) {
  const RunResult r = facetfit("fit builtin:copper-beckmann-0.30 --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  std::vector<std::string> keys;
  for (const auto& item : j.items()) keys.push_back(item.key());
  EXPECT_EQ(keys, (std::vector<std::string>{"alpha_beckmann", "alpha_ggx", "anisotropic", "beckmann", "body", "body_exponent", "closures", "coat", "error",
                                            "error_extraction", "f0", "f82", "ggx", "iterations", "lsq", "recommended",
                                            "refine", "residual", "seconds", "source", "warnings"}));
  for (const char* fit : {"ggx", "beckmann", "lsq"}) {
    std::vector<std::string> sub;
    for (const auto& item : j[fit].items()) sub.push_back(item.key());
    EXPECT_EQ(sub, (std::vector<std::string>{"alpha", "body", "coat", "error", "f0", "f82"})) << fit;
  }
  EXPECT_NEAR(j["alpha_beckmann"].get<double>(), 0.30, 0.30 * 0.005);
  EXPECT_EQ(j["f0"].size(), 3u);
  EXPECT_EQ(j["source"], "builtin:copper-beckmann-0.30");
}

TEST(Cli, ConvertThenFitTheFile) {
  TempDir dir;
  const std::string path = dir.file("gold.binary");
  ASSERT_EQ(facetfit("convert builtin:gold-ggx-0.15 -o " + path).status, 0);
  const RunResult r = facetfit("fit " + path + " --json --smith correlated --resolution 90");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NEAR(nlohmann::json::parse(r.out)["alpha_ggx"].get<double>(), 0.15, 0.15 * 0.005);
}

// UTIA files: convert writes them (any input sampled at the file's nodes), fit and folder expansion take
// them (as their azimuthal mean; tests/fit/test_accuracy.cpp checks what comes back), bad outputs get a line.
TEST(Cli, ConvertToUtiaThenFitTheFile) {
  TempDir dir;
  const std::string path = dir.file("silver.bin");
  ASSERT_EQ(facetfit("convert builtin:silver-ggx-0.60 -o " + path).status, 0);
  EXPECT_EQ(std::filesystem::file_size(path), UtiaBrdf::kFileBytes);
  const RunResult r = facetfit("fit " + dir.path().string() + " --json");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(lines(r.out), 1);
  // The 15-degree grid limits it (tests/fit/test_accuracy.cpp): -0.7% here.
  EXPECT_NEAR(nlohmann::json::parse(r.out)["alpha_ggx"].get<double>(), 0.60, 0.60 * 0.03);
  EXPECT_NEAR(nlohmann::json::parse(r.out)["anisotropic"]["alpha_ggx"]["alpha_y"].get<double>(), 0.60, 0.60 * 0.03);
  // An anisotropic file: its principal alphas beside the isotropic fit, in the record and the table.
  TempDir other;
  UtiaBrdf::tabulate(MicrofacetBrdf(Ndf{NdfType::ggx, 0.5, 0.25}, Smith::correlated, Fresnel::schlick(Rgb(0.9)))).write(other.file("a.bin"));
  const RunResult aniso = facetfit("fit " + other.file("a.bin") + " --json");
  ASSERT_EQ(aniso.status, 0) << aniso.err;
  const nlohmann::json a = nlohmann::json::parse(aniso.out)["anisotropic"];
  EXPECT_NEAR(a["alpha_ggx"]["alpha_x"].get<double>(), 0.5, 0.5 * 0.03);
  EXPECT_NEAR(a["alpha_ggx"]["alpha_y"].get<double>(), 0.25, 0.25 * 0.03);
  EXPECT_NEAR(a["alpha_ggx"]["angle_degrees"].get<double>(), 0.0, 2.0);
  const RunResult table = facetfit("fit " + other.file("a.bin"));
  EXPECT_NE(table.out.find("anisotropic: ggx 0."), std::string::npos) << table.out;
  // Its LUT's anisotropic GGX fit, as info shows it, is the record's (to the LUT's float precision).
  ASSERT_EQ(facetfit("bake " + other.file("a.bin") + " -o " + other.file("luts")).status, 0);
  const RunResult info = facetfit("info " + other.file("luts/a.exr") + " --json");
  ASSERT_EQ(info.status, 0) << info.err;
  const nlohmann::json from_lut = nlohmann::json::parse(info.out)["metadata"]["anisotropic"], from_fit = a["ggx"];
  ASSERT_TRUE(from_lut.is_object()) << info.out;
  for (const char* key : {"alpha_x", "alpha_y", "angle_degrees", "error"})
    EXPECT_NEAR(from_lut["ggx"][key].get<double>(), from_fit[key].get<double>(), 1e-5 * std::max(1.0, std::abs(from_fit[key].get<double>()))) << key;
  EXPECT_EQ(from_lut["phi_count"].get<int>(), 48);
  EXPECT_NE(facetfit("info " + other.file("luts/a.exr")).out.find("anisotropic     tabulated lobe on 90 x 48 nodes"), std::string::npos);
  // An isotropic LUT has none.
  ASSERT_EQ(facetfit("bake builtin:gold-ggx-0.15 --refine none -o " + other.file("luts")).status, 0);
  EXPECT_TRUE(nlohmann::json::parse(facetfit("info " + other.file("luts/gold-ggx-0.15.exr") + " --json").out)["metadata"]["anisotropic"].is_null());
  const RunResult bad = facetfit("convert builtin:silver-ggx-0.60 -o " + dir.file("x.png"));
  EXPECT_EQ(bad.status, 1);
  EXPECT_NE(bad.err.find("x.png: unsupported output format '.png' (supported: .binary, .bin)"), std::string::npos) << bad.err;
}

// An anisotropic RGL file (the tests' tensor writer: GGX 0.45 x 0.25 turned 30 degrees, F = 1): the
// isotropic fits see its azimuthal mean, the 2D extraction its axes.
TEST(Cli, FitsAnAnisotropicRglFile) {
  TempDir dir;
  const std::vector<unsigned char> bytes =
      test::serialize(test::microfacet_tensor_fields(Ndf{NdfType::ggx, 0.45, 0.25}, Smith::correlated, 30.0 * kPi / 180.0, 25, 32, 64));
  test::write_bytes(dir.file("aniso.bsdf"), std::string(bytes.begin(), bytes.end()));
  const RunResult r = facetfit("fit " + dir.file("aniso.bsdf") + " --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  const nlohmann::json a = j["anisotropic"];
  std::printf("[ rgl fit ] isotropic GGX %.4f; 2D: %.4f x %.4f at %.2f degrees\n", j["alpha_ggx"].get<double>(),
              a["ggx"]["alpha_x"].get<double>(), a["ggx"]["alpha_y"].get<double>(), a["ggx"]["angle_degrees"].get<double>());
  EXPECT_NEAR(a["ggx"]["alpha_x"].get<double>(), 0.45, 0.45 * 0.02);
  EXPECT_NEAR(a["ggx"]["alpha_y"].get<double>(), 0.25, 0.25 * 0.02);
  EXPECT_NEAR(a["ggx"]["angle_degrees"].get<double>(), 30.0, 0.5);
  // The isotropic GGX of the mean lies between the two axes.
  EXPECT_GT(j["alpha_ggx"].get<double>(), 0.25);
  EXPECT_LT(j["alpha_ggx"].get<double>(), 0.45);
  EXPECT_NE(r.err.find("anisotropic (GGX 0.4"), std::string::npos) << r.err;
}

TEST(Cli, FolderInputFitsEveryTableInIt) {
  TempDir dir;
  ASSERT_EQ(facetfit("convert builtin:gold-ggx-0.15 -o " + dir.file("a.binary")).status, 0);
  ASSERT_EQ(facetfit("convert builtin:silver-ggx-0.60 -o " + dir.file("b.binary")).status, 0);
  const RunResult r = facetfit("fit " + dir.path().string() + " --json");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(lines(r.out), 2);
}

TEST(Cli, UsageErrors) {
  EXPECT_EQ(facetfit("fit builtin:gold-ggx-0.15 --smith wrong").status, 2);
  EXPECT_NE(facetfit("fit").status, 0);
  EXPECT_EQ(facetfit("fit builtin:gold-ggx-0.15 --resolution 1").status, 2);
  // Values CLI11 or sscanf would have wrapped or cut short (issue 47).
  for (const char* args : {"render --seed -1 -o x.exr", "render --seed 18446744073709551616 -o x.exr", "render --seed 1e3 -o x.exr",
                           "render --max-memory 0x10G -o x.exr", "report builtin:gold-ggx-0.15 -o r --shard 1/2/3",
                           "report builtin:gold-ggx-0.15 -o r --shard 1/4294967297", "report builtin:gold-ggx-0.15 -o r --shard 1/+2",
                           "report builtin:gold-ggx-0.15 -o r --shard 2/1",
                           "report builtin:gold-ggx-0.15 -o r --spp 2000000"}) {
    const RunResult r = facetfit(args);
    EXPECT_EQ(r.status, 2) << args << ": " << r.err;
    EXPECT_EQ(lines(r.err), 1) << args << ": " << r.err;
  }
  // Usage errors point to the command's help, and a mistyped command to the nearest one (issue 48).
  const RunResult typo = facetfit("rendr -o x.exr");
  EXPECT_EQ(typo.status, 2);
  EXPECT_NE(typo.err.find("unknown command 'rendr' (did you mean 'facetfit render'?)"), std::string::npos) << typo.err;
  const RunResult jobs = facetfit("bake --jobs 0 builtin:gold-ggx-0.15 -o out");
  EXPECT_EQ(jobs.status, 2);
  EXPECT_NE(jobs.err.find("(see facetfit bake --help)"), std::string::npos) << jobs.err;
  const RunResult help = facetfit("help render");
  EXPECT_EQ(help.status, 0);
  EXPECT_NE(help.out.find("--material-type"), std::string::npos) << help.out;
  EXPECT_NE(help.out.find("Usage: facetfit render"), std::string::npos) << help.out;  // as render --help
  // Help of a command that does not exist is the usage error `facetfit WORD` gives.
  const RunResult no_help = facetfit("help rendr");
  EXPECT_EQ(no_help.status, 2);
  EXPECT_EQ(no_help.out, "");
  EXPECT_NE(no_help.err.find("unknown command 'rendr' (did you mean 'facetfit render'?)"), std::string::npos) << no_help.err;
  const RunResult view = facetfit("render --view foo -o x.exr");  // a flag that needs another: usage
  EXPECT_EQ(view.status, 2);
  EXPECT_NE(view.err.find("--view requires --display (see facetfit render --help)"), std::string::npos) << view.err;
  // A path the system refuses is one line naming it, not "internal: filesystem error" (issue 47).
  const RunResult long_path = facetfit("bake builtin:gold-ggx-0.15 -o /tmp/" + std::string(300, 'b'));
  EXPECT_EQ(long_path.status, 1);
  EXPECT_EQ(lines(long_path.err), 1) << long_path.err;
  EXPECT_NE(long_path.err.find("bbb...: File name too long"), std::string::npos) << long_path.err;
  const RunResult fresnel = facetfit("bake builtin:gold-ggx-0.15 -o out --closure-fresnel f83");
  EXPECT_EQ(fresnel.status, 2);
  EXPECT_NE(fresnel.err.find("--closure-fresnel f83: must be f82 or schlick"), std::string::npos) << fresnel.err;
  // Parser errors are usage errors too: exit 2, not the parser library's own codes (104-109).
  for (const char* args : {"fit --no-such-flag builtin:gold-ggx-0.15", "no-such-command", "", "--threads 0 fit builtin:gold-ggx-0.15",
                           "bake builtin:gold-ggx-0.15", "render --spp abc -o x.exr",
                           "render --material-type foo -o x.exr", "render --width -5 -o x.exr", "render --spp -3 -o x.exr",
                           "render --width 2147483647 -o x.exr"})
    EXPECT_EQ(facetfit(args).status, 2) << args;
  EXPECT_EQ(facetfit("--help").status, 0);
  const RunResult version = facetfit("--version");
  EXPECT_EQ(version.status, 0);
  EXPECT_NE(version.out.find(FACETFIT_VERSION), std::string::npos) << version.out;
  EXPECT_NE(version.out.find("Embree 3."), std::string::npos) << version.out;  // the build's details (issue 48)
  // --threads caps the work, it does not change it.
  const RunResult one = facetfit("--threads 1 fit builtin:gold-ggx-0.15 --refine none --json");
  ASSERT_EQ(one.status, 0) << one.err;
  EXPECT_NEAR(nlohmann::json::parse(one.out)["alpha_ggx"].get<double>(), 0.15, 0.15 * 0.005);
  const RunResult unknown = facetfit("fit builtin:no-such-material");
  EXPECT_EQ(unknown.status, 1);
  EXPECT_NE(unknown.err.find("no such built-in material"), std::string::npos);
}

// An output named with a '?' (OpenImageIO reads "name?query" as options) is written, not refused as a full disk.
TEST(Cli, AQuestionMarkInAnOutputNameIsWritten) {
  TempDir dir;
  const RunResult r = facetfit("render -o '" + dir.file("a?b.exr") + "' --png '" + dir.file("c?d.png") + "' --spp 1 --width 8 --height 8");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(std::filesystem::exists(dir.file("a?b.exr")));
  EXPECT_TRUE(std::filesystem::exists(dir.file("c?d.png")));
}

TEST(Cli, ConvertIntoReadOnlyFolderFailsCleanly) {
  // Root writes through permission bits, but nobody creates files in /proc.
  TempDir dir;
  std::filesystem::permissions(dir.path(), std::filesystem::perms::owner_read | std::filesystem::perms::owner_exec);
  const std::string target = ::geteuid() == 0 ? "/proc/facetfit-x.binary" : dir.file("x.binary");
  const RunResult r = facetfit("convert builtin:gold-ggx-0.15 -o " + target);
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(target + ": cannot write"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(target));
}

TEST(Cli, MeaninglessFitIsReportedWithNulls) {
  TempDir dir;
  // A table with every measurement zero.
  HalfDiffTable table;
  for (int c = 0; c < 3; ++c)
    for (std::size_t n = 0; n < HalfDiffTable::kBins; ++n) table.channel(c)[n] = 0.0f;
  table.write(dir.file("zero.binary"));
  const RunResult r = facetfit("fit " + dir.file("zero.binary") + " --json");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("meaningless fit: no back-scattered signal"), std::string::npos) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j["alpha_ggx"].is_null());
}

}  // namespace
}  // namespace facetfit
