// write_seeds OUT: the seeds that only the library can write: LUTs of a built-in material (with and
// without sampling tables, fuzz_lut), small environment maps (EXR, HDR; fuzz_env), and a UTIA file of an
// analytic model (fuzz_utia).
#include <cstdio>
#include <filesystem>
#include <string>

#include "fit/fit.h"
#include "io/image_file.h"
#include "io/input.h"
#include "io/utia.h"
#include "lut/lut.h"
#include "render/environment.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: write_seeds OUT\n");
    return 2;
  }
  namespace fs = std::filesystem;
  using namespace facetfit;
  const fs::path out = argv[1];
  fs::create_directories(out / "lut");
  fs::create_directories(out / "env");
  fs::create_directories(out / "utia");
  const Fitter fitter(FitOptions::paper());
  const FitResult fit = fitter.fit(load_table("builtin:gold-ggx-0.15"));
  for (const bool sampling : {false, true})
    write_lut((out / "lut" / (sampling ? "gold.exr" : "gold-eval-only.exr")).string(),
              make_lut(fit, fitter.quadrature(), "builtin:gold-ggx-0.15", "seed", 0.02, sampling));
  const Environment sky = Environment::sky(16);
  const ImageSpec spec(sky.width(), sky.height(), {"R", "G", "B"});
  for (const char* name : {"sky.exr", "sky.hdr"}) write_image_atomic((out / "env" / name).string(), spec, sky.pixels().data());
  UtiaBrdf::tabulate(*load_brdf("builtin:gold-ggx-0.15")).write((out / "utia" / "gold.bin").string());
  return 0;
}
