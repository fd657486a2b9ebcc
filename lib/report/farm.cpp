#include "report/farm.h"

#include <algorithm>
#include <filesystem>
#include <map>

#include "lut/record.h"

namespace facetfit {

namespace fs = std::filesystem;

std::vector<std::vector<std::string>> balance_shards(std::vector<std::pair<std::string, double>> costs, int shards) {
  std::sort(costs.begin(), costs.end(), [](const auto& a, const auto& b) { return a.second != b.second ? a.second > b.second : a.first < b.first; });
  std::vector<std::vector<std::string>> bins(std::size_t(std::max(1, shards)));
  std::vector<double> load(bins.size(), 0.0);
  for (const auto& [name, cost] : costs) {
    const std::size_t k = std::size_t(std::min_element(load.begin(), load.end()) - load.begin());  // first of the least loaded
    bins[k].push_back(name);
    load[k] += cost;
  }
  bins.erase(std::remove_if(bins.begin(), bins.end(), [](const auto& b) { return b.empty(); }), bins.end());
  for (auto& b : bins) std::sort(b.begin(), b.end());
  return bins;
}

std::vector<std::pair<std::string, double>> material_costs(const std::vector<std::string>& sources, const nlohmann::json& previous) {
  std::map<std::string, double> seen;
  if (previous.is_object() && previous.contains("materials") && previous["materials"].is_array())
    for (const auto& m : previous["materials"]) {
      if (!m.is_object() || !m.contains("source") || !m.contains("seconds")) continue;
      double total = m["seconds"].value("bake", 0.0);
      if (m["seconds"].contains("render"))
        for (const auto& [r, v] : m["seconds"]["render"].items())
          if (v.is_number()) total += v.get<double>();
      seen[m["source"].get<std::string>()] = total;
    }
  std::vector<double> known;
  for (const auto& [s, c] : seen) known.push_back(c);
  std::sort(known.begin(), known.end());
  const double fallback = known.empty() ? 1.0 : known[known.size() / 2];
  std::vector<std::pair<std::string, double>> out;
  for (const std::string& s : sources) {
    const auto it = seen.find(s);
    out.emplace_back(s, it != seen.end() && it->second > 0.0 ? it->second : fallback);
  }
  return out;
}

std::string FarmPlan::part(std::size_t k) const { return (fs::path(parts_dir) / std::to_string(k + 1)).string(); }

nlohmann::json FarmPlan::to_json() const {
  return {{"out_dir", out_dir}, {"parts_dir", parts_dir}, {"luts_dir", luts_dir}, {"shards", shards}, {"commands", commands}, {"merge", merge}};
}

FarmPlan plan_report_farm(const std::vector<std::string>& sources, int shards, const std::string& out_dir, const std::string& luts_dir,
                          const std::vector<std::string>& report_args, const std::vector<std::string>& merge_args) {
  FarmPlan plan;
  plan.out_dir = out_dir;
  plan.parts_dir = (fs::path(out_dir) / ".farm").string();
  plan.luts_dir = luts_dir.empty() ? (fs::path(out_dir) / "luts").string() : luts_dir;
  plan.shards = balance_shards(material_costs(sources, read_json_file((fs::path(out_dir) / "report.json").string())), shards);
  plan.merge = {"report", "merge"};
  for (std::size_t k = 0; k < plan.shards.size(); ++k) {
    std::vector<std::string> c = {"report"};
    c.insert(c.end(), plan.shards[k].begin(), plan.shards[k].end());
    c.insert(c.end(), {"-o", plan.part(k), "--luts", plan.luts_dir});
    c.insert(c.end(), report_args.begin(), report_args.end());
    plan.commands.push_back(std::move(c));
    plan.merge.push_back(plan.part(k));
  }
  plan.merge.insert(plan.merge.end(), {"-o", out_dir});
  plan.merge.insert(plan.merge.end(), merge_args.begin(), merge_args.end());
  return plan;
}

}  // namespace facetfit
