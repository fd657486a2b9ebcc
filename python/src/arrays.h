// numpy arrays in and out of the module: directions as (..., 3) float64 arrays, broadcast one against
// the other, and the loops over them run with the GIL released, in parallel.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <tbb/parallel_for.h>

#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/vec.h"

namespace facetfit::python {

namespace py = pybind11;
using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

// A stack of 3-vectors: shape (..., 3), each checked before any model sees it: a direction is finite and of
// unit length (within 1e-3: NaN, 1e300 and denormal vectors indexed tables out of range), a triple of
// uniform numbers (sample's u) is in [0, 1]. `name` is the argument's, for the one-line error.
struct Vectors {
  enum class Kind { direction, uniform };
  Array array;
  std::vector<py::ssize_t> shape;  // without the last axis
  std::size_t count = 0;

  Vectors(py::handle h, const char* name, Kind kind = Kind::direction) : array(Array::ensure(h)) {
    if (!array || array.ndim() < 1 || array.shape(array.ndim() - 1) != 3)
      throw py::value_error(std::string(name) + ": must be an array of 3-vectors, shape (..., 3)");
    shape.assign(array.shape(), array.shape() + array.ndim() - 1);
    count = std::size_t(array.size() / 3);
    for (std::size_t k = 0; k < count; ++k) {
      const Vec3 v = at(k);
      const bool ok = kind == Kind::direction ? std::abs(glm::dot(v, v) - 1.0) <= 2e-3
                                              : v.x >= 0.0 && v.x <= 1.0 && v.y >= 0.0 && v.y <= 1.0 && v.z >= 0.0 && v.z <= 1.0;
      if (!ok)
        throw py::value_error(std::string(name) + "[" + std::to_string(k) + "]: " +
                              (kind == Kind::direction ? "must be a finite unit vector" : "must be three numbers in [0, 1]"));
    }
  }
  Vec3 at(std::size_t k) const {
    const double* p = array.data() + 3 * k;
    return Vec3(p[0], p[1], p[2]);
  }
};

// The broadcast of two stacks: equal shapes, or one of them a single vector.
inline std::vector<py::ssize_t> broadcast(const Vectors& a, const Vectors& b, const char* what) {
  if (a.count == 1) return b.shape;
  if (b.count == 1 || a.shape == b.shape) return a.shape;
  throw py::value_error(std::string(what) + ": the two arrays of directions must have the same shape, or one be a single vector");
}

inline std::size_t count_of(const std::vector<py::ssize_t>& shape) {
  std::size_t n = 1;
  for (py::ssize_t s : shape) n *= std::size_t(s);
  return n;
}

inline std::vector<py::ssize_t> with_axis(std::vector<py::ssize_t> shape, py::ssize_t last) {
  shape.push_back(last);
  return shape;
}

// body(k) for k in [0, n), GIL released, over oneTBB's threads (each call must be thread-safe).
template <class F>
void parallel(std::size_t n, F&& body) {
  py::gil_scoped_release release;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t k = r.begin(); k < r.end(); ++k) body(k);
  });
}

inline py::array_t<double> rgb_array(const Rgb& c) {
  py::array_t<double> a(3);
  a.mutable_at(0) = c.r;
  a.mutable_at(1) = c.g;
  a.mutable_at(2) = c.b;
  return a;
}

inline py::array_t<double> vector_array(const std::vector<double>& v) {
  py::array_t<double> a(py::ssize_t(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

}  // namespace facetfit::python
