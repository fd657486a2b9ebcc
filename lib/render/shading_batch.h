// Many samplings and evaluations of one shading model at once, in structure-of-arrays form: the renderer
// gathers what a tile's samples need (BRDF sample directions; then f and the density for light samples,
// BRDF samples and lights) and makes each kind in one call, which the GGX material, a LUT and a MERL table
// run in SIMD lanes (render/ggx_batch.h, render/tabulated_batch.h, render/merl_batch.h).
#pragma once

#include <cstddef>
#include <initializer_list>
#include <vector>

#include "core/vec.h"

namespace facetfit {

// Columns of doubles that grow together and stay padded to a multiple of kPadding, so that SIMD kernels
// need no remainder loop: slots [0, padded_size()) always hold finite inputs (past size(), the `fill`
// values or those of an earlier use).
class Columns {
 public:
  // Lanes of the widest SIMD target times two (AVX-512: 8 doubles; the single-precision kernels read 16
  // entries at once).
  static constexpr std::size_t kPadding = 16;

  // n rounded up to a multiple of kPadding: how far a kernel reads columns of n entries.
  static constexpr std::size_t padded(std::size_t n) { return (n + kPadding - 1) / kPadding * kPadding; }

  std::size_t size() const { return size_; }
  std::size_t padded_size() const { return padded(size_); }
  void clear() { size_ = 0; }

 protected:
  // The slot of a new entry, after grow(capacity) has resized every column when full.
  template <class Grow>
  std::size_t next(const Grow& grow) {
    if (size_ == capacity_) grow(capacity_ += 4 * kPadding);
    return size_++;
  }
  // Room for n entries (columns of at least n's padded size), for kernels that write entries in place.
  template <class Grow>
  void ensure(std::size_t n, const Grow& grow) {
    if (padded(n) > capacity_) grow(capacity_ = padded(n));
  }
  void set_size(std::size_t n) { size_ = n; }
  static void resize(std::initializer_list<std::vector<double>*> columns, std::size_t n, double fill) {
    for (std::vector<double>* c : columns) c->resize(n, fill);
  }

 private:
  std::size_t size_ = 0, capacity_ = 0;
};

class Brdf;
class Proposal;
class ShadingModel;

// What a lanes back-end (render/lanes.h) recognises a model by: its BRDF, its proposal (null: the cosine
// alone) and the probability of drawing from the proposal rather than the cosine.
struct LanesInput {
  const Brdf& brdf;
  const Proposal* proposal;
  double lobe_weight;
};

// How a shading model draws its directions, as the SIMD kernels read it (ShadingModel::sample_direction):
// lobe_weight of the draws from the proposal, whose parts (ProposalParts, model/proposal.h) are the lobe,
// the body's cosine and a coat's visible normals (part_coat 0 without a coat), the rest cosine sampling.
struct ProposalWeights {
  double lobe_weight = 0.85, part_lobe = 1.0, part_body = 0.0, part_coat = 0.0;
};

// f(o, i) and the sampling density of i, for pairs (o, i) in the local frame. A pair pushed without
// `with_pdf` (a light's direction, which nothing weighs against sampling) may get its density or zero.
struct EvaluationBatch : Columns {
  std::vector<double> ox, oy, oz, ix, iy, iz, with_pdf;  // in (with_pdf: 1 or 0)
  std::vector<double> r, g, b, pdf;                      // out
  std::size_t push(const Vec3& o, const Vec3& i, bool density = true) {
    const std::size_t k = next([this](std::size_t n) { grow(n); });
    ox[k] = o.x, oy[k] = o.y, oz[k] = o.z, ix[k] = i.x, iy[k] = i.y, iz[k] = i.z, with_pdf[k] = density ? 1.0 : 0.0;
    return k;
  }
  Vec3 o(std::size_t k) const { return {ox[k], oy[k], oz[k]}; }
  Vec3 i(std::size_t k) const { return {ix[k], iy[k], iz[k]}; }
  Rgb f(std::size_t k) const { return {r[k], g[k], b[k]}; }

 protected:
  void grow(std::size_t n) {
    resize({&ox, &oy, &ix, &iy, &with_pdf, &r, &g, &b, &pdf}, n, 0.0);
    resize({&oz, &iz}, n, 1.0);  // up
  }
};

// A direction i drawn for o with the numbers (u1, u2, u3); `found` 1 or 0 (none: o or i below the
// horizon).
struct SampleBatch : Columns {
  std::vector<double> ox, oy, oz, u1, u2, u3;  // in
  std::vector<double> ix, iy, iz, found;       // out
  std::size_t push(const Vec3& o, double a, double b, double c) {
    const std::size_t k = next([this](std::size_t n) { grow(n); });
    ox[k] = o.x, oy[k] = o.y, oz[k] = o.z, u1[k] = a, u2[k] = b, u3[k] = c;
    return k;
  }
  // n entries, whose inputs the caller writes in place.
  void resize_to(std::size_t n) {
    reserve(n);
    set_size(n);
  }
  // Room for n entries written in place; size() stays.
  void reserve(std::size_t n) {
    ensure(n, [this](std::size_t m) { grow(m); });
  }
  Vec3 o(std::size_t k) const { return {ox[k], oy[k], oz[k]}; }
  Vec3 i(std::size_t k) const { return {ix[k], iy[k], iz[k]}; }

 private:
  void grow(std::size_t n) {
    resize({&ox, &oy, &ix, &iy, &found}, n, 0.0);
    resize({&oz, &iz}, n, 1.0);  // up
    resize({&u1, &u2, &u3}, n, 0.5);
  }
};

}  // namespace facetfit
