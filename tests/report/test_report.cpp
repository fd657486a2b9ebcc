// The nightly report: outputs, the cache of unchanged entries, regressions, shards and merge.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <regex>

#include "io/atomic_file.h"
#include "io/folder_lock.h"
#include "io/input.h"
#include "io/merl.h"
#include "model/analytic.h"
#include "report/report.h"
#include "test_util.h"

namespace facetfit {
namespace {

using nlohmann::json;
using test::TempDir;

ReportOptions small(const std::string& out) {
  ReportOptions o;
  o.inputs = {"builtin:gold-ggx-0.15", "builtin:copper-beckmann-0.30", "builtin:red-plastic"};
  o.out_dir = out;
  o.size = 24;
  o.spp = 4;
  return o;
}

// The report page (DIR/out/index.html) of one Lambert material written as DIR/NAME.binary.
std::string page_of_material_named(const TempDir& dir, const std::string& name) {
  HalfDiffTable::tabulate(LambertBrdf(Rgb(0.5))).write(dir.file(name + ".binary"));
  ReportOptions o = small(dir.file("out"));
  o.inputs = {dir.file(name + ".binary")};
  EXPECT_EQ(run_report(o)["materials"].size(), 1u);
  return test::read_bytes(dir.file("out/index.html"));
}

// A material file named to break out of a single-quoted attribute: its name is escaped in every HTML
// context, so the page holds no attribute the name wrote (issue 47).
TEST(Report, AMaterialNameCannotWriteHtml) {
  TempDir dir;
  const std::string html = page_of_material_named(dir, "x' onerror='alert(1)");
  EXPECT_EQ(html.find("onerror='"), std::string::npos);
  EXPECT_NE(html.find("x&#39; onerror=&#39;alert(1)"), std::string::npos);
  EXPECT_NE(html.find("src='images/x%27%20onerror%3D%27alert%281%29/measured.png'"), std::string::npos);
}

// A name with '#' and '%' links to its own folder: the links are URL-encoded (issue 61).
TEST(Report, ImageLinksAreUrlEncoded) {
  TempDir dir;
  const std::string name = "paint #5 100%";
  const std::string html = page_of_material_named(dir, name);
  const std::string link = "images/paint%20%235%20100%25/";
  for (const char* file : {"measured.png", "ggx.png", "lobes_30.svg"}) {
    EXPECT_NE(html.find("'" + link + file + "'"), std::string::npos) << file;
    EXPECT_TRUE(std::filesystem::exists(dir.path() / "out" / "images" / name / file)) << file;
  }
}

// Two inputs of one stem: the second is a failure naming the first, not a second row over its images and
// LUT (issue 47).
TEST(Report, TwoInputsOfOneNameAreNotTwoRows) {
  TempDir dir;
  std::filesystem::create_directories(dir.path() / "d1");
  std::filesystem::create_directories(dir.path() / "d2");
  HalfDiffTable::tabulate(LambertBrdf(Rgb(0.5))).write(dir.file("d1/mat.binary"));
  HalfDiffTable::tabulate(LambertBrdf(Rgb(0.2))).write(dir.file("d2/mat.binary"));
  ReportOptions o = small(dir.file("out"));
  o.inputs = {dir.file("d1/mat.binary"), dir.file("d2/mat.binary")};
  const json r = run_report(o);
  ASSERT_EQ(r["materials"].size(), 1u);
  EXPECT_EQ(r["materials"][0]["source"], dir.file("d1/mat.binary"));
  ASSERT_EQ(r["failures"].size(), 1u);
  EXPECT_NE(r["failures"][0]["error"].get<std::string>().find("output name mat is already taken by " + dir.file("d1/mat.binary")),
            std::string::npos);
}

// Folders of a report that are symbolic links are not followed (issue 47: its writes and clean-up went
// outside the report): a material's image folder fails that material, the luts folder the report.
TEST(Report, SymlinkedFoldersAreNotFollowed) {
  TempDir dir;
  std::filesystem::create_directories(dir.path() / "outside");
  std::filesystem::create_directories(dir.path() / "out" / "images");
  std::filesystem::create_directory_symlink(dir.path() / "outside", dir.path() / "out" / "images" / "gold-ggx-0.15");
  ReportOptions o = small(dir.file("out"));
  o.inputs = {"builtin:gold-ggx-0.15"};
  const json r = run_report(o);
  ASSERT_EQ(r["failures"].size(), 1u);
  EXPECT_NE(r["failures"][0]["error"].get<std::string>().find("gold-ggx-0.15: is a symbolic link"), std::string::npos) << r["failures"];
  EXPECT_TRUE(std::filesystem::is_empty(dir.path() / "outside"));
  std::filesystem::create_directory_symlink(dir.path() / "outside", dir.path() / "out2-luts");
  std::filesystem::create_directories(dir.path() / "out2");
  std::filesystem::rename(dir.path() / "out2-luts", dir.path() / "out2" / "luts");
  EXPECT_NE(test::error_of([&] { run_report(small(dir.file("out2"))); }).find("luts: is a symbolic link"), std::string::npos);
  EXPECT_TRUE(std::filesystem::is_empty(dir.path() / "outside"));
}

TEST(Report, ASecondReportIntoTheSameFolderIsRefused) {
  // Another process's report holds the folder (its images/ locked): this one is refused at once, naming
  // the folder, and writes nothing; a merge into it too. Once released, the report runs.
  TempDir dir;
  ReportOptions o = small(dir.file("part"));
  o.inputs = {"builtin:gold-ggx-0.15"};
  ASSERT_EQ(run_report(o)["materials"].size(), 1u);
  std::filesystem::create_directories(dir.path() / "out" / "images");
  o.out_dir = dir.file("out");
  {
    const FolderLock other((dir.path() / "out" / "images").string());
    EXPECT_NE(test::error_of([&] { run_report(o); }).find("images: is being written by another facetfit process"), std::string::npos);
    EXPECT_NE(test::error_of([&] { merge_reports({dir.file("part")}, dir.file("out")); }).find("is being written by another"), std::string::npos);
    EXPECT_FALSE(std::filesystem::exists(dir.path() / "out" / "report.json"));
  }
  EXPECT_EQ(run_report(o)["materials"].size(), 1u);
  // Its LUTs in its own images/ would wait on its own lock: refused, not a hang.
  o.luts_dir = dir.file("out/images");
  EXPECT_NE(test::error_of([&] { run_report(o); }).find("is the report's images folder"), std::string::npos);
}

json read_json(const std::string& path) {
  std::ifstream in(path);
  return json::parse(in);
}

TEST(Report, WritesEveryOutputAndTheRightOrder) {
  TempDir dir;
  const json r = run_report(small(dir.path().string()));
  ASSERT_EQ(r["materials"].size(), 3u);
  EXPECT_TRUE(r["failures"].empty());
  for (const json& m : r["materials"]) {
    const std::string name = m["name"];
    for (const char* f : {"measured.png", "tabulated.png", "ggx.png", "beckmann.png", "lsq.png", "closures.png", "ggx_delta_e.png",
                          "lobes_0.svg", "lobes_30.svg", "lobes_60.svg", "ndf.svg", "fresnel.svg"})
      EXPECT_TRUE(std::filesystem::exists(dir.path() / "images" / name / f)) << name << "/" << f;
    // A lobe figure holds one curve per representation and the measurement.
    const std::string lobes = test::read_bytes((dir.path() / "images" / name / "lobes_30.svg").string());
    std::size_t curves = 0;
    for (std::size_t at = lobes.find("<polyline"); at != std::string::npos; at = lobes.find("<polyline", at + 1)) ++curves;
    EXPECT_EQ(curves, 6u) << name;  // measured, tabulated, ggx, beckmann, lsq, closures
    EXPECT_TRUE(std::filesystem::exists(dir.path() / "luts" / (name + ".exr")));
  }
  // Each family fits its own material; Beckmann cannot fit a GGX lobe (the worst entry of all).
  const auto entry = [&](const std::string& name) {
    for (const json& m : r["materials"])
      if (m["name"] == name) return m;
    return json();
  };
  EXPECT_LT(entry("gold-ggx-0.15")["delta_e"]["ggx"].get<double>(), 0.5);
  EXPECT_LT(entry("copper-beckmann-0.30")["delta_e"]["beckmann"].get<double>(), 0.5);
  EXPECT_GT(entry("gold-ggx-0.15")["delta_e"]["beckmann"].get<double>(), 3.0);
  // The worst materials are ranked by their recommended representation (what a renderer is told to ship), not
  // by a representation nobody recommends (gold's Beckmann fit), each figure that representation's mean Delta E,
  // under the mean's name (not the per-pixel maximum's).
  ASSERT_FALSE(r["worst"].empty());
  for (const json& w : r["worst"]) {
    const json m = entry(w["name"].get<std::string>());
    EXPECT_EQ(w["representation"], m["representation"]) << w;
    EXPECT_EQ(w["delta_e"], m["delta_e"][m["representation"].get<std::string>()]) << w;
    EXPECT_FALSE(w.contains("max_delta_e"));
  }
  for (std::size_t k = 1; k < r["worst"].size(); ++k) EXPECT_GE(r["worst"][k - 1]["delta_e"], r["worst"][k]["delta_e"]);
  // What production shades with, beside the tabulated model, and what each costs to render.
  EXPECT_LT(entry("gold-ggx-0.15")["delta_e"]["closures"].get<double>(), 0.5);
  for (const char* column : {"tabulated", "ggx", "closures"}) EXPECT_GT(r["database_mean_render_seconds"][column].get<double>(), 0.0) << column;
  EXPECT_EQ(read_json(dir.file("report.json")), r);
  const std::string html = test::read_bytes(dir.file("index.html"));
  EXPECT_NE(html.find("<svg"), std::string::npos);          // run time against error
  // A page a person reads (issue 48): two decimals, the worst entry's representation, the recommended
  // representation of each material, the heatmaps' scale.
  EXPECT_FALSE(std::regex_search(html, std::regex(R"(<td>-?[0-9]+\.[0-9]{3,}</td>)"))) << "a table figure with more than two decimals";
  EXPECT_NE(html.find(" (beckmann)</li>"), std::string::npos);
  EXPECT_NE(html.find("<th>recommended</th>"), std::string::npos);
  EXPECT_NE(html.find("<td>" + entry("gold-ggx-0.15")["representation"].get<std::string>() + "</td>"), std::string::npos);
  EXPECT_NE(html.find("class='heatmap-scale'"), std::string::npos);
  EXPECT_TRUE(std::regex_search(html, std::regex("<text x='50' y='275'>[0-9.e+-]{1,7}</text>"))) << "the time axis' bound";
  EXPECT_NE(html.find("images/red-plastic/ggx_delta_e.png"), std::string::npos);
}

TEST(Report, UnchangedMaterialsAreNotRenderedAgain) {
  TempDir dir;
  const json first = run_report(small(dir.path().string()));
  const json second = run_report(small(dir.path().string()));
  EXPECT_EQ(first["materials"], second["materials"]);  // the same entries, render timings included
  ReportOptions bigger = small(dir.path().string());
  bigger.spp = 8;  // other settings: everything is rendered again
  const json third = run_report(bigger);
  EXPECT_NE(first["materials"][0]["seconds"], third["materials"][0]["seconds"]);
}

// An entry whose images were emptied or removed since is rendered again; the untouched one is reused.
TEST(Report, AnEntryWithAnImageEmptiedOrRemovedIsRenderedAgain) {
  TempDir dir;
  const json first = run_report(small(dir.path().string()));
  ASSERT_EQ(first["materials"].size(), 3u);
  const std::filesystem::path images = dir.path() / "images";
  std::filesystem::resize_file(images / first["materials"][0]["name"].get<std::string>() / "ggx.png", 0);
  std::filesystem::remove(images / first["materials"][1]["name"].get<std::string>() / "lsq.png");
  const json second = run_report(small(dir.path().string()));
  EXPECT_NE(first["materials"][0]["seconds"], second["materials"][0]["seconds"]);
  EXPECT_NE(first["materials"][1]["seconds"], second["materials"][1]["seconds"]);
  EXPECT_EQ(first["materials"][2], second["materials"][2]);  // control: untouched, reused
  EXPECT_GT(std::filesystem::file_size(images / first["materials"][0]["name"].get<std::string>() / "ggx.png"), 0u);
  EXPECT_TRUE(std::filesystem::exists(images / first["materials"][1]["name"].get<std::string>() / "lsq.png"));
}

TEST(Report, RegressionsAgainstThePreviousReport) {
  TempDir dir;
  json r = run_report(small(dir.path().string()));
  // Pretend the previous night was much better for gold's GGX fit.
  r["baseline"]["gold-ggx-0.15"]["delta_e"]["ggx"] = 0.0;
  test::write_bytes(dir.file("report.json"), r.dump());
  ReportOptions again = small(dir.path().string());
  again.force = true;
  const json now = run_report(again);
  bool found = false;
  for (const json& g : now["regressions"]) found |= g["name"] == "gold-ggx-0.15" && g["representation"] == "ggx";
  double gold_ggx = 0.0;
  for (const json& m : now["materials"])
    if (m["name"] == "gold-ggx-0.15") gold_ggx = m["delta_e"]["ggx"].get<double>();
  // A regression needs +10% and +0.1: from the pretended 0, exactly when gold's Delta E exceeds 0.1.
  EXPECT_EQ(found, gold_ggx > 0.1);
  json previous = now, current = now;
  previous.erase("baseline");  // reports from before baselines: judged against their own figures
  current.erase("baseline");
  previous["materials"][2]["delta_e"]["ggx"] = 1.0;
  current["materials"][2]["delta_e"]["ggx"] = 2.0;
  ASSERT_EQ(find_regressions(previous, current).size(), 1u);
  EXPECT_EQ(find_regressions(current, previous).size(), 0u);  // getting better is not a regression
}

TEST(Report, AFailedNightlyStaysFailedUntilAccepted) {
  TempDir dir;
  ReportOptions o = small(dir.path().string());
  json r = run_report(o);
  ASSERT_EQ(r["baseline"].size(), 3u);
  EXPECT_TRUE(r["regressions"].empty());
  // The baseline pretends the worst figure of the report was 0: this run regresses on it.
  std::string name, representation;
  double worst = 0.0;
  for (const json& m : r["materials"])
    for (const auto& [rep, v] : m["delta_e"].items())
      if (v.get<double>() > worst) worst = v.get<double>(), name = m["name"], representation = rep;
  ASSERT_GT(worst, 0.2);
  r["baseline"][name]["delta_e"][representation] = 0.0;
  test::write_bytes(dir.file("report.json"), r.dump());
  const auto regressed = [&](const json& report) {
    for (const json& g : report["regressions"])
      if (g["name"] == name && g["representation"] == representation) return g.value("cause", std::string());
    return std::string();
  };
  // Failed, and failed again on the rerun (its entries reused): the failed figures did not become the baseline.
  for (int night = 0; night < 2; ++night) {
    const json again = run_report(o);
    EXPECT_EQ(regressed(again), "neither input file nor facetfit changed") << night;
    EXPECT_EQ(again["baseline"][name]["delta_e"][representation].get<double>(), 0.0) << night;
  }
  // A changed input file is named as the cause.
  json edited = read_json(dir.file("report.json"));
  edited["baseline"][name]["source_sha256"] = std::string(64, '0');
  test::write_bytes(dir.file("report.json"), edited.dump());
  EXPECT_EQ(regressed(run_report(o)), "input file changed");
  // Accepted: still listed this once, then the baseline.
  ReportOptions accept = o;
  accept.accept = true;
  const json accepted = run_report(accept);
  EXPECT_TRUE(accepted["accepted"].get<bool>());
  EXPECT_FALSE(regressed(accepted).empty());
  EXPECT_NEAR(accepted["baseline"][name]["delta_e"][representation].get<double>(), worst, 1e-12);
  EXPECT_TRUE(run_report(o)["regressions"].empty());
  // A material that leaves the database is listed until accepted.
  ReportOptions fewer = o;
  fewer.inputs.pop_back();
  const std::string gone = source_name(o.inputs.back());
  for (int night = 0; night < 2; ++night) EXPECT_EQ(run_report(fewer)["removed"], json::array({gone})) << night;
  fewer.accept = true;
  EXPECT_EQ(run_report(fewer)["removed"], json::array());
  fewer.accept = false;
  EXPECT_EQ(run_report(fewer)["removed"], json::array());
}

TEST(Report, ShardsMergeIntoTheWholeReport) {
  TempDir whole, part1, part2, merged;
  const json full = run_report(small(whole.path().string()));
  ReportOptions a = small(part1.path().string()), b = small(part2.path().string());
  a.shard = 1, a.shards = 2;
  b.shard = 2, b.shards = 2;
  const json ra = run_report(a), rb = run_report(b);
  EXPECT_EQ(ra["materials"].size() + rb["materials"].size(), 3u);
  EXPECT_FALSE(ra["materials"].empty());
  EXPECT_FALSE(rb["materials"].empty());
  const json m = merge_reports({part1.path().string(), part2.path().string()}, merged.path().string());
  ASSERT_EQ(m["materials"].size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(m["materials"][k]["name"], full["materials"][k]["name"]);
    EXPECT_EQ(m["materials"][k]["delta_e"], full["materials"][k]["delta_e"]);  // fixed seeds: the same numbers
    EXPECT_TRUE(std::filesystem::exists(merged.path() / "images" / m["materials"][k]["name"].get<std::string>() / "measured.png"));
  }
  EXPECT_EQ(m["database_mean_delta_e"], full["database_mean_delta_e"]);
  EXPECT_NE(test::error_of([&] { merge_reports({merged.file("nope")}, merged.path().string()); }).find("not a facetfit report"),
            std::string::npos);
  // A shard twice or one missing is refused before anything is written.
  TempDir refused;
  const std::string out = (refused.path() / "m").string();
  EXPECT_NE(test::error_of([&] { merge_reports({part1.path().string(), part1.path().string()}, out); }).find("(a part given twice?)"),
            std::string::npos);
  EXPECT_NE(test::error_of([&] { merge_reports({part2.path().string()}, out); }).find("shard 1/2 of its split is not among the parts"),
            std::string::npos);
  EXPECT_NE(test::error_of([&] { merge_reports({part1.path().string(), merged.path().string()}, out); }).find("is also in"),
            std::string::npos);
  // A part's material names are file names, never paths (issue 47: "../../p1" copied its images beside the
  // output), and strings (a number ended in an internal JSON error).
  TempDir hostile;
  json forged = ra;
  forged["shard"] = "1/1";
  forged["materials"][0]["name"] = "../../p1";
  write_file_atomic((hostile.path() / "report.json").string(), forged.dump());
  EXPECT_NE(test::error_of([&] { merge_reports({hostile.path().string()}, out); }).find("material name \"../../p1\" holds a '/'"),
            std::string::npos);
  forged["materials"][0]["name"] = 7;
  write_file_atomic((hostile.path() / "report.json").string(), forged.dump());
  EXPECT_NE(test::error_of([&] { merge_reports({hostile.path().string()}, out); }).find("a material without a \"name\" string"),
            std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(out));
  EXPECT_FALSE(std::filesystem::exists(refused.path() / "p1"));
  // A merged report's image folder that is a symbolic link is not copied through.
  TempDir linked;
  std::filesystem::create_directories(linked.path() / "outside");
  std::filesystem::create_directories(linked.path() / "m" / "images");
  std::filesystem::create_directory_symlink(linked.path() / "outside",
                                            linked.path() / "m" / "images" / ra["materials"][0]["name"].get<std::string>());
  EXPECT_NE(test::error_of([&] { merge_reports({part1.path().string(), part2.path().string()}, (linked.path() / "m").string()); })
                .find("is a symbolic link"),
            std::string::npos);
  EXPECT_TRUE(std::filesystem::is_empty(linked.path() / "outside"));
}

}  // namespace
}  // namespace facetfit

#include "report/farm.h"

namespace facetfit {
namespace {

TEST(Farm, ShardsAreBalancedLongestFirstAndDeterministic) {
  // Costs 8, 7, 6, 5, 4, 3, 2, 1 over 3 shards, longest first onto the least loaded: 13, 12, 11 (the
  // best split is 12, 12, 12; the greedy rule is within 4/3 of it, here within the smallest item but one).
  std::vector<std::pair<std::string, double>> costs;
  for (int k = 1; k <= 8; ++k) costs.emplace_back("m" + std::to_string(k), double(k));
  const auto shards = balance_shards(costs, 3);
  ASSERT_EQ(shards.size(), 3u);
  std::map<std::string, double> cost(costs.begin(), costs.end());
  std::vector<double> totals;
  for (const auto& s : shards) {
    double total = 0.0;
    for (const auto& m : s) total += cost[m];
    totals.push_back(total);
    EXPECT_TRUE(std::is_sorted(s.begin(), s.end()));
  }
  EXPECT_EQ(totals, (std::vector<double>{13.0, 12.0, 11.0}));
  EXPECT_EQ(shards[0], (std::vector<std::string>{"m2", "m3", "m8"}));
  // The same costs in any order give the same shards; more shards than items drop the empty ones.
  std::reverse(costs.begin(), costs.end());
  EXPECT_EQ(balance_shards(costs, 3), shards);
  EXPECT_EQ(balance_shards({{"a", 1.0}, {"b", 1.0}}, 5).size(), 2u);
}

TEST(Farm, CostsComeFromThePreviousReportAndDefaultToItsMedian) {
  const nlohmann::json previous = {{"materials",
                                    {{{"source", "a"}, {"seconds", {{"bake", 1.0}, {"render", {{"measured", 2.0}, {"ggx", 1.0}}}}}},
                                     {{"source", "b"}, {"seconds", {{"bake", 10.0}}}},
                                     {{"source", "c"}, {"seconds", {{"bake", 2.0}}}}}}};
  const auto costs = material_costs({"a", "b", "new"}, previous);
  EXPECT_DOUBLE_EQ(costs[0].second, 4.0);
  EXPECT_DOUBLE_EQ(costs[1].second, 10.0);
  EXPECT_DOUBLE_EQ(costs[2].second, 4.0);  // median of 4, 10, 2
  EXPECT_DOUBLE_EQ(material_costs({"x"}, nlohmann::json())[0].second, 1.0);
}

TEST(Farm, PlanCommandsShareTheBakeCacheAndMergeEveryPart) {
  const FarmPlan plan = plan_report_farm({"builtin:a", "builtin:b", "builtin:c"}, 2, "/r", "", {"--size", "16"}, {"--fail-on-regression"});
  ASSERT_EQ(plan.shards.size(), 2u);
  EXPECT_EQ(plan.commands[0], (std::vector<std::string>{"report", "builtin:a", "builtin:c", "-o", "/r/.farm/1", "--luts", "/r/luts", "--size", "16"}));
  EXPECT_EQ(plan.merge, (std::vector<std::string>{"report", "merge", "/r/.farm/1", "/r/.farm/2", "-o", "/r", "--fail-on-regression"}));
  EXPECT_EQ(plan_report_farm({"builtin:a"}, 1, "/r", "/cache", {}, {}).commands[0],
            (std::vector<std::string>{"report", "builtin:a", "-o", "/r/.farm/1", "--luts", "/cache"}));
}

}  // namespace
}  // namespace facetfit
