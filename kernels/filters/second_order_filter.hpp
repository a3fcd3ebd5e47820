#pragma once
// SOF: Schwartz's (truncated) second-order filter, seed 000 Tables 1-2 row [9], vector form (6.8)-(6.9):
//   f_bar_i = f_i(m) + 1/2 tr(Hess f_i P),  h_bar_l = h_l(m) + 1/2 tr(Hess h_l P),
//   dm = f_bar dt + P H^T V^{-1} (dy - h_bar dt),
//   dP = (F P + P F^T + W - P H^T V^{-1} H P) dt + sum_l P Hess h_l P [V^{-1}(dy - h_bar dt)]_l.
// SOF-B: Schwartz-Bass, row [12]: the same mean, the covariance without the dy term.
#include "kernels/filters/filter_protocol.hpp"
#include "kernels/filters/second_order_terms.hpp"

namespace kushner {

template <class Model, bool WithCurvatureTerm>
struct SecondOrderStep {
  static constexpr int n = Model::state_dim, p = Model::obs_dim;

  KOKKOS_INLINE_FUNCTION static Status step(const Model& model, const StepInput<p>& in, Vec<n>& m, Mat<n, n>& P) {
    const Vec<n> m0 = m;
    const Mat<n, n> P0 = P;
    const ObservationLinearization<n, p> obs{hessian_corrected_observation(model, in.t, m0, P0),
                                             model.observation_jacobian(in.t, m0)};
    Vec<p> w;
    if (!kalman_update(obs, in, m, P, w)) return Status::not_positive_definite;
    if constexpr (WithCurvatureTerm) P = symmetrize(P + observation_curvature_term(model, in.t, m0, P0, w));
    euler_predict(hessian_corrected_drift_linearization(model, in.t, m, P), in.dt, m, P);
    return Status::ok;
  }
};

template <class Model, class MemSpace>
struct SecondOrderFilter {
  static constexpr int n = Model::state_dim, p = Model::obs_dim;
  static constexpr const char* name = "SOF";
  static constexpr const char* description =
      "second-order filter, Schwartz (row [9], Hessian terms in mean and covariance)";
  static constexpr const char* unsupported = nullptr;  // every continuous-time model has its Hessians

  static SecondOrderFilter create(const OptionValues&, const Model&, long) { return {}; }

  KOKKOS_INLINE_FUNCTION Status step(const Model& model, int, const StepInput<p>& in, Vec<n>& m, Mat<n, n>& P) const {
    return SecondOrderStep<Model, true>::step(model, in, m, P);
  }
};

template <class Model, class MemSpace>
struct SchwartzBassFilter {
  static constexpr int n = Model::state_dim, p = Model::obs_dim;
  static constexpr const char* name = "SOF-B";
  static constexpr const char* description = "second-order filter, Schwartz-Bass (row [12], no dy covariance term)";
  static constexpr const char* unsupported = nullptr;

  static SchwartzBassFilter create(const OptionValues&, const Model&, long) { return {}; }

  KOKKOS_INLINE_FUNCTION Status step(const Model& model, int, const StepInput<p>& in, Vec<n>& m, Mat<n, n>& P) const {
    return SecondOrderStep<Model, false>::step(model, in, m, P);
  }
};

}  // namespace kushner
