#pragma once
// The Hessian terms of the second-order filters (seed 000 (6.8)-(6.9), Tables 1-2 rows [9], [12], [13]).
#include "kernels/filters/filter_step.hpp"
#include "kernels/filters/jacobian_linearization.hpp"

namespace kushner {

/// sum_jk A_jk B_jk = tr(A B) for symmetric A, B.
template <int N>
KOKKOS_INLINE_FUNCTION double frobenius(const Mat<N, N>& A, const Mat<N, N>& B) {
  double s = 0.0;
  for (int j = 0; j < N; ++j)
    for (int k = 0; k < N; ++k) s += A(j, k) * B(j, k);
  return s;
}

/// f_i(m) + 1/2 tr(Hess f_i(m) P) (seed 000 (6.9)), df/dx(m) and W at m: the second-order filters' drift
/// linearization. f, df/dx and the Hessians from one evaluation where the model has drift_derivatives (the sine
/// model: one sincos for the three), else from drift_and_jacobian and drift_hessian.
template <class Model>
KOKKOS_INLINE_FUNCTION DriftLinearization<Model::state_dim> hessian_corrected_drift_linearization(
    const Model& model, double t, const Vec<Model::state_dim>& m, const Mat<Model::state_dim, Model::state_dim>& P) {
  const auto u = Model::Control::zero();
  DriftAndJacobian<Model::state_dim> f;
  if constexpr (detail::has_drift_derivatives<Model>::value) {
    const DriftDerivatives<Model::state_dim> d = model.drift_derivatives(t, m, u);
    f = {d.drift, d.jacobian};
    for (int i = 0; i < Model::state_dim; ++i) f.drift[i] += 0.5 * frobenius(d.hessian[i], P);
  } else {
    f = drift_and_jacobian(model, t, m, u);
    for (int i = 0; i < Model::state_dim; ++i) f.drift[i] += 0.5 * frobenius(model.drift_hessian(t, m, u, i), P);
  }
  return drift_linearization_of(model, t, m, f);
}

/// h_l(m) + 1/2 tr(Hess h_l(m) P): the predicted observation of rows [9], [12] (the "- 1/2 p h''" of n(x)).
template <class Model>
KOKKOS_INLINE_FUNCTION Vec<Model::obs_dim> hessian_corrected_observation(
    const Model& model, double t, const Vec<Model::state_dim>& m, const Mat<Model::state_dim, Model::state_dim>& P) {
  Vec<Model::obs_dim> h = model.observation(t, m);
  for (int l = 0; l < Model::obs_dim; ++l) h[l] += 0.5 * frobenius(model.observation_hessian(t, m, l), P);
  return h;
}

/// sum_l P Hess h_l(m) P w_l, w = V^{-1}(dy - h_hat dt): the dy-driven covariance term of rows [9] (weight 1)
/// and [13] (weight 1/2), the vector form of p^2 h'' [y - h ...] in e2.
template <class Model>
KOKKOS_INLINE_FUNCTION Mat<Model::state_dim, Model::state_dim> observation_curvature_term(
    const Model& model, double t, const Vec<Model::state_dim>& m, const Mat<Model::state_dim, Model::state_dim>& P,
    const Vec<Model::obs_dim>& w) {
  constexpr int n = Model::state_dim;
  Mat<n, n> weighted = Mat<n, n>::zero();
  for (int l = 0; l < Model::obs_dim; ++l) weighted += model.observation_hessian(t, m, l) * w[l];
  return P * weighted * P;
}

}  // namespace kushner
