// The OSL shaders in a real OSL renderer: Blender's Cycles from the bpy wheel (OSL 1.14, CPU), driven by
// tests/osl/cycles_render.py. The shaders compile (and a broken one fails with the compiler's message);
// facetfit.h's eval, sample and pdf equal the C++ library to 1e-4 on grids of directions and uniform
// numbers; the preview shader matches the reference renderer's tabulated model on a sphere under an
// environment map (mean Delta E 2000 < 1), and the material shader its closures material (<= 0.5).
//
// With FACETFIT_OSL_PICTURES=FOLDER set, the sphere tests also write the pictures and figures of
// docs/osl.md there (make osl-docs).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/file.h>
#include <unistd.h>

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <regex>
#include <sstream>

#include "color/image_diff.h"
#include "model/theta_grid.h"
#include "io/image_file.h"
#include "lut/lut.h"
#include "model/analytic.h"
#include "model/ndf.h"
#include "support/tensor_file.h"
#include "test_util.h"

namespace facetfit {
namespace {

using test::facetfit;
using test::RunResult;
using test::TempDir;

const std::string kSource = FACETFIT_SOURCE_DIR;

using glm::dot;
using glm::length;
using glm::normalize;

double radians(double degrees) { return degrees * kPi / 180.0; }

std::string str(const Vec3& v) {
  return "(" + std::to_string(v.x) + ", " + std::to_string(v.y) + ", " + std::to_string(v.z) + ")";
}

std::string quoted(const std::string& s) { return "'" + s + "'"; }

RunResult python(const std::string& args) { return test::run_command(quoted(FACETFIT_BPY_PYTHON) + " " + args); }

// Renders with Cycles; returns the run (status, messages) and fails the test on a nonzero exit.
RunResult cycles(const std::string& args) {
  RunResult r = python(quoted(kSource + "/tests/osl/cycles_render.py") + " " + args);
  EXPECT_EQ(r.status, 0) << r.out << r.err;
  return r;
}

struct Image {
  int width = 0, height = 0, channels = 0;
  std::vector<float> pixels;
  const float* at(int x, int y) const { return &pixels[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * std::size_t(channels)]; }
};

Image read_image(const std::string& path) {
  ImageReader in = ImageReader::open(path);
  Image img;
  img.width = in.spec().width;
  img.height = in.spec().height;
  img.channels = int(in.spec().channels.size());
  img.pixels = in.read_pixels();
  return img;
}

// A size x size float RGB image holding one vector per pixel, row-major from the top left.
void write_vectors(const std::string& path, int size, const std::vector<Vec3>& v) {
  std::vector<float> rgb;
  for (const Vec3& d : v) rgb.insert(rgb.end(), {float(d.x), float(d.y), float(d.z)});
  write_image_atomic(path, ImageSpec(size, size, {"R", "G", "B"}), rgb.data());
}

Vec3 as_float(const Vec3& v) { return {double(float(v.x)), double(float(v.y)), double(float(v.z))}; }

// Compiles every .osl of `folder` into `out` with Cycles' compiler (scripts/osl_compile.py).
RunResult osl_compile(const std::string& folder, const std::string& out) {
  return python(quoted(kSource + "/scripts/osl_compile.py") + " " + quoted(folder) + " " + quoted(out));
}

// Compiles the shaders of osl/ and tests/osl/ into `dir`. The renders load these .oso files: a script
// node given a .osl compiles it into a temporary file of Blender's own, which concurrent test processes
// would share.
void compile_shaders(const std::filesystem::path& dir) {
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

// ---- compilation ------------------------------------------------------------------------------------

TEST(OslCompile, EveryShaderCompiles) {
  TempDir out;
  const RunResult r = osl_compile(kSource + "/osl", out.path().string());
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  int shaders = 0;
  for (const auto& e : std::filesystem::directory_iterator(kSource + "/osl")) {
    if (e.path().extension() != ".osl") continue;
    ++shaders;
    EXPECT_NE(r.out.find("compiled " + e.path().string()), std::string::npos) << r.out;
    EXPECT_TRUE(std::filesystem::exists(out.file(e.path().stem().string() + ".oso"))) << e.path();
  }
  EXPECT_GE(shaders, 2);
  // The test probe too: it includes facetfit.h from its own folder.
  const RunResult probe = osl_compile(kSource + "/tests/osl", out.path().string());
  EXPECT_EQ(probe.status, 0) << probe.out << probe.err;
}

TEST(OslCompile, BrokenShaderFailsWithTheCompilersMessage) {
  TempDir dir;
  test::write_bytes(dir.file("broken.osl"),
                    "#include \"" + kSource + "/osl/facetfit.h\"\n"
                    "shader broken(output color c = 0) {\n"
                    "  c = facetfit_no_such_function(1.0);\n"
                    "}\n");
  const RunResult r = osl_compile(dir.path().string(), dir.path().string());
  EXPECT_EQ(r.status, 1) << r.out << r.err;
  EXPECT_NE(r.out.find("FAILED   " + dir.file("broken.osl")), std::string::npos) << r.out;
  // The compiler's own line: file, line number, and what is wrong.
  EXPECT_NE(r.err.find("broken.osl:3: error: function 'facetfit_no_such_function' was not declared"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("broken.oso")));
}

// A missing LUT renders the material's error colour, not the texture system's silent magenta, and the
// shader says why, naming the file.
TEST(OslMaterial, MissingLutRendersTheErrorColourAndWarns) {
  TempDir dir;
  compile_shaders(dir.path());
  const RunResult r = cycles("probe " + dir.file("facetfit_material.oso") + " " + dir.file("out.exr") + " 6 lut=" + dir.file("no-such-lut.exr"));
  const Image img = read_image(dir.file("out.exr"));
  const float* px = img.at(3, 3);
  EXPECT_FLOAT_EQ(px[0], 1.0f);
  EXPECT_FLOAT_EQ(px[1], 0.0f);
  EXPECT_FLOAT_EQ(px[2], 0.5f);
  EXPECT_NE((r.out + r.err).find("facetfit_material: " + dir.file("no-such-lut.exr") + " is missing or not a facetfit LUT"),
            std::string::npos) << r.out << r.err;
}

// ---- eval, sample and pdf against the library --------------------------------------------------------

constexpr int kGrid = 32;  // cases a side: 1024 cases per render
constexpr int kCell = 3;   // pixels a side per case: the centre pixel is read, far from the case's edges

// 1e-4 relative, with a floor for values that are zero in exact arithmetic (below the horizon of one
// side, outside the support) and come out as float round-off.
bool close(double osl, double cpp, double floor) { return std::abs(osl - cpp) <= 1e-4 * std::abs(cpp) + floor; }

// How much `value` (a function of two unit directions) moves when a coordinate of either moves by 4
// float ulps (a relative 2.4e-7): the OSL side reads its inputs from float images and computes in
// float, so it can agree with the double library only to about this. Large for a sharp coat, whose
// density changes by 1/alpha^2 per radian near its peak; negligible elsewhere.
template <class F>
double input_sensitivity(const Vec3& a, const Vec3& b, F value) {
  constexpr double kUlps = 2.4e-7;
  const double base = value(a, b);
  double worst = 0.0;
  for (int k = 0; k < 3; ++k)
    for (const double s : {-1.0, 1.0}) {
      Vec3 da = a, db = b;
      da[k] += s * kUlps * std::max(std::abs(a[k]), 1e-3);
      db[k] += s * kUlps * std::max(std::abs(b[k]), 1e-3);
      worst = std::max({worst, std::abs(value(normalize(da), b) - base), std::abs(value(a, normalize(db)) - base)});
    }
  return worst;
}

// The inputs of one render, as written to the input images (float). Float rounding leaves a direction
// off unit length by up to 1e-7, which the OSL side ignores (it takes angles from all three components)
// and the library, which reads theta from z alone, does not: the library gets them renormalised in double.
struct Cases {
  std::vector<Vec3> o, second;  // second: i (eval, pdf) or (u1, u2, 1) (sample)
  Vec3 unit_o(int k) const { return normalize(o[std::size_t(k)]); }
  Vec3 unit_i(int k) const { return normalize(second[std::size_t(k)]); }
};

// Directions that reach the edges: the normal, grazing (89.9 degrees), retro-reflection, near the
// mirror direction (the peak), and random pairs; all rounded to float as the OSL side reads them.
Cases direction_pairs(std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Cases c;
  for (int k = 0; k < kGrid * kGrid; ++k) {
    Vec3 o = test::random_direction(rng), i = test::random_direction(rng);
    switch (k % 8) {
      case 0: o = spherical_direction(0.0, 0.0); break;
      case 1: o = spherical_direction(radians(89.9), 2.0 * kPi * u(rng)); break;
      case 2: i = o; break;
      case 3:
      case 4: {  // near mirror: reflect o about a normal close to z
        const Vec3 h = spherical_direction(0.3 * u(rng) * u(rng), 2.0 * kPi * u(rng));
        i = 2.0 * dot(o, h) * h - o;
        if (i.z <= 0.0) i = test::random_direction(rng);
        break;
      }
      case 5: i = spherical_direction(radians(89.9), 2.0 * kPi * u(rng)); break;
      default: break;
    }
    c.o.push_back(as_float(normalize(as_float(o))));
    c.second.push_back(as_float(normalize(as_float(i))));
  }
  return c;
}

Cases sample_inputs(std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Cases c;
  for (int k = 0; k < kGrid * kGrid; ++k) {
    Vec3 o = test::random_direction(rng);
    if (k % 16 == 0) o = spherical_direction(0.0, 0.0);
    if (k % 16 == 1) o = spherical_direction(radians(89.0), 2.0 * kPi * u(rng));
    // Corners of the unit square as well as its inside.
    double u1 = k % 16 == 2 ? 0.0 : u(rng), u2 = k % 16 == 3 ? 0.999999 : u(rng);
    c.o.push_back(as_float(normalize(as_float(o))));
    c.second.push_back(as_float({u1, u2, 1.0}));
  }
  return c;
}

class OslModel : public ::testing::TestWithParam<std::string> {
 protected:
  static void SetUpTestSuite() { luts_ = new SharedFolder(FACETFIT_OSL_FIXTURE, make_luts); }
  static void TearDownTestSuite() {
    delete luts_;
    luts_ = nullptr;
  }

 public:
  // The LUTs the probe reads, and the compiled shaders, into `dir`.
  static void make_luts(const std::filesystem::path& dir) {
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

 protected:
  // A parameter ending in "+stretch" is that LUT with the artist's stretch (model/stretch.h), which the
  // probe hands to facetfit_stretch.
  bool stretched() const { return GetParam().size() > 8 && GetParam().substr(GetParam().size() - 8) == "+stretch"; }
  std::string lut() const { return luts_->file((stretched() ? GetParam().substr(0, GetParam().size() - 8) : GetParam()) + ".exr"); }
  Stretch stretch() const { return stretched() ? Stretch{2.0, 0.5, 0.5235987755982988} : Stretch{}; }
  TabulatedMicrofacet model() const {
    Lut l = read_lut(lut());
    return TabulatedMicrofacet(std::move(l.tables), std::move(l.sampling), stretch());
  }

  // Renders the probe in `mode` over the cases; returns one pixel per case (kGrid x kGrid RGBA): the
  // centre of its kCell x kCell block, so that no sub-pixel offset of the renderer reaches a neighbour.
  Image probe(int mode, const Cases& cases) const {
    TempDir dir;
    write_vectors(dir.file("o.exr"), kGrid, cases.o);
    write_vectors(dir.file("second.exr"), kGrid, cases.second);
    const RunResult r = cycles("probe " + luts_->file("facetfit_probe.oso") + " " + dir.file("out.exr") + " " +
                               std::to_string(kGrid * kCell) + " lut=" + lut() + " directions_o=" + dir.file("o.exr") +
                               " inputs_2=" + dir.file("second.exr") + " mode=" + std::to_string(mode) +
                               (stretched() ? " stretch_x=2.0 stretch_y=0.5 rotation=0.5235987755982988" : ""));
    // The probe's warnings (an input or the LUT it could not read) fail the test with Cycles' messages.
    EXPECT_EQ(r.out.find("facetfit_probe:"), std::string::npos) << r.out;
    EXPECT_EQ(r.err.find("facetfit_probe:"), std::string::npos) << r.err;
    const Image full = read_image(dir.file("out.exr"));
    EXPECT_EQ(full.width, kGrid * kCell);
    EXPECT_EQ(full.height, kGrid * kCell);
    Image img{kGrid, kGrid, full.channels, {}};
    for (int y = 0; y < kGrid; ++y)
      for (int x = 0; x < kGrid; ++x) {
        const float* px = full.at(kCell * x + kCell / 2, kCell * y + kCell / 2);
        img.pixels.insert(img.pixels.end(), px, px + full.channels);
      }
    return img;
  }

  // probe(), rendered again once when pixels come back black where the library's value is not (`drawn`
  // says which cases carry a value). Cycles does that now and then: in about one run of the osl label in
  // five under a parallel ctest, one to three of the 1024 pixels of one probe render are exactly 0 while
  // every other pixel agrees to 1e-5, and the same render is right when repeated (inputs, LUT and shader
  // unchanged; the probe's input checks do not fire). A fault of ours would repeat; the second render
  // is then checked as strictly as the first.
  template <class Drawn>
  Image probe_checked(int mode, const Cases& cases, Drawn drawn) const {
    Image img = probe(mode, cases);
    int black = 0;
    for (int k = 0; k < kGrid * kGrid; ++k) {
      const float* px = img.at(k % kGrid, k / kGrid);
      if (px[0] == 0.0f && px[1] == 0.0f && px[2] == 0.0f && drawn(k)) ++black;
    }
    if (black > 0) {
      std::cout << "mode " << mode << ": " << black << " pixel(s) black where the library has a value; rendering again\n";
      img = probe(mode, cases);
    }
    return img;
  }

  static SharedFolder* luts_;
};
SharedFolder* OslModel::luts_ = nullptr;

TEST_P(OslModel, MetadataEqualsLibrary) {
  const Lut table = read_lut(lut());
  Cases cases;  // any valid inputs: the metadata do not depend on them
  cases.o.assign(kGrid * kGrid, Vec3(0.0, 0.0, 1.0));
  cases.second.assign(kGrid * kGrid, Vec3(0.0, 0.0, 1.0));
  const Image img = probe(5, cases);
  const int smith = table.meta.smith == Smith::masking ? 0 : (table.meta.smith == Smith::correlated ? 1 : 2);
  const int representation = representation_code(table.meta.representation);
  EXPECT_EQ(img.at(0, 0)[0], float(smith));
  EXPECT_EQ(img.at(0, 0)[1], float(representation));
  EXPECT_EQ(img.at(0, 0)[2], float(table.meta.resolution));
}

TEST_P(OslModel, EvalEqualsLibrary) {
  const TabulatedMicrofacet model = this->model();
  const Cases cases = direction_pairs(11);
  const Image img = probe_checked(0, cases, [&](int k) {
    const Rgb f = model.eval(cases.unit_o(k), cases.unit_i(k)).value_or(Rgb(0.0));
    return f.r > 1e-3 || f.g > 1e-3 || f.b > 1e-3;
  });
  ASSERT_EQ(img.width, kGrid);
  double worst = 0.0;
  int checked = 0;
  for (int k = 0; k < kGrid * kGrid; ++k) {
    const Rgb f = model.eval(cases.unit_o(k), cases.unit_i(k)).value_or(Rgb(0.0));
    const float* px = img.at(k % kGrid, k / kGrid);
    for (int c = 0; c < 3; ++c) {
      const double moved = 2.0 * input_sensitivity(cases.unit_i(k), cases.unit_o(k), [&](const Vec3& i, const Vec3& o) {
        return model.eval(o, i).value_or(Rgb(0.0))[c];
      });
      EXPECT_TRUE(close(px[c], f[c], 1e-6 + moved)) << "case " << k << " channel " << c << ": OSL " << px[c] << ", C++ " << f[c]
                                            << "; o " << str(cases.o[std::size_t(k)]) << ", i " << str(cases.second[std::size_t(k)]);
      if (f[c] > 1e-3) worst = std::max(worst, std::abs(px[c] - f[c]) / f[c]), ++checked;
    }
  }
  EXPECT_GT(checked, kGrid * kGrid);  // most cases carry energy
  std::cout << GetParam() << ": eval, worst relative difference " << worst << " over " << checked << " values\n";
}

TEST_P(OslModel, PdfAndTermsEqualLibrary) {
  const TabulatedMicrofacet model = this->model();
  const Cases cases = direction_pairs(12);
  const Image img = probe_checked(1, cases, [&](int k) { return model.g1(cases.unit_i(k)) > 1e-3; });
  double worst = 0.0;
  for (int k = 0; k < kGrid * kGrid; ++k) {
    const Vec3 o = cases.unit_o(k), i = cases.unit_i(k);
    const float* px = img.at(k % kGrid, k / kGrid);
    const double pdf = model.pdf(o, i), d = model.D(normalize(i + o)), g1 = model.g1(i);
    const double moved = 2.0 * input_sensitivity(o, i, [&](const Vec3& a, const Vec3& b) { return model.pdf(a, b); });
    EXPECT_TRUE(close(px[0], pdf, 1e-6 + moved)) << "pdf, case " << k << ": OSL " << px[0] << ", C++ " << pdf << "; o " << str(o) << ", i " << str(i);
    EXPECT_TRUE(close(px[1], d, 1e-6)) << "D, case " << k << ": OSL " << px[1] << ", C++ " << d;
    EXPECT_TRUE(close(px[2], g1, 1e-6)) << "G1, case " << k << ": OSL " << px[2] << ", C++ " << g1;
    if (pdf > 1e-3) worst = std::max(worst, std::abs(px[0] - pdf) / pdf);
  }
  std::cout << GetParam() << ": pdf, worst relative difference " << worst << "\n";
}

// How far sample() moves its direction when an input moves by a few float ulps (4, a relative 2.4e-7):
// u1, u2, or o's coordinate x = R sqrt(theta / (pi/2)) on the grid, whose fraction weighs the two view
// slices the sampler mixes. The OSL side computes in float, so it can agree with the double library only
// to about this. It exceeds 1e-4 where the map to i is steep: near the switch between the two slices
// (u1 close to 1 - t) and in the low-density tail of a slice.
double sample_sensitivity(const TabulatedMicrofacet& model, const Vec3& o, double u1, double u2) {
  constexpr double kUlps = 2.4e-7;
  const int r = model.tables().ndf.grid.resolution;
  const double theta = std::atan2(std::hypot(o.x, o.y), o.z), phi = std::atan2(o.y, o.x);
  const double x = ThetaGrid::u_of_theta(theta) * r;
  const auto view = [&](double dx) { return spherical_direction(ThetaGrid::theta_of_u((x + dx) / r), phi); };
  const auto at = [&](const Vec3& v, double a, double b) {
    return model.sample_direction(v, clamp(a, 0.0, 0.9999999), clamp(b, 0.0, 0.9999999));
  };
  double worst = 0.0;
  for (const auto& [a, b] : {std::pair{at(o, u1 * (1.0 - kUlps), u2), at(o, u1 * (1.0 + kUlps), u2)},
                             std::pair{at(o, u1, u2 * (1.0 - kUlps)), at(o, u1, u2 * (1.0 + kUlps))},
                             std::pair{at(view(-kUlps * r), u1, u2), at(view(kUlps * r), u1, u2)}})
    if (a && b) worst = std::max(worst, 0.5 * length(*a - *b));
  return worst;
}

TEST_P(OslModel, SampleEqualsLibrary) {
  const TabulatedMicrofacet model = this->model();
  const Cases cases = sample_inputs(13);
  const auto draws = [&](int k) {
    return model.sample(cases.unit_o(k), cases.second[std::size_t(k)].x, cases.second[std::size_t(k)].y).has_value();
  };
  const Image dirs = probe_checked(2, cases, draws), pdfs = probe_checked(3, cases, draws);
  double worst_dir = 0.0, worst_pdf = 0.0;
  int drawn = 0, beyond = 0;  // beyond: farther apart than 1e-4
  for (int k = 0; k < kGrid * kGrid; ++k) {
    const Vec3 o = cases.unit_o(k);
    const double u1 = cases.second[std::size_t(k)].x, u2 = cases.second[std::size_t(k)].y;
    const auto s = model.sample(o, u1, u2);
    const float* d = dirs.at(k % kGrid, k / kGrid);
    const float* p = pdfs.at(k % kGrid, k / kGrid);
    const bool osl_ok = p[1] > 0.5f;
    if (s.has_value() != osl_ok) {
      // Only a reflection that grazes the horizon may fall on either side of it in float.
      const double z = s ? s->i.z : 2.0 * d[2] - 1.0;
      EXPECT_LT(std::abs(z), 1e-4) << "case " << k << ": C++ " << (s ? "draws" : "draws nothing") << ", OSL does not";
      continue;
    }
    if (!s) continue;
    ++drawn;
    const Vec3 i_osl{2.0 * d[0] - 1.0, 2.0 * d[1] - 1.0, 2.0 * d[2] - 1.0};
    const double dist = length(i_osl - s->i);
    const double bound = std::max(1e-4, 2.0 * sample_sensitivity(model, o, u1, u2));
    if (dist > 1e-4) ++beyond;
    EXPECT_LE(dist, bound) << "case " << k << ": OSL " << str(i_osl) << ", C++ " << str(s->i) << "; o " << str(o) << ", u " << u1 << " " << u2;
    worst_dir = std::max(worst_dir, dist);
    // The pdf OSL returns with its sample is the library's pdf of that direction (the density is
    // piecewise smooth in theta_h: compared at the OSL direction, not the C++ one).
    const double pdf = model.pdf(o, i_osl);
    const double moved = 2.0 * input_sensitivity(o, i_osl, [&](const Vec3& a, const Vec3& b) { return model.pdf(a, b); });
    EXPECT_TRUE(close(p[0], pdf, 1e-6 + moved)) << "sample pdf, case " << k << ": OSL " << p[0] << ", C++ " << pdf;
    if (pdf > 0.0) worst_pdf = std::max(worst_pdf, std::abs(p[0] - pdf) / pdf);
  }
  EXPECT_GT(drawn, kGrid * kGrid / 2);
  // 99% within 1e-4; the rest where the map is steep, within twice what 4 float ulps of an input move it.
  // Stretched, the view the tables see is itself computed in float (rotated, scaled, normalized): 98%.
  EXPECT_LE(beyond, drawn / (stretched() ? 50 : 100));
  std::cout << GetParam() << ": sample, " << drawn << " directions drawn, " << beyond << " farther apart than 1e-4 (worst "
            << worst_dir << "), worst pdf relative difference " << worst_pdf << "\n";
}

INSTANTIATE_TEST_SUITE_P(Materials, OslModel,
                         ::testing::Values("gold-ggx-0.15", "silver-ggx-0.60", "copper-beckmann-0.30", "blue-clearcoat-paint",
                                           "minnaert-ggx-0.20", "masking/silver-ggx-0.60", "gold-ggx-0.15+stretch",
                                           "blue-clearcoat-paint+stretch"),
                         [](const ::testing::TestParamInfo<std::string>& param) {
                           std::string name = param.param;
                           std::replace_if(name.begin(), name.end(), [](char c) { return !std::isalnum(static_cast<unsigned char>(c)); }, '_');
                           return name;
                         });

// ---- spheres under an environment map: Cycles against the reference renderer ---------------------

// Small renders with many samples: the comparison is of means over pixels, and Monte Carlo noise in
// either image adds to Delta E (the pictures of make osl-docs are larger).
int sphere_size() { return std::getenv("FACETFIT_OSL_PICTURES") ? 96 : 64; }

// The environment of the sphere tests: a lat-long map in the reference renderer's convention (row 0 at
// the zenith, u = (atan2(x, -z) + pi) / 2 pi, +y up), smooth enough that the preview shader's BRDF
// sampling converges in a test's time (a small sun would not), and different in every direction so that
// a misoriented map shows: a blue-to-white sky, a brown ground, a broad warm light 35 degrees up and a
// cool one low on the other side.
void write_test_environment(const std::string& path) {
  constexpr int kWidth = 256, kHeight = 128;
  const auto lobe = [](const Vec3& d, const Vec3& axis, double power) { return std::pow(std::max(0.0, dot(d, normalize(axis))), power); };
  std::vector<float> rgb;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const double theta = kPi * (y + 0.5) / kHeight, phi = 2.0 * kPi * (x + 0.5) / kWidth - kPi;
      const Vec3 d(std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi));
      const double up = d.y;
      Rgb c = up > 0.0 ? Rgb(0.25, 0.4, 0.8) * (1.0 - up) + Rgb(0.7, 0.8, 1.0) * up : Rgb(0.25, 0.18, 0.12) * (1.0 + 0.5 * up);
      c += Rgb(6.0, 4.5, 2.5) * lobe(d, {1.0, 0.7, 0.6}, 24.0) + Rgb(0.8, 1.4, 2.2) * lobe(d, {-1.0, 0.2, -0.4}, 8.0);
      rgb.insert(rgb.end(), {float(c.r), float(c.g), float(c.b)});
    }
  write_image_atomic(path, ImageSpec(kWidth, kHeight, {"R", "G", "B"}), rgb.data());
}

// Where pictures and figures go (make osl-docs), or "" in a plain test run.
std::string pictures_dir() {
  const char* dir = std::getenv("FACETFIT_OSL_PICTURES");
  return dir && *dir ? dir : "";
}

class OslSphere : public ::testing::Test {
 public:  // the comparison helper below the class uses the renders
  static void SetUpTestSuite() {
    work_ = new TempDir;
    shaders_ = new SharedFolder(FACETFIT_OSL_FIXTURE, OslModel::make_luts);
    rendered_ = new std::map<std::string, std::pair<std::string, double>>;
    write_test_environment(work_->file("sky.exr"));
  }
  static void TearDownTestSuite() {
    delete work_;
    work_ = nullptr;
    delete shaders_;
    shaders_ = nullptr;
    delete rendered_;
    rendered_ = nullptr;
  }

  static std::string bake(const std::string& material) {
    const RunResult r = facetfit("bake builtin:" + material + " -o " + work_->path().string());
    EXPECT_EQ(r.status, 0) << r.err;
    return work_->file(material + ".exr");
  }

  // The reference renderer: the default view of a unit sphere of `material` (scene-format JSON) under
  // the test environment, sphere_size()^2, `spp` samples per pixel.
  static std::string reference(const std::string& name, const nlohmann::json& material, int spp, double* seconds) {
    const nlohmann::json scene = {
        {"camera", {{"position", {0, 0.6, 4}}, {"look_at", {0, 0, 0}}, {"up", {0, 1, 0}}, {"fov", 30}, {"width", sphere_size()}, {"height", sphere_size()}}},
        {"render", {{"spp", spp}, {"seed", 1}}},
        {"environment", {{"file", work_->file("sky.exr")}}},
        {"materials", {{"m", material}}},
        {"objects", {{{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", 1}, {"material", "m"}}}}};
    return render_scene(name, scene, seconds);
  }

  // A scene rendered before in this suite (the preview and the material shader share references) is
  // not rendered again: its image and time are the earlier render's.
  static std::string render_scene(const std::string& name, const nlohmann::json& scene, double* seconds) {
    const std::string key = scene.dump();
    if (const auto done = rendered_->find(key); done != rendered_->end()) {
      *seconds = done->second.second;
      return done->second.first;
    }
    std::ofstream(work_->file(name + ".json")) << scene.dump(2);
    const RunResult r = facetfit("render " + work_->file(name + ".json") + " -o " + work_->file(name + ".exr"));
    EXPECT_EQ(r.status, 0) << r.err;
    std::smatch m;
    if (std::regex_search(r.out, m, std::regex("spp, ([0-9.]+) s\\)"))) *seconds = std::stod(m[1]);
    if (r.status == 0) (*rendered_)[key] = {work_->file(name + ".exr"), *seconds};
    return work_->file(name + ".exr");
  }

  // The same view in the scene of ../shared/data/realref: a constant environment of 0.3 and a directional
  // light of irradiance 3 toward (0.3, 1, 0.5).
  static std::string reference_sun(const std::string& name, const nlohmann::json& material, int spp, double* seconds) {
    const nlohmann::json scene = {
        {"camera", {{"position", {0, 0.6, 4}}, {"look_at", {0, 0, 0}}, {"up", {0, 1, 0}}, {"fov", 30}, {"width", sphere_size()}, {"height", sphere_size()}}},
        {"render", {{"spp", spp}, {"seed", 1}}},
        {"environment", {{"constant", {0.3, 0.3, 0.3}}}},
        {"lights", {{{"type", "directional"}, {"direction", {0.3, 1, 0.5}}, {"irradiance", {3, 3, 3}}}}},
        {"materials", {{"m", material}}},
        {"objects", {{{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", 1}, {"material", "m"}}}}};
    return render_scene(name, scene, seconds);
  }

  // Cycles renders of the sphere in one Blender process (its start-up and the shader's compilation are
  // much of a small render's time): one job each, {"command": "sphere" or "sun", "shader", "out", "size",
  // "spp", "environment", "params"} (tests/osl/cycles_render.py). Returns the seconds per render.
  static double cycles_batch(const nlohmann::json& jobs, const std::string& name) {
    std::ofstream(work_->file(name + "-jobs.json")) << jobs.dump(1);
    const auto start = std::chrono::steady_clock::now();
    cycles("batch " + work_->file(name + "-jobs.json"));
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::cout << jobs.size() << " Cycles renders in one process: " << seconds << " s\n";
    return seconds / double(std::max<std::size_t>(1, jobs.size()));
  }

  // A Cycles job of the sphere: NAME=VALUE words of `params` as the shader's parameters.
  static nlohmann::json cycles_job(const std::string& command, const std::string& shader, const std::string& out, int spp,
                                   const std::string& params) {
    nlohmann::json p = nlohmann::json::object();
    std::istringstream words(params);
    for (std::string item; words >> item;) p[item.substr(0, item.find('='))] = item.substr(item.find('=') + 1);
    return {{"command", command}, {"shader", shaders_->file(shader + ".oso")}, {"out", out}, {"size", sphere_size()},
            {"spp", spp}, {"environment", work_->file("sky.exr")}, {"params", p}};
  }

  // Mean Delta E 2000 over the pixels both renders cover fully (alpha > 0.999: the silhouette's pixels
  // mix sphere and background in proportions that depend on each renderer's pixel sampling).
  static ImageDiff compare(const std::string& a_path, const std::string& b_path, const std::string& picture_name) {
    const Image a = read_image(a_path), b = read_image(b_path);
    EXPECT_EQ(a.channels, 4);
    EXPECT_EQ(b.channels, 4);
    std::vector<float> a_rgb, b_rgb;
    std::vector<bool> mask;
    for (int y = 0; y < a.height; ++y)
      for (int x = 0; x < a.width; ++x) {
        const float* pa = a.at(x, y);
        const float* pb = b.at(x, y);
        a_rgb.insert(a_rgb.end(), pa, pa + 3);
        b_rgb.insert(b_rgb.end(), pb, pb + 3);
        mask.push_back(pa[3] > 0.999f && pb[3] > 0.999f);
      }
    ImageDiff d = image_delta_e(a_rgb, false, b_rgb, false, mask, DisplayTransform());
    EXPECT_GT(d.pixels, std::size_t(sphere_size() * sphere_size() / 5));  // the sphere fills a good part of the view
    if (const std::string dir = pictures_dir(); !dir.empty()) {
      std::filesystem::create_directories(dir);
      write_display_png(dir + "/" + picture_name + "-cycles.png", b.pixels.data(), b.width, b.height, 4, DisplayTransform());
      write_display_png(dir + "/" + picture_name + "-reference.png", a.pixels.data(), a.width, a.height, 4, DisplayTransform());
      write_heatmap_png(dir + "/" + picture_name + "-delta-e.png", a.width, a.height, d.delta_e, mask);
    }
    return d;
  }

  // One line of docs/osl.md's figures (make osl-docs), appended to figures.md in the pictures folder.
  static void record(const std::string& line) {
    if (const std::string dir = pictures_dir(); !dir.empty()) std::ofstream(dir + "/figures.md", std::ios::app) << line << "\n";
  }

  static TempDir* work_;
  static SharedFolder* shaders_;  // the compiled shaders (and OslModel's LUTs)
  static std::map<std::string, std::pair<std::string, double>>* rendered_;  // scene JSON -> (image, seconds)
};
TempDir* OslSphere::work_ = nullptr;
SharedFolder* OslSphere::shaders_ = nullptr;
std::map<std::string, std::pair<std::string, double>>* OslSphere::rendered_ = nullptr;

// One comparison: `material` rendered by the reference renderer (`reference`, a scene-format material, at
// `reference_spp`) and by Cycles through `shader` (`cycles_spp` samples per pixel, shader parameters
// `params` as NAME=VALUE words); `what` names it in the log and in docs/osl.md's figures.
struct SphereCase {
  std::string material, what;
  nlohmann::json reference;
  int reference_spp;
  std::string shader;
  int cycles_spp;
  std::string params;
};

// Every case's Cycles render in one Blender process, then each reference render; the mean Delta E 2000 of
// each must stay below the issue's 1.0.
void check_spheres(const std::vector<SphereCase>& cases, const std::string& suite) {
  nlohmann::json jobs = nlohmann::json::array();
  for (std::size_t k = 0; k < cases.size(); ++k)
    jobs.push_back(OslSphere::cycles_job("sphere", cases[k].shader, OslSphere::work_->file(suite + "-cycles-" + std::to_string(k) + ".exr"),
                                         cases[k].cycles_spp, cases[k].params));
  const double cycles_seconds = OslSphere::cycles_batch(jobs, suite);
  for (std::size_t k = 0; k < cases.size(); ++k) {
    const SphereCase& c = cases[k];
    double ref_s = 0.0;
    const std::string name = c.shader + "-" + c.material;
    const std::string ref = OslSphere::reference("reference-" + name, c.reference, c.reference_spp, &ref_s);
    const ImageDiff d = OslSphere::compare(ref, jobs[k]["out"].get<std::string>(), c.shader.substr(c.shader.find('_') + 1) + "-" + c.material);
    EXPECT_LT(d.mean, 1.0) << c.material << ": max " << d.max;
    std::cout << c.material << ", " << c.what << ": mean Delta E " << d.mean << ", max " << d.max << " over " << d.pixels
              << " pixels; reference " << ref_s << " s (" << c.reference_spp << " spp)\n";
    OslSphere::record("| " + c.material + " | " + c.what + " | " + std::to_string(d.mean) + " | " + std::to_string(d.max) + " | " +
                      std::to_string(cycles_seconds) + " |");
  }
}

// The preview shader integrates the environment against the tabulated model with facetfit.h's sampling;
// the reference renderer renders the same LUT's tabulated model with its C++ implementation. Both images
// carry Monte Carlo noise, which Delta E adds up pixel by pixel, hence the sample counts.
TEST_F(OslSphere, PreviewShaderMatchesReferenceTabulated) {
  constexpr int kPasses = 8, kSamples = 64;  // Cycles samples per pixel x the shader's own samples
  // red-plastic and blue-clearcoat-paint: a body and a coat, sampled by the mixture.
  std::vector<SphereCase> cases;
  for (const std::string material : {"gold-ggx-0.15", "silver-ggx-0.60", "copper-beckmann-0.30", "red-plastic", "blue-clearcoat-paint"}) {
    const std::string lut = bake(material);
    cases.push_back({material, "preview (tabulated, " + std::to_string(kPasses) + " x " + std::to_string(kSamples) + " samples)",
                     {{"type", "lut"}, {"file", lut}}, 4096, "facetfit_preview", kPasses,
                     "lut=" + lut + " environment_map=" + work_->file("sky.exr") + " samples=" + std::to_string(kSamples)});
  }
  check_spheres(cases, "preview");
}

// The artist's stretch (model/stretch.h) through the preview shader's parameters, along a tangent that
// follows world up, against the reference renderer's stretched LUT material with the same tangent.
TEST_F(OslSphere, StretchedPreviewMatchesReference) {
  constexpr int kPasses = 8, kSamples = 64;
  const std::string lut = bake("gold-ggx-0.15");
  // facetfit's world up (0, 1, 0) is Blender's (0, 0, 1).
  // Named apart from the unstretched spheres: make osl-docs keeps both pictures.
  const nlohmann::json reference = {{"type", "lut"}, {"file", lut}, {"stretch", {3.0, 0.5}}, {"rotation", 30.0}, {"tangent", {0.0, 1.0, 0.0}}};
  std::vector<SphereCase> cases;
  cases.push_back({"gold-ggx-0.15-stretched", "preview stretched (3, 0.5) at 30 degrees", reference, 4096, "facetfit_preview", kPasses,
                   "lut=" + lut + " environment_map=" + work_->file("sky.exr") + " samples=" + std::to_string(kSamples) +
                       " roughness_scale_x=3.0 roughness_scale_y=0.5 rotation=30.0 tangent=0,0,1"});
  // The material shader's closure with its alphas scaled: for a GGX material the stretched tabulated lobe
  // is the anisotropic GGX (tests/model/test_stretch.cpp), so the same reference holds, F82-tint against the curve.
  cases.push_back({"gold-ggx-0.15-stretched", "material stretched (3, 0.5) at 30 degrees", reference, 4096, "facetfit_material", 512,
                   "lut=" + lut + " roughness_scale_x=3.0 roughness_scale_y=0.5 rotation=30.0 tangent=0,0,1"});
  check_spheres(cases, "stretched");
}

// A roughness texture for the spheres: from sharper to much rougher around the sphere and between the
// axes, R = exp(0.9 sin(2 pi u + 1) sin(pi v)), G = exp(-0.7 cos(2 pi u) sin^2(pi v)); 1 along its top and
// bottom rows, which the repeat extension blends at the poles.
std::string write_roughness_texture(const TempDir& dir) {
  constexpr int kWidth = 64, kHeight = 32;
  std::vector<float> px;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const double u = (x + 0.5) / kWidth, v = 1.0 - (y + 0.5) / kHeight, band = std::sin(kPi * v);
      px.insert(px.end(), {float(std::exp(0.9 * std::sin(2.0 * kPi * u + 1.0) * band)),
                           float(std::exp(-0.7 * std::cos(2.0 * kPi * u) * band * band)), 0.0f});
    }
  const std::string path = dir.file("roughness.exr");
  write_image_atomic(path, ImageSpec(kWidth, kHeight, {"R", "G", "B"}), px.data());
  return path;
}

// A roughness texture: the stretch per shading point from an image, through Blender's Image Texture node
// into the shaders' roughness_scale parameters, against the reference renderer's stretch_texture (its
// coordinates are Blender's sphere projection: render/texture.h). The test sees the mapping: with the
// reference's texture mirrored in u, or turned a quarter, the same renders differ by a mean Delta E of
// 3.6 and 5.3 (0.5 as it is).
TEST_F(OslSphere, TextureDrivenStretchMatchesReference) {
  constexpr int kPasses = 8, kSamples = 64;
  const std::string lut = bake("gold-ggx-0.15");
  const std::string texture = write_roughness_texture(*work_);
  const nlohmann::json reference = {{"type", "lut"},     {"file", lut},         {"stretch", {2.0, 1.0}},
                                    {"rotation", 30.0},  {"tangent", {0, 1, 0}}, {"stretch_texture", texture}};
  const std::string stretch = " roughness_scale_x=2.0 roughness_scale_y=1.0 rotation=30.0 tangent=0,0,1 stretch_texture=" + texture;
  check_spheres({{"gold-ggx-0.15-textured", "preview, stretch (2, 1) times a texture, at 30 degrees", reference, 4096, "facetfit_preview",
                  kPasses, "lut=" + lut + " environment_map=" + work_->file("sky.exr") + " samples=" + std::to_string(kSamples) + stretch},
                 {"gold-ggx-0.15-textured", "material, stretch (2, 1) times a texture, at 30 degrees", reference, 4096, "facetfit_material",
                  512, "lut=" + lut + stretch}},
                "textured");
}

// The artist's control on a real measurement (the paper's figure of an edited measured material): one
// RGL material's LUT at several stretches and under the roughness texture, each through the preview
// shader against the reference renderer.
TEST_F(OslSphere, StretchSeriesOfAMeasuredMaterialMatchesReference) {
  const std::filesystem::path source = test::rgl_dir() / "ilm_l3_37_metallic_rgb.bsdf";
  if (!std::filesystem::exists(source)) GTEST_SKIP() << source << " is absent (the RGL database of ../shared/data): no measured series";
  constexpr int kPasses = 8, kSamples = 64;
  const RunResult r = facetfit("bake " + source.string() + " -o " + work_->path().string());
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string lut = work_->file("ilm_l3_37_metallic_rgb.exr");
  const std::string texture = write_roughness_texture(*work_);
  struct Case {
    std::string name;
    double x, y, degrees;
    bool textured;
  };
  std::vector<SphereCase> cases;
  for (const Case& c : {Case{"sharper", 0.5, 0.5, 0.0, false}, Case{"rougher", 2.0, 2.0, 0.0, false},
                        Case{"anisotropic", 4.0, 0.5, 45.0, false}, Case{"textured", 1.0, 1.0, 0.0, true}}) {
    nlohmann::json reference = {{"type", "lut"}, {"file", lut}, {"stretch", {c.x, c.y}}, {"rotation", c.degrees}, {"tangent", {0, 1, 0}}};
    std::string params = "lut=" + lut + " environment_map=" + work_->file("sky.exr") + " samples=" + std::to_string(kSamples) +
                         " roughness_scale_x=" + std::to_string(c.x) + " roughness_scale_y=" + std::to_string(c.y) +
                         " rotation=" + std::to_string(c.degrees) + " tangent=0,0,1";
    if (c.textured) reference["stretch_texture"] = texture, params += " stretch_texture=" + texture;
    std::ostringstream what;
    what << "preview, " << (c.textured ? "the roughness texture" : "stretch (" + std::to_string(c.x).substr(0, 3) + ", " +
                                                                     std::to_string(c.y).substr(0, 3) + ")")
         << (c.degrees != 0.0 ? " at " + std::to_string(int(c.degrees)) + " degrees" : "");
    cases.push_back({"ilm_l3_37_metallic-" + c.name, what.str(), reference, 4096, "facetfit_preview", kPasses, params});
  }
  check_spheres(cases, "series");
}

// The material shader emits a format 5 LUT's closures (lib/model/closures.h) as Cycles' own: diffuse,
// microfacet_f82_tint, generalized_schlick_bsdf. The reference renderer renders the same LUT's `closures`
// material. Both in the scene of ../shared/data/realref (a constant world and a sun: little noise besides
// the BSDF's), every Cycles render in one Blender process. Built-ins with a body, a coat, a Beckmann lobe
// (fitted as GGX closures); with ../shared/data, two RGL materials whose closures have two or three lobes
// (generalized Schlick among them); and an anisotropic input's LUT along a tangent, turned and scaled by
// the artist's parameters, with a control turned a quarter more. The issue's bar: mean Delta E <= 0.5.
TEST_F(OslSphere, MaterialShaderEmitsTheClosures) {
  constexpr int kCyclesSpp = 256, kReferenceSpp = 4096;
  struct Case {
    std::string name, lut, params;
    nlohmann::json reference;
  };
  std::vector<Case> cases;
  for (const std::string material : {"gold-ggx-0.15", "silver-ggx-0.60", "copper-beckmann-0.30", "red-plastic", "blue-clearcoat-paint"}) {
    const std::string lut = bake(material);
    cases.push_back({material, lut, "", {{"type", "material"}, {"file", lut}}});
  }
  for (const std::string rgl : {"cc_ibiza_sunset_rgb", "ilm_l3_37_metallic_rgb"}) {
    const std::filesystem::path source = test::rgl_dir() / (rgl + ".bsdf");
    if (!std::filesystem::exists(source)) {
      std::cout << source << " is absent (the RGL database of ../shared/data): not rendered\n";
      continue;
    }
    const RunResult r = facetfit("bake " + source.string() + " -o " + work_->path().string());
    ASSERT_EQ(r.status, 0) << r.err;
    const std::string lut = work_->file(rgl + ".exr");
    cases.push_back({rgl, lut, "", {{"type", "material"}, {"file", lut}}});
    if (rgl != "cc_ibiza_sunset_rgb") continue;
    // Its lobes follow the view (format 6). The control: the reference of the same lobes along the tangent (their
    // view exponents set to 0) is far from the material's render, so the shader does turn them with the view.
    const Lut film = read_lut(lut);
    ASSERT_EQ(film.meta.format_version, kLutViewLobesVersion);
    std::string zeroed = "oiiotool " + lut;
    for (std::size_t k = 0; k < film.meta.closures.lobes.size(); ++k)
      zeroed += " --attrib:type=float facetfit:closures_lobe" + std::to_string(k) + "_view_exponent 0";
    ASSERT_EQ(test::run_command(zeroed + " -o " + work_->file("along-the-tangent.exr")).status, 0);
    cases.push_back({rgl + "-along-the-tangent", lut, "", {{"type", "material"}, {"file", work_->file("along-the-tangent.exr")}}});
  }
  // An RGL file of GGX 0.45 x 0.2 turned 30 degrees, F = 1 (the tests' tensor writer): one anisotropic lobe,
  // along world up (Blender's z), turned 20 degrees more and scaled (1.5, 0.75) along its axes.
  const std::vector<unsigned char> bytes =
      test::serialize(test::microfacet_tensor_fields(Ndf{NdfType::ggx, 0.45, 0.2}, Smith::correlated, radians(30.0), 25, 32, 64));
  test::write_bytes(work_->file("aniso-ggx.bsdf"), std::string(bytes.begin(), bytes.end()));
  ASSERT_EQ(facetfit("bake " + work_->file("aniso-ggx.bsdf") + " -o " + work_->path().string()).status, 0);
  const std::string aniso = work_->file("aniso-ggx.exr");
  const Lut aniso_lut = read_lut(aniso);
  ASSERT_EQ(aniso_lut.meta.format_version, kLutClosuresVersion);
  ASSERT_EQ(aniso_lut.meta.closures.lobes.size(), 1u);
  EXPECT_GT(aniso_lut.meta.closures.lobes[0].alpha_x, 1.5 * aniso_lut.meta.closures.lobes[0].alpha_y);
  const nlohmann::json turned = {{"type", "material"}, {"file", aniso}, {"tangent", {0.0, 1.0, 0.0}},
                                 {"stretch", {1.5, 0.75}}, {"rotation", 20.0}};
  const std::string artist = " tangent=0,0,1 roughness_scale_x=1.5 roughness_scale_y=0.75 rotation=";
  cases.push_back({"aniso-ggx", aniso, artist + "20", turned});
  cases.push_back({"aniso-ggx-turned", aniso, artist + "110", turned});  // the control: a quarter more
  // Without a tangent a lobe's axes are core/frame.h's Frame(n) in both renderers (osl/facetfit.h
  // facetfit_frame): gold stretched (3, 0.5), turned 30 degrees. The control: the reference a quarter more.
  const std::string gold = bake("gold-ggx-0.15"), free = " roughness_scale_x=3 roughness_scale_y=0.5 rotation=30";
  const nlohmann::json no_tangent = {{"type", "material"}, {"file", gold}, {"stretch", {3.0, 0.5}}, {"rotation", 30.0}};
  cases.push_back({"gold-stretched-without-tangent", gold, free, no_tangent});
  nlohmann::json no_tangent_turned = no_tangent;
  no_tangent_turned["rotation"] = 120.0;
  cases.push_back({"gold-stretched-without-tangent-turned", gold, free, no_tangent_turned});

  nlohmann::json jobs = nlohmann::json::array();
  for (const Case& c : cases)
    jobs.push_back(cycles_job("sun", "facetfit_material", work_->file("cycles-closures-" + c.name + ".exr"), kCyclesSpp, "lut=" + c.lut + c.params));
  const double cycles_seconds = cycles_batch(jobs, "closures");
  for (const Case& c : cases) {
    double ref_s = 0.0;
    const std::string ref = reference_sun("reference-closures-" + c.name, c.reference, kReferenceSpp, &ref_s);
    const ImageDiff d = compare(ref, work_->file("cycles-closures-" + c.name + ".exr"), "material-" + c.name);
    std::cout << c.name << ", material (closures): mean Delta E " << d.mean << ", max " << d.max << " over " << d.pixels << " pixels\n";
    if (c.name == "aniso-ggx-turned" || c.name == "gold-stretched-without-tangent-turned") {
      EXPECT_GT(d.mean, 2.0) << c.name << ": the rotation does not turn the lobe";
      continue;
    }
    if (c.name == "cc_ibiza_sunset_rgb-along-the-tangent") {
      EXPECT_GT(d.mean, 1.0) << "the lobes do not follow the view";  // 1.35 when written
      continue;
    }
    EXPECT_LE(d.mean, 0.5) << c.name << ": max " << d.max;
    const std::size_t lobes = read_lut(c.lut).production_closures().lobes.size();
    record("| " + c.name + " | material (closures: " + std::to_string(lobes) + (lobes > 1 ? " lobes" : " lobe") + ", " +
           std::to_string(kCyclesSpp) + " spp, sun) | " + std::to_string(d.mean) + " | " + std::to_string(d.max) + " | " +
           std::to_string(cycles_seconds) + " |");
  }
}

}  // namespace
}  // namespace facetfit
