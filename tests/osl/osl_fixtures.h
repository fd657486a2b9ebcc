// What the OSL tests (tests/osl/test_osl_*.cpp, label osl) share: Blender's Cycles from the bpy wheel,
// driven by tests/osl/cycles_render.py; Cycles' compiler; and the folder of the build, made once, that holds
// the LUTs and compiled shaders the test processes read.
#pragma once

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/file.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "io/image_file.h"
#include "io/merl.h"
#include "lut/lut.h"
#include "model/analytic.h"
#include "test_util.h"

namespace facetfit::test::osl {

inline const std::string kSource = FACETFIT_SOURCE_DIR;

inline double radians(double degrees) { return degrees * kPi / 180.0; }

inline std::string str(const Vec3& v) {
  return "(" + std::to_string(v.x) + ", " + std::to_string(v.y) + ", " + std::to_string(v.z) + ")";
}

inline std::string quoted(const std::string& s) { return "'" + s + "'"; }

inline RunResult python(const std::string& args) { return test::run_command(quoted(FACETFIT_BPY_PYTHON) + " " + args); }

// Renders with Cycles; returns the run (status, messages) and fails the test on a nonzero exit.
inline RunResult cycles(const std::string& args) {
  RunResult r = python(quoted(kSource + "/tests/osl/cycles_render.py") + " " + args);
  EXPECT_EQ(r.status, 0) << r.out << r.err;
  return r;
}

struct Image {
  int width = 0, height = 0, channels = 0;
  std::vector<float> pixels;
  const float* at(int x, int y) const { return &pixels[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * std::size_t(channels)]; }
};

inline Image read_image(const std::string& path) {
  ImageReader in = ImageReader::open(path);
  Image img;
  img.width = in.spec().width;
  img.height = in.spec().height;
  img.channels = int(in.spec().channels.size());
  img.pixels = in.read_pixels();
  return img;
}

// Compiles every .osl of `folder` into `out` with Cycles' compiler (scripts/osl_compile.py).
inline RunResult osl_compile(const std::string& folder, const std::string& out) {
  return python(quoted(kSource + "/scripts/osl_compile.py") + " " + quoted(folder) + " " + quoted(out));
}

// Compiles the shaders of osl/ and tests/osl/ into `dir`. The renders load these .oso files: a script
// node given a .osl compiles it into a temporary file of Blender's own, which concurrent test processes
// would share.
inline void compile_shaders(const std::filesystem::path& dir) {
  for (const std::string folder : {"/osl", "/tests/osl"}) {
    const RunResult r = osl_compile(kSource + folder, dir.string());
    ASSERT_EQ(r.status, 0) << r.out << r.err;
  }
}

// A folder of the build that the test processes share (`make test` runs each test in a process of its own):
// made by `make` once, under a lock that the other processes wait on, and made again when it is older
// than what it was made from (the command and its plugin, this test binary, the shaders' sources).
class SharedFolder {
 public:
  template <class Make>
  SharedFolder(const std::filesystem::path& path, const Make& make) : path_(path) {
    namespace fs = std::filesystem;
    fs::create_directories(path.parent_path());
    const std::string lock_path = path.string() + ".lock";
    const int fd = ::open(lock_path.c_str(), O_CREAT | O_RDWR | O_CLOEXEC, 0644);
    if (fd < 0 || ::flock(fd, LOCK_EX) != 0) throw std::runtime_error("cannot lock " + lock_path);
    if (!fresh()) {
      const fs::path staging = path.string() + ".making";
      fs::remove_all(staging), fs::create_directories(staging);
      make(staging);
      if (::testing::Test::HasFailure()) throw std::runtime_error("could not make " + path.string());
      std::ofstream(staging / "made").put('\n');
      fs::remove_all(path), fs::rename(staging, path);
    }
    ::close(fd);  // releases the lock
  }
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  const std::filesystem::path& path() const { return path_; }

 private:
  // Whether the folder was made after every input last changed.
  bool fresh() const {
    namespace fs = std::filesystem;
    std::error_code ec;
    const auto made = fs::last_write_time(path_ / "made", ec);
    if (ec) return false;
    std::vector<fs::path> inputs = {FACETFIT_CLI, fs::path(FACETFIT_CLI).parent_path() / "facetfit-commands.so", "/proc/self/exe"};
    for (const std::string folder : {"/osl", "/tests/osl"})
      for (const auto& e : fs::directory_iterator(kSource + folder)) inputs.push_back(e.path());
    for (fs::path input : inputs) {
      if (input == "/proc/self/exe") input = fs::read_symlink(input);
      const auto changed = fs::last_write_time(input, ec);
      if (ec || changed > made) return false;
    }
    return true;
  }
  std::filesystem::path path_;
};

// The LUTs the probe reads, and the compiled shaders, into `dir`: the folder of the build
// (FACETFIT_OSL_FIXTURE) that OslModel and OslSphere share.
inline void make_luts(const std::filesystem::path& dir) {
  const auto file = [&](const std::string& name) { return (dir / name).string(); };
  const RunResult r = facetfit("bake builtin:gold-ggx-0.15 builtin:silver-ggx-0.60 builtin:copper-beckmann-0.30 "
                               "builtin:blue-clearcoat-paint -o " + dir.string());
  ASSERT_EQ(r.status, 0) << r.err;
  // One LUT fitted with the masking form, so that a Smith model other than the default is read.
  const RunResult masking = facetfit("bake builtin:silver-ggx-0.60 --smith masking -o " + file("masking"));
  ASSERT_EQ(masking.status, 0) << masking.err;
  // A body darker toward grazing angles (Minnaert's exponent 1.4, model/body.h): format 4's attribute, in a
  // format 5 LUT.
  HalfDiffTable::tabulate(SumBrdf({std::make_shared<LambertBrdf>(Rgb(0.5, 0.3, 0.1), 1.4),
                               std::make_shared<MicrofacetBrdf>(Ndf::isotropic(NdfType::ggx, 0.2), Smith::correlated,
                                                                Fresnel::schlick(Rgb(0.04)))}))
      .write(file("minnaert-ggx-0.20.binary"));
  const RunResult minnaert = facetfit("bake " + file("minnaert-ggx-0.20.binary") + " -o " + dir.string());
  ASSERT_EQ(minnaert.status, 0) << minnaert.err;
  const Lut minnaert_lut = read_lut(file("minnaert-ggx-0.20.exr"));
  ASSERT_GE(minnaert_lut.meta.format_version, kLutClosuresVersion);  // 6 where its closures follow the view
  ASSERT_GT(minnaert_lut.tables.body_exponent, 1.0);
  compile_shaders(dir);
}

}  // namespace facetfit::test::osl
