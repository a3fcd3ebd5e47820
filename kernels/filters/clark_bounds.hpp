#pragma once
// The support of Clark's posterior (seed 003 (2.11)-(2.12), (2.15)-(2.16)): with bounded noises the posterior of
// x[k] given z[1..k] lives on an interval [l_k, f_k]; the prediction maps it through the linear transition and
// widens it by the plant noise's bound, the measurement cuts it to z -+ the measurement noise's bound. Shared
// by the moment filter (MOM) and Clark's cheap approximations (MOM-MID, MOM-LS, MOM-LINE, MOM-HYP).
#include "core/errors.hpp"
#include "core/math.hpp"
#include "models/model_traits.hpp"

#include <Kokkos_Core.hpp>

namespace kushner {

struct Interval {
  double lower, upper;
};

/// Why a Clark filter cannot run Model (nullptr: it can).
template <class Model>
constexpr const char* clark_filter_unsupported() {
  if (!Model::discrete_time) return "continuous-time model (discrete-time filter)";
  if (Model::state_dim != 1 || Model::obs_dim != 1) return "state or observation is not scalar";
  if (!DiscreteModelTraits<Model>::linear) return "transition is not linear";
  if (!DiscreteModelTraits<Model>::bounded_noises) return "noises are not bounded (Clark's family)";
  return nullptr;
}

/// x[k+1] | Z_k lives on the image of [l, f] under x -> a x + c, widened by w's bound (2.11)-(2.12).
KOKKOS_INLINE_FUNCTION Interval clark_predicted_bounds(const Interval& posterior, double a, double c, double w_bound) {
  const double p = a * posterior.lower, q = a * posterior.upper;
  return {(p < q ? p : q) + c - w_bound, (p < q ? q : p) + c + w_bound};
}

/// ... and x[k+1] | Z_{k+1} on its intersection with (z - v_bound, z + v_bound) (2.15)-(2.16); empty when
/// lower >= upper (z is impossible under the model).
KOKKOS_INLINE_FUNCTION Interval clark_posterior_bounds(const Interval& predicted, double z, double v_bound) {
  return {predicted.lower > z - v_bound ? predicted.lower : z - v_bound,
          predicted.upper < z + v_bound ? predicted.upper : z + v_bound};
}

/// The prior's support: the point prior_mean when prior_cov = 0, else the uniform law with the prior's mean and
/// variance (Clark's filters need bounds; a Gaussian prior has none).
template <class Model>
Interval clark_prior_bounds(const Model& model) {
  const double m = model.prior_mean[0], half = math::sqrt(3.0 * model.prior_cov(0, 0));
  return {m - half, m + half};
}

}  // namespace kushner
