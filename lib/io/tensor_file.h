// Mitsuba's tensor files, as RGL's tools write them and Mitsuba's TensorFile reads them: a table of named,
// typed n-dimensional arrays. Parsed here with every size checked against the file before anything trusts
// it; what the fields mean is the caller's (RGL's `.bsdf` files: io/rgl.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace facetfit {

// dtype codes of the format (as enumerated by RGL's own reader, powitacq's Tensor::Type):
// 1 uint8, 2 int8, 3 uint16, 4 int16, 5 uint32, 6 int32, 7 uint64, 8 int64, 9 float16, 10 float32,
// 11 float64. Verified on the RGL database files: `description` is 1, `version` 5, the tables 10.
constexpr std::uint8_t kTensorUInt8 = 1;
constexpr std::uint8_t kTensorFloat32 = 10;

// One entry of the field table.
struct TensorField {
  std::uint8_t dtype = 0;
  std::uint64_t offset = 0;
  std::vector<std::uint64_t> shape;
  std::size_t count = 0;     // product of shape; fits in the file once extents are checked
  std::uint64_t bytes = 0;  // count times the element size, without overflow
};

// A shape as messages write it: "2 x 90 x 3", or "(scalar)".
std::string tensor_shape_string(const std::vector<std::uint64_t>& shape);

// The fields of a tensor file's bytes. Holds `path` (for messages) and `bytes` by reference: both outlive it.
class TensorFile {
 public:
  // Reads the field table. Throws Error("<path>: <problem>") for a wrong preamble, a truncated or
  // inconsistent table, or a field whose data lies outside the file or over the table.
  TensorFile(const std::string& path, const std::vector<unsigned char>& bytes);

  bool has(const std::string& name) const { return fields_.count(name) != 0; }
  // A required field with its expected dtype and rank; throws naming it where it is missing or differs.
  // Shapes are the caller's to cross-check.
  const TensorField& get(const std::string& name, std::uint8_t dtype, std::size_t rank) const;
  // A float32 field's payload as doubles; NaN or infinity is an error.
  std::vector<double> floats(const std::string& name, const TensorField& f) const;
  const unsigned char* data(const TensorField& f) const { return bytes_.data() + f.offset; }

  const std::string& path() const { return path_; }
  // Throws Error("<path>: <problem>") unless ok.
  void check(bool ok, const std::string& problem) const;

 private:
  const std::string& path_;
  const std::vector<unsigned char>& bytes_;
  std::map<std::string, TensorField> fields_;
};

}  // namespace facetfit
