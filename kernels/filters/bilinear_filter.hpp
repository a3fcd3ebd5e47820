#pragma once
// BILIN: Basin's optimal filter for a bilinear (quadratic) drift f = a0 + a1 x + a2 x x^T with a linear
// observation (seed 002 ACC03 (13)-(14), components (16)-(17)):
//   dm_k = (a0_k + sum_i a1_ki m_i + sum_ij a2_kij (m_i m_j + P_ij)) dt + [P A^T V^{-1}(dy - A m dt)]_k,
//   dP   = (J P + P J^T + b b^T - P A^T V^{-1} A P) dt,   J = a1 + 2 a2 m  (a2 symmetric in i, j).
#include "kernels/filters/filter_protocol.hpp"
#include "kernels/filters/jacobian_linearization.hpp"
#include "kernels/filters/polynomial_moments.hpp"
#include "models/model_traits.hpp"

namespace kushner {

template <class Model>
constexpr const char* bilinear_filter_unsupported() {
  if (!ModelTraits<Model>::quadratic_polynomial) return "drift is not bilinear";
  if (!ModelTraits<Model>::linear_observation) return "observation is not linear";
  return nullptr;
}

template <class Model, class MemSpace>
struct BilinearFilter {
  static constexpr int n = Model::state_dim, p = Model::obs_dim;
  static constexpr const char* name = "BILIN";
  static constexpr const char* description = "Basin's optimal filter for a bilinear drift (coefficient tensor a2)";
  static constexpr const char* unsupported = bilinear_filter_unsupported<Model>();

  static const char* unsupported_by(const ModelFacts& f) {
    if (f.drift_degree > 2) return "drift is not bilinear (degree above 2)";
    return observation_unsupported_by(f);
  }

  static BilinearFilter create(const OptionValues&, const Model&, long) { return {}; }

  KOKKOS_INLINE_FUNCTION Status step(const Model& model, int, const StepInput<p>& in, Vec<n>& m, Mat<n, n>& P) const {
    static_assert(unsupported == nullptr,
                  "BilinearFilter: Model must define drift_quadratic_polynomial(t) and a linear observation");
    Vec<p> weighted_innovation;
    if (!kalman_update(observation_linearization(model, in.t, m), in, m, P, weighted_innovation))
      return Status::not_positive_definite;
    const GaussianDrift<n> g = gaussian_drift(drift_quadratic_polynomial(model, in.t), m, P);
    euler_predict(DriftLinearization<n>{g.mean, g.jacobian, noise_intensity(model.diffusion(in.t, m))}, in.dt, m, P);
    return Status::ok;
  }
};

}  // namespace kushner
