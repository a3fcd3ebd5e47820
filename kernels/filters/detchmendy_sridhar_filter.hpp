#pragma once
// EKF-DS: the Detchmendy-Sridhar first-order filter, seed 000 Tables 1-2 row [13]: the EKF mean, and the
// covariance with the extra term 1/2 p^2 h''(m) [y - h(m)] (000 L315), in vector form
//   dP = (F P + P F^T + W - P H^T V^{-1} H P) dt + 1/2 sum_l P Hess h_l(m) P [V^{-1}(dy - h(m) dt)]_l.
// The factor 1/2 is the printed one; an invariant-imbedding derivation of the same filter gives 1. We keep the
// paper's, since the comparison of Tables 1-2 is what this filter is for.
// With a linear observation the term vanishes and EKF-DS is the EKF.
#include "kernels/filters/filter_protocol.hpp"
#include "kernels/filters/jacobian_linearization.hpp"
#include "kernels/filters/second_order_terms.hpp"

namespace kushner {

template <class Model, class MemSpace>
struct DetchmendySridharFilter {
  static constexpr int n = Model::state_dim, p = Model::obs_dim;
  static constexpr const char* name = "EKF-DS";
  static constexpr const char* description =
      "first-order filter, Detchmendy-Sridhar (row [13]: extra h'' covariance term)";
  static constexpr const char* unsupported = nullptr;

  static DetchmendySridharFilter create(const OptionValues&, const Model&, long) { return {}; }

  KOKKOS_INLINE_FUNCTION Status step(const Model& model, int, const StepInput<p>& in, Vec<n>& m, Mat<n, n>& P) const {
    const Vec<n> m0 = m;
    const Mat<n, n> P0 = P;
    Vec<p> w;
    if (!kalman_update(observation_linearization(model, in.t, m0), in, m, P, w)) return Status::not_positive_definite;
    P = symmetrize(P + observation_curvature_term(model, in.t, m0, P0, w) * 0.5);
    euler_predict(drift_linearization(model, in.t, m), in.dt, m, P);
    return Status::ok;
  }
};

}  // namespace kushner
