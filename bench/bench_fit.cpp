// Speed of the fit pipeline (Google Benchmark). `make bench` runs this and writes docs/benchmarks.md.
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <filesystem>
#include <memory>

#include "fit/fit.h"
#include "fit/roughness.h"
#include "io/merl.h"
#include "model/analytic.h"

namespace facetfit {
namespace {

// One realistic material, tabulated once: GGX alpha 0.2, height-correlated, gold.
const MerlTable& gold() {
  static const MerlTable table = MerlTable::tabulate(MicrofacetBrdf(
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
  for (auto _ : state) benchmark::DoNotOptimize(MerlTable::read(path));
  std::filesystem::remove(path);
  state.SetBytesProcessed(int64_t(state.iterations()) * int64_t(MerlTable::kFileBytes));
}
BENCHMARK(BM_ReadMerl)->Unit(benchmark::kMillisecond);

// Extraction + Fresnel pass + both alphas: what `fit` costs per material once the table is loaded.
void BM_Fit(benchmark::State& state) {
  const auto threads = limit_threads(state);
  FitOptions options;
  options.resolution = int(state.range(1));
  const Fitter fitter(options);
  for (auto _ : state) benchmark::DoNotOptimize(fitter.fit(gold()));
}
BENCHMARK(BM_Fit)->ArgNames({"threads", "resolution"})
    ->Args({0, 90})->Args({1, 90})->Args({0, 32})->Args({0, 64})->Args({0, 128})->Args({0, 256})
    ->Unit(benchmark::kMillisecond);

void BM_Extraction(benchmark::State& state) {
  const Quadrature quadrature(int(state.range(0)));
  const Backscatter back = backscatter_of(gold());
  for (auto _ : state) benchmark::DoNotOptimize(extract_ndf(back, quadrature, {}));
}
BENCHMARK(BM_Extraction)->ArgName("resolution")->Arg(90)->Arg(256)->Unit(benchmark::kMicrosecond);

void BM_FresnelPass(benchmark::State& state) {
  const auto threads = limit_threads(state);
  const Fitter fitter(FitOptions{});
  const FitResult fit = fitter.fit(gold());
  for (auto _ : state) benchmark::DoNotOptimize(fit_fresnel(gold(), fit.ndf(), Smith::correlated, nullptr));
  state.SetBytesProcessed(int64_t(state.iterations()) * int64_t(3 * MerlTable::kBins * sizeof(float)));
}
BENCHMARK(BM_FresnelPass)->ArgName("threads")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// Built once per resolution and shared by every material of a batch.
void BM_Quadrature(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(Quadrature(int(state.range(0))));
}
BENCHMARK(BM_Quadrature)->ArgName("resolution")->Arg(90)->Arg(256)->Unit(benchmark::kMillisecond);

void BM_RefineAlpha(benchmark::State& state) {
  const Fitter fitter(FitOptions{});
  const FitResult fit = fitter.fit(gold());
  for (auto _ : state)
    benchmark::DoNotOptimize(refine_alpha(fitter.quadrature(), fit.ndf(), NdfType::ggx, fit.alpha_ggx));
}
BENCHMARK(BM_RefineAlpha)->Unit(benchmark::kMillisecond);

void BM_TabulateAnalytic(benchmark::State& state) {
  const MicrofacetBrdf brdf(Ndf::isotropic(NdfType::ggx, 0.2), Smith::correlated, Fresnel::schlick(Rgb(0.9)));
  for (auto _ : state) benchmark::DoNotOptimize(MerlTable::tabulate(brdf));
}
BENCHMARK(BM_TabulateAnalytic)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace facetfit

BENCHMARK_MAIN();
