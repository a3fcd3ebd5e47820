#pragma once
// MIXED: Basin's mixed filter (seed 002 ACC03, L1795): "the estimate equations coincide with ... the optimal
// bilinear filter, and the variance equations coincide with ... the linear Kalman-Bucy filter":
//   dm = E_N[f] dt + P H0^T V^{-1} (dy - (c0 + H0 m) dt)   with E_N[f] the polynomial filter's mean drift,
//   dP = (F0 P + P F0^T + W0 - P H0^T V^{-1} H0 P) dt       the KBL covariance (origin linearization).
// The paper uses it for the bilinear terpolymer model; for componentwise polynomials (cubic oscillator, the
// car's Taylor model) we take the POLY3/POLY4 mean: the same Gaussian closure E_N[f], in the form those
// filters compute it.
#include "kernels/filters/filter_protocol.hpp"
#include "kernels/filters/linearized_kalman_bucy_filter.hpp"
#include "kernels/filters/polynomial_moments.hpp"
#include "models/model_traits.hpp"

namespace kushner {

template <class Model>
constexpr const char* mixed_filter_unsupported() {
  using T = ModelTraits<Model>;
  if (!(T::quadratic_polynomial || (T::power_polynomial && T::power_degree() <= 4))) return "drift is not polynomial";
  if (!T::linear_observation) return "observation is not linear";
  return nullptr;
}

template <class Model, class MemSpace>
struct MixedFilter {
  static constexpr int n = Model::state_dim, p = Model::obs_dim;
  static constexpr const char* name = "MIXED";
  static constexpr const char* description =
      "Basin's mixed filter: polynomial-filter mean, linearized Kalman-Bucy covariance";
  static constexpr const char* unsupported = mixed_filter_unsupported<Model>();

  static const char* unsupported_by(const ModelFacts& f) { return observation_unsupported_by(f); }

  OriginLinearization<Model> origin;  // KBL's

  static MixedFilter create(const OptionValues&, const Model& model, long) {
    return {OriginLinearization<Model>::of(model)};
  }

  KOKKOS_INLINE_FUNCTION Status step(const Model& model, int, const StepInput<p>& in, Vec<n>& m, Mat<n, n>& P) const {
    static_assert(unsupported == nullptr, "MixedFilter: Model must have a polynomial drift and a linear observation");
    Vec<p> weighted_innovation;
    if (!kalman_update(observation_linearization_at_origin(origin, model, in.t, m), in, m, P, weighted_innovation))
      return Status::not_positive_definite;
    DriftLinearization<n> drift = drift_linearization_at_origin(origin, model, in.t, m);
    drift.a = polynomial_mean(model, in.t, m, P);
    euler_predict(drift, in.dt, m, P);
    return Status::ok;
  }

  KOKKOS_INLINE_FUNCTION static Vec<n> polynomial_mean(const Model& model, double t, const Vec<n>& m,
                                                       const Mat<n, n>& P) {
    if constexpr (ModelTraits<Model>::runtime_checked)  // a run-time polynomial: its own exact E_N[f]
      return model.gaussian_drift(t, m, P).mean;
    else if constexpr (ModelTraits<Model>::quadratic_polynomial)
      return gaussian_drift(drift_quadratic_polynomial(model, t), m, P).mean;
    else
      return gaussian_drift(drift_power_polynomial(model, t), m, P).mean;
  }
};

}  // namespace kushner
