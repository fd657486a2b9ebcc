// Writes docs/accuracy.md: every figure there comes from this program (`make accuracy`).
#include <algorithm>
#include <chrono>
#include <cstdarg>
#include <filesystem>
#include <memory>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>

#include "core/error.h"
#include "fit/extract.h"
#include "fit/fit.h"
#include "support/ground_truth.h"
#include "support/tensor_file.h"
#include "fit/roughness.h"
#include "io/atomic_file.h"
#include "io/input.h"
#include "io/rgl.h"
#include "io/utia.h"
#include "model/analytic.h"

namespace facetfit {
namespace {

std::string format(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
std::string format(const char* fmt, ...) {
  char buf[512];
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(buf, sizeof buf, fmt, args);
  va_end(args);
  return buf;
}

Fitter fitter_for(Smith smith, int resolution = 90, int max_iterations = 1000) {
  FitOptions options = FitOptions::paper();
  options.smith = smith;
  options.resolution = resolution;
  options.max_iterations = max_iterations;
  return Fitter(options);
}

void ground_truth_section(std::ostringstream& md) {
  md << "## Ground truth: analytic materials through the MERL writer\n\n"
        "Each material is GGX or Beckmann with gold's conductor Fresnel, made with the Smith model in the "
        "first column, written as a MERL `.binary`, read back and fitted with the matching `--smith` at "
        "resolution 90. Bars (tests/fit/test_accuracy.cpp): alpha within 0.5% (1.5% at 0.02), D within 1% "
        "relative L1 weighted by projected area, Fresnel within 0.005 for theta_d <= 80 degrees.\n\n"
        "| NDF | smith | alpha | fitted alpha | alpha error | D L1 error | max Fresnel error | iterations |\n"
        "|---|---|---|---|---|---|---|---|\n";
  const std::string tmp = "/tmp/facetfit-accuracy.binary";
  double worst_alpha = 0, worst_l1 = 0, worst_f = 0;
  for (const GroundTruthCase& c : standard_ground_truth_cases()) {
    const GroundTruthError e = measure_ground_truth(c, fitter_for(c.smith), tmp);
    md << format("| %s | %s | %.2f | %.5f | %+.3f%% | %.3f%% | %.5f | %d |\n", to_string(c.type), to_string(c.smith), c.alpha,
                 e.alpha, 100 * e.alpha_relative, 100 * e.ndf_l1, e.fresnel_abs, e.iterations);
    worst_alpha = std::max(worst_alpha, std::abs(e.alpha_relative));
    worst_l1 = std::max(worst_l1, e.ndf_l1);
    worst_f = std::max(worst_f, e.fresnel_abs);
  }
  std::remove(tmp.c_str());
  md << format("\nWorst over the table: alpha %.3f%%, D %.3f%%, Fresnel %.5f.\n\n", 100 * worst_alpha, 100 * worst_l1, worst_f);
}

void consistency_section(std::ostringstream& md) {
  md << "## Extract with the Smith model you render with\n\n"
        "Data made with the height-correlated Smith model (what pbrt-v4 and Cycles render), fitted with "
        "the paper's masking assumption as the reference implementation does, and with `--smith "
        "correlated`. Fitted alpha of the material's own NDF family:\n\n"
        "| NDF | alpha | `--smith masking` | error | `--smith correlated` | error |\n|---|---|---|---|---|---|\n";
  const Fitter masking = fitter_for(Smith::masking), correlated = fitter_for(Smith::correlated);
  for (NdfType type : {NdfType::ggx, NdfType::beckmann})
    for (double alpha : {0.1, 0.4, 0.7, 1.0}) {
      const GroundTruthCase c{type, alpha, Smith::correlated, Fresnel::schlick(Rgb(0.9))};
      const GroundTruthError a = measure_ground_truth(c, masking), b = measure_ground_truth(c, correlated);
      md << format("| %s | %.1f | %.4f | %+.1f%% | %.4f | %+.3f%% |\n", to_string(type), alpha, a.alpha, 100 * a.alpha_relative,
                   b.alpha, 100 * b.alpha_relative);
    }
  md << "\n";
}

void iterations_section(std::ostringstream& md) {
  md << "## Iterate to a tolerance\n\n"
        "The reference implementation runs four iterations. Residual (relative L1 change of D in the last "
        "iteration) and alpha error after 4 iterations and at convergence (tolerance 1e-10), GGX, "
        "height-correlated:\n\n"
        "| alpha | residual after 4 | alpha error after 4 | iterations to converge | alpha error converged |\n"
        "|---|---|---|---|---|\n";
  for (double alpha : {0.05, 0.2, 0.7, 1.0, 1.5}) {
    const GroundTruthCase c{NdfType::ggx, alpha, Smith::correlated, Fresnel::one()};
    const GroundTruthError four = measure_ground_truth(c, fitter_for(Smith::correlated, 90, 4));
    const GroundTruthError full = measure_ground_truth(c, fitter_for(Smith::correlated));
    md << format("| %.2f | %.1e | %+.3f%% | %d | %+.4f%% |\n", alpha, four.residual, 100 * four.alpha_relative, full.iterations,
                 100 * full.alpha_relative);
  }
  md << "\n";
}

void anisotropic_section(std::ostringstream& md, const std::string& scratch) {
  md << "## Anisotropic ground truth: the 2D extraction\n\n"
        "Analytic NDFs with F = 1 and their axes turned (fit/extract_2d.h, tests/support/ground_truth.h): principal "
        "alphas, angle and D (projected-area weighted relative L1 at the grid's nodes) from the back-scattering. Dense: "
        "the analytic back-scattering at MERL's 90 theta_h bins on a 90 x 64 grid, bars 1% and 0.5 degree "
        "(tests/fit/test_extract_2d.cpp). UTIA: written by facetfit's UTIA writer and read back, six polar angles 15 degrees "
        "apart, masking form, 90 x 48 grid, bar 3% for alpha >= 0.2 (tests/io/test_utia.cpp). RGL: the dense cases written "
        "as an anisotropic RGL tensor file by the tests' writer (tests/support/tensor_file.h: 25 x 48 slices, 64 x 64 RGB "
        "nodes warped toward grazing half vectors) and read back through the file's evaluation at 90 polar angles x 64 "
        "azimuths, bar 1% (tests/io/test_rgl.cpp). The writer's resolution near grazing decides GGX, whose long tail weighs "
        "grazing back-scattering: on an unwarped 64-node square with 32 slices it came back 1.4-3.2% low.\n\n"
        "| input | NDF | smith | alpha_x, alpha_y, angle | fitted | alpha_x error | alpha_y error | angle error | D L1 |\n"
        "|---|---|---|---|---|---|---|---|---|\n";
  const auto row = [&](const char* input, const AnisotropicCase& c, const AnisotropicError& e) {
    md << format("| %s | %s | %s | %.2f, %.2f, %.0f deg | %.4f, %.4f, %.2f deg | %+.2f%% | %+.2f%% | %+.3f deg | %.3f%% |\n", input,
                 to_string(c.type), to_string(c.smith), c.alpha_x, c.alpha_y, c.angle_degrees, e.fitted.alpha_x, e.fitted.alpha_y,
                 e.fitted.angle * 180.0 / kPi, 100 * e.alpha_x_relative, 100 * e.alpha_y_relative, e.angle_degrees, 100 * e.ndf_l1);
  };
  const Quadrature2D dense(90, 64), utia(90, 48);
  for (const AnisotropicCase& c : dense_anisotropic_cases()) row("dense", c, measure_anisotropic(c, dense));
  for (const AnisotropicCase& c : utia_anisotropic_cases()) row("UTIA", c, measure_anisotropic(c, utia, AnisotropicInput::utia, scratch));
  for (const AnisotropicCase& c : dense_anisotropic_cases()) row("RGL", c, measure_anisotropic(c, dense, AnisotropicInput::rgl, scratch + ".bsdf"));
  md << "\n";
}

// UTIA files through the isotropic fit (io/input.h): the table is the file's azimuthal mean, the
// back-scattering read at the file's own six polar angles (or, for comparison, from the table between them),
// and the 2D extraction beside it (FitResult::anisotropic).
void utia_fit_section(std::ostringstream& md, const std::string& scratch) {
  md << "## UTIA files through the fit\n\n"
        "GGX written by facetfit's UTIA writer (Schlick Fresnel), read as `fit` reads a `.bin` file: the isotropic "
        "fit of its azimuthal mean, back-scattering from the file's six diagonal polar angles (`lattice`) or from "
        "the mean's table between them (`table`, for comparison), and the 2D extraction's principal alphas and "
        "angle (tests/fit/test_accuracy.cpp, Utia.LoadsAsItsAzimuthalMeanForTheIsotropicFit).\n\n"
        "| written | smith | isotropic alpha_ggx: lattice | table | anisotropic: alpha_x, alpha_y, angle |\n"
        "|---|---|---|---|---|\n";
  struct Case {
    double alpha_x, alpha_y, degrees;
    Smith smith;
  };
  for (const Case& c : {Case{0.3, 0.3, 0.0, Smith::masking}, Case{0.6, 0.6, 0.0, Smith::correlated},
                        Case{0.45, 0.2, 34.38, Smith::masking}}) {
    const MicrofacetBrdf brdf(Ndf{NdfType::ggx, c.alpha_x, c.alpha_y}, c.smith, Fresnel::schlick(Rgb(0.9, 0.6, 0.3)));
    UtiaBrdf::tabulate(RotatedBrdf(brdf, c.degrees * kPi / 180.0)).write(scratch);
    const HalfDiffTable table = load_table(scratch);
    HalfDiffTable without = table;
    without.set_source_backscatter({});
    const Fitter fitter = fitter_for(c.smith, 90);
    const FitResult fit = fitter.fit(table), from_table = fitter.fit(without);
    if (!fit.ok() || !from_table.ok() || !fit.anisotropic) throw Error("UTIA fit failed: " + fit.problem + from_table.problem);
    const AnisotropicAlpha& a = fit.anisotropic->alpha_ggx;
    // An isotropic lobe has no axis: its angle is whatever the eigen-decomposition returns.
    const std::string angle = a.alpha_x > 1.001 * a.alpha_y ? format("%.2f deg", a.angle * 180.0 / kPi) : "no axis (isotropic)";
    md << format("| %.2f x %.2f at %.1f deg | %s | %.4f | %.4f | %.4f, %.4f, %s |\n", c.alpha_x, c.alpha_y, c.degrees, to_string(c.smith),
                 fit.alpha_ggx, from_table.alpha_ggx, a.alpha_x, a.alpha_y, angle.c_str());
  }
  md << "\n";
}

// The anisotropic lobes with a body fitted on the whole file (--refine full; fit/parametric_fit.h) beside
// the 2D extraction's moment alphas, for anisotropic materials written as UTIA and RGL files.
void anisotropic_lobe_section(std::ostringstream& md, const std::string& scratch) {
  md << "## Anisotropic lobes with a body, fitted on the whole file\n\n"
        "The default fit (`--refine full`) of anisotropic materials written by facetfit's UTIA writer and the tests' RGL "
        "tensor writer (F = 1, no body: the format stores a microfacet lobe): the 2D extraction's moment estimates "
        "(no body: a body broadens them) and the anisotropic GGX lobe with a body and F82-tint Fresnel fitted on the "
        "file: a UTIA file at its node pairs, an RGL file on a half/difference lattice read through its evaluation "
        "(docs/conventions.md). Height-correlated Smith (tests/fit/test_refine.cpp).\n\n"
        "| file | written: GGX alpha_x, alpha_y, angle; body; f0 | moments: alpha_x, alpha_y, angle | fitted: alpha_x, alpha_y, angle | body | f0 | distance |\n"
        "|---|---|---|---|---|---|---|\n";
  FitOptions options;
  const Fitter fitter(options);
  const auto row = [&](const char* input, const std::string& path, const std::string& written) {
    const FitResult fit = fitter.fit(load_table(path));
    if (!fit.ok() || !fit.anisotropic) throw Error(path + ": no anisotropic fit: " + fit.problem);
    const AnisotropicFit& a = *fit.anisotropic;
    const auto deg = [](double r) { return r * 180.0 / kPi; };
    md << format("| %s | %s | %.3f, %.3f, %.2f deg | %.4f, %.4f, %.2f deg | %.3f %.3f %.3f | %.3f %.3f %.3f | %.4f |\n", input, written.c_str(),
                 a.alpha_ggx.alpha_x, a.alpha_ggx.alpha_y, deg(a.alpha_ggx.angle), a.ggx.alpha.alpha_x, a.ggx.alpha.alpha_y,
                 deg(a.ggx.alpha.angle), a.ggx.body.r, a.ggx.body.g, a.ggx.body.b, a.ggx.f0.r, a.ggx.f0.g, a.ggx.f0.b, a.ggx.error);
  };
  const Rgb f0(0.9, 0.6, 0.3);
  for (const Rgb& albedo : {Rgb(0.0), Rgb(0.4, 0.25, 0.1)}) {
    const auto lobe = std::make_shared<MicrofacetBrdf>(Ndf{NdfType::ggx, 0.45, 0.2}, Smith::correlated, Fresnel::schlick(f0));
    const SumBrdf material({std::make_shared<LambertBrdf>(albedo), lobe});
    UtiaBrdf::tabulate(RotatedBrdf(material, 0.6)).write(scratch);
    row("UTIA", scratch, format("0.45, 0.2, 34.38 deg; %.2f %.2f %.2f; 0.9 0.6 0.3", albedo.r, albedo.g, albedo.b));
  }
  const std::vector<unsigned char> bytes =
      test::serialize(test::microfacet_tensor_fields(Ndf{NdfType::ggx, 0.45, 0.25}, Smith::correlated, 30.0 * kPi / 180.0, 25, 32, 64));
  write_file_atomic(scratch + ".bsdf", std::string(bytes.begin(), bytes.end()));
  row("RGL", scratch + ".bsdf", "0.45, 0.25, 30 deg; 0; 1");
  md << "\n";
}

void resolution_section(std::ostringstream& md) {
  md << "## Run time against error: grid resolution\n\n"
        "GGX, height-correlated, gold Fresnel. Fit time is the paper's fit (extraction + Fresnel pass + both "
        "alphas) and the distances of its representations from the measurement (bins and directional albedo, "
        "fit/measurement.h: most of the time) on a loaded table, median of 9 runs on this machine (2 cores); the quadrature of each resolution is "
        "built once per batch and not counted (see docs/benchmarks.md).\n\n"
        "| resolution | alpha 0.02: alpha error | D error | alpha 0.7: alpha error | D error | fit ms |\n"
        "|---|---|---|---|---|---|\n";
  for (int resolution : {16, 32, 64, 90, 128, 256}) {
    const Fitter fitter = fitter_for(Smith::correlated, resolution);
    const Fresnel gold = Fresnel::conductor({0.143, 0.374, 1.442}, {3.983, 2.385, 1.603});
    const GroundTruthError smooth = measure_ground_truth({NdfType::ggx, 0.02, Smith::correlated, gold}, fitter);
    const GroundTruthError rough = measure_ground_truth({NdfType::ggx, 0.7, Smith::correlated, gold}, fitter);
    const HalfDiffTable table = HalfDiffTable::tabulate(MicrofacetBrdf(Ndf::isotropic(NdfType::ggx, 0.7), Smith::correlated, gold));
    std::vector<double> ms;
    for (int r = 0; r < 9; ++r) {
      const auto start = std::chrono::steady_clock::now();
      const FitResult fit = fitter.fit(table);
      ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
      if (!fit.ok()) fail("resolution " + std::to_string(resolution), fit.problem);
    }
    std::nth_element(ms.begin(), ms.begin() + 4, ms.end());
    md << format("| %d | %+.3f%% | %.3f%% | %+.4f%% | %.4f%% | %.2f |\n", resolution, 100 * smooth.alpha_relative,
                 100 * smooth.ndf_l1, 100 * rough.alpha_relative, 100 * rough.ndf_l1, ms[4]);
  }
  md << "\n";
}

// f(k, k) of the green channel per theta_h bin, as backscatter_of does for luminance.
Backscatter green_backscatter(const HalfDiffTable& table) {
  Backscatter back;
  for (int i = 0; i < HalfDiffTable::kThetaH; ++i) {
    const float* row = table.channel(1) + HalfDiffTable::index(i, 0, 0);
    double sum = 0.0;
    int n = 0;
    for (int k = 0; k < HalfDiffTable::kPhiD; ++k)
      if (!HalfDiffTable::missing(row[k])) sum += row[k], ++n;
    if (n == 0) continue;
    back.theta.push_back(HalfDiffTable::theta_h(i));
    back.value.push_back(sum / n);
  }
  return back;
}

// The RGB table's value at exact retro-reflection, as luminance: the format stores
// f(k, o) cos(theta_o) / (D(h) / (4 sigma(k))), so at o = k it is f(k,k) cos 4 sigma / D_file.
// Under the masking power iteration D_file is reproduced exactly when this is constant.
double retro_rgb(const RglBsdf& b, double theta) {
  const Vec3 k = spherical_direction(theta, 0.0);
  return luminance(*b.eval(k, k)) * std::cos(theta) * 4.0 * b.measured_sigma(theta) / b.measured_ndf(theta);
}

// The NDF that the normal-incidence slice implies, up to a constant: f(n, o) = F D(h) G1(o) / (4 cos o)
// for any Smith model (G1(n) = 1), so D(h) ~ f(n, o) sigma(o) with theta_o = 2 theta_h (Fresnel taken
// constant for theta_d = theta_h <= 30 degrees). No back-scattering involved.
double normal_incidence_ndf(const RglBsdf& b, double theta_h) {
  const Vec3 n(0.0, 0.0, 1.0), o = spherical_direction(2.0 * theta_h, 0.0);
  return luminance(*b.eval(o, n)) * b.measured_sigma(2.0 * theta_h);
}

void rgl_section(std::ostringstream& md, const std::string& folder) {
  md << "## Real measurements: RGL database NDF against the file's own `ndf`\n\n";
  namespace fs = std::filesystem;
  std::error_code ec;
  if (folder.empty() || !fs::is_directory(folder, ec)) {
    md << "Not measured: the RGL folder (`../shared/data/rgl`) was absent when this page was generated.\n\n";
    return;
  }
  md << "Each `.bsdf` is evaluated in RGB behind the BRDF interface, tabulated in MERL layout and fitted; the "
        "extracted NDF is compared with the `ndf` field the acquisition measured (relative L1, projected-area "
        "weighted; the issue's bar is 5%), for each `--smith`, and with `--smith masking` on the green channel "
        "instead of luminance (the acquisition's back-scattering measurement is monochromatic, at 532 nm as "
        "NVIDIA Falcor's re-implementation of the pipeline notes). Fitted GGX alpha and the ratio of extracted "
        "to file D at 0, 30 and 60 degrees with `--smith masking` (the form of the acquisition's own power "
        "iteration).\n\n"
        "| material | alpha_ggx | masking | correlated | separable | masking, green | D ratio 0 deg | 30 deg | 60 deg |\n"
        "|---|---|---|---|---|---|---|---|---|\n";
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(folder, ec))
    if (e.path().extension() == ".bsdf") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  std::ostringstream why;
  for (const fs::path& file : files) {
    const RglBsdf bsdf = RglBsdf::read(file.string());
    const HalfDiffTable table = HalfDiffTable::tabulate(bsdf);
    const auto file_ndf = [&](double theta) { return bsdf.measured_ndf(theta); };
    md << "| " << file.stem().string();
    std::string errors;
    double alpha = 0.0;
    std::string ratios;
    for (Smith smith : {Smith::masking, Smith::correlated, Smith::separable}) {
      const Fitter fitter = fitter_for(smith);
      const FitResult fit = fitter.fit(table);
      if (smith == Smith::correlated) alpha = fit.alpha_ggx;
      if (smith == Smith::masking)
        for (double deg : {0.0, 30.0, 60.0}) {
          const double theta = deg * kPi / 180.0;
          ratios += format(" | %.2f", fit.ndf().D(theta) / bsdf.measured_ndf(theta));
        }
      const double d = ndf_distance(fitter.quadrature(), file_ndf, [&](double theta) { return fit.ndf().D(theta); });
      errors += format(" | %.1f%%", 100 * d);
    }
    const Fitter masking = fitter_for(Smith::masking);
    const Extraction green = extract_ndf(green_backscatter(table), masking.quadrature(), {Smith::masking, 1e-10, 1000});
    if (!green.problem.empty()) fail(file.string(), green.problem);
    errors += format(" | %.1f%%", 100 * ndf_distance(masking.quadrature(), file_ndf, [&](double theta) { return green.ndf.D(theta); }));
    md << format(" | %.4f", alpha) << errors << ratios << " |\n";

    const RglBsdf::Consistency c = bsdf.self_consistency();
    const std::vector<double>& slices = bsdf.slice_elevations();
    why << "| " << file.stem().string() << format(" | %.1e | %.1e", c.sigma_error, c.vndf_error);
    const double retro0 = retro_rgb(bsdf, 0.0);
    for (std::size_t s = 1; s <= 3 && s < slices.size(); ++s)
      why << format(" | %.2f (%.0f)", retro_rgb(bsdf, slices[s]) / retro0, slices[s] * 180.0 / kPi);
    const double normal0 = normal_incidence_ndf(bsdf, 0.0) / bsdf.measured_ndf(0.0);
    for (double deg : {10.0, 20.0, 30.0}) {
      const double theta = deg * kPi / 180.0;
      why << format(" | %.2f", normal_incidence_ndf(bsdf, theta) / bsdf.measured_ndf(theta) / normal0);
    }
    why << " |\n";
  }
  md << "\nThe bar is not met, and the reader is not the cause. The acquisition derives the `sigma` and `vndf` "
        "fields from its `ndf`, so they test the reader's parameterization (theta -> u = sqrt(theta / (pi/2)), phi "
        "from the slice's plane, node-centred grids, theta along the last axis): sigma recomputed from `ndf` "
        "matches the `sigma` field, and the `vndf` table matches D(m) max(0, i.m) times the Jacobian of the "
        "unit square (largest total-variation distance over the slices), to the precision below; a linear theta "
        "map would put sigma off by ~40%, texel centres by ~5% (`RglSynthetic.SelfConsistencySeesAParameterizationMismatch`, "
        "`RglReal.TablesAreSelfConsistent`). The f(k,k) the power iteration reads is the format's evaluation "
        "(Mitsuba 3's `measured` plugin) of the `rgb` table.\n\n"
        "What does not agree is the `rgb` table with the `ndf` field. The table stores f cos / (D_file / 4 sigma), "
        "so under the masking form the extraction returns D_file exactly when that value at retro-reflection is "
        "constant. The columns below give it at the first three measured theta_i slices (angle in degrees), "
        "relative to normal incidence: it is far from constant, falling for the glossy films and rising for "
        "paper and felt, and the extracted D follows it. Nor is it an artefact of retro-reflection, which a "
        "goniophotometer cannot reach exactly: the normal-incidence slice, a different set of measured "
        "configurations, implies an NDF of its own for any Smith model (last columns: f(n, o) sigma(o) over "
        "D_file, relative to 0 degrees), and for the two materials that are one glossy lobe (cc_ibiza_sunset, "
        "ilm_l3_37_metallic) it has the same too-light tail as the back-scattering (compare slice 1 with 30 deg). "
        "For the others the two routes part, as they do for reflection that is not a single microfacet lobe "
        "(diffuse bases), which no microfacet NDF reproduces from back-scattering alone. At the larger angles the "
        "glossy materials' retro-reflection also falls in the far tail of their VNDF, in the last patch of the "
        "32 x 32 sample square beside its below-horizon column, so the table hardly resolves it there (the 60 "
        "degree ratios). The acquisition measured its `ndf` in a separate back-scattering pass that these files "
        "do not contain, so no reading of them reproduces it to 5%; the extracted NDF describes the reflectance "
        "the `rgb` table holds. The green channel, nearer the acquisition's 532 nm, moves the distance by a few "
        "points at most; the masking form, the acquisition's own, is the closest of the three.\n\n"
        "| material | sigma check | VNDF check | retro `rgb`, slice 1 | slice 2 | slice 3 | normal-incidence D / D_file, 10 deg | 20 deg | 30 deg |\n"
        "|---|---|---|---|---|---|---|---|---|\n"
     << why.str() << "\n";
}

}  // namespace
}  // namespace facetfit

int main(int argc, char** argv) {
  using namespace facetfit;
  if (argc < 2 || argc > 3) {
    std::fprintf(stderr, "usage: facetfit_accuracy OUTPUT.md [RGL_FOLDER]\n");
    return 2;
  }
  try {
    std::ostringstream md;
    md << "# Accuracy\n\nGenerated by `make accuracy` (bench/accuracy_table.cpp); do not edit by hand.\n\n";
    ground_truth_section(md);
    consistency_section(md);
    iterations_section(md);
    resolution_section(md);
    const std::string scratch = (std::filesystem::temp_directory_path() / "facetfit-accuracy-utia.bin").string();
    anisotropic_section(md, scratch);
    utia_fit_section(md, scratch);
    anisotropic_lobe_section(md, scratch);
    std::filesystem::remove(scratch);
    std::filesystem::remove(scratch + ".bsdf");
    rgl_section(md, argc > 2 ? argv[2] : "");
    write_file_atomic(argv[1], md.str());
    std::printf("%s\n", argv[1]);
  } catch (const Error& e) {
    std::fprintf(stderr, "facetfit_accuracy: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
