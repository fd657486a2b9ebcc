// facetfit bake and info, end to end: batches with bad files, read-only folders, kills mid-write, the
// cache, scenes, metadata.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <thread>

#include "io/merl.h"
#include "lut/lut.h"
#include "model/analytic.h"
#include "test_util.h"

namespace facetfit {
namespace {

using test::facetfit;
using test::RunResult;
using test::TempDir;

nlohmann::json read_json(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

// On a terminal, a warning takes the progress bar's line, cleared first, and the bar is drawn again after
// it (issue 48: warnings were printed over the bar). A terminal from script(1), where it is installed.
TEST(Bake, WarningsDoNotOverwriteTheProgressBar) {
  if (test::run_command("command -v script >/dev/null").status != 0) GTEST_SKIP() << "no script(1) to give the command a terminal";
  TempDir dir;
  HalfDiffTable::tabulate(LambertBrdf(Rgb(1.3, 0.3, 0.1))).write(dir.file("bright.binary"));  // albedo above 1: warnings
  HalfDiffTable::tabulate(LambertBrdf(Rgb(0.5))).write(dir.file("plain.binary"));
  const RunResult r = test::run_command("script -qec \"" + std::string(FACETFIT_CLI) + " bake " + dir.file("bright.binary") + " " +
                                        dir.file("plain.binary") + " --refine none -o " + dir.file("out") + "\" /dev/null");
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  std::size_t warnings = 0;
  for (std::size_t at = r.out.find("facetfit: warning:"); at != std::string::npos; at = r.out.find("facetfit: warning:", at + 1), ++warnings)
    EXPECT_EQ(r.out.substr(at - 4, 4), "\r\033[K") << r.out;
  EXPECT_GT(warnings, 0u) << r.out;
  EXPECT_NE(r.out.rfind("] 2/2 "), std::string::npos) << r.out;  // the bar, drawn last
  EXPECT_GT(r.out.rfind("] 2/2 "), r.out.rfind("facetfit: warning:"));
}

TEST(Bake, BatchGoesOnPastACorruptedFile) {
  TempDir in, out;
  ASSERT_EQ(facetfit("convert builtin:gold-ggx-0.15 -o " + in.file("gold.binary")).status, 0);
  ASSERT_EQ(facetfit("convert builtin:silver-ggx-0.60 -o " + in.file("silver.binary")).status, 0);
  std::string bytes = test::read_bytes(in.file("gold.binary"));
  test::write_bytes(in.file("broken.binary"), bytes.substr(0, 1000));
  const RunResult r = facetfit("bake " + in.path().string() + " -o " + out.path().string());
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("broken.binary: size is 1000 bytes"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("1 of 3 inputs failed"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("baked 2, cached 0, failed 1"), std::string::npos) << r.out;
  EXPECT_TRUE(std::filesystem::exists(out.file("gold.exr")));
  EXPECT_TRUE(std::filesystem::exists(out.file("silver.exr")));
  EXPECT_FALSE(std::filesystem::exists(out.file("broken.exr")));
  const auto index = read_json(out.file("index.json"));
  EXPECT_EQ(index["materials"].size(), 2u);
  ASSERT_EQ(index["failures"].size(), 1u);
  EXPECT_NE(index["failures"][0]["error"].get<std::string>().find("truncated"), std::string::npos);
  // A second batch into the same folder adds to the index; a LUT deleted since drops out of it.
  ASSERT_EQ(facetfit("bake builtin:red-plastic --refine none -o " + out.path().string()).status, 0);
  const auto luts_in_index = [&] {
    const nlohmann::json now = read_json(out.file("index.json"));  // named: a loop over a temporary's member dangles
    std::set<std::string> luts;
    for (const auto& m : now["materials"]) luts.insert(m["lut"].get<std::string>());
    EXPECT_TRUE(now["failures"].empty());
    return luts;
  };
  EXPECT_EQ(luts_in_index(), (std::set<std::string>{"gold.exr", "silver.exr", "red-plastic.exr"}));
  std::filesystem::remove(out.file("silver.exr"));
  ASSERT_EQ(facetfit("bake builtin:red-plastic --refine none -o " + out.path().string()).status, 0);
  EXPECT_EQ(luts_in_index(), (std::set<std::string>{"gold.exr", "red-plastic.exr"}));
}

TEST(Bake, ReadOnlyOutputFolderFailsEveryMaterialCleanly) {
  TempDir out;
  const std::string dir = out.file("locked");
  std::filesystem::create_directory(dir);
  // Root ignores permission bits but not the immutable attribute.
  const bool root = ::geteuid() == 0;
  if (root && test::run_command("chattr +i " + dir).status != 0) GTEST_SKIP() << "chattr +i not available to root here";
  if (!root) std::filesystem::permissions(dir, std::filesystem::perms::owner_read | std::filesystem::perms::owner_exec);
  const RunResult r = facetfit("bake builtin:gold-ggx-0.15 builtin:aluminium-ggx-0.05 -o " + dir);
  if (root) test::run_command("chattr -i " + dir);
  EXPECT_EQ(r.status, 1);
  // The system's reason, not OpenImageIO's "Could not open" naming the temporary.
  EXPECT_NE(r.err.find(std::string("cannot write: ") + (root ? "Operation not permitted" : "Permission denied")), std::string::npos) << r.err;
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir), {}), 0);
  // The batch still ends with its summary, index.json included in what failed.
  EXPECT_NE(r.out.find("baked 0, cached 0, failed 2: no index.json written"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("facetfit: 2 of 2 inputs failed:"), std::string::npos) << r.err;
}

TEST(Bake, KilledMidRunLeavesOnlyWholeFiles) {
  TempDir out;
  const std::string dir = out.path().string();
  // Kill a forced rebake at different moments; after each kill, every visible output must be whole.
  // (A kill rarely lands inside one write, which takes microseconds: io/test_atomic.cpp kills a writer
  // deterministically between writing and committing. This test checks the command as a whole.)
  for (int delay_ms : {60, 150, 250, 400, 550, 700}) {
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      ::setpgid(0, 0);  // its own group, so that one kill reaches the shell and facetfit
      ::execl("/bin/sh", "sh", "-c", (std::string(FACETFIT_CLI) + " bake builtin: --force -j 2 -o " + dir + " >/dev/null 2>&1").c_str(),
              static_cast<char*>(nullptr));
      ::_exit(127);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms));
    ::kill(-pid, SIGKILL);
    int st = 0;
    ::waitpid(pid, &st, 0);
    for (const auto& entry : std::filesystem::directory_iterator(dir)) {
      const std::string name = entry.path().filename().string();
      if (name[0] == '.') continue;  // a writer's temporary, never a finished name
      if (entry.path().extension() == ".exr") {
        EXPECT_NO_THROW(read_lut(entry.path().string())) << name << " after " << delay_ms << " ms";
      }
      if (entry.path().extension() == ".json") {
        EXPECT_NO_THROW(read_json(entry.path().string())) << name << " after " << delay_ms << " ms";
      }
    }
  }
  // The next run finishes the job and clears the dead runs' temporaries.
  const RunResult r = facetfit("bake builtin: -o " + dir);
  EXPECT_EQ(r.status, 0) << r.err;
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    EXPECT_NE(entry.path().filename().string()[0], '.') << entry.path();
}

TEST(Bake, CacheHitsAndMisses) {
  TempDir in, out;
  const std::string src = in.file("copper.binary"), dir = out.path().string();
  ASSERT_EQ(facetfit("convert builtin:copper-beckmann-0.30 -o " + src).status, 0);
  EXPECT_NE(facetfit("bake " + src + " -o " + dir).out.find("baked 1, cached 0"), std::string::npos);
  const auto first_write = std::filesystem::last_write_time(out.file("copper.exr"));
  EXPECT_NE(facetfit("bake " + src + " -o " + dir).out.find("baked 0, cached 1"), std::string::npos);
  EXPECT_EQ(std::filesystem::last_write_time(out.file("copper.exr")), first_write);
  // Other settings, --force, other content: each a miss.
  EXPECT_NE(facetfit("bake " + src + " --tolerance 0.1 -o " + dir).out.find("baked 1, cached 0"), std::string::npos);
  EXPECT_NE(facetfit("bake " + src + " --tolerance 0.1 --force -o " + dir).out.find("baked 1, cached 0"), std::string::npos);
  ASSERT_EQ(facetfit("convert builtin:gold-ggx-0.15 -o " + src).status, 0);
  EXPECT_NE(facetfit("bake " + src + " --tolerance 0.1 -o " + dir).out.find("baked 1, cached 0"), std::string::npos);
  // A deleted, truncated or emptied LUT is rebaked even though its sidecar is current; the control: whole
  // again, it is a hit.
  std::filesystem::remove(out.file("copper.exr"));
  EXPECT_NE(facetfit("bake " + src + " --tolerance 0.1 -o " + dir).out.find("baked 1, cached 0"), std::string::npos);
  const auto lut_size = std::filesystem::file_size(out.file("copper.exr"));
  for (std::uintmax_t size : {lut_size / 2, std::uintmax_t(0)}) {
    std::filesystem::resize_file(out.file("copper.exr"), size);
    EXPECT_NE(facetfit("bake " + src + " --tolerance 0.1 -o " + dir).out.find("baked 1, cached 0"), std::string::npos) << size;
    EXPECT_EQ(facetfit("info " + out.file("copper.exr")).status, 0);  // the LUT is whole again
  }
  EXPECT_NE(facetfit("bake " + src + " --tolerance 0.1 -o " + dir).out.find("baked 0, cached 1"), std::string::npos);
}

TEST(Bake, MetadataRoundTripThroughInfo) {
  TempDir out;
  ASSERT_EQ(facetfit("bake builtin:copper-beckmann-0.30 --smith separable -o " + out.path().string()).status, 0);
  const auto sidecar = read_json(out.file("copper-beckmann-0.30.json"));
  const RunResult info = facetfit("info --json " + out.file("copper-beckmann-0.30.exr"));
  ASSERT_EQ(info.status, 0) << info.err;
  const auto j = nlohmann::json::parse(info.out);
  const auto& m = j["metadata"];
  EXPECT_EQ(m["source"], "builtin:copper-beckmann-0.30");
  EXPECT_EQ(m["smith"], "separable");
  EXPECT_EQ(m["source_sha256"], sidecar["source_sha256"]);
  EXPECT_EQ(m["representation"], sidecar["representation"]);
  EXPECT_EQ(m["representation"], "beckmann");
  EXPECT_NEAR(m["alpha_beckmann"].get<double>(), sidecar["alpha_beckmann"].get<double>(), 1e-6);
  EXPECT_NEAR(m["f82"][1].get<double>(), sidecar["f82"][1].get<double>(), 1e-6);
  EXPECT_EQ(j["ndf"]["slope_pdf"].size(), 91u);
  EXPECT_EQ(j["fresnel"]["rgb"].size(), 90u);
  // The human form names the same things.
  const RunResult text = facetfit("info " + out.file("copper-beckmann-0.30.exr"));
  EXPECT_NE(text.out.find("recommended     beckmann (tolerance"), std::string::npos) << text.out;
}

// One truth for the recommended representation (fit/recommend.h): `fit`'s table and JSON, the bake's sidecar
// and `info` of its LUT name the same representation with the same own parameters, and it is the one the
// definition gives from the record's distances; with the paper's method alone the distances are measured too.
TEST(Bake, RecommendedParametersAgreeEverywhere) {
  for (const std::string flags : {"", " --refine none", " --tolerance 100"})
    for (const std::string material : {"red-plastic", "black-glossy-ggx-0.08"}) {
      SCOPED_TRACE(material + flags);
      TempDir out;
      const RunResult fit = facetfit("fit --json builtin:" + material + flags);
      ASSERT_EQ(fit.status, 0) << fit.err;
      const nlohmann::json from_fit = nlohmann::json::parse(fit.out)["recommended"];
      ASSERT_EQ(facetfit("bake builtin:" + material + flags + " -o " + out.path().string()).status, 0);
      const nlohmann::json sidecar = read_json(out.file(material + ".json"));
      const RunResult info = facetfit("info --json " + out.file(material + ".exr"));
      ASSERT_EQ(info.status, 0) << info.err;
      const nlohmann::json from_info = nlohmann::json::parse(info.out)["metadata"]["recommended"];
      EXPECT_EQ(sidecar["recommended"], from_fit);
      EXPECT_EQ(sidecar["representation"], from_fit["representation"]);
      EXPECT_EQ(from_info["representation"], from_fit["representation"]);
      EXPECT_EQ(from_info["alpha"].is_null(), from_fit["representation"] == "tabulated" || from_fit["representation"] == "closures");
      // The one definition: the cheapest representation within max((1 + T) d, d + 0.2 / 116) of the nearest one's d
      // (0.2 L* units), the nearer parametric fit, else the closures (where fitted), else the tabulated lobe.
      const nlohmann::json record = nlohmann::json::parse(fit.out);
      const double tab = record["error"], ggx = record["ggx"]["error"], beckmann = record["beckmann"]["error"];
      const double closures = record["closures"]["error"];
      const double d = std::min({tab, ggx, beckmann, closures > 0.0 ? closures : tab});
      const double tolerance = flags == " --tolerance 100" ? 100.0 : 0.02, bar = std::max((1.0 + tolerance) * d, d + 0.2 / 116.0);
      const std::string expected = std::min(ggx, beckmann) <= bar ? (ggx <= beckmann ? "ggx" : "beckmann")
                                   : closures > 0.0 && closures <= bar ? "closures"
                                                                       : "tabulated";
      EXPECT_EQ(from_fit["representation"], expected) << "d " << d << ", ggx " << ggx << ", beckmann " << beckmann;
      // The LUT stores its attributes as floats.
      const auto near = [](const nlohmann::json& a, const nlohmann::json& b) { EXPECT_NEAR(a.get<double>(), b.get<double>(), 1e-6 + 1e-6 * std::abs(b.get<double>())); };
      if (!from_fit["alpha"].is_null()) near(from_info["alpha"], from_fit["alpha"]);
      for (const char* key : {"f0", "f82", "body"})
        for (int c = 0; c < 3; ++c) near(from_info[key][c], from_fit[key][c]);
      near(from_info["error"], from_fit["error"]);
      // The table prints the same representation and alpha.
      const RunResult table = facetfit("fit builtin:" + material + flags);
      char alpha[32] = "table";
      if (!from_fit["alpha"].is_null()) std::snprintf(alpha, sizeof alpha, "%.4f", from_fit["alpha"].get<double>());
      const std::size_t lobes = record["closures"]["lobes"].size();
      if (from_fit["representation"] == "closures") std::snprintf(alpha, sizeof alpha, "%zu lobe%s", lobes, lobes > 1 ? "s" : "");
      const std::string row = material + std::string(28 - material.size(), ' ') + "  " + from_fit["representation"].get<std::string>();
      EXPECT_NE(table.out.find(row), std::string::npos) << table.out;
      EXPECT_NE(table.out.find(std::string(alpha) + "  "), std::string::npos) << table.out;
    }
}

TEST(Bake, SceneBakesOnlyWhatItReferences) {
  TempDir in, out;
  ASSERT_EQ(facetfit("convert builtin:gold-ggx-0.15 -o " + in.file("gold.binary")).status, 0);
  ASSERT_EQ(facetfit("convert builtin:silver-ggx-0.60 -o " + in.file("silver.binary")).status, 0);
  test::write_bytes(in.file("scene.json"), R"({"materials": ["gold.binary", {"file": "builtin:red-plastic"}]})");
  // Inputs the scene does not reference are skipped.
  RunResult r = facetfit("bake " + in.path().string() + " --scene " + in.file("scene.json") + " -o " + out.path().string());
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(std::filesystem::exists(out.file("gold.exr")));
  EXPECT_FALSE(std::filesystem::exists(out.file("silver.exr")));
  // Without inputs, the scene's own list.
  r = facetfit("bake --scene " + in.file("scene.json") + " -o " + out.file("all"));
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(std::filesystem::exists(out.file("all/gold.exr")));
  EXPECT_TRUE(std::filesystem::exists(out.file("all/red-plastic.exr")));
  // A renderer scene (docs/scene-format.md): only the measured materials its objects use.
  test::write_bytes(in.file("render.json"), R"({
    "materials": {"a": {"type": "measured", "file": "silver.binary"}, "b": {"type": "lambert"},
                  "unused": {"type": "measured", "file": "gold.binary"}},
    "objects": [{"type": "sphere", "material": "a"}, {"type": "plane", "material": "b"}]})");
  r = facetfit("bake " + in.path().string() + " --scene " + in.file("render.json") + " -o " + out.file("render"));
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(std::filesystem::exists(out.file("render/silver.exr")));
  EXPECT_FALSE(std::filesystem::exists(out.file("render/gold.exr")));
  test::write_bytes(in.file("bad.json"), "{not json");
  EXPECT_NE(facetfit("bake --scene " + in.file("bad.json") + " -o " + out.file("x")).status, 0);
  // A scene that measures nothing (a Lambertian plane) has nothing to bake: said, and a success.
  test::write_bytes(in.file("plain.json"), R"({"materials": {"b": {"type": "lambert"}}, "objects": [{"type": "plane", "material": "b"}]})");
  r = facetfit("bake --scene " + in.file("plain.json") + " -o " + out.file("plain"));
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("plain.json references no measurement to bake"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out.file("plain")));
}

TEST(Bake, EvalOnlyAndDuplicateNames) {
  TempDir a, b, out;
  ASSERT_EQ(facetfit("convert builtin:gold-ggx-0.15 -o " + a.file("m.binary")).status, 0);
  ASSERT_EQ(facetfit("convert builtin:silver-ggx-0.60 -o " + b.file("m.binary")).status, 0);
  const RunResult r = facetfit("bake " + a.file("m.binary") + " " + b.file("m.binary") + " --eval-only -o " + out.path().string());
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("output name m is already taken by " + a.file("m.binary")), std::string::npos) << r.err;
  EXPECT_FALSE(read_lut(out.file("m.exr")).meta.sampling);
  EXPECT_NEAR(read_lut(out.file("m.exr")).meta.alpha_ggx, 0.15, 0.001);  // the first input's
}

TEST(Bake, GlobsAndQuotedGlobs) {
  TempDir in, out;
  ASSERT_EQ(facetfit("convert builtin:gold-ggx-0.15 -o " + in.file("a1.binary")).status, 0);
  ASSERT_EQ(facetfit("convert builtin:silver-ggx-0.60 -o " + in.file("a2.binary")).status, 0);
  const RunResult r = facetfit("bake '" + in.path().string() + "/a*.binary' -o " + out.path().string());
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("baked 2"), std::string::npos);
}

}  // namespace
}  // namespace facetfit

namespace facetfit {
namespace {

// Real measurements through every command that takes an input.
class RglPipeline : public testing::Test {
 protected:
  void SetUp() override {
    if (!std::filesystem::is_directory(test::rgl_dir()))
      GTEST_SKIP() << "RGL data folder " << test::rgl_dir().string() << " is absent (set FACETFIT_RGL_DIR)";
  }
  std::string file(const char* name) const { return (test::rgl_dir() / name).string(); }
};

TEST_F(RglPipeline, ConvertWritesARealMerlFileThatFitsTheSame) {
  TempDir out;
  const std::string merl = out.file("metallic.binary");
  ASSERT_EQ(facetfit("convert " + file("ilm_l3_37_metallic_rgb.bsdf") + " -o " + merl).status, 0);
  EXPECT_EQ(std::filesystem::file_size(merl), 34992012u);
  // The MERL file holds the same table at float precision: the same fit by the paper's method, which
  // reads the table alone. (The refinement reads the RGL file's two one-sided estimates, which a MERL
  // file cannot hold: fit/measurement.h.)
  const RunResult a = facetfit("fit " + file("ilm_l3_37_metallic_rgb.bsdf") + " --refine none --json");
  const RunResult b = facetfit("fit " + merl + " --refine none --json");
  ASSERT_EQ(a.status, 0) << a.err;
  ASSERT_EQ(b.status, 0) << b.err;
  const auto ja = nlohmann::json::parse(a.out), jb = nlohmann::json::parse(b.out);
  EXPECT_NEAR(jb["alpha_ggx"].get<double>(), ja["alpha_ggx"].get<double>(), 1e-5);
  EXPECT_NEAR(jb["f0"][0].get<double>(), ja["f0"][0].get<double>(), 1e-5);
}

// Every real file converted to MERL and rendered as a measurement stays near Mitsuba's render of the file
// (../shared/data/realref): MERL's readers take a negative number for a missing bin, so the noise around zero of
// a dark channel is written as 0 (with a warning that counts it) and a lookup keeps the channels it has.
// Written as it was (negative, so missing, and a bin dropped whole where one channel was), leaf_maple rendered
// 7.7 from the reference and vch_golden_yellow 4.5.
TEST_F(RglPipeline, EveryFileConvertedToMerlRendersAsItsMeasurement) {
  const std::filesystem::path realref = test::rgl_dir().parent_path() / "realref";
  if (!std::filesystem::is_directory(realref)) GTEST_SKIP() << realref << " is absent: nothing to compare with";
  TempDir out;
  int files = 0, warned = 0;
  for (const auto& entry : std::filesystem::directory_iterator(test::rgl_dir())) {
    if (entry.path().extension() != ".bsdf") continue;
    const std::string name = entry.path().stem().string(), merl = out.file(name + ".binary");
    SCOPED_TRACE(name);
    const RunResult converted = facetfit("convert " + entry.path().string() + " -o " + merl);
    ASSERT_EQ(converted.status, 0) << converted.err;
    warned += converted.err.find("below zero") != std::string::npos;
    const nlohmann::json scene = {
        {"camera", {{"position", {0, 0.6, 4}}, {"look_at", {0, 0, 0}}, {"up", {0, 1, 0}}, {"fov", 30}, {"width", 128}, {"height", 128}}},
        {"render", {{"spp", 256}, {"seed", 1}}},  // the spp of make accuracy's table: at 64 noise adds up to 0.5
        {"environment", {{"constant", {0.3, 0.3, 0.3}}}},
        {"lights", {{{"type", "directional"}, {"direction", {0.3, 1, 0.5}}, {"irradiance", {3, 3, 3}}}}},
        {"materials", {{"m", {{"type", "measured"}, {"file", merl}}}}},
        {"objects", {{{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", 1}, {"material", "m"}}}}};
    std::ofstream(out.file("scene.json")) << scene.dump();
    ASSERT_EQ(facetfit("render " + out.file("scene.json") + " -o " + out.file(name + ".exr")).status, 0);
    const RunResult d = facetfit("diff --json " + out.file(name + ".exr") + " " + (realref / (name + ".exr")).string() + " --mask " +
                                 (realref / "mask.exr").string());
    ASSERT_EQ(d.status, 0) << d.err;
    const double mean = nlohmann::json::parse(d.out)["mean"].get<double>();
    std::printf("%s converted to MERL: mean Delta E %.2f against Mitsuba's render of the file\n", name.c_str(), mean);
    EXPECT_LE(mean, 1.5);
    ++files;
  }
  EXPECT_GT(files, 0);
  EXPECT_GT(warned, 0);  // the data hold dark channels of noise around zero
}

TEST_F(RglPipeline, BakeTheWholeDatabase) {
  TempDir out;
  std::size_t files = 0;  // however many the data folder holds
  for (const auto& entry : std::filesystem::directory_iterator(test::rgl_dir())) files += entry.path().extension() == ".bsdf";
  ASSERT_GT(files, 0u);
  const RunResult r = facetfit("bake " + test::rgl_dir().string() + " -o " + out.path().string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("baked " + std::to_string(files) + ", cached 0, failed 0"), std::string::npos) << r.out;
  const nlohmann::json index = read_json(out.file("index.json"));  // named: a loop over a temporary's member dangles
  ASSERT_EQ(index["materials"].size(), files);
  for (const auto& m : index["materials"]) {
    EXPECT_GT(m["alpha_ggx"].get<double>(), 0.01);
    EXPECT_LT(m["alpha_ggx"].get<double>(), 1.0);
    const Lut lut = read_lut(out.file(m["lut"].get<std::string>()));
    EXPECT_EQ(lut.meta.source_sha256.size(), 64u);
  }
}

}  // namespace
}  // namespace facetfit

namespace facetfit {
namespace {

TEST(ReportCli, FailOnRegressionAndMerge) {
  TempDir dir;
  const std::string out = dir.file("r"), args = " builtin:gold-ggx-0.15 builtin:red-plastic --size 16 --spp 2 ";
  RunResult r = facetfit("report" + args + "-o " + out);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find(out + "/index.html"), std::string::npos);
  // Make the baseline better than anything this run can do.
  nlohmann::json previous = read_json(out + "/report.json");
  for (auto& [name, b] : previous["baseline"].items()) b["delta_e"]["ggx"] = 0.0;
  test::write_bytes(out + "/report.json", previous.dump());
  r = facetfit("report" + args + "--force --fail-on-regression -o " + out);
  EXPECT_EQ(r.status, 3);  // regressions, nothing failed
  EXPECT_NE(r.err.find("regression: red-plastic ggx"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("(neither input file nor facetfit changed)"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("report: 2/2 red-plastic (rendered)"), std::string::npos) << r.err;  // --force renders again
  // The same nightly run again fails again (its entries reused, and it says so); accepted, it passes, and so
  // does the next.
  r = facetfit("report" + args + "--fail-on-regression -o " + out);
  EXPECT_EQ(r.status, 3);
  EXPECT_NE(r.err.find("report: 2/2 red-plastic (reused)"), std::string::npos) << r.err;
  r = facetfit("report" + args + "--fail-on-regression --accept -o " + out);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("regression (accepted): red-plastic ggx"), std::string::npos) << r.err;
  EXPECT_EQ(facetfit("report" + args + "--fail-on-regression -o " + out).status, 0);
  // A material that left the database fails the nightly until accepted.
  r = facetfit("report builtin:gold-ggx-0.15 --size 16 --spp 2 --fail-on-regression -o " + out);
  EXPECT_EQ(r.status, 3);
  EXPECT_NE(r.err.find("removed: red-plastic is in the baseline"), std::string::npos) << r.err;
  // Shards and merge through the command.
  ASSERT_EQ(facetfit("report" + args + "--shard 1/2 -o " + dir.file("s1")).status, 0);
  ASSERT_EQ(facetfit("report" + args + "--shard 2/2 -o " + dir.file("s2")).status, 0);
  r = facetfit("report merge " + dir.file("s1") + " " + dir.file("s2") + " -o " + dir.file("m"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(read_json(dir.file("m/report.json"))["materials"].size(), 2u);
  EXPECT_EQ(facetfit("report" + args + "--shard 3/2 -o " + dir.file("x")).status, 2);
  // A merge into a folder that cannot be made names that folder, not a part.
  test::write_bytes(dir.file("a_file"), "");
  r = facetfit("report merge " + dir.file("s1") + " " + dir.file("s2") + " -o " + dir.file("a_file"));
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.err, "facetfit: error: " + dir.file("a_file") + ": cannot create output folder: Not a directory\n");
}

TEST(RenderCli, DefaultSceneToExrAndPng) {
  TempDir dir;
  const RunResult r = facetfit("render -o " + dir.file("a.exr") + " --png " + dir.file("a.png") + " --width 24 --height 24 --spp 2");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(std::filesystem::exists(dir.file("a.exr")));
  EXPECT_TRUE(std::filesystem::exists(dir.file("a.png")));
  const RunResult diff = facetfit("diff " + dir.file("a.exr") + " " + dir.file("a.exr"));
  EXPECT_EQ(diff.status, 0) << diff.err;
  EXPECT_NE(diff.out.find("mean 0.000000"), std::string::npos) << diff.out;
  EXPECT_EQ(facetfit("render " + dir.file("missing.json") + " -o " + dir.file("b.exr")).status, 1);
}

// The LUT-based types on the default (measured) material: it is baked on the fly, then rendered.
TEST(RenderCli, DefaultMaterialAsEveryRepresentation) {
  TempDir dir;
  for (const char* type : {"lut", "ggx", "beckmann", "lsq"}) {
    const RunResult r = facetfit(std::string("render --material-type ") + type + " -o " + dir.file(std::string(type) + ".exr") +
                                 " --width 16 --height 16 --spp 2");
    EXPECT_EQ(r.status, 0) << type << ": " << r.err;
    EXPECT_TRUE(std::filesystem::exists(dir.file(std::string(type) + ".exr"))) << type;
  }
  // A LUT named without a type is rendered as one (issue 48: "unsupported format '.exr'"), the same image
  // as --material-type lut.
  ASSERT_EQ(facetfit("bake builtin:gold-ggx-0.15 -o " + dir.file("luts")).status, 0);
  const std::string lut = " --material " + dir.file("luts/gold-ggx-0.15.exr") + " --width 16 --height 16 --spp 2 -o ";
  const RunResult inferred = facetfit("render" + lut + dir.file("inferred.exr"));
  ASSERT_EQ(inferred.status, 0) << inferred.err;
  ASSERT_EQ(facetfit("render --material-type lut" + lut + dir.file("typed.exr")).status, 0);
  const RunResult same = facetfit("diff " + dir.file("inferred.exr") + " " + dir.file("typed.exr"));
  EXPECT_NE(same.out.find("mean 0.000000"), std::string::npos) << same.out;
}

}  // namespace
}  // namespace facetfit

namespace facetfit {
namespace {

TEST(Cli, ExitCodesOfEveryCommand) {
  // bin/commands.h: 0 success, 1 some input failed, 2 usage (parser errors included); 3 (report
  // regressions) is ReportCli.FailOnRegressionAndMerge's.
  TempDir dir;
  ASSERT_EQ(facetfit("bake builtin:gold-ggx-0.15 --refine none -o " + dir.file("luts")).status, 0);
  const std::string lut = dir.file("luts") + "/gold-ggx-0.15.exr";
  test::write_bytes(dir.file("bad.binary"), "not a MERL table");
  test::write_bytes(dir.file("pair.txt"), "50 0 0 50 -1 2\n");
  test::write_bytes(dir.file("bad_pair.txt"), "50 0 0\n");
  ASSERT_EQ(facetfit("render --spp 1 --width 8 --height 8 -o " + dir.file("a.exr")).status, 0);
  const std::string bad = dir.file("bad.binary"), a = dir.file("a.exr");
  struct Case {
    std::string args;
    int status;
  };
  const Case cases[] = {
      {"fit builtin:gold-ggx-0.15 --refine none", 0},
      {"fit " + bad, 1},
      {"fit --frobnicate builtin:gold-ggx-0.15", 2},
      {"convert builtin:gold-ggx-0.15 -o " + dir.file("g.binary"), 0},
      {"convert " + bad + " -o " + dir.file("h.binary"), 1},
      {"convert builtin:gold-ggx-0.15", 2},
      {"list-builtins", 0},
      {"list-builtins extra", 2},
      {"bake builtin:gold-ggx-0.15 --refine none -o " + dir.file("luts"), 0},
      {"bake " + bad + " -o " + dir.file("luts"), 1},
      {"bake builtin:gold-ggx-0.15", 2},
      {"info " + lut, 0},
      {"info " + bad, 1},
      {"info", 2},
      {"render --spp 1 --width 8 --height 8 -o " + dir.file("b.exr"), 0},
      {"render --material " + bad + " --spp 1 --width 8 --height 8 -o " + dir.file("c.exr"), 1},
      {"render --spp x -o " + dir.file("d.exr"), 2},
      {"render --max-memory 1M -o " + dir.file("e.exr"), 1},  // 256 x 256 takes 3.8 MiB
      {"render --max-memory lots -o " + dir.file("e.exr"), 2},
      {"diff " + a + " " + a, 0},
      {"diff " + a + " " + bad, 1},
      {"diff " + a, 2},
      {"deltae <" + dir.file("pair.txt"), 0},
      {"deltae <" + dir.file("bad_pair.txt"), 1},
      {"deltae extra <" + dir.file("pair.txt"), 2},
      {"report --refine none --size 8 --spp 1 -o " + dir.file("report") + " builtin:gold-ggx-0.15", 0},
      {"report --refine none --size 8 --spp 1 -o " + dir.file("report2") + " " + bad, 1},
      {"report --shard 3/2 -o " + dir.file("report3") + " builtin:gold-ggx-0.15", 2},
  };
  for (const Case& c : cases) {
    const RunResult r = facetfit(c.args);
    EXPECT_EQ(r.status, c.status) << c.args << "\n" << r.err;
    if (c.status == 1) {  // the failed input named in the command's error style
      EXPECT_NE(r.err.find("facetfit: error: "), std::string::npos) << c.args << "\n" << r.err;
    }
    if (c.status == 2) {  // a usage error, parser's included: one line in the same style
      EXPECT_EQ(r.err.rfind("facetfit: error: ", 0), 0u) << c.args << "\n" << r.err;
      EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << c.args << "\n" << r.err;
    }
  }
}

TEST(Cli, QuietPrintsOnlyResultsAndErrorsVerbosePrintsSettings) {
  TempDir dir;
  const std::string out = " -o " + dir.file("luts");
  const RunResult quiet = facetfit("-q bake builtin:gold-ggx-0.15 --refine none" + out);
  EXPECT_EQ(quiet.status, 0);
  EXPECT_EQ(quiet.out + quiet.err, "");
  const RunResult normal = facetfit("bake builtin:gold-ggx-0.15 --refine none" + out);
  EXPECT_NE(normal.out.find("baked 0, cached 1, failed 0"), std::string::npos) << normal.out;
  const RunResult verbose = facetfit("-v bake builtin:gold-ggx-0.15 --refine none" + out);
  EXPECT_NE(verbose.err.find("facetfit: bake: refine none, resolution 90"), std::string::npos) << verbose.err;
  EXPECT_NE(verbose.err.find("cached gold-ggx-0.15"), std::string::npos) << verbose.err;
  // -q keeps results (the fit table) and errors.
  const RunResult fit = facetfit("--quiet fit builtin:gold-ggx-0.15 --refine none");
  EXPECT_NE(fit.out.find("gold-ggx-0.15"), std::string::npos);
  EXPECT_EQ(fit.err, "");
  const RunResult failed = facetfit("-q bake builtin:no-such-material" + out);
  EXPECT_EQ(failed.status, 1);
  EXPECT_NE(failed.err.find("facetfit: error: "), std::string::npos);
  const RunResult render = facetfit("-q render --spp 1 --width 8 --height 8 -o " + dir.file("a.exr"));
  EXPECT_EQ(render.status, 0);
  EXPECT_EQ(render.out + render.err, "");
  EXPECT_NE(facetfit("-v render --spp 1 --width 8 --height 8 -o " + dir.file("b.exr")).err.find("facetfit: render: pass 1/1"), std::string::npos);
}

}  // namespace
}  // namespace facetfit

namespace facetfit {
namespace {

TEST(Bake, ConcurrentBakesIntoOneFolderStayConsistent) {
  // Four bakes with different --tolerance into one folder at once, five times: every index.json entry
  // must be the sidecar on disk (same cache key), and every LUT the bake its sidecar describes (same
  // tolerance). Without the folder lock, some rounds disagree (here about one in ten).
  TempDir out;
  const std::string dir = out.path().string();
  // Half of them take the materials in the other order, so that their writes interleave.
  const std::string forward = "builtin:gold-ggx-0.15 builtin:copper-beckmann-0.30 builtin:red-plastic builtin:blue-clearcoat-paint",
                    backward = "builtin:blue-clearcoat-paint builtin:red-plastic builtin:copper-beckmann-0.30 builtin:gold-ggx-0.15";
  for (int round = 0; round < 5; ++round) {
    std::string script;
    for (const char* tolerance : {"0.01", "0.02", "0.05", "0.1"})
      script += std::string(FACETFIT_CLI) + " -q bake " + (tolerance[3] == '2' || tolerance[2] == '1' ? forward : backward) +
                " --refine none --force -j 1 --tolerance " + tolerance + " -o " + dir + " & ";
    ASSERT_EQ(test::run_command("sh -c '" + script + "wait'").status, 0);
    const nlohmann::json index = read_json(dir + "/index.json");
    ASSERT_EQ(index["materials"].size(), 4u) << index.dump();
    for (const auto& entry : index["materials"]) {
      const std::string name = entry["lut"].get<std::string>().substr(0, entry["lut"].get<std::string>().size() - 4);
      const nlohmann::json sidecar = read_json(dir + "/" + name + ".json");
      EXPECT_EQ(entry["cache_key"], sidecar["cache_key"]) << name << " round " << round;
      EXPECT_EQ(float(read_lut(dir + "/" + name + ".exr").meta.tolerance), float(sidecar["tolerance"].get<double>())) << name << " round " << round;
    }
  }
}

}  // namespace
}  // namespace facetfit

namespace facetfit {
namespace {

TEST(ReportCli, LocalFarmPublishesTheSameReportAsOneProcess) {
  TempDir dir;
  const std::string settings = " builtin:gold-ggx-0.15 builtin:red-plastic builtin:silver-ggx-0.60 --refine none --size 16 --spp 2 -o ";
  ASSERT_EQ(facetfit("-q report" + settings + dir.file("one")).status, 0);
  const RunResult farm = facetfit("-q report" + settings + dir.file("farm") + " --farm local --shards 2");
  ASSERT_EQ(farm.status, 0) << farm.err;
  const auto delta_e = [](const nlohmann::json& r) {
    std::map<std::string, nlohmann::json> m;
    for (const auto& e : r["materials"]) m[e["name"].get<std::string>()] = e["delta_e"];
    return m;
  };
  EXPECT_EQ(delta_e(read_json(dir.file("one") + "/report.json")), delta_e(read_json(dir.file("farm") + "/report.json")));
  // The plan as sbatch scripts; a farm splits the database itself, so --shard is a usage error.
  const RunResult dry = facetfit("report builtin: --farm slurm --shards 3 --partition night --time 1:00:00 --sbatch-arg=--qos=low --dry-run -o " +
                                 dir.file("plan"));
  EXPECT_EQ(dry.status, 0) << dry.err;
  for (const char* line : {"sbatch --array=1-3", "#SBATCH --partition=night", "#SBATCH --time=1:00:00", "#SBATCH --qos=low", "3) (",
                           "--dependency=afterok", "'report' 'merge'"})
    EXPECT_NE(dry.out.find(line), std::string::npos) << line << "\n" << dry.out;
  EXPECT_FALSE(std::filesystem::exists(dir.file("plan") + "/.farm")) << "a dry run writes nothing";
  EXPECT_EQ(facetfit("report builtin: --farm local --shard 2/3 -o " + dir.file("x")).status, 2);
}

}  // namespace
}  // namespace facetfit

namespace facetfit {
namespace {

TEST(Cli, FileNamesThatAreNotUtf8AreWrittenNotRefused) {
  // A name's bytes need not be UTF-8; JSON must be. fit --json and bake wrote nothing and said
  // "internal: [json.exception.type_error.316] invalid UTF-8 byte": now the byte becomes U+FFFD.
  TempDir dir;
  const std::string name = "\"" + dir.path().string() + "/m$(printf '\\376').binary\"";
  ASSERT_EQ(facetfit("convert builtin:gold-ggx-0.15 -o " + name).status, 0);
  const RunResult fit = facetfit("fit --refine none --json " + name);
  ASSERT_EQ(fit.status, 0) << fit.err;
  EXPECT_NE(nlohmann::json::parse(fit.out)["source"].get<std::string>().find("m\xEF\xBF\xBD.binary"), std::string::npos);
  const RunResult bake = facetfit("bake --refine none -o " + dir.file("luts") + " " + name);
  EXPECT_EQ(bake.status, 0) << bake.err;
  EXPECT_EQ(read_json(dir.file("luts") + "/index.json")["materials"].size(), 1u);
}

}  // namespace
}  // namespace facetfit

namespace facetfit {
namespace {

// Hostile input found by a robustness audit: each gets one error line and a nonzero exit, at once.
TEST(Cli, HostileInputsGetOneLineAndAnExitStatus) {
  TempDir dir;
  const auto one_line = [](const RunResult& r, const std::string& says) {
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
  };
  // A FIFO named like a MERL file: open() would wait for a writer forever (timeout: a regression fails,
  // it does not hang the suite).
  ASSERT_EQ(::mkfifo(dir.file("f.binary").c_str(), 0600), 0);
  RunResult r = test::run_command("timeout 60 " + std::string(FACETFIT_CLI) + " -q convert " + dir.file("f.binary") + " -o " +
                                  dir.file("x.binary"));
  EXPECT_EQ(r.status, 1);
  one_line(r, "f.binary: not a regular file");
  // A material list for bake --scene nested past the limit (100,000 levels overflowed the stack).
  test::write_bytes(dir.file("deep.json"), std::string(100000, '[') + std::string(100000, ']'));
  r = facetfit("bake --scene " + dir.file("deep.json") + " -o " + dir.file("out"));
  EXPECT_EQ(r.status, 1);
  one_line(r, "deep.json: nested more than 32 levels deep");
  // Results that cannot be written are a failure, not a success with a lost result.
  r = test::run_command("{ " + std::string(FACETFIT_CLI) + " list-builtins >/dev/full; }");
  EXPECT_EQ(r.status, 1);
  one_line(r, "cannot write to standard output");
  // A tolerance a LUT reader would refuse is refused when given.
  for (const char* bad : {"nan", "-1", "inf"}) {
    r = facetfit(std::string("bake builtin:red-plastic -o ") + dir.file("luts") + " --tolerance " + bad);
    EXPECT_EQ(r.status, 2) << bad;
    one_line(r, "is not a finite number");
  }
  EXPECT_FALSE(std::filesystem::exists(dir.file("luts")));
  // Outputs checked before the render: two flags naming one file, a missing folder, a non-EXR image, and
  // a scene's own environment map.
  const std::string small = " --width 8 --height 8 --spp 1";
  r = facetfit("render -o " + dir.file("y.exr") + " --save-sky " + dir.file("y.exr") + small);
  EXPECT_EQ(r.status, 1);
  one_line(r, "-o and --save-sky name the same file");
  r = facetfit("render -o " + dir.file("no/y.exr") + small);
  EXPECT_EQ(r.status, 1);
  one_line(r, "does not exist");
  r = facetfit("render -o " + dir.file("y.png") + small);
  EXPECT_EQ(r.status, 1);
  one_line(r, "give it a .exr name");
  // Each output of its flag's format, and a folder that takes no new file, refused before -o is written.
  const std::pair<std::string, std::string> refused[] = {
      {" --png " + dir.file("y"), "--png writes a display-referred PNG image: give it a .png name"},
      {" --save-sky " + dir.file("sky.png"), "--save-sky writes a lat-long OpenEXR image: give it a .exr name"},
      {" --png /proc/y.png", "/proc/y.png: cannot write: "}};
  for (const auto& [flags, error] : refused) {
    r = facetfit("render -o " + dir.file("z.exr") + flags + small);
    EXPECT_EQ(r.status, 1) << flags;
    one_line(r, error);
    EXPECT_FALSE(std::filesystem::exists(dir.file("z.exr"))) << flags;
  }
  ASSERT_EQ(facetfit("render -o " + dir.file("env.exr") + small).status, 0);
  test::write_bytes(dir.file("s.json"), R"({"environment": {"file": "env.exr"}, "materials": {"m": {"type": "lambert"}},
      "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}]})");
  r = facetfit("render " + dir.file("s.json") + " -o " + dir.file("env.exr") + small);
  EXPECT_EQ(r.status, 1);
  one_line(r, "-o would overwrite an input of the scene");
  // Flags of the default scene given with a scene of one's own would be ignored.
  r = facetfit("render " + dir.file("s.json") + " --material builtin:red-plastic -o " + dir.file("t.exr") + small);
  EXPECT_EQ(r.status, 2);
  one_line(r, "shape the default scene");
  // A heatmap never replaces one of the images it compares.
  ASSERT_EQ(facetfit("render -o " + dir.file("w.exr") + " --png " + dir.file("w.png") + small).status, 0);
  const auto before = std::filesystem::last_write_time(dir.file("w.png"));
  r = facetfit("diff " + dir.file("w.png") + " " + dir.file("w.exr") + " --heatmap " + dir.path().string() + "/./w.png");
  EXPECT_EQ(r.status, 1);
  one_line(r, "--heatmap would overwrite an input of the diff");
  EXPECT_EQ(std::filesystem::last_write_time(dir.file("w.png")), before);
  EXPECT_EQ(facetfit("diff " + dir.file("w.png") + " " + dir.file("w.exr") + " --heatmap " + dir.file("h.png")).status, 0);
  // A small file whose header claims a huge image is refused before its pixels are read.
  r = facetfit("diff " + dir.file("env.exr") + " " + dir.file("env.exr") + " --max-memory 1K");
  EXPECT_EQ(r.status, 1);
  one_line(r, "env.exr: its 8 x 8 image (diff --max-memory) needs");
  // CIELAB coordinates whose squares overflow inside the formula (1e308 gave 0).
  test::write_bytes(dir.file("huge.txt"), "1e308 1e308 1e308 0 0 0\n");
  r = facetfit("deltae <" + dir.file("huge.txt"));
  EXPECT_EQ(r.status, 1);
  one_line(r, "outside +-1e6");
}

}  // namespace
}  // namespace facetfit
