// The Python module `facetfit._facetfit` (pybind11): measurements, fits, LUTs, every material as a model
// to evaluate, sample and give a pdf on numpy arrays of directions, rendering and Delta E. The package
// python/facetfit re-exports it (docs/python.md).
//
// Conventions are the library's (docs/conventions.md): directions are unit vectors in the local frame,
// normal +z, pointing away from the surface, o toward the viewer first, i toward the light second.
// Errors the library reports as facetfit::Error arrive as facetfit.Error, one line naming the input.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "arrays.h"
#include "color/ocio_config.h"
#include "color/image_diff.h"
#include "core/error.h"
#include "core/memory_budget.h"
#include "fit/fit.h"
#include "fit/representations.h"
#include "io/atomic_file.h"
#include "io/input.h"
#include "lut/bake.h"
#include "lut/lut.h"
#include "lut/materialx.h"
#include "lut/record.h"
#include "model/closures.h"
#include "model/ndf.h"
#include "model/parametric.h"
#include "model/tabulated.h"
#include "render/renderer.h"
#include "render/scene.h"
#include "render/shading.h"

namespace facetfit::python {
namespace {

py::object to_python(const nlohmann::json& j) { return py::module_::import("json").attr("loads")(json_text(j)); }
std::string to_json_text(const py::object& o) { return py::module_::import("json").attr("dumps")(o).cast<std::string>(); }

// A measured material as the fit reads it: the MERL-layout table of any input.
struct Measurement {
  std::string source;
  std::shared_ptr<const HalfDiffTable> table;
};

struct Model {
  std::shared_ptr<const ShadingModel> shading;
};

Model tabulated_model(const MicrofacetTables& tables) {
  auto m = std::make_shared<TabulatedMicrofacet>(tables);
  return Model{std::make_shared<ShadingModel>(m, m)};
}

// The closures as the production shader emits them, sampled as the renderer samples them.
Model closures_model(const Closures& c) {
  return Model{std::make_shared<ShadingModel>(std::make_shared<ClosureBrdf>(c), std::make_shared<ClosureProposal>(c))};
}

struct Fit {
  std::string source;
  FitResult result;
  std::shared_ptr<const Fitter> fitter;  // its quadrature bakes the LUT
};

FitOptions fit_options(const std::string& refine, int resolution, const std::string& smith, const std::string& merl_bins,
                       const std::string& closure_fresnel) {
  FitOptions o;
  const auto r = parse_refine(refine);
  if (!r) throw py::value_error("refine: must be full or none, not '" + refine + "'");
  const auto s = parse_smith(smith);
  if (!s) throw py::value_error("smith: must be masking, correlated or separable, not '" + smith + "'");
  const auto b = parse_bin_point(merl_bins);
  if (!b) throw py::value_error("merl_bins: must be start or center, not '" + merl_bins + "'");
  const auto c = parse_closure_fresnel(closure_fresnel);
  if (!c) throw py::value_error("closure_fresnel: must be f82 or schlick, not '" + closure_fresnel + "'");
  if (resolution < kMinResolution || resolution > kMaxResolution)  // the CLI's range
    throw py::value_error("resolution: must be in [" + std::to_string(kMinResolution) + ", " + std::to_string(kMaxResolution) + "]");
  o.refine = *r;
  o.resolution = resolution;
  o.smith = *s;
  o.merl_bins = *b;
  o.closure_fresnel = *c;
  return o;
}

// A path argument (str, bytes or os.PathLike) as the file system's bytes: a name that is not UTF-8 (a
// str of os.fsdecode's surrogates) is taken as it is, where pybind11's str conversion refused it.
std::string fs_path(const py::handle& path) { return py::module_::import("os").attr("fsencode")(path).cast<std::string>(); }

Measurement load(const std::string& source, const std::string& merl_bins) {
  const auto b = parse_bin_point(merl_bins);
  if (!b) throw py::value_error("merl_bins: must be start or center, not '" + merl_bins + "'");
  py::gil_scoped_release release;
  return Measurement{source, std::make_shared<HalfDiffTable>(load_table(source, *b))};
}

Fit fit(const Measurement& m, const FitOptions& options) {
  py::gil_scoped_release release;
  auto fitter = std::make_shared<const Fitter>(options);
  return Fit{m.source, fitter->fit(*m.table), fitter};
}

// f(o, i): shape (..., 3) from two stacks of directions.
py::array_t<double> eval_rgb(const py::handle& o, const py::handle& i, const std::function<Rgb(const Vec3&, const Vec3&)>& f) {
  const Vectors vo(o, "o"), vi(i, "i");
  const auto shape = broadcast(vo, vi, "eval");
  py::array_t<double> out(with_axis(shape, 3));
  double* p = out.mutable_data();
  parallel(count_of(shape), [&](std::size_t k) {
    const Rgb v = f(vo.at(vo.count == 1 ? 0 : k), vi.at(vi.count == 1 ? 0 : k));
    p[3 * k] = v.r;
    p[3 * k + 1] = v.g;
    p[3 * k + 2] = v.b;
  });
  return out;
}

py::dict sample(const Model& m, const py::handle& o, const py::handle& u) {
  const Vectors vo(o, "o"), vu(u, "u", Vectors::Kind::uniform);
  const auto shape = broadcast(vo, vu, "sample");
  const std::size_t n = count_of(shape);
  py::array_t<double> dir(with_axis(shape, 3)), weight(with_axis(shape, 3)), pdf(shape);
  double *pd = dir.mutable_data(), *pw = weight.mutable_data(), *pp = pdf.mutable_data();
  parallel(n, [&](std::size_t k) {
    const Vec3 uk = vu.at(vu.count == 1 ? 0 : k);
    const auto s = m.shading->sample(vo.at(vo.count == 1 ? 0 : k), uk.x, uk.y, uk.z);
    const Vec3 i = s ? s->i : Vec3(0.0);
    const Rgb w = s ? s->weight : Rgb(0.0);
    for (int c = 0; c < 3; ++c) {
      pd[3 * k + c] = i[c];
      pw[3 * k + c] = w[c];
    }
    pp[k] = s ? s->pdf : 0.0;
  });
  py::dict d;
  d["i"] = dir;
  d["weight"] = weight;
  d["pdf"] = pdf;
  return d;
}

py::array_t<double> pdf(const Model& m, const py::handle& o, const py::handle& i) {
  const Vectors vo(o, "o"), vi(i, "i");
  const auto shape = broadcast(vo, vi, "pdf");
  py::array_t<double> out(shape);
  double* p = out.mutable_data();
  parallel(count_of(shape), [&](std::size_t k) { p[k] = m.shading->pdf(vo.at(vo.count == 1 ? 0 : k), vi.at(vi.count == 1 ? 0 : k)); });
  return out;
}

// A material as a scene describes it (docs/scene-format.md), e.g. {"type": "ggx", "alpha": 0.2}.
Model material(const py::dict& description, const std::string& base_dir) {
  const std::string text = R"({"materials": {"m": )" + to_json_text(description) + R"(}, "objects": [{"type": "sphere", "material": "m"}]})";
  py::gil_scoped_release release;
  const SceneDesc scene = parse_scene_text(text, "material", base_dir);
  return Model{load_material(scene, scene.materials.at("m"))};
}

py::array_t<float> render_scene(const py::object& scene, int spp, std::uint64_t seed, const std::string& max_memory) {
  SceneDesc desc;
  if (py::isinstance<py::dict>(scene)) {
    const std::string text = to_json_text(scene);
    desc = parse_scene_text(text, "scene", py::module_::import("os").attr("getcwd")().cast<std::string>());
  } else {
    desc = parse_scene(fs_path(scene));
  }
  if (spp < 0 || spp > (1 << 20)) throw py::value_error("spp: must be in [1, 1048576], or 0 for the scene's");
  RenderSettings settings;
  settings.spp = spp;
  settings.seed = seed;
  if (!max_memory.empty()) {
    const auto bytes = parse_byte_size(max_memory);
    if (!bytes) throw py::value_error("max_memory: '" + max_memory + "' is not a size such as 512M or 4G");
    settings.max_memory = *bytes;
  }
  RenderedImage image;
  {
    py::gil_scoped_release release;
    image = render(desc, settings);
  }
  py::array_t<float> out({py::ssize_t(image.height), py::ssize_t(image.width), py::ssize_t(4)});
  std::copy(image.rgba.begin(), image.rgba.end(), out.mutable_data());
  return out;
}

py::tuple delta_e(const py::handle& a, const py::handle& b, const py::object& mask, bool a_display_referred, bool b_display_referred) {
  using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;
  const FloatArray fa = FloatArray::ensure(a), fb = FloatArray::ensure(b);
  const auto rgb_or_rgba = [](const FloatArray& x) { return x.shape(2) == 3 || x.shape(2) == 4; };
  if (!fa || !fb || fa.ndim() != 3 || fb.ndim() != 3 || !rgb_or_rgba(fa) || !rgb_or_rgba(fb) || fa.shape(0) != fb.shape(0) ||
      fa.shape(1) != fb.shape(1))
    throw py::value_error("delta_e: images must be (height, width, 3 or 4) arrays of the same size");
  const py::ssize_t h = fa.shape(0), w = fa.shape(1);
  const std::size_t pixels = std::size_t(h) * std::size_t(w);
  // A NaN or infinite pixel has no colour difference: refused, as `facetfit diff` refuses it.
  const auto rgb = [pixels, w](const FloatArray& x, const char* name) {
    std::vector<float> v(pixels * 3);
    const py::ssize_t channels = x.shape(2);
    for (std::size_t p = 0; p < pixels; ++p)
      for (int c = 0; c < 3; ++c) {
        v[3 * p + c] = x.data()[p * std::size_t(channels) + c];
        if (!std::isfinite(v[3 * p + c]))
          throw py::value_error(std::string("delta_e: ") + name + "[" + std::to_string(p / std::size_t(w)) + ", " +
                                std::to_string(p % std::size_t(w)) + "] is NaN or infinite");
      }
    return v;
  };
  std::vector<bool> keep(pixels, true);
  if (!mask.is_none()) {
    using BoolArray = py::array_t<bool, py::array::c_style | py::array::forcecast>;
    const BoolArray m = BoolArray::ensure(mask);
    if (!m || m.ndim() != 2 || m.shape(0) != h || m.shape(1) != w) throw py::value_error("delta_e: mask must be a (height, width) array");
    for (std::size_t p = 0; p < pixels; ++p) keep[p] = m.data()[p];
  }
  std::vector<float> va = rgb(fa, "a"), vb = rgb(fb, "b");
  ImageDiff d;
  {
    py::gil_scoped_release release;
    d = image_delta_e(std::move(va), a_display_referred, std::move(vb), b_display_referred, keep, DisplayTransform());
  }
  py::array_t<float> map({h, w});
  std::copy(d.delta_e.begin(), d.delta_e.end(), map.mutable_data());
  return py::make_tuple(map, d.mean, d.max);
}

// A render's image, (height, width, 3 or 4) scene-linear float, as a linear EXR (alpha 1 where it has none)
// or a display-referred sRGB PNG, as `facetfit render -o` and `--png` write them.
void write_image(const py::handle& path_arg, const py::handle& image) {
  const std::string path = fs_path(path_arg);
  using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;
  const FloatArray a = FloatArray::ensure(image);
  if (!a || a.ndim() != 3 || (a.shape(2) != 3 && a.shape(2) != 4) || a.shape(0) < 1 || a.shape(1) < 1)
    throw py::value_error("write_image: image must be a (height, width, 3 or 4) array");
  const int height = int(a.shape(0)), width = int(a.shape(1)), channels = int(a.shape(2));
  const float* px = a.data();
  if (!std::all_of(px, px + a.size(), [](float v) { return std::isfinite(v); }))
    throw py::value_error("write_image: the image holds NaN or infinite values");
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext != ".exr" && ext != ".png") throw py::value_error("write_image: " + path + ": must end in .exr or .png");
  py::gil_scoped_release release;
  if (ext == ".png") return write_display_png(path, px, width, height, channels, DisplayTransform());
  RenderedImage out;
  out.width = width, out.height = height;
  out.rgba.resize(std::size_t(width) * std::size_t(height) * 4, 1.0f);
  for (std::size_t p = 0; p < std::size_t(width) * std::size_t(height); ++p)
    for (int c = 0; c < channels; ++c) out.rgba[4 * p + std::size_t(c)] = px[std::size_t(channels) * p + std::size_t(c)];
  write_exr(path, out, {});
}

py::array_t<double> fresnel_array(const FresnelCurve& f) {
  py::array_t<double> a({py::ssize_t(FresnelCurve::kSize), py::ssize_t(3)});
  for (int j = 0; j < FresnelCurve::kSize; ++j)
    for (int c = 0; c < 3; ++c) a.mutable_at(j, c) = f.value[std::size_t(j)][c];
  return a;
}

py::array_t<double> theta_array(const ThetaGrid& grid) {
  std::vector<double> t(std::size_t(grid.size()));
  for (int j = 0; j < grid.size(); ++j) t[std::size_t(j)] = grid.theta(j);
  return vector_array(t);
}

py::array_t<double> fresnel_theta_d() {
  std::vector<double> t(FresnelCurve::kSize);
  for (int j = 0; j < FresnelCurve::kSize; ++j) t[std::size_t(j)] = FresnelCurve::theta_d(j);
  return vector_array(t);
}

// Evaluates `per_theta` at every element of an array of polar angles.
py::array_t<double> over_theta(const py::handle& theta, const std::function<double(double)>& per_theta) {
  const Array t = Array::ensure(theta);
  if (!t) throw py::value_error("theta: must be an array of angles in radians");
  py::array_t<double> out(std::vector<py::ssize_t>(t.shape(), t.shape() + t.ndim()));
  for (py::ssize_t k = 0; k < t.size(); ++k) {
    const double x = t.data()[k];
    if (!(x >= 0.0 && x <= 0.5 * kPi))  // a polar angle of the upper hemisphere; NaN is not one
      throw py::value_error("theta: angles must be in [0, pi/2] radians; element " + std::to_string(k) + " is " + std::to_string(x));
    out.mutable_data()[k] = per_theta(x);
  }
  return out;
}

// The recommendation's tolerance, as `--tolerance` takes it (bin/app.cpp): finite, in [0, 1e30].
double checked_tolerance(double tolerance) {
  if (!(tolerance >= 0.0 && tolerance <= 1e30)) throw py::value_error("tolerance: must be a finite number in [0, 1e30], not " + std::to_string(tolerance));
  return tolerance;
}

}  // namespace
}  // namespace facetfit::python

using namespace facetfit;
using namespace facetfit::python;

PYBIND11_MODULE(_facetfit, m) {
  m.doc() = "facetfit: microfacet fits of measured BRDFs (Dupuy et al. 2015), LUTs, rendering, Delta E 2000";
  m.attr("__version__") = FACETFIT_VERSION;
  m.attr("lut_format_version") = kLutViewLobesVersion;  // the newest LUT format it writes; the shaders in shader_dir() read it
  // facetfit.Error, its message decoded as os.fsdecode does: a path in it that is not UTF-8 stays readable.
  static py::exception<Error> error_type(m, "Error", PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const Error& e) {
      const std::string what = e.what();
      PyObject* message = PyUnicode_DecodeUTF8(what.data(), Py_ssize_t(what.size()), "surrogateescape");
      PyErr_SetObject(error_type.ptr(), message);
      Py_XDECREF(message);
    }
  });

  py::class_<Measurement>(m, "Measurement", "A measured material in MERL layout (MERL, RGL or builtin: source).")
      .def_readonly("source", &Measurement::source)
      .def_property_readonly("name", [](const Measurement& x) { return source_name(x.source); })
      .def(
          "eval",
          [](const Measurement& x, const py::handle& o, const py::handle& i) {
            return eval_rgb(o, i, [&x](const Vec3& vo, const Vec3& vi) {
              const auto v = x.table->eval(vo, vi);
              return v ? *v : Rgb(std::nan(""));
            });
          },
          py::arg("o"), py::arg("i"), "f(o, i) in 1/sr, shape (..., 3); NaN where the measurement has no value.")
      .def("__repr__", [](const Measurement& x) { return "<facetfit.Measurement " + x.source + ">"; });

  m.def(
      "load", [](const py::object& source, const std::string& merl_bins) { return load(fs_path(source), merl_bins); }, py::arg("source"),
      py::arg("merl_bins") = "start",
        "Loads a measurement: a MERL .binary, an RGL .bsdf, a UTIA .bin or builtin:NAME. Raises facetfit.Error naming the file.");
  m.def("builtins", [] {
    std::vector<std::string> names;
    for (const std::string& s : expand_inputs({kBuiltinPrefix})) names.push_back(source_name(s));
    return names;
  });

  py::class_<Model>(m, "Model",
                    "Any material (measured, tabulated, parametric): eval, pdf and sample on numpy arrays of directions, "
                    "o toward the viewer and i toward the light, local frame with the normal along +z.")
      .def(
          "eval", [](const Model& x, const py::handle& o, const py::handle& i) { return eval_rgb(o, i, [&x](const Vec3& a, const Vec3& b) { return x.shading->f(a, b); }); },
          py::arg("o"), py::arg("i"), "f(o, i) in 1/sr, shape (..., 3).")
      .def("pdf", &pdf, py::arg("o"), py::arg("i"), "Density of sample() per steradian of i, shape (...).")
      .def("sample", &sample, py::arg("o"), py::arg("u"),
           "Draws i for each o from three uniform numbers u (..., 3): a dict of i (..., 3), weight = f cos / pdf (..., 3) "
           "and pdf (...); failed draws have pdf 0.");

  m.def("material", &material, py::arg("description"), py::arg("base_dir") = ".",
        "The model of a material described as in a scene (docs/scene-format.md), e.g. {'type': 'ggx', 'alpha': 0.2}.");

  py::class_<Fit>(m, "Fit", "The fit of one measured material (docs/extraction.md).")
      .def_readonly("source", &Fit::source)
      .def_property_readonly("ok", [](const Fit& f) { return f.result.ok(); })
      .def_property_readonly("problem", [](const Fit& f) { return f.result.problem; })
      .def_property_readonly("warnings", [](const Fit& f) { return f.result.warnings; })
      .def_property_readonly("theta", [](const Fit& f) { return theta_array(f.result.ndf().grid); }, "polar angles of the NDF's nodes")
      .def_property_readonly("ndf", [](const Fit& f) { return vector_array(f.result.ndf().ndf); }, "D at the nodes, 1/sr")
      .def_property_readonly("sigma", [](const Fit& f) { return vector_array(f.result.ndf().sigma); }, "projected area at the nodes")
      .def_property_readonly("ndf_extraction", [](const Fit& f) { return vector_array(f.result.extraction.ndf.ndf); },
                             "the paper's NDF (the power iteration alone)")
      .def("D", [](const Fit& f, const py::handle& t) { return over_theta(t, [&f](double x) { return f.result.ndf().D(x); }); }, py::arg("theta"))
      .def("slope_pdf", [](const Fit& f, const py::handle& t) { return over_theta(t, [&f](double x) { return f.result.ndf().slope_pdf(x); }); },
           py::arg("theta"))
      .def_property_readonly("fresnel", [](const Fit& f) { return fresnel_array(f.result.fresnel()); }, "RGB Fresnel at fresnel_theta_d, (90, 3)")
      .def_property_readonly_static("fresnel_theta_d", [](const py::object&) { return fresnel_theta_d(); })
      .def_property_readonly("body", [](const Fit& f) { return rgb_array(f.result.body()); }, "body albedo at normal incidence")
      .def_property_readonly("body_exponent", [](const Fit& f) { return f.result.lobe.body_exponent; },
                             "the body's Minnaert exponent (1: Lambert)")
      .def_property_readonly("alpha_ggx", [](const Fit& f) { return f.result.alpha_ggx; },
                             "the paper's moment estimate E|x~| of the tabulated NDF (not the ggx fit's alpha: see recommended)")
      .def_property_readonly("alpha_beckmann", [](const Fit& f) { return f.result.alpha_beckmann; },
                             "the paper's moment estimate sqrt(2 E[x~^2]) of the tabulated NDF")
      .def(
          "recommended",
          [](const Fit& f, double tolerance) {
            if (!f.result.ok()) throw Error(f.source + ": " + f.result.problem);
            checked_tolerance(tolerance);
            return to_python(recommended_json(parameters_of(f.result, recommend(f.result, tolerance)), tolerance));
          },
          py::arg("tolerance") = kDefaultTolerance,
          "The representation a renderer should use and its own parameters, as `facetfit fit` shows them: "
          "{representation, tolerance, alpha (None for tabulated), body, f0, f82, coat, error}")
      .def_property_readonly("error", [](const Fit& f) { return f.result.error; })
      .def_property_readonly("distances", [](const Fit& f) {
        py::dict d;  // every representation (fit/representations.h), in report order
        for (const RepresentationRow& r : kRepresentations) d[r.name] = r.distance(f.result);
        return d;
      }, "each representation's distance from the measurement: {tabulated, ggx, beckmann, lsq, closures}")
      .def_property_readonly("error_extraction", [](const Fit& f) { return f.result.error_extraction; })
      .def_property_readonly("eigenvalue", [](const Fit& f) { return f.result.extraction.eigenvalue; })
      .def_property_readonly("iterations", [](const Fit& f) { return f.result.extraction.iterations; })
      .def_property_readonly("record", [](const Fit& f) { return to_python(fit_record(f.source, f.result, 0.0)); },
                             "everything as `facetfit fit --json` prints it (parametric fits, coat, errors)")
      .def("model", [](const Fit& f) {
        if (!f.result.ok()) throw Error(f.source + ": " + f.result.problem);
        return tabulated_model(f.result.lobe.tables(f.result.smith));
      }, "The tabulated model: body + tabulated lobe + coat.")
      .def_property_readonly("closures", [](const Fit& f) { return to_python(closures_json(f.result.closures.closures, f.result.closures.error)); },
                             "the closure representation, what the production OSL material renders (docs/osl.md): "
                             "{body, lobes: [{family, alpha_x, alpha_y, angle_degrees, weight, fresnel, f0, f82 or f90 and exponent}], coat, error}")
      .def("closures_model", [](const Fit& f) {
        if (!f.result.ok()) throw Error(f.source + ": " + f.result.problem);
        return closures_model(f.result.closures.closures);
      }, "The closure representation as a model.")
      .def(
          "write_lut",
          [](const Fit& f, const py::object& path_arg, double tolerance, bool sampling) {
            if (!f.result.ok()) throw Error(f.source + ": " + f.result.problem);
            const std::string path = fs_path(path_arg);
            py::gil_scoped_release release;
            write_lut(path, make_lut(f.result, f.fitter->quadrature(), f.source, source_sha256(f.source), checked_tolerance(tolerance), sampling));
          },
          py::arg("path"), py::arg("tolerance") = kDefaultTolerance, py::arg("sampling") = true, "Bakes the LUT texture (docs/lut-format.md).")
      .def("__repr__", [](const Fit& f) {
        return "<facetfit.Fit " + f.source + (f.result.ok() ? " alpha_ggx=" + std::to_string(f.result.alpha_ggx) : " failed") + ">";
      });

  m.def(
      "fit",
      [](const py::object& what, const std::string& refine, int resolution, const std::string& smith, const std::string& merl_bins,
         const std::string& closure_fresnel) {
        const FitOptions o = fit_options(refine, resolution, smith, merl_bins, closure_fresnel);
        if (py::isinstance<Measurement>(what)) return fit(what.cast<const Measurement&>(), o);
        return fit(load(fs_path(what), merl_bins), o);
      },
      py::arg("measurement"), py::arg("refine") = "full", py::arg("resolution") = 90, py::arg("smith") = "correlated",
      py::arg("merl_bins") = "start", py::arg("closure_fresnel") = "f82",
      "Fits a Measurement or a source path (refine='none': the paper's method alone; closure_fresnel='schlick': "
      "closures of generalized-Schlick lobes only).");

  py::class_<Lut>(m, "Lut", "A baked LUT texture.")
      .def_property_readonly("theta", [](const Lut& l) { return theta_array(l.tables.ndf.grid); })
      .def_property_readonly("ndf", [](const Lut& l) { return vector_array(l.tables.ndf.ndf); })
      .def_property_readonly("sigma", [](const Lut& l) { return vector_array(l.tables.ndf.sigma); })
      .def_property_readonly("fresnel", [](const Lut& l) { return fresnel_array(l.tables.fresnel); })
      .def_property_readonly("body", [](const Lut& l) { return rgb_array(l.tables.body); })
      .def_property_readonly("body_exponent", [](const Lut& l) { return l.tables.body_exponent; })
      .def_property_readonly("source", [](const Lut& l) { return l.meta.source; })
      .def_property_readonly("format_version", [](const Lut& l) { return l.meta.format_version; }, "facetfit:format_version (docs/lut-format.md)")
      .def_property_readonly("representation", [](const Lut& l) { return std::string(to_string(l.meta.representation)); })
      .def_property_readonly("recommended", [](const Lut& l) { return to_python(recommended_json(recommended_parameters(l.meta), l.meta.tolerance)); },
                             "the recommended representation and its own parameters, as Fit.recommended() with the bake's tolerance")
      .def_property_readonly("distances", [](const Lut& l) {
        py::dict d;
        for (const RepresentationRow& r : kRepresentations) d[r.name] = l.meta.distance(r.name);
        return d;
      }, "each representation's distance from the measurement, as Fit.distances")
      .def_property_readonly("alpha_ggx", [](const Lut& l) { return l.meta.alpha_ggx; }, "the paper's moment estimate (see Fit.alpha_ggx)")
      .def_property_readonly("alpha_beckmann", [](const Lut& l) { return l.meta.alpha_beckmann; }, "the paper's moment estimate")
      .def_property_readonly("warnings", [](const Lut& l) { return l.meta.warnings; })
      .def_property_readonly("colorspace", [](const Lut& l) { return l.meta.colorspace; }, "the linear space of its colours (docs/colour.md)")
      .def("model", [](const Lut& l) { return tabulated_model(l.tables); }, "The tabulated model.")
      .def_property_readonly("closures", [](const Lut& l) { return to_python(closures_json(l.closures(), l.meta.error_closures)); },
                             "the closures the material shader emits (format 5; an older LUT's one lobe), as Fit.closures")
      .def("closures_model", [](const Lut& l) { return closures_model(l.closures()); }, "The closure representation as a model.")
      .def(
          "materialx",
          [](const Lut& l, const std::string& name, bool color82) { return materialx_document(materialx_name(name), l, color82); },
          py::arg("name"), py::arg("color82") = false,
          "The closures as a MaterialX document's text (as `facetfit export` writes it, `color82` as its --color82; the "
          "name made a valid MaterialX name).")
      .def(
          "usd",
          [](const Lut& l, const std::string& name) {
            const std::string n = materialx_name(name);
            return usd_document(n, "./" + n + ".mtlx", l);
          },
          py::arg("name"),
          "The UsdShade material `facetfit export --usd` writes (USD ASCII): it references ./NAME.mtlx (write materialx(name) "
          "there) and carries a UsdPreviewSurface fallback.")
      .def(
          "parametric",
          [](const Lut& l, const std::string& family) {
            if (!l.meta.fit(family)) throw py::value_error("family: must be " + parametric_names() + ", not '" + family + "'");
            return Model{lut_parametric_model(l, family, l.tables.smith, false)};
          },
          py::arg("family"), "One of the parametric fits the LUT carries: 'ggx', 'beckmann' or 'lsq'.");
  m.def(
      "read_lut", [](const py::object& path_arg) {
        const std::string path = fs_path(path_arg);
        py::gil_scoped_release release;
        return read_lut(path);
      },
      py::arg("path"), "Reads a LUT; raises facetfit.Error for anything that is not a complete facetfit LUT.");

  m.def(
      "bake",
      [](const py::object& source_arg, const py::object& out_dir_arg, std::string name, bool force, double tolerance, bool sampling,
         const std::string& refine, int resolution, const std::string& smith, const std::string& merl_bins,
         const std::string& closure_fresnel, const std::string& working_space, const std::string& ocio_config) {
        const std::string source = fs_path(source_arg), out_dir = fs_path(out_dir_arg);
        BakeOptions o;
        o.fit = fit_options(refine, resolution, smith, merl_bins, closure_fresnel);
        o.colorspace = working_space;
        o.from_rec709 = ColorConfig(ocio_config).from_rec709(working_space);
        o.force = force;
        o.tolerance = checked_tolerance(tolerance);
        o.with_sampling = sampling;
        prepare_output_folder(out_dir);  // as the command does
        const std::vector<std::string> sources = expand_inputs({source});
        const bool batch = sources.size() != 1 || sources.front() != source;  // a folder, a glob or builtin:
        if (batch && !name.empty()) throw py::value_error("name: for one source, not a folder or glob of them");
        const Fitter fitter(o.fit);
        const auto bake_one = [&](const std::string& s, const std::string& n) {
          BakeOutcome r;
          {
            py::gil_scoped_release release;
            r = bake_material(s, n, out_dir, o, fitter);
          }
          if (r.status == BakeOutcome::Status::failed) {
            if (!batch) throw Error(r.error);
            return py::dict(py::arg("source") = s, py::arg("status") = "failed", py::arg("error") = r.error);
          }
          py::dict d = to_python(r.record);
          d["status"] = r.status == BakeOutcome::Status::baked ? "baked" : "cached";
          return d;
        };
        if (!batch) return py::object(bake_one(source, name.empty() ? source_name(source) : name));
        // A batch goes on past a bad file, as the command does: its entry says "failed" and why.
        py::list out;
        for (const std::string& s : sources) out.append(bake_one(s, source_name(s)));
        return py::object(out);
      },
      py::arg("source"), py::arg("out_dir"), py::arg("name") = "", py::arg("force") = false, py::arg("tolerance") = kDefaultTolerance,
      py::arg("sampling") = true, py::arg("refine") = "full", py::arg("resolution") = 90, py::arg("smith") = "correlated",
      py::arg("merl_bins") = "start", py::arg("closure_fresnel") = "f82", py::arg("working_space") = kRec709Space,
      py::arg("ocio_config") = "",
      "Bakes OUT_DIR/NAME.exr and its JSON sidecar as `facetfit bake` does (cached by content, OUT_DIR created; "
      "working_space: the LUT's colours in that space of the OpenColorIO config ocio_config, else $OCIO); "
      "returns the sidecar, or for a folder, glob or 'builtin:' a list of them (a failed one as {source, status: "
      "'failed', error}).");

  m.def("render", &render_scene, py::arg("scene"), py::arg("spp") = 0, py::arg("seed") = 0, py::arg("max_memory") = "",
        "Renders a scene (a path, or a dict as in docs/scene-format.md; relative files against the current folder): "
        "(height, width, 4) float32, linear Rec.709 RGB and coverage. max_memory ('4G', '512M'; default half of the "
        "machine's) bounds the image and environment map, checked before allocating.");
  m.def("write_image", &write_image, py::arg("path"), py::arg("image"),
        "Writes a (height, width, 3 or 4) scene-linear image: .exr as it is (linear Rec.709, float), .png through the "
        "display transform (8-bit sRGB), each through a temporary file.");
  m.def("delta_e", &delta_e, py::arg("a"), py::arg("b"), py::arg("mask") = py::none(), py::arg("a_display_referred") = false,
        py::arg("b_display_referred") = false,
        "CIE Delta E 2000 per pixel through the display chain (docs/colour.md): (map, mean, max) over the mask.");
}
