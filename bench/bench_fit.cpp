// Speed of the fit pipeline (Google Benchmark). `make bench` runs this and writes docs/benchmarks.md.
#include <benchmark/benchmark.h>
#include <embree3/rtcore.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <limits>
#include <optional>
#include <random>
#include <vector>

#include "fit/extract_2d.h"
#include "fit/fit.h"
#include "fit/roughness.h"
#include "io/input.h"
#include "io/merl.h"
#include "io/sha256.h"
#include "io/utia.h"
#include "lut/bake.h"
#include "lut/lut.h"
#include "model/analytic.h"
#include "model/tabulated.h"
#include "model/visible_slopes.h"
#include "model/tabulated_anisotropic.h"
#include "render/renderer.h"
#include "render/scene.h"
#include "render/tracer.h"

namespace facetfit {
namespace {

// One realistic material, tabulated once: GGX alpha 0.2, height-correlated, gold.
const HalfDiffTable& gold() {
  static const HalfDiffTable table = HalfDiffTable::tabulate(MicrofacetBrdf(
      Ndf::isotropic(NdfType::ggx, 0.2), Smith::correlated, Fresnel::conductor({0.143, 0.374, 1.442}, {3.983, 2.385, 1.603})));
  return table;
}

// state.range(0) threads (0: all cores).
std::unique_ptr<tbb::global_control> limit_threads(const benchmark::State& state) {
  if (state.range(0) <= 0) return nullptr;
  return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, std::size_t(state.range(0)));
}

void BM_ReadMerl(benchmark::State& state) {
  const std::string path = (std::filesystem::temp_directory_path() / "facetfit-bench-gold.binary").string();
  gold().write(path);
  for (auto _ : state) benchmark::DoNotOptimize(HalfDiffTable::read(path));
  std::filesystem::remove(path);
  state.SetBytesProcessed(int64_t(state.iterations()) * int64_t(HalfDiffTable::kFileBytes));
}
BENCHMARK(BM_ReadMerl)->Unit(benchmark::kMillisecond);

// Extraction + Fresnel pass + both alphas: what `fit` costs per material once the table is loaded.
void BM_Fit(benchmark::State& state) {
  const auto threads = limit_threads(state);
  FitOptions options = FitOptions::paper();
  options.resolution = int(state.range(1));
  const Fitter fitter(options);
  for (auto _ : state) benchmark::DoNotOptimize(fitter.fit(gold()));
}
BENCHMARK(BM_Fit)->ArgNames({"threads", "resolution"})
    ->Args({0, 90})->Args({1, 90})->Args({0, 32})->Args({0, 64})->Args({0, 128})->Args({0, 256})
    ->Unit(benchmark::kMillisecond);

// A real measurement: one RGL material, from FACETFIT_RGL_DIR or ../shared/data/rgl (run from the
// repository's root, as make bench does).
const HalfDiffTable* rgl_material(const char* name) {
  static std::map<std::string, std::optional<HalfDiffTable>> cache;
  auto [it, added] = cache.try_emplace(name);
  if (added) {
    const char* env = std::getenv("FACETFIT_RGL_DIR");
    const std::filesystem::path file = std::filesystem::path(env ? env : "../shared/data/rgl") / (std::string(name) + ".bsdf");
    if (std::filesystem::exists(file)) it->second = load_table(file.string());
  }
  return it->second ? &*it->second : nullptr;
}

// Loading an RGL file as the fits read it (load_table: the tensor file, its one-sided estimates, the
// MERL-layout table), one thread: the part of a whole `facetfit fit` that BM_FitRgl does not time.
void BM_LoadRgl(benchmark::State& state) {
  const char* env = std::getenv("FACETFIT_RGL_DIR");
  const std::filesystem::path file = std::filesystem::path(env ? env : "../shared/data/rgl") / "ilm_l3_37_metallic_rgb.bsdf";
  if (!std::filesystem::exists(file)) return state.SkipWithError("no RGL data: set FACETFIT_RGL_DIR");
  const auto threads = limit_threads(state);
  for (auto _ : state) benchmark::DoNotOptimize(load_table(file.string()));
}
BENCHMARK(BM_LoadRgl)->ArgName("threads")->Arg(1)->Unit(benchmark::kMillisecond);

// The default fit (--refine full) of real materials against the paper's method alone on the same
// table (the anchor): extraction, parametric fits, refinement, every distance.
// The RGL material the benchmark's second argument names (0: acrylic_felt_green_rgb, 1:
// ilm_l3_37_metallic_rgb), or null after skipping the benchmark without the data.
const HalfDiffTable* rgl_material_of(benchmark::State& state, const char** name) {
  *name = state.range(1) == 0 ? "acrylic_felt_green_rgb" : "ilm_l3_37_metallic_rgb";
  const HalfDiffTable* table = rgl_material(*name);
  if (!table) state.SkipWithError("no RGL data: set FACETFIT_RGL_DIR");
  return table;
}

void BM_FitRgl(benchmark::State& state) {
  const char* name = nullptr;
  const HalfDiffTable* table = rgl_material_of(state, &name);
  if (!table) return;
  const auto threads = limit_threads(state);
  FitOptions options;
  options.refine = state.range(2) ? FitOptions::Refine::full : FitOptions::Refine::none;
  const Fitter fitter(options);
  for (auto _ : state) benchmark::DoNotOptimize(fitter.fit(*table));
  state.SetLabel(std::string(name) + (state.range(2) ? ", refine full" : ", refine none"));
}
BENCHMARK(BM_FitRgl)->ArgNames({"threads", "material", "refine"})
    ->Args({1, 0, 0})->Args({1, 0, 1})->Args({0, 0, 1})->Args({1, 1, 0})->Args({1, 1, 1})->Args({0, 1, 1})
    ->Unit(benchmark::kMillisecond);

// The closure step of a full fit (fit/closure_fit.h) alone: its bins, the measurement's albedo and the
// solves, on the materials of BM_FitRgl, whose refine-full rows include it: their ratio is what the
// closures add to a fit (the issue's bar: at most 50% of the rest).
void BM_ClosureFit(benchmark::State& state) {
  const char* name = nullptr;
  const HalfDiffTable* table = rgl_material_of(state, &name);
  if (!table) return;
  const auto threads = limit_threads(state);
  const FitResult fit = Fitter(FitOptions{}).fit(*table);
  const MeasuredBins errors = error_bins(*table);
  const VisibleSlopeProposal proposal(fit.lobe.tables(fit.smith));
  ClosureFit closures;
  for (auto _ : state) {
    const AlbedoTarget albedo = albedo_target(*table, proposal);
    benchmark::DoNotOptimize(closures = fit_closures(closure_bins(*table), &albedo, errors, fit.ggx));
  }
  state.counters["lobes"] = double(closures.closures.lobes.size());
  state.SetLabel(name);
}
BENCHMARK(BM_ClosureFit)->ArgNames({"threads", "material"})->Args({1, 0})->Args({0, 0})->Args({1, 1})->Args({0, 1})->Unit(benchmark::kMillisecond);

void BM_Extraction(benchmark::State& state) {
  const Quadrature quadrature(int(state.range(0)));
  const Backscatter back = backscatter_of(gold());
  for (auto _ : state) benchmark::DoNotOptimize(extract_ndf(back, quadrature, {}));
}
BENCHMARK(BM_Extraction)->ArgName("resolution")->Arg(90)->Arg(256)->Unit(benchmark::kMicrosecond);

// The anisotropic extraction (fit/extract_2d.h) of GGX alpha (0.4, 0.15), masking form, on J theta nodes x
// M azimuthal bins: the issue's target is <= 100 ms and <= 50 MB at 90 x 128; the reference
// implementation's dense (J M)^2 matrix took 6.58 s and 994 MiB there.
void BM_Extraction2D(benchmark::State& state) {
  const Quadrature2D quadrature(int(state.range(0)), int(state.range(1)));
  const MicrofacetBrdf brdf(Ndf{NdfType::ggx, 0.4, 0.15}, Smith::masking, Fresnel::one());
  const Backscatter2D back = backscatter_2d(brdf, quadrature);
  Extraction2D e;
  for (auto _ : state) benchmark::DoNotOptimize(e = extract_ndf_2d(back, quadrature, {Smith::masking, 1e-10, 1000}));
  state.counters["iterations"] = e.iterations;
  state.counters["quadrature_MiB"] = double(quadrature.bytes()) / (1 << 20);
  state.counters["ndf_MiB"] = double(e.ndf.size() * sizeof(double) * 6) / (1 << 20);  // D, sigma and the iteration's buffers
}
BENCHMARK(BM_Extraction2D)->ArgNames({"resolution", "phi"})->Args({90, 128})->Args({64, 64})->Unit(benchmark::kMillisecond);

// The 2D quadrature: its kernel spectra, once per (resolution, phi count) for a whole batch.
void BM_Quadrature2D(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(Quadrature2D(int(state.range(0)), int(state.range(1))));
}
BENCHMARK(BM_Quadrature2D)->ArgNames({"resolution", "phi"})->Args({90, 128})->Unit(benchmark::kMillisecond);

void BM_FresnelPass(benchmark::State& state) {
  const auto threads = limit_threads(state);
  const Fitter fitter(FitOptions::paper());
  const FitResult fit = fitter.fit(gold());
  for (auto _ : state) benchmark::DoNotOptimize(fit_fresnel(gold(), fit.ndf(), Smith::correlated));
  state.SetBytesProcessed(int64_t(state.iterations()) * int64_t(3 * HalfDiffTable::kBins * sizeof(float)));
}
BENCHMARK(BM_FresnelPass)->ArgName("threads")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// Built once per resolution and shared by every material of a batch.
void BM_Quadrature(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(Quadrature(int(state.range(0))));
}
BENCHMARK(BM_Quadrature)->ArgName("resolution")->Arg(90)->Arg(256)->Unit(benchmark::kMillisecond);

void BM_RefineAlpha(benchmark::State& state) {
  const Fitter fitter(FitOptions::paper());
  const FitResult fit = fitter.fit(gold());
  for (auto _ : state)
    benchmark::DoNotOptimize(refine_alpha(fitter.quadrature(), fit.ndf(), NdfType::ggx, fit.alpha_ggx));
}
BENCHMARK(BM_RefineAlpha)->Unit(benchmark::kMillisecond);

void BM_TabulateAnalytic(benchmark::State& state) {
  const MicrofacetBrdf brdf(Ndf::isotropic(NdfType::ggx, 0.2), Smith::correlated, Fresnel::schlick(Rgb(0.9)));
  for (auto _ : state) benchmark::DoNotOptimize(HalfDiffTable::tabulate(brdf));
}
BENCHMARK(BM_TabulateAnalytic)->Unit(benchmark::kMillisecond);

// A UTIA file (anisotropic GGX written by facetfit's writer) to the fit's table: read, azimuthal mean,
// tabulation in MERL layout (io/input.h); then the default fit of it, which adds the 2D extraction.
const std::string& utia_file() {
  static const std::string path = [] {
    const std::string p = (std::filesystem::temp_directory_path() / "facetfit-bench-anisotropic.bin").string();
    UtiaBrdf::tabulate(MicrofacetBrdf(Ndf{NdfType::ggx, 0.45, 0.2}, Smith::correlated, Fresnel::schlick(Rgb(0.9, 0.6, 0.3)))).write(p);
    return p;
  }();
  return path;
}
void BM_LoadUtia(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(load_table(utia_file()));
}
BENCHMARK(BM_LoadUtia)->Unit(benchmark::kMillisecond);
void BM_FitUtia(benchmark::State& state) {
  const HalfDiffTable table = load_table(utia_file());
  FitOptions options;
  options.refine = state.range(0) ? FitOptions::Refine::full : FitOptions::Refine::none;
  const Fitter fitter(options);
  for (auto _ : state) benchmark::DoNotOptimize(fitter.fit(table));
}
BENCHMARK(BM_FitUtia)->ArgName("refine")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// The anisotropic GGX lobe with a body fitted on that file's node pairs, one core: the part of
// BM_FitUtia/refine:1 the anisotropic input adds (twice: GGX and Beckmann).
void BM_FitAnisotropicLobe(benchmark::State& state) {
  const auto limit = limit_threads(state);
  const HalfDiffTable table = load_table(utia_file());
  const MeasuredBins solve = anisotropic_bins(table, 24), all = anisotropic_bins(table, 1);
  AnisotropicParametricFit start;
  start.alpha = {0.5, 0.3, 0.2};
  start.body = Rgb(0.05);
  start.f0 = start.f82 = Rgb(0.5);
  for (auto _ : state) benchmark::DoNotOptimize(fit_parametric_anisotropic(solve, all, Smith::correlated, start));
}
BENCHMARK(BM_FitAnisotropicLobe)->ArgName("threads")->Arg(1)->Unit(benchmark::kMillisecond);

// One eval and one draw (sample + pdf + eval) of the tabulated lobes at random directions: the isotropic
// lobe (the anchor) and the anisotropic one, GGX 0.4 x 0.15 tabulated at 90 x 64 nodes, plain and stretched.
AnisotropicTables anisotropic_ggx_tables() {
  AnisotropicTables t;
  t.grid.resolution = 90;
  t.phi_count = 64;
  for (int j = 0; j < FresnelCurve::kSize; ++j) t.fresnel.value[std::size_t(j)] = Rgb(1.0);
  const Ndf ndf{NdfType::ggx, 0.4, 0.15};
  for (int j = 0; j < t.grid.size(); ++j)
    for (int m = 0; m < t.phi_count; ++m) {
      const Vec3 w = spherical_direction(std::min(t.grid.theta(j), 0.5 * kPi - 1e-6), 2.0 * kPi * m / t.phi_count);
      t.ndf.push_back(ndf.D(w));
      t.sigma.push_back(ndf.sigma(w));
    }
  return t;
}
template <class Lobe>
void lobe_benchmark(benchmark::State& state, const Lobe& lobe) {
  std::vector<Vec3> directions;
  for (int k = 0; k < 1024; ++k) directions.push_back(spherical_direction(std::acos(1.0 - 0.98 * ((k * 37 % 1024) + 0.5) / 1024.0), 0.0061 * k * 1000.0));
  std::size_t k = 0;
  const bool draw = state.range(0) == 1;
  for (auto _ : state) {
    const Vec3 &o = directions[k % 1024], &i = directions[(k * 7 + 3) % 1024];
    ++k;
    if (draw) {
      benchmark::DoNotOptimize(lobe.sample(o, 0.37, double(k % 997) / 997.0));
    } else {
      benchmark::DoNotOptimize(lobe.eval(o, i));
    }
  }
}
void BM_TabulatedLobe(benchmark::State& state) {
  static const TabulatedMicrofacet lobe(MicrofacetTables{tabulate_ndf(Ndf::isotropic(NdfType::ggx, 0.25)), Smith::correlated, FresnelCurve{}, Rgb(0.0), {}});
  lobe_benchmark(state, state.range(1) ? lobe.stretched(Stretch(0.5, 2.0, 0.5)) : lobe);
}
BENCHMARK(BM_TabulatedLobe)->ArgNames({"draw", "stretched"})->Args({0, 0})->Args({1, 0})->Args({0, 1})->Args({1, 1})->Unit(benchmark::kNanosecond);
void BM_TabulatedAnisotropicLobe(benchmark::State& state) {
  static const TabulatedAnisotropic lobe(anisotropic_ggx_tables());
  lobe_benchmark(state, state.range(1) ? lobe.stretched(Stretch(0.5, 2.0, 0.5)) : lobe);
}
BENCHMARK(BM_TabulatedAnisotropicLobe)->ArgNames({"draw", "stretched"})->Args({0, 0})->Args({1, 0})->Args({0, 1})->Args({1, 1})->Unit(benchmark::kNanosecond);

// The renderer's shadow rays on a sphere: leaving a unit sphere 2e-4 above it, toward random directions
// above its surface. embree:1 (anchor): Embree's sphere primitive, one ray at a time, as the renderer had
// it; embree:0: the tracer's closed form (render/tracer.h).
void BM_ShadowRay(benchmark::State& state) {
  std::vector<Ray> rays;
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  for (int k = 0; k < 4096; ++k) {
    const Vec3 p = glm::normalize(Vec3(normal(rng), normal(rng), normal(rng)));
    Vec3 d = glm::normalize(Vec3(normal(rng), normal(rng), normal(rng)));
    if (glm::dot(d, p) < 0.0) d = -d;
    rays.push_back(Ray{p * (1.0 + 2e-4), d, 2e-4});
  }
  if (state.range(0) == 0) {
    SceneDesc scene;
    scene.objects.push_back(ObjectDesc{});  // a unit sphere at the origin
    const Tracer tracer(scene);
    std::size_t k = 0;
    for (auto _ : state) benchmark::DoNotOptimize(tracer.occluded(rays[k++ % rays.size()]));
    return;
  }
  RTCDevice device = rtcNewDevice("threads=1");
  RTCScene rtc_scene = rtcNewScene(device);
  RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), 1));
  v[0] = v[1] = v[2] = 0.0f, v[3] = 1.0f;
  rtcCommitGeometry(g);
  rtcAttachGeometry(rtc_scene, g);
  rtcReleaseGeometry(g);
  rtcCommitScene(rtc_scene);
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  std::size_t k = 0;
  for (auto _ : state) {
    const Ray& r = rays[k++ % rays.size()];
    RTCRay ray{};
    ray.org_x = float(r.origin.x), ray.org_y = float(r.origin.y), ray.org_z = float(r.origin.z);
    ray.dir_x = float(r.dir.x), ray.dir_y = float(r.dir.y), ray.dir_z = float(r.dir.z);
    ray.tnear = float(r.tnear), ray.tfar = std::numeric_limits<float>::infinity(), ray.mask = 0xFFFFFFFFu;
    rtcOccluded1(rtc_scene, &context, &ray);
    benchmark::DoNotOptimize(ray.tfar);
  }
  rtcReleaseScene(rtc_scene);
  rtcReleaseDevice(device);
}
BENCHMARK(BM_ShadowRay)->ArgName("embree")->Arg(1)->Arg(0)->Unit(benchmark::kNanosecond);

// One render of the scene of ../shared/data/realref (bench/render_compare.py's), 96 x 96 at 16 spp on one
// thread: the renderer's cost per sample without start-up or thread scheduling. material:0 (anchor) a
// Lambertian sphere, 1 GGX 0.3 with F = 1 and separable masking (the scene Mitsuba renders in make bench).
void BM_RenderSphere(benchmark::State& state) {
  const tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
  const char* material = state.range(0) == 0 ? R"({"type": "lambert", "albedo": [0.5, 0.5, 0.5]})"
                                              : R"({"type": "ggx", "alpha": 0.3, "f0": [1, 1, 1], "f82": [1, 1, 1], "smith": "separable"})";
  const SceneDesc scene = parse_scene_text(std::string(R"({
    "camera": {"position": [0, 0.6, 4], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": 30, "width": 96, "height": 96},
    "render": {"spp": 16, "seed": 1},
    "environment": {"constant": [0.3, 0.3, 0.3]},
    "lights": [{"type": "directional", "direction": [0.3, 1, 0.5], "irradiance": [3, 3, 3]}],
    "materials": {"m": )") + material + R"(},
    "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}]})",
                                            "bench", ".");
  for (auto _ : state) benchmark::DoNotOptimize(render(scene).rgba.data());
  state.counters["ns_per_sample"] = benchmark::Counter(96.0 * 96.0 * 16.0, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_RenderSphere)->ArgName("material")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// A MERL file on disk for the bake benchmarks, written once.
const std::string& gold_file() {
  static const std::string path = [] {
    const std::string p = (std::filesystem::temp_directory_path() / "facetfit-bench-gold-bake.binary").string();
    gold().write(p);
    return p;
  }();
  return path;
}

// The whole bake of one MERL file: SHA-256, read, fit, sampling tables, EXR and sidecar.
void BM_Bake(benchmark::State& state) {
  gold_file();  // made once, outside the timing
  const auto threads = limit_threads(state);
  const std::string dir = (std::filesystem::temp_directory_path() / "facetfit-bench-bake").string();
  std::filesystem::create_directories(dir);
  BakeOptions options;
  options.force = true;
  const Fitter fitter(options.fit);
  for (auto _ : state) benchmark::DoNotOptimize(bake_material(gold_file(), "gold", dir, options, fitter));
  std::filesystem::remove_all(dir);
}
BENCHMARK(BM_Bake)->ArgName("threads")->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond);

void BM_Sha256File(benchmark::State& state) {
  gold_file();
  for (auto _ : state) benchmark::DoNotOptimize(sha256_file(gold_file()));
  state.SetBytesProcessed(int64_t(state.iterations()) * int64_t(HalfDiffTable::kFileBytes));
}
BENCHMARK(BM_Sha256File)->Unit(benchmark::kMillisecond);

void BM_VisibleNormalTables(benchmark::State& state) {
  const auto threads = limit_threads(state);
  const FitResult fit = Fitter(FitOptions::paper()).fit(gold());
  for (auto _ : state) benchmark::DoNotOptimize(VisibleNormalTables::build(fit.ndf()));
}
BENCHMARK(BM_VisibleNormalTables)->ArgName("threads")->Arg(1)->Unit(benchmark::kMillisecond);

void BM_VisibleSlopes(benchmark::State& state) {
  const auto threads = limit_threads(state);
  const FitResult fit = Fitter(FitOptions::paper()).fit(gold());
  for (auto _ : state) benchmark::DoNotOptimize(VisibleSlopes(fit.ndf()));
}
BENCHMARK(BM_VisibleSlopes)->ArgName("threads")->Arg(1)->Unit(benchmark::kMillisecond);

void BM_WriteLut(benchmark::State& state) {
  const Fitter fitter(FitOptions::paper());
  const Lut lut = make_lut(fitter.fit(gold()), fitter.quadrature(), "gold", "", 0.02, true);
  const std::string path = (std::filesystem::temp_directory_path() / "facetfit-bench-lut.exr").string();
  for (auto _ : state) write_lut(path, lut);
  std::filesystem::remove(path);
}
BENCHMARK(BM_WriteLut)->Unit(benchmark::kMillisecond);

// A batch: 8 materials baked at once (bake --jobs), one core or both.
void BM_BakeBatch(benchmark::State& state) {
  const int jobs = int(state.range(0));
  gold_file();
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(jobs));
  const std::string dir = (std::filesystem::temp_directory_path() / "facetfit-bench-batch").string();
  std::filesystem::create_directories(dir);
  BakeOptions options;
  options.force = true;
  options.fit = FitOptions::paper();  // the pipeline's overhead, not the solves (BM_FitRgl)
  const Fitter fitter(options.fit);
  for (auto _ : state) {
    tbb::parallel_for(0, 8, [&](int k) { bake_material(gold_file(), "m" + std::to_string(k), dir, options, fitter); },
                      tbb::simple_partitioner());
  }
  state.counters["materials_per_second"] = benchmark::Counter(8.0 * double(state.iterations()), benchmark::Counter::kIsRate);
  std::filesystem::remove_all(dir);
}
BENCHMARK(BM_BakeBatch)->ArgName("jobs")->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

// A 3.9 MB scene of 100k Lambert materials, parsed and checked (issue 47: the depth-limiting callback parser
// took minutes on a third of its size; the bar is a 2 MB scene under a second).
void BM_ParseScene(benchmark::State& state) {
  std::string text = R"({"materials": {)";
  for (int k = 0; k < 100000; ++k) text += "\"material_" + std::to_string(k) + "\": {\"type\": \"lambert\"}, ";
  text += R"("m": {"type": "lambert"}}, "objects": [{"type": "sphere", "material": "m"}]})";
  state.counters["bytes"] = double(text.size());
  for (auto _ : state) benchmark::DoNotOptimize(parse_scene_text(text, "large.json", "."));
}
BENCHMARK(BM_ParseScene)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace facetfit

BENCHMARK_MAIN();
