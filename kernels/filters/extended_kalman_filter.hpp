#pragma once
// EKF: the first-order filter of Cox, seed 000 Tables 1-2 row [14] (the reference list, 000 L470-471, has
// [13] = Detchmendy-Sridhar and [14] = Cox, whatever a table row label suggests):
//   dm = f(m) dt + P H(m)^T V^{-1} (dy - h(m) dt),   dP = (F(m) P + P F(m)^T + W - P H^T V^{-1} H P) dt.
#include "kernels/filters/filter_protocol.hpp"
#include "kernels/filters/jacobian_linearization.hpp"

namespace kushner {

template <class Model, class MemSpace>
struct ExtendedKalmanFilter {
  static constexpr int n = Model::state_dim, p = Model::obs_dim;
  static constexpr const char* name = "EKF";
  static constexpr const char* description = "first-order filter (Cox; Sunahara 1968 Table 1-2 row [14])";
  static constexpr const char* unsupported = nullptr;  // every continuous-time model has its Jacobians

  static ExtendedKalmanFilter create(const OptionValues&, const Model&, long) { return {}; }

  KOKKOS_INLINE_FUNCTION Status step(const Model& model, int, const StepInput<p>& in, Vec<n>& m, Mat<n, n>& P) const {
    Vec<p> weighted_innovation;
    if (!kalman_update(observation_linearization(model, in.t, m), in, m, P, weighted_innovation))
      return Status::not_positive_definite;
    euler_predict(drift_linearization(model, in.t, m), in.dt, m, P);
    return Status::ok;
  }
};

}  // namespace kushner
