// Writing RGL tensor files (the layout io/rgl.cpp reads), for tests: synthetic fields, malformed files,
// and analytic materials as the format stores them. A test oracle, not part of the library.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "model/ndf.h"
#include "model/smith.h"

namespace facetfit::test {

constexpr std::uint8_t kTensorU8 = 1, kTensorF32 = 10, kTensorF64 = 11;

struct TensorField {
  std::string name;
  std::uint8_t dtype;
  std::vector<std::uint64_t> shape;
  std::vector<unsigned char> payload;
  std::uint64_t offset_override = 0;  // nonzero: written instead of the true offset
};

TensorField f32(const std::string& name, std::vector<std::uint64_t> shape, const std::vector<float>& v);
TensorField u8(const std::string& name, std::vector<std::uint64_t> shape, const std::vector<unsigned char>& v);
// The field of that name (it must exist).
TensorField& field(std::vector<TensorField>& fields, const std::string& name);

// The file's bytes: header, field table, arrays 8-byte aligned.
std::vector<unsigned char> serialize(const std::vector<TensorField>& fields, unsigned char major = 1, unsigned char minor = 0);

// An analytic microfacet BRDF (F = 1, `smith` masking) with its axes turned by `angle` about the normal,
// as an RGL file stores it: `ndf` and `sigma` (Smith's projected area, sigma(0) = 1) tabulated over the
// half vector's (u_theta, u_phi) on 128 x 256 nodes; slices at `phi_slices` incident azimuths over
// [-pi, pi] (anisotropic when more than two) and `theta_slices` elevations from 0 to 89 degrees, closer
// toward the horizon; a VNDF that is not the material's but a warp putting the sample square's nodes near
// grazing half vectors (see the writer); and the RGB table T(p, q) 4 sigma(p) / D(h) (jacobian set) on its
// `rgb_nodes` x `rgb_nodes` nodes, T = f cos(q), continued past q's horizon.
// The format's reference evaluation (Mitsuba's `measured`) reads the BRDF back up to interpolation.
std::vector<TensorField> microfacet_tensor_fields(const Ndf& ndf, Smith smith, double angle, int phi_slices,
                                                  int theta_slices, int rgb_nodes);

// A file of arbitrary positive tables (seeded), slices at the incident azimuths `phi_i` (more than two:
// anisotropic; their span says which symmetry, as Mitsuba reads it) and three elevations, a VNDF of 9 x 7
// nodes varying per slice and an RGB table of 6 x 6: every interpolation and warp of the evaluation is
// exercised, nothing is physical.
std::vector<TensorField> arbitrary_tensor_fields(unsigned seed, const std::vector<float>& phi_i);

}  // namespace facetfit::test
