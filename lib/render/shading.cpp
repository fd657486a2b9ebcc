#include "render/shading.h"

#include <cmath>
#include <type_traits>
#include <variant>

#include "model/ndf.h"
#include "model/parametric.h"

namespace facetfit {

namespace {

// fn(the back-end in `lanes`), or false where no back-end runs the model.
template <class Fn>
bool with_lanes(const LanesBackend& lanes, Fn fn) {
  return std::visit([&](const auto& backend) {
    if constexpr (std::is_same_v<std::decay_t<decltype(backend)>, std::monostate>) return false;
    else return fn(backend);
  }, lanes);
}

}  // namespace

ShadingModel::ShadingModel(std::shared_ptr<const Brdf> brdf, std::shared_ptr<const Proposal> proposal)
    : brdf_(std::move(brdf)), proposal_(std::move(proposal)), lobe_weight_(proposal_ && proposal_->can_sample() ? 0.85 : 0.0) {
  const LanesInput in{*brdf_, proposal_.get(), lobe_weight_};
  if ((ggx_brdf_ = ggx_drawn_by_itself(in))) ggx_proposal_ = static_cast<const GgxProposal*>(proposal_.get());
  lanes_ = recognise_lanes(in);
}

bool ShadingModel::f_in_lanes() const {
  return with_lanes(lanes_, [](const auto& backend) { return backend.f_in_lanes(); });
}

Rgb ShadingModel::f(const Vec3& o, const Vec3& i) const {
  // Negative values (a measurement's noise around zero) are rendered as they are, as Mitsuba does.
  const auto v = ggx_brdf_ ? ggx_brdf_->eval(o, i) : brdf_->eval(o, i);  // the first a direct call (final class)
  return v ? *v : Rgb(0.0);
}

double ShadingModel::mixture(const Vec3& i, double proposal_pdf) const {
  const double cosine = i.z * kInvPi;
  return lobe_weight_ > 0.0 ? lobe_weight_ * proposal_pdf + (1.0 - lobe_weight_) * cosine : cosine;
}

double ShadingModel::pdf(const Vec3& o, const Vec3& i) const {
  if (!above_horizon(o, i)) return 0.0;
  return mixture(i, lobe_weight_ > 0.0 ? proposal_->pdf(o, i) : 0.0);
}

ShadingModel::Evaluation ShadingModel::eval(const Vec3& o, const Vec3& i) const {
  if (!ggx_brdf_ || !above_horizon(o, i)) return {f(o, i), pdf(o, i)};
  const Vec3 h = glm::normalize(i + o);
  const Ndf& ndf = ggx_brdf_->ndf();
  const double d = ndf.D(h), lambda_o = ndf.lambda(o);
  return {ggx_brdf_->eval_with(o, i, h, d, lambda_o), mixture(i, ggx_proposal_->pdf_with(o, i, h, d, 1.0 / (1.0 + lambda_o)))};
}

void ShadingModel::eval(EvaluationBatch& batch, bool simd) const {
  if (simd && with_lanes(lanes_, [&](const auto& backend) {
    backend.eval(batch, *this);
    return true;
  })) return;
  for (std::size_t k = 0; k < batch.size(); ++k) {
    const Evaluation e = eval(batch.o(k), batch.i(k), batch.with_pdf[k] != 0.0);
    batch.r[k] = e.f.r, batch.g[k] = e.f.g, batch.b[k] = e.f.b, batch.pdf[k] = e.pdf;
  }
}

void ShadingModel::sample_directions(SampleBatch& batch, bool simd) const {
  if (simd && with_lanes(lanes_, [&](const auto& backend) {
    backend.sample(batch);
    return true;
  })) return;
  for (std::size_t k = 0; k < batch.size(); ++k) {
    const auto i = sample_direction(batch.o(k), batch.u1[k], batch.u2[k], batch.u3[k]);
    batch.found[k] = i ? 1.0 : 0.0;
    if (i) batch.ix[k] = i->x, batch.iy[k] = i->y, batch.iz[k] = i->z;
  }
}

std::optional<ShadingModel::Sample> ShadingModel::sample(const Vec3& o, double u1, double u2, double u3) const {
  const auto i = sample_direction(o, u1, u2, u3);
  if (!i) return std::nullopt;
  const Evaluation e = eval(o, *i);
  if (!(e.pdf > 0.0)) return std::nullopt;
  return Sample{*i, e.f * (i->z / e.pdf), e.pdf};
}

std::optional<Vec3> ShadingModel::sample_direction(const Vec3& o, double u1, double u2, double u3) const {
  if (!above_horizon(o)) return std::nullopt;
  if (u3 < lobe_weight_) return proposal_->sample_direction(o, u1, u2);
  return cosine_direction(u1, u2);  // the cosine part, whose density mixture() adds
}

}  // namespace facetfit
