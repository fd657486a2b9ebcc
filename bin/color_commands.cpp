// facetfit deltae : CIEDE2000 of Lab pairs read on stdin.
// facetfit diff A.exr B.exr : mean and max ΔE00 between two renders through the display chain, and a heatmap.
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "color/ciede2000.h"
#include "color/display.h"
#include "commands.h"
#include "core/error.h"
#include "io/atomic_file.h"

namespace facetfit::cli {

void add_deltae_command(CLI::App& app, int& status);
void add_diff_command(CLI::App& app, int& status);

namespace {

// ---- deltae ----------------------------------------------------------------------------------------------

// The six numbers of one line, or an Error naming the line.
std::array<double, 6> parse_pair(const std::string& line, int number) {
  const std::string what = "stdin line " + std::to_string(number);
  std::array<double, 6> v{};
  std::size_t count = 0, i = 0;
  while (true) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    if (i == line.size()) break;
    std::size_t end = i;
    while (end < line.size() && line[end] != ' ' && line[end] != '\t') ++end;
    const std::string token = line.substr(i, end - i);
    if (count == 6) fail(what, "more than 6 numbers (expected L1 a1 b1 L2 a2 b2)");
    // from_chars: locale-independent, and it must consume the whole token.
    const char* first = token.data() + (token[0] == '+' ? 1 : 0);
    const char* last = token.data() + token.size();
    double x = 0;
    const auto [ptr, ec] = std::from_chars(first, last, x);
    if (ec != std::errc() || ptr != last || !std::isfinite(x)) fail(what, "'" + token + "' is not a finite number");
    v[count++] = x;
    i = end;
  }
  if (count != 6) fail(what, std::to_string(count) + " numbers, expected 6 (L1 a1 b1 L2 a2 b2)");
  return v;
}

void run_deltae(int& status) {
  std::string line;
  int number = 0, failures = 0;
  while (std::getline(std::cin, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();  // files written on Windows
    if (line.find_first_not_of(" \t") == std::string::npos) continue;
    try {
      const auto v = parse_pair(line, number);
      std::printf("%.6f\n", ciede2000({v[0], v[1], v[2]}, {v[3], v[4], v[5]}));
    } catch (const Error& e) {
      report_error(e.what());
      ++failures;
    }
  }
  if (failures > 0) status = 1;
}

// ---- diff ------------------------------------------------------------------------------------------------

// An image's colour (and alpha, if it has an A channel), as float.
struct Image {
  int width = 0, height = 0;
  std::vector<float> rgb;    // interleaved, 3 per pixel
  std::vector<float> alpha;  // empty without an A channel
  bool display_referred = false;

  std::size_t pixels() const { return std::size_t(width) * std::size_t(height); }
};

std::string size_text(int width, int height) { return std::to_string(width) + " x " + std::to_string(height); }

// Every channel of the first subimage as float, with its spec.
std::vector<float> read_all(const std::string& path, OIIO::ImageSpec& spec) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) {
    const std::string why = OIIO::geterror();
    fail(path, why.empty() ? "cannot open" : why.substr(0, why.find('\n')));
  }
  spec = in->spec();
  if (spec.deep) fail(path, "deep images are not supported");
  if (spec.depth != 1) fail(path, "volume images are not supported");
  if (spec.width < 1 || spec.height < 1 || spec.nchannels < 1) fail(path, "empty image");
  std::vector<float> all(std::size_t(spec.width) * std::size_t(spec.height) * std::size_t(spec.nchannels));
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, all.data()))
    fail(path, "cannot read pixels: " + in->geterror());
  return all;
}

// Channels by name, never by position: EXR stores them sorted by name (A, B, G, R).
Image read_image(const std::string& path) {
  OIIO::ImageSpec spec;
  const std::vector<float> all = read_all(path, spec);
  int channel[3];
  const char* names[3] = {"R", "G", "B"};
  for (int c = 0; c < 3; ++c) {
    channel[c] = spec.channelindex(names[c]);
    if (channel[c] < 0) {
      std::string present;
      for (const std::string& n : spec.channelnames) present += (present.empty() ? "" : ", ") + n;
      fail(path, std::string("no ") + names[c] + " channel (channels: " + present + ")");
    }
  }
  const int a = spec.channelindex("A");
  Image image;
  image.width = spec.width;
  image.height = spec.height;
  // OIIO reports 8- and 16-bit PNG, JPEG and the like as "sRGB": their values are already display
  // code values and skip the display transform. Everything else (EXR: "Linear") is scene-linear.
  image.display_referred = spec.get_string_attribute("oiio:ColorSpace") == "sRGB";
  const std::size_t n = image.pixels(), nch = std::size_t(spec.nchannels);
  image.rgb.resize(3 * n);
  if (a >= 0) image.alpha.resize(n);
  for (std::size_t p = 0; p < n; ++p) {
    for (int c = 0; c < 3; ++c) image.rgb[3 * p + c] = all[p * nch + std::size_t(channel[c])];
    if (a >= 0) image.alpha[p] = all[p * nch + std::size_t(a)];
  }
  return image;
}

// The --mask image: a pixel counts where its first channel is > 0.5.
std::vector<bool> read_mask(const std::string& path, int width, int height) {
  OIIO::ImageSpec spec;
  const std::vector<float> all = read_all(path, spec);
  if (spec.width != width || spec.height != height)
    fail(path, "mask is " + size_text(spec.width, spec.height) + ", the images are " + size_text(width, height));
  std::vector<bool> mask(std::size_t(width) * std::size_t(height));
  for (std::size_t p = 0; p < mask.size(); ++p) mask[p] = all[p * std::size_t(spec.nchannels)] > 0.5f;
  return mask;
}

// Without --mask: where either image has alpha > 0 (a render's background has none), else everywhere.
std::vector<bool> coverage_mask(const Image& a, const Image& b) {
  if (a.alpha.empty() && b.alpha.empty()) return std::vector<bool>(a.pixels(), true);
  std::vector<bool> mask(a.pixels());
  for (std::size_t p = 0; p < mask.size(); ++p)
    mask[p] = (!a.alpha.empty() && a.alpha[p] > 0) || (!b.alpha.empty() && b.alpha[p] > 0);
  return mask;
}

// viridis (van der Walt and Smith, matplotlib; CC0), its 256 entries rounded to 8 bits. Perceptually
// uniform in lightness and readable in greyscale and by colour-blind viewers.
constexpr std::uint8_t kViridis[256][3] = {
    {68, 1, 84}, {68, 2, 86}, {69, 4, 87}, {69, 5, 89}, {70, 7, 90}, {70, 8, 92}, {70, 10, 93},
    {70, 11, 94}, {71, 13, 96}, {71, 14, 97}, {71, 16, 99}, {71, 17, 100}, {71, 19, 101}, {72, 20, 103},
    {72, 22, 104}, {72, 23, 105}, {72, 24, 106}, {72, 26, 108}, {72, 27, 109}, {72, 28, 110}, {72, 29, 111},
    {72, 31, 112}, {72, 32, 113}, {72, 33, 115}, {72, 35, 116}, {72, 36, 117}, {72, 37, 118}, {72, 38, 119},
    {72, 40, 120}, {72, 41, 121}, {71, 42, 122}, {71, 44, 122}, {71, 45, 123}, {71, 46, 124}, {71, 47, 125},
    {70, 48, 126}, {70, 50, 126}, {70, 51, 127}, {70, 52, 128}, {69, 53, 129}, {69, 55, 129}, {69, 56, 130},
    {68, 57, 131}, {68, 58, 131}, {68, 59, 132}, {67, 61, 132}, {67, 62, 133}, {66, 63, 133}, {66, 64, 134},
    {66, 65, 134}, {65, 66, 135}, {65, 68, 135}, {64, 69, 136}, {64, 70, 136}, {63, 71, 136}, {63, 72, 137},
    {62, 73, 137}, {62, 74, 137}, {62, 76, 138}, {61, 77, 138}, {61, 78, 138}, {60, 79, 138}, {60, 80, 139},
    {59, 81, 139}, {59, 82, 139}, {58, 83, 139}, {58, 84, 140}, {57, 85, 140}, {57, 86, 140}, {56, 88, 140},
    {56, 89, 140}, {55, 90, 140}, {55, 91, 141}, {54, 92, 141}, {54, 93, 141}, {53, 94, 141}, {53, 95, 141},
    {52, 96, 141}, {52, 97, 141}, {51, 98, 141}, {51, 99, 141}, {50, 100, 142}, {50, 101, 142}, {49, 102, 142},
    {49, 103, 142}, {49, 104, 142}, {48, 105, 142}, {48, 106, 142}, {47, 107, 142}, {47, 108, 142}, {46, 109, 142},
    {46, 110, 142}, {46, 111, 142}, {45, 112, 142}, {45, 113, 142}, {44, 113, 142}, {44, 114, 142}, {44, 115, 142},
    {43, 116, 142}, {43, 117, 142}, {42, 118, 142}, {42, 119, 142}, {42, 120, 142}, {41, 121, 142}, {41, 122, 142},
    {41, 123, 142}, {40, 124, 142}, {40, 125, 142}, {39, 126, 142}, {39, 127, 142}, {39, 128, 142}, {38, 129, 142},
    {38, 130, 142}, {38, 130, 142}, {37, 131, 142}, {37, 132, 142}, {37, 133, 142}, {36, 134, 142}, {36, 135, 142},
    {35, 136, 142}, {35, 137, 142}, {35, 138, 141}, {34, 139, 141}, {34, 140, 141}, {34, 141, 141}, {33, 142, 141},
    {33, 143, 141}, {33, 144, 141}, {33, 145, 140}, {32, 146, 140}, {32, 146, 140}, {32, 147, 140}, {31, 148, 140},
    {31, 149, 139}, {31, 150, 139}, {31, 151, 139}, {31, 152, 139}, {31, 153, 138}, {31, 154, 138}, {30, 155, 138},
    {30, 156, 137}, {30, 157, 137}, {31, 158, 137}, {31, 159, 136}, {31, 160, 136}, {31, 161, 136}, {31, 161, 135},
    {31, 162, 135}, {32, 163, 134}, {32, 164, 134}, {33, 165, 133}, {33, 166, 133}, {34, 167, 133}, {34, 168, 132},
    {35, 169, 131}, {36, 170, 131}, {37, 171, 130}, {37, 172, 130}, {38, 173, 129}, {39, 173, 129}, {40, 174, 128},
    {41, 175, 127}, {42, 176, 127}, {44, 177, 126}, {45, 178, 125}, {46, 179, 124}, {47, 180, 124}, {49, 181, 123},
    {50, 182, 122}, {52, 182, 121}, {53, 183, 121}, {55, 184, 120}, {56, 185, 119}, {58, 186, 118}, {59, 187, 117},
    {61, 188, 116}, {63, 188, 115}, {64, 189, 114}, {66, 190, 113}, {68, 191, 112}, {70, 192, 111}, {72, 193, 110},
    {74, 193, 109}, {76, 194, 108}, {78, 195, 107}, {80, 196, 106}, {82, 197, 105}, {84, 197, 104}, {86, 198, 103},
    {88, 199, 101}, {90, 200, 100}, {92, 200, 99}, {94, 201, 98}, {96, 202, 96}, {99, 203, 95}, {101, 203, 94},
    {103, 204, 92}, {105, 205, 91}, {108, 205, 90}, {110, 206, 88}, {112, 207, 87}, {115, 208, 86}, {117, 208, 84},
    {119, 209, 83}, {122, 209, 81}, {124, 210, 80}, {127, 211, 78}, {129, 211, 77}, {132, 212, 75}, {134, 213, 73},
    {137, 213, 72}, {139, 214, 70}, {142, 214, 69}, {144, 215, 67}, {147, 215, 65}, {149, 216, 64}, {152, 216, 62},
    {155, 217, 60}, {157, 217, 59}, {160, 218, 57}, {162, 218, 55}, {165, 219, 54}, {168, 219, 52}, {170, 220, 50},
    {173, 220, 48}, {176, 221, 47}, {178, 221, 45}, {181, 222, 43}, {184, 222, 41}, {186, 222, 40}, {189, 223, 38},
    {192, 223, 37}, {194, 223, 35}, {197, 224, 33}, {200, 224, 32}, {202, 225, 31}, {205, 225, 29}, {208, 225, 28},
    {210, 226, 27}, {213, 226, 26}, {216, 226, 25}, {218, 227, 25}, {221, 227, 24}, {223, 227, 24}, {226, 228, 24},
    {229, 228, 25}, {231, 228, 25}, {234, 229, 26}, {236, 229, 27}, {239, 229, 28}, {241, 229, 29}, {244, 230, 30},
    {246, 230, 32}, {248, 230, 33}, {251, 231, 35}, {253, 231, 37},
};

// The heatmap's fixed scale: ΔE00 0 to kHeatmapMax across the map, saturating beyond, so two heatmaps
// compare by eye. 10 spans "invisible" (< 1) to "obviously different" (> 5) with room to see both.
constexpr double kHeatmapMax = 10.0;

void write_heatmap(const std::string& path, int width, int height, const std::vector<float>& delta_e,
                   const std::vector<bool>& mask) {
  std::vector<std::uint8_t> pixels(3 * delta_e.size(), 0);  // outside the mask: black, not on the map
  for (std::size_t p = 0; p < delta_e.size(); ++p) {
    if (!mask[p]) continue;
    const double t = std::clamp(double(delta_e[p]) / kHeatmapMax, 0.0, 1.0);
    const auto& c = kViridis[int(std::lround(t * 255))];
    std::copy(c, c + 3, pixels.begin() + std::ptrdiff_t(3 * p));
  }
  OIIO::ImageSpec spec(width, height, 3, OIIO::TypeDesc::UINT8);
  spec.channelnames = {"R", "G", "B"};
  spec.attribute("oiio:ColorSpace", "sRGB");
  AtomicFile out(path);
  auto image = OIIO::ImageOutput::create(out.temp_path());
  if (!image) fail(path, "cannot write: " + OIIO::geterror());
  if (!image->open(out.temp_path(), spec) || !image->write_image(OIIO::TypeDesc::UINT8, pixels.data()) || !image->close())
    fail(path, "cannot write: " + image->geterror());
  image.reset();
  out.commit();
}

struct DiffArgs {
  std::string a, b, mask, heatmap;
  bool json = false;
};

void run_diff(const DiffArgs& args, int& status) {
  if (!args.heatmap.empty()) {
    std::string ext = args.heatmap.size() >= 4 ? args.heatmap.substr(args.heatmap.size() - 4) : "";
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char ch) { return char(std::tolower(ch)); });
    if (ext != ".png") {
      report_error("--heatmap " + args.heatmap + ": must end in .png");
      status = 2;
      return;
    }
  }
  try {
    Image a = read_image(args.a);
    Image b = read_image(args.b);
    if (a.width != b.width || a.height != b.height)
      fail(args.b, "is " + size_text(b.width, b.height) + " but " + args.a + " is " + size_text(a.width, a.height));
    const std::vector<bool> mask = args.mask.empty() ? coverage_mask(a, b) : read_mask(args.mask, a.width, a.height);

    const DisplayTransform display;
    if (!a.display_referred) display.to_display(a.rgb.data(), a.pixels());
    if (!b.display_referred) display.to_display(b.rgb.data(), b.pixels());
    std::vector<float> delta_e(a.pixels(), 0.0f);
    double sum = 0, max = 0;
    std::size_t count = 0;
    for (std::size_t p = 0; p < a.pixels(); ++p) {
      if (!mask[p]) continue;
      const float* ca = a.rgb.data() + 3 * p;
      const float* cb = b.rgb.data() + 3 * p;
      // Equal display values (a shared background, an unchanged region) differ by exactly 0.
      const bool same = ca[0] == cb[0] && ca[1] == cb[1] && ca[2] == cb[2];
      const double d = same ? 0.0
                            : ciede2000(display_to_lab(Rgb(ca[0], ca[1], ca[2])), display_to_lab(Rgb(cb[0], cb[1], cb[2])));
      delta_e[p] = float(d);
      sum += d;
      max = std::max(max, d);
      ++count;
    }
    if (count == 0)
      fail(args.mask.empty() ? args.a : args.mask,
           args.mask.empty() ? "no pixel has alpha > 0 in either image" : "the mask selects no pixel");
    if (!args.heatmap.empty()) write_heatmap(args.heatmap, a.width, a.height, delta_e, mask);
    const double mean = sum / double(count);
    if (args.json)
      std::printf("%s\n", nlohmann::json{{"mean", mean}, {"max", max}, {"pixels", count}}.dump().c_str());
    else
      std::printf("mean %.6f max %.6f pixels %zu\n", mean, max, count);
  } catch (const Error& e) {
    report_error(e.what());
    status = 1;
  }
}

}  // namespace

void add_deltae_command(CLI::App& app, int& status) {
  CLI::App* cmd = app.add_subcommand(
      "deltae", "CIEDE2000 of colour pairs: reads lines 'L1 a1 b1 L2 a2 b2' on stdin, prints one Delta E 2000 per line");
  cmd->callback([&status] { run_deltae(status); });
}

void add_diff_command(CLI::App& app, int& status) {
  auto args = std::make_shared<DiffArgs>();
  CLI::App* cmd = app.add_subcommand(
      "diff", "Mean and max CIEDE2000 between two scene-linear images, through the sRGB display transform");
  cmd->add_option("a", args->a, "First image (scene-linear Rec.709, e.g. an EXR from facetfit render)")->required();
  cmd->add_option("b", args->b, "Second image, the same size")->required();
  cmd->add_option("--mask", args->mask, "Only pixels whose first channel is > 0.5 (default: alpha > 0 in either image, "
                                        "or every pixel without alpha)");
  cmd->add_option("--heatmap", args->heatmap, "Write a PNG of per-pixel Delta E 2000 (viridis, 0 to 10, black outside the mask)");
  cmd->add_flag("--json", args->json, "As one JSON object {\"mean\", \"max\", \"pixels\"}");
  cmd->callback([args, &status] { run_diff(*args, status); });
}

}  // namespace facetfit::cli
