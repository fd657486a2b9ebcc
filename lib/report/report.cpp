#include "report/report.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <tuple>

#include "color/image_diff.h"
#include "core/error.h"
#include "fit/representations.h"
#include "io/atomic_file.h"
#include "io/folder_lock.h"
#include "io/input.h"
#include "io/sha256.h"
#include "lut/lut.h"
#include "lut/record.h"
#include "render/renderer.h"
#include "report/plots.h"

namespace facetfit {

namespace fs = std::filesystem;
using nlohmann::json;

const std::vector<std::string>& report_representations() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const RepresentationRow& r : kRepresentations) n.push_back(r.name);
    return n;
  }();
  return names;
}

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The scene every material is rendered in: the default sphere under the built-in sky.
SceneDesc report_scene(const MaterialDesc& m, const ReportOptions& o) {
  SceneDesc s = default_scene(m);
  s.camera.width = s.camera.height = o.size;
  s.spp = o.spp;
  return s;
}

// Means per representation, and the worst materials by the mean Delta E of their recommended representation.
void summarize(json& report) {
  json means = json::object();
  for (const std::string& r : report_representations()) {
    double sum = 0.0;
    int n = 0;
    for (const json& m : report["materials"])
      if (m["delta_e"].contains(r)) sum += m["delta_e"][r].get<double>(), ++n;
    means[r] = n > 0 ? json(sum / n) : json(nullptr);
  }
  report["database_mean_delta_e"] = means;
  // And the mean render time of each: what a representation costs beside what it gains.
  json seconds = json::object();
  for (const std::string& r : report_representations()) {
    double sum = 0.0;
    int n = 0;
    for (const json& m : report["materials"])
      if (m["seconds"]["render"].contains(r)) sum += m["seconds"]["render"][r].get<double>(), ++n;
    seconds[r] = n > 0 ? json(sum / n) : json(nullptr);
  }
  report["database_mean_render_seconds"] = seconds;
  // Each material's recommended representation (what a renderer is told to ship; without one in the entry,
  // its worst), the worst five materials first.
  std::vector<std::tuple<double, std::string, std::string>> worst;
  for (const json& m : report["materials"]) {
    const std::string recommended = m.value("representation", std::string());
    if (m["delta_e"].contains(recommended)) {
      worst.emplace_back(m["delta_e"][recommended].get<double>(), m["name"].get<std::string>(), recommended);
      continue;
    }
    double w = 0.0;
    std::string of;
    for (const auto& [r, v] : m["delta_e"].items())
      if (v.get<double>() >= w) w = v.get<double>(), of = r;
    worst.emplace_back(w, m["name"].get<std::string>(), of);
  }
  std::sort(worst.rbegin(), worst.rend());
  report["worst"] = json::array();
  for (std::size_t k = 0; k < std::min<std::size_t>(5, worst.size()); ++k)
    report["worst"].push_back({{"name", std::get<1>(worst[k])}, {"delta_e", std::get<0>(worst[k])}, {"representation", std::get<2>(worst[k])}});
}

// A path segment as a URL: every byte but unreserved ones (RFC 3986) percent-encoded, so '#', '%', '?' or a
// space in a material's name still links to its folder. Safe inside a quoted attribute as it is.
std::string url_segment(const std::string& s) {
  static const char* hex = "0123456789ABCDEF";
  std::string out;
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    if (std::isalnum(c) || c == '-' || c == '_' || c == '.' || c == '~') {
      out += ch;
    } else {
      out += '%';
      out += hex[c >> 4];
      out += hex[c & 15];
    }
  }
  return out;
}

std::string html_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '<') out += "&lt;";
    else if (c == '>') out += "&gt;";
    else if (c == '&') out += "&amp;";
    else if (c == '"') out += "&quot;";
    else if (c == '\'') out += "&#39;";  // the page's attributes are single-quoted
    else out += c;
  }
  return out;
}

namespace {

// An axis bound: three significant digits.
std::string axis_number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", v);
  return text;
}

// A figure of the page: two decimals (Delta E differences below 0.01 are noise at any spp).
std::string two_decimals(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2f", v);
  return text;
}

// The heatmaps' scale: viridis from 0 to kHeatmapMax, saturating beyond, as an inline SVG bar.
std::string heatmap_scale() {
  std::ostringstream s;
  s << "<svg class='heatmap-scale' width='300' height='34'><defs><linearGradient id='hm'>";
  for (int k = 0; k <= 10; ++k) {
    const auto c = heatmap_colour(kHeatmapMax * k / 10.0);
    s << "<stop offset='" << k * 10 << "%' stop-color='rgb(" << int(c[0]) << "," << int(c[1]) << "," << int(c[2]) << ")'/>";
  }
  s << "</linearGradient></defs><rect x='10' y='2' width='280' height='14' fill='url(#hm)'/>";
  for (int k = 0; k <= 2; ++k)
    s << "<text x='" << 10 + 140 * k << "' y='30' font-size='11' text-anchor='middle'>" << kHeatmapMax * k / 2 << (k == 2 ? "+" : "")
      << "</text>";
  s << "</svg>";
  return s.str();
}

}  // namespace

// Run time against error: one point per material and representation, log-scaled time.
std::string time_error_plot(const json& report) {
  double max_de = 0.1, min_t = 1e9, max_t = 1e-9;
  for (const json& m : report["materials"])
    for (const std::string& r : report_representations())
      if (m["delta_e"].contains(r)) {
        max_de = std::max(max_de, m["delta_e"][r].get<double>());
        const double t = m["seconds"]["render"][r].get<double>();
        min_t = std::min(min_t, t), max_t = std::max(max_t, t);
      }
  if (min_t > max_t) min_t = 0.1, max_t = 1.0;
  const double lo = std::log10(min_t) - 0.1, hi = std::log10(max_t) + 0.1;
  std::ostringstream svg;
  // The legend right of the plot, where no point falls.
  svg << "<svg width='660' height='300' xmlns='http://www.w3.org/2000/svg' font-size='11'>"
      << "<line x1='50' y1='260' x2='540' y2='260' stroke='black'/><line x1='50' y1='20' x2='50' y2='260' stroke='black'/>"
      << "<text x='240' y='292'>render time (s, log scale)</text><text x='4' y='14'>mean Delta E 2000</text>"
      << "<text x='50' y='275'>" << axis_number(min_t) << "</text><text x='500' y='275'>" << axis_number(max_t) << "</text>"
      << "<text x='8' y='30'>" << axis_number(max_de) << "</text>";
  for (std::size_t k = 0; k < std::size(kRepresentations); ++k) {
    const std::string r = kRepresentations[k].name;
    const char* colour = kRepresentations[k].colour;
    svg << "<text x='" << 555 << "' y='" << 30 + 14 * k << "' fill='" << colour << "'>&#9679; " << r << "</text>";
    for (const json& m : report["materials"]) {
      if (!m["delta_e"].contains(r)) continue;
      const double t = m["seconds"]["render"][r].get<double>(), de = m["delta_e"][r].get<double>();
      const double x = 50 + 490 * (std::log10(std::max(t, 1e-6)) - lo) / (hi - lo), y = 260 - 240 * de / max_de;
      svg << "<circle cx='" << x << "' cy='" << y << "' r='4' fill='" << colour << "'><title>"
          << html_escape(m["name"].get<std::string>()) << " " << r << ": " << de << "</title></circle>";
    }
  }
  svg << "</svg>";
  return svg.str();
}

namespace {

// The page's head and the run's settings.
void html_head(std::ostream& h, const json& report) {
  h << "<!doctype html><html><head><meta charset='utf-8'><title>facetfit accuracy report</title><style>"
       "body{font-family:sans-serif;margin:2em}table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:4px 8px}"
       "th{cursor:pointer;background:#eee}img{image-rendering:pixelated;width:96px;display:block}.bad{color:#b00}"
       "</style></head><body><h1>facetfit accuracy report</h1>";
  h << "<p>facetfit " << html_escape(report["facetfit_version"].get<std::string>()) << ", "
    << report["materials"].size() << " materials, " << report["settings"]["size"] << "&sup2; pixels, "
    << report["settings"]["spp"] << " spp. Mean CIE Delta E 2000 over the sphere between the render of the measurement "
    << "and of each representation, on the sRGB display of their Rec.709 colour (docs/colour.md). Pictures: "
    << html_escape(report["settings"].value("pictures", std::string("the same sRGB display"))) << ".</p>";
}

// The database's mean Delta E and render time per representation.
void html_database_mean(std::ostream& h, const json& report) {
  h << "<h2>Database mean</h2><table><tr>";
  for (const std::string& r : report_representations()) h << "<th>" << r << "</th>";
  h << "<th></th></tr>";
  for (const auto& [key, label] : {std::pair{"database_mean_delta_e", "mean &Delta;E"}, {"database_mean_render_seconds", "mean render s"}}) {
    h << "<tr>";
    for (const std::string& r : report_representations()) {
      const json& v = report.value(key, json::object()).value(r, json(nullptr));
      h << "<td>" << (v.is_null() ? std::string("-") : two_decimals(v.get<double>())) << "</td>";
    }
    h << "<td>" << label << "</td></tr>";
  }
  h << "</table>";
}

// The judgement against the baseline (regressions, removed materials) and the worst materials.
void html_judgement(std::ostream& h, const json& report) {
  const bool accepted = report.value("accepted", false);
  if (!report["regressions"].empty()) {
    h << "<h2 class='bad'>Regressions against the baseline" << (accepted ? " (accepted: the new baseline)" : "") << "</h2><ul>";
    for (const json& g : report["regressions"])
      h << "<li class='bad'>" << html_escape(g["name"].get<std::string>()) << " " << g["representation"].get<std::string>() << ": "
        << two_decimals(g["before"].get<double>()) << " &rarr; " << two_decimals(g["after"].get<double>()) << " ("
        << html_escape(g.value("cause", std::string())) << ")</li>";
    h << "</ul>";
  }
  if (!report.value("removed", json::array()).empty()) {
    h << "<h2 class='bad'>In the baseline, not in this report</h2><ul>";
    for (const json& name : report["removed"]) h << "<li class='bad'>" << html_escape(name.get<std::string>()) << "</li>";
    h << "</ul>";
  }
  h << "<h2>Worst materials</h2><ol>";
  for (const json& w : report["worst"])
    h << "<li>" << html_escape(w["name"].get<std::string>()) << ": " << two_decimals(w["delta_e"].get<double>()) << " ("
      << html_escape(w.value("representation", std::string())) << ")</li>";
  h << "</ol>";
}

// One row per material. One cell per representation: its Delta E (what a click on the header sorts by), its
// render and its Delta E map, so that the table fits a 1400-pixel window (tests/report/layout.sh).
void html_material_table(std::ostream& h, const json& report) {
  h << "<h2>Materials</h2><p>Click a column header to sort. Each representation: mean &Delta;E, render, &Delta;E map "
    << heatmap_scale() << "</p><table id='t'><tr><th>material</th><th>recommended</th><th>bake s</th><th>measured</th>";
  for (const std::string& r : report_representations()) h << "<th>" << r << "</th>";
  h << "</tr>";
  for (const json& m : report["materials"]) {
    const std::string name = html_escape(m["name"].get<std::string>()), folder = "images/" + url_segment(m["name"].get<std::string>());
    h << "<tr><td>" << name << "</td><td>" << html_escape(m.value("representation", std::string("-"))) << "</td><td>"
      << two_decimals(m["seconds"]["bake"].get<double>()) << "</td><td><img src='" << folder << "/measured.png'></td>";
    for (const std::string& r : report_representations())
      h << "<td>" << (m["delta_e"].contains(r) ? two_decimals(m["delta_e"][r].get<double>()) : std::string("-")) << "<img src='"
        << folder << "/" << r << ".png'><img src='" << folder << "/" << r << "_delta_e.png'></td>";
    h << "</tr>";
  }
  h << "</table>";
}

// Per material: the BRDF in the plane of incidence (measured solid, fits dashed), NDF, Fresnel.
void html_figures(std::ostream& h, const json& report) {
  h << "<h2>Lobes, NDF and Fresnel</h2>";
  for (const json& m : report["materials"]) {
    h << "<h3>" << html_escape(m["name"].get<std::string>()) << "</h3><p>";
    for (const char* f : {"lobes_0", "lobes_30", "lobes_60", "ndf", "fresnel"})
      h << "<img style='width:360px;image-rendering:auto' src='images/" << url_segment(m["name"].get<std::string>()) << "/" << f << ".svg'>";
    h << "</p>";
  }
}

// Implausible measurements and fits (fit/plausibility.h) per material, and the materials that failed.
void html_warnings_and_failures(std::ostream& h, const json& report) {
  bool any_warning = false;
  for (const json& m : report["materials"])
    for (const json& w : m.value("warnings", json::array())) {
      if (!any_warning) h << "<h2>Warnings</h2><ul>";
      any_warning = true;
      h << "<li>" << html_escape(m["name"].get<std::string>()) << ": " << html_escape(w.get<std::string>()) << "</li>";
    }
  if (any_warning) h << "</ul>";
  if (!report["failures"].empty()) {
    h << "<h2 class='bad'>Failures</h2><ul>";
    for (const json& f : report["failures"]) h << "<li>" << html_escape(f["error"].get<std::string>()) << "</li>";
    h << "</ul>";
  }
}

// The heat maps' legend and the script sorting the material table by a clicked column.
void html_tail(std::ostream& h) {
  h << "<p>Heatmaps: Delta E 2000 from 0 (dark) to 10 (bright), see docs/colour.md.</p>"
       "<script>document.querySelectorAll('#t th').forEach((th,c)=>th.onclick=()=>{const t=th.closest('table');"
       "const rows=[...t.rows].slice(1);const num=v=>{const x=parseFloat(v);return isNaN(x)?v:x};"
       "const dir=th.dataset.dir=th.dataset.dir==='1'?'-1':'1';rows.sort((a,b)=>{const x=num(a.cells[c].innerText),"
       "y=num(b.cells[c].innerText);return (x>y?1:x<y?-1:0)*dir});rows.forEach(r=>t.appendChild(r))});</script></body></html>";
}

}  // namespace

std::string report_html(const json& report) {
  std::ostringstream h;
  html_head(h, report);
  html_database_mean(h, report);
  html_judgement(h, report);
  h << "<h2>Run time against error</h2>" << time_error_plot(report);
  html_material_table(h, report);
  html_figures(h, report);
  html_warnings_and_failures(h, report);
  html_tail(h);
  return h.str();
}

// report.json last: its presence says the page and every image it names are whole.
void write_outputs(const json& report, const std::string& out_dir) {
  write_file_atomic((fs::path(out_dir) / "index.html").string(), report_html(report));
  write_file_atomic((fs::path(out_dir) / "report.json").string(), json_text(report, 2) + "\n");
}

// images/NAME/complete holds the key of the entry whose images are all in the folder, then a line
// "SHA-256 FILE" for each of them: written after the last of them, removed before the first is replaced,
// so that a run killed in between leaves a folder that is not reused (its images may be of other
// settings), and a file removed, emptied or replaced since makes the entry render again.
constexpr const char* kCompleteStamp = "complete";

void stamp_complete(const fs::path& images, const std::string& key, const std::vector<std::string>& files) {
  std::string stamp = key + "\n";
  for (const std::string& file : files) stamp += sha256_file((images / file).string()) + " " + file + "\n";
  write_file_atomic((images / kCompleteStamp).string(), stamp);
}

bool images_complete(const fs::path& images, const std::string& key) {
  std::ifstream in(images / kCompleteStamp);
  std::string line;
  if (!in || !std::getline(in, line) || line != key) return false;
  int files = 0;
  for (; std::getline(in, line); ++files) {
    const std::size_t space = line.find(' ');
    if (space == std::string::npos) return false;
    const fs::path file = images / line.substr(space + 1);
    std::error_code ec;
    if (!fs::is_regular_file(file, ec) || sha256_file(file.string()) != line.substr(0, space)) return false;
  }
  return files > 0;
}

}  // namespace

json baseline_of(const json& previous) {
  if (!previous.is_object()) return json::object();
  if (previous.contains("baseline") && previous["baseline"].is_object()) return previous["baseline"];
  json base = json::object();  // a report written before baselines: its own values
  for (const json& m : previous.value("materials", json::array()))
    base[m["name"].get<std::string>()] = {{"delta_e", m["delta_e"]},
                                          {"source_sha256", m.value("source_sha256", "")},
                                          {"facetfit_version", previous.value("facetfit_version", "")}};
  return base;
}

namespace {

// Why a material's figures moved: its input file, facetfit, both, or neither (the settings or noise).
std::string regression_cause(const json& before, const json& material, const std::string& version) {
  const std::string sha = before.value("source_sha256", ""), version_before = before.value("facetfit_version", "");
  const bool data = !sha.empty() && sha != material.value("source_sha256", "");
  const bool code = !version_before.empty() && version_before != version;
  if (data && code) return "input file and facetfit changed";
  if (data) return "input file changed";
  if (code) return "facetfit changed (" + version_before + " -> " + version + ")";
  return "neither input file nor facetfit changed";
}

}  // namespace

json find_regressions(const json& previous, const json& current) {
  json out = json::array();
  const json base = baseline_of(previous);
  const std::string version = current.value("facetfit_version", "");
  for (const json& m : current["materials"]) {
    const auto it = base.find(m["name"].get<std::string>());
    if (it == base.end()) continue;
    const json& before = (*it)["delta_e"];
    for (const auto& [r, v] : m["delta_e"].items()) {
      if (!before.contains(r)) continue;
      const double a = before[r].get<double>(), b = v.get<double>();
      if (b > a * 1.1 && b > a + 0.1)
        out.push_back({{"name", m["name"]}, {"representation", r}, {"before", a}, {"after", b}, {"cause", regression_cause(*it, m, version)}});
    }
  }
  return out;
}

void judge_against_baseline(const json& previous, json& report, bool accept) {
  report["regressions"] = find_regressions(previous, report);
  json base = baseline_of(previous);
  std::set<std::string> regressed, present;
  for (const json& g : report["regressions"]) regressed.insert(g["name"].get<std::string>());
  // A material that failed this run is not removed: its baseline stays, and the failure says what happened.
  for (const json& f : report.value("failures", json::array()))
    if (f.contains("source")) present.insert(source_name(f["source"].get<std::string>()));
  for (const json& m : report["materials"]) {
    const std::string name = m["name"].get<std::string>();
    present.insert(name);
    if (accept || !regressed.count(name))
      base[name] = {{"delta_e", m["delta_e"]}, {"source_sha256", m.value("source_sha256", "")}, {"facetfit_version", report["facetfit_version"]}};
  }
  report["removed"] = json::array();
  for (auto it = base.begin(); it != base.end();) {
    if (present.count(it.key())) {
      ++it;
    } else if (accept) {
      it = base.erase(it);
    } else {
      report["removed"].push_back(it.key());
      ++it;
    }
  }
  report["baseline"] = base;
  report["accepted"] = accept;
}

namespace {

// A report writes only inside its folder: a folder of it that is a symbolic link (planted, or made by
// another tool) would take its writes, and its clean-up of stale temporaries, elsewhere.
void refuse_link(const fs::path& p) {
  std::error_code ec;
  if (fs::is_symlink(p, ec)) fail(p.string(), "is a symbolic link; a report writes only into folders of its own");
}

// The report folder's images/, created and held for the whole run: a second report or merge into the same
// folder is refused at once rather than mixing its files with this one's (the LUTs' folder has its own lock,
// taken per bake).
FolderLock lock_report(const fs::path& out_dir) {
  const fs::path images = out_dir / "images";
  refuse_link(images);
  std::error_code ec;
  fs::create_directories(images, ec);
  if (!fs::is_directory(images)) fail(images.string(), "cannot create folder" + (ec ? ": " + ec.message() : std::string()));
  return FolderLock(images.string(), FolderLock::Wait::no);
}

// The report's folders, made: OUT and its LUTs' folder (OUT/luts unless --luts), never through a link.
void make_report_folders(const ReportOptions& o, const fs::path& luts) {
  std::error_code ec;
  refuse_link(fs::path(o.out_dir) / "images");
  if (o.luts_dir.empty()) refuse_link(luts);  // a --luts folder is the user's to place
  fs::create_directories(fs::path(o.out_dir), ec);
  fs::create_directories(luts, ec);
  if (!fs::is_directory(o.out_dir) || !fs::is_directory(luts))
    fail(fs::is_directory(o.out_dir) ? luts.string() : o.out_dir, "cannot create folder" + (ec ? ": " + ec.message() : std::string()));
}

// Under the report's lock: the LUTs' folder checked, stale temporaries of a killed run removed.
void clean_report_folders(const ReportOptions& o, const fs::path& luts) {
  std::error_code ec;
  // Each bake locks the LUTs' folder: in the report's images/ it would wait on the report's own lock.
  if (fs::equivalent(luts, fs::path(o.out_dir) / "images", ec))
    fail(luts.string(), "is the report's images folder: give --luts another folder");
  remove_stale_temporaries(o.out_dir);
  remove_stale_temporaries(luts.string());
  for (const auto& entry : fs::directory_iterator(fs::path(o.out_dir) / "images", ec))
    if (!entry.is_symlink(ec) && entry.is_directory(ec)) remove_stale_temporaries(entry.path().string());
}

// The previous run's entries by name: reused where their key is unchanged.
std::map<std::string, json> reusable_entries(const json& previous) {
  std::map<std::string, json> reusable;
  if (previous.is_object() && previous.contains("materials"))
    for (const json& m : previous["materials"]) reusable[m["name"].get<std::string>()] = m;
  return reusable;
}

// A new report's head: version, settings, shard, empty lists.
json report_head(const ReportOptions& o) {
  json report;
  report["facetfit_version"] = FACETFIT_VERSION;
  report["settings"] = {{"size", o.size}, {"spp", o.spp}, {"smith", to_string(o.bake.fit.smith)}, {"resolution", o.bake.fit.resolution},
                        {"tolerance", o.bake.tolerance}};
  if (o.pictures) report["settings"]["pictures"] = o.pictures_name;
  report["shard"] = std::to_string(o.shard) + "/" + std::to_string(o.shards);
  report["materials"] = json::array();
  report["failures"] = json::array();
  return report;
}

// One material's renders: the measurement and each representation of its LUT, their pictures, Delta E and
// heat maps, and the paper's figures, into `images`; the entry's figures added to `entry`.
void render_material(const ReportOptions& o, const DisplayTransform& display, const std::string& source, const std::string& lut,
                     const fs::path& images, const std::string& key, json& entry) {
  const auto render_as = [&](const std::string& type, const std::string& file) {
    MaterialDesc m;
    m.type = type;
    m.file = file;
    if (type == "measured") m.proposal = lut;  // the bake's fit, not a second one
    RenderSettings settings;
    settings.max_memory = o.max_memory;
    return render(report_scene(m, o), settings);
  };
  const DisplayTransform& pictures = o.pictures ? *o.pictures : display;
  std::vector<std::string> written;  // the entry's files, for its stamp
  const auto image = [&](const std::string& file) { return (images / written.emplace_back(file)).string(); };
  const RenderedImage measured = render_as("measured", source);
  entry["seconds"]["render"]["measured"] = measured.seconds;
  write_display_png(image("measured.png"), measured.rgba.data(), measured.width, measured.height, 4, pictures);
  std::vector<bool> mask(std::size_t(measured.width) * measured.height);
  for (std::size_t p = 0; p < mask.size(); ++p) mask[p] = measured.rgba[p * 4 + 3] >= 1.0f;  // the sphere
  for (const RepresentationRow& row : kRepresentations) {
    const std::string r = row.name;
    const RenderedImage img = render_as(row.material_type, lut);
    entry["seconds"]["render"][r] = img.seconds;
    write_display_png(image(r + ".png"), img.rgba.data(), img.width, img.height, 4, pictures);
    const ImageDiff diff = image_delta_e(measured.rgb(), false, img.rgb(), false, mask, display);
    entry["delta_e"][r] = diff.mean;
    entry["max_delta_e"][r] = diff.max;
    write_heatmap_png(image(r + "_delta_e.png"), img.width, img.height, diff.delta_e, mask);
  }
  // The figures the paper validates fits with: lobes in the plane of incidence, NDF, Fresnel.
  const HalfDiffTable table = load_table(source, o.bake.fit.merl_bins);
  for (const auto& [file, svg] : material_figures(table, read_lut(lut))) write_file_atomic(image(file), svg);
  stamp_complete(images, key, written);
}

// What happened to one material in a run, for the progress line.
enum class MaterialRun { rendered, reused };

// One material of the report: baked (or found baked), then its previous entry reused where its key (the bake,
// the render settings and facetfit) is unchanged and its images complete, else rendered again.
MaterialRun report_material(const ReportOptions& o, const DisplayTransform& display, const std::string& source, const fs::path& luts,
                            const Fitter& fitter, const std::map<std::string, json>& reusable, json& report) {
  const std::string name = source_name(source);
  const fs::path images = fs::path(o.out_dir) / "images" / name;
  const auto bake_start = std::chrono::steady_clock::now();
  const BakeOutcome baked = bake_material(source, name, luts.string(), o.bake, fitter);
  if (baked.status == BakeOutcome::Status::failed) throw Error(baked.error);
  const double bake_seconds = seconds_since(bake_start);
  const std::string key_text = baked.record["cache_key"].get<std::string>() + "|" + json_text(report["settings"]) + "|" + FACETFIT_VERSION;
  const std::string key = sha256_hex(key_text.data(), key_text.size());
  const auto old = reusable.find(name);
  if (!o.force && old != reusable.end() && old->second.value("key", "") == key && images_complete(images, key)) {
    report["materials"].push_back(old->second);
    return MaterialRun::reused;
  }
  refuse_link(images);
  std::error_code ec;
  fs::create_directories(images, ec);
  fs::remove(images / kCompleteStamp, ec);
  json entry;
  entry["name"] = name;
  entry["source"] = source;
  entry["key"] = key;
  entry["source_sha256"] = baked.record.value("source_sha256", "");
  entry["representation"] = baked.record["representation"];
  entry["warnings"] = baked.record.value("warnings", json::array());
  entry["seconds"]["bake"] = bake_seconds;
  render_material(o, display, source, (luts / (name + ".exr")).string(), images, key, entry);
  report["materials"].push_back(entry);
  return MaterialRun::rendered;
}

// This shard's inputs: a deterministic subset of all the inputs, sorted.
std::vector<std::string> shard_inputs(const std::vector<std::string>& inputs, const ReportOptions& o) {
  std::vector<std::string> mine;
  for (std::size_t k = 0; k < inputs.size(); ++k)
    if (int(k % std::size_t(o.shards)) == o.shard - 1) mine.push_back(inputs[k]);
  return mine;
}

}  // namespace

json run_report(const ReportOptions& o) {
  const fs::path luts = o.luts_dir.empty() ? fs::path(o.out_dir) / "luts" : fs::path(o.luts_dir);
  make_report_folders(o, luts);
  const FolderLock lock = lock_report(o.out_dir);
  clean_report_folders(o, luts);
  const json previous = read_json_file((fs::path(o.out_dir) / "report.json").string());
  const std::map<std::string, json> reusable = reusable_entries(previous);
  std::vector<std::string> inputs = expand_inputs(o.inputs.empty() ? std::vector<std::string>{kBuiltinPrefix} : o.inputs);
  std::sort(inputs.begin(), inputs.end());
  const std::vector<std::string> mine = shard_inputs(inputs, o);
  // Names must be unique over all the inputs (every shard sees the same owner): a second input of the same
  // stem is a failure, not a second row over the first one's images and LUT.
  std::map<std::string, std::string> owner;
  for (const std::string& source : inputs) owner.emplace(source_name(source), source);

  json report = report_head(o);
  const Fitter fitter(o.bake.fit);
  const DisplayTransform display;  // the sRGB display, through which Delta E is measured
  std::size_t done = 0;
  for (const std::string& source : mine) {
    const std::string name = source_name(source);
    std::string what;
    try {
      if (owner.at(name) != source) fail(source, "output name " + name + " is already taken by " + owner.at(name));
      what = report_material(o, display, source, luts, fitter, reusable, report) == MaterialRun::reused ? "reused" : "rendered";
    } catch (const Error& e) {
      report["failures"].push_back({{"source", source}, {"error", e.what()}});
      what = "failed";
    }
    if (o.progress) o.progress(name, what, ++done, mine.size());
  }
  summarize(report);
  judge_against_baseline(previous, report, o.accept);
  write_outputs(report, o.out_dir);
  return report;
}

namespace {

// Every part of a merge, read and checked before anything is written: a refused merge leaves no output. No
// material may come from two parts (a shard given twice), and the shards of a K/N split must all be there; a
// farm's parts are whole reports of disjoint lists (1/1) and cannot be checked for that.
std::vector<json> read_parts(const std::vector<std::string>& parts) {
  std::vector<json> reports;
  std::map<std::string, std::string> from_part;  // material name -> the part holding it
  std::map<int, std::vector<int>> shards_of;      // N -> the K given
  for (const std::string& part : parts) {
    const fs::path file = fs::path(part) / "report.json";
    std::error_code ec;
    if (!fs::exists(file, ec)) fail(part, "no report.json (not a facetfit report folder)");
    const json r = read_json_file(file.string());
    if (!r.is_object() || !r.contains("materials") || !r["materials"].is_array())
      fail(file.string(), "not a facetfit report (unreadable JSON or no \"materials\" list)");
    if (!reports.empty() && reports.front()["settings"] != r["settings"])
      fail(file.string(), "rendered with other settings than " + parts.front());
    for (const json& m : r["materials"]) {
      if (!m.is_object() || !m.contains("name") || !m["name"].is_string()) fail(file.string(), "a material without a \"name\" string");
      const std::string name = m["name"].get<std::string>();
      // A name becomes a folder of the merged report: a path would write outside it.
      if (const std::string problem = output_name_problem(name); !problem.empty())
        fail(file.string(), "material name \"" + excerpt(name, 60) + "\" " + problem);
      if (const auto [at, added] = from_part.emplace(name, part); !added)
        fail(part, "material " + name + " is also in " + at->second + " (a part given twice?)");
    }
    int k = 0, n = 0;
    if (std::sscanf(r.value("shard", std::string()).c_str(), "%d/%d", &k, &n) == 2 && n > 1 && k >= 1 && k <= n)
      shards_of[n].push_back(k);
    reports.push_back(r);
  }
  for (auto& [n, ks] : shards_of) {
    std::sort(ks.begin(), ks.end());
    for (int k = 1; k <= n; ++k)
      if (!std::binary_search(ks.begin(), ks.end(), k))
        fail(parts.front(), "shard " + std::to_string(k) + "/" + std::to_string(n) + " of its split is not among the parts");
  }
  return reports;
}

// The parts' entries and failures in one report, sorted by name, their images copied into `images`.
json join_parts(const std::vector<json>& reports, const std::vector<std::string>& parts, const fs::path& images) {
  std::error_code ec;
  json merged;
  merged["materials"] = json::array();
  merged["failures"] = json::array();
  for (std::size_t p = 0; p < parts.size(); ++p) {
    const json& r = reports[p];
    merged["facetfit_version"] = r["facetfit_version"];
    merged["settings"] = r["settings"];
    for (const json& m : r["materials"]) {
      merged["materials"].push_back(m);
      const fs::path from = fs::path(parts[p]) / "images" / m["name"].get<std::string>(), to = images / m["name"].get<std::string>();
      fs::copy(from, to, fs::copy_options::recursive | fs::copy_options::overwrite_existing, ec);
      if (ec) fail(to.string(), "cannot copy images from " + from.string() + ": " + ec.message());
    }
    for (const json& f : r.value("failures", json::array())) merged["failures"].push_back(f);
  }
  std::sort(merged["materials"].begin(), merged["materials"].end(),
            [](const json& a, const json& b) { return a["name"].get<std::string>() < b["name"].get<std::string>(); });
  merged["shard"] = "merged";
  return merged;
}

}  // namespace

json merge_reports(const std::vector<std::string>& parts, const std::string& out_dir, bool accept) {
  const std::vector<json> reports = read_parts(parts);
  prepare_output_folder(out_dir);
  const FolderLock lock = lock_report(out_dir);
  const fs::path images = fs::path(out_dir) / "images";
  for (const json& r : reports)
    for (const json& m : r["materials"]) refuse_link(images / m["name"].get<std::string>());
  const json previous = read_json_file((fs::path(out_dir) / "report.json").string());
  json merged = join_parts(reports, parts, images);
  summarize(merged);
  judge_against_baseline(previous, merged, accept);
  write_outputs(merged, out_dir);
  return merged;
}

}  // namespace facetfit
