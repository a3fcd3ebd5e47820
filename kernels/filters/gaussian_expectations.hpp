#pragma once
// Gaussian expectations of the drift and the observation under x ~ N(m, P), the statistical linearization of
// Sunahara's quasi-linear filter (seed 000 (5.3)-(5.4), (5.9)-(5.10)), in the Stein form
//   a = E[f],  B = E[grad f] (= E[(f - a)(x - m)^T] P^{-1}),  h1 = E[h],  H2 = E[grad h],
// which needs no P^{-1} and so holds for singular P too. Two ways to get them:
//   closed form: the model's own formulas (sine (6.4)-(6.5), cubic oscillator (6.14)) or exact Gaussian
//                moments of a polynomial drift (kernels/filters/polynomial_moments.hpp);
//   cubature:    a tensor-product Gauss-Hermite rule on x = m + L xi, L L^T = P, for any model with
//                state dimension <= 3.
#include "kernels/filters/filter_step.hpp"
#include "kernels/filters/gauss_hermite.hpp"
#include "kernels/filters/polynomial_moments.hpp"
#include "models/model_traits.hpp"

namespace kushner {

/// E_N[f], E_N[grad f] in closed form (ModelTraits<Model>::closed_form_expectations).
template <class Model>
KOKKOS_INLINE_FUNCTION GaussianDrift<Model::state_dim> closed_form_drift(
    const Model& model, double t, const Vec<Model::state_dim>& m, const Mat<Model::state_dim, Model::state_dim>& P) {
  static_assert(ModelTraits<Model>::closed_form_expectations,
                "closed_form_drift: Model needs gaussian_drift(t, m, P) or a polynomial drift");
  if constexpr (detail::has_gaussian_drift<Model>::value)
    return model.gaussian_drift(t, m, P);
  else if constexpr (detail::has_quadratic_polynomial<Model>::value)
    return gaussian_drift(model.drift_quadratic_polynomial(t), m, P);
  else
    return gaussian_drift(drift_power_polynomial(model, t), m, P);
}

/// Calls g(x, w) for every node x = m + L xi and weight w of the tensor-product rule, in a fixed order.
template <int N, class G>
KOKKOS_INLINE_FUNCTION void for_each_cubature_node(const GaussHermiteRule& rule, const Vec<N>& m, const Mat<N, N>& L,
                                                   G&& g) {
  static_assert(N <= max_cubature_dim, "for_each_cubature_node: tensor-product rules are limited to dimension 3");
  const int K = rule.order;
  int total = 1;
  for (int j = 0; j < N; ++j) total *= K;
  for (int q = 0; q < total; ++q) {
    Vec<N> xi;
    double w = 1.0;
    for (int j = 0, index = q; j < N; ++j, index /= K) {
      xi[j] = rule.node[index % K];
      w *= rule.weight[index % K];
    }
    g(m + L * xi, w);
  }
}

/// E_N[f], E_N[grad f] by cubature; false when P is not positive semidefinite.
template <class Model>
KOKKOS_INLINE_FUNCTION bool cubature_drift(const Model& model, double t, const Vec<Model::state_dim>& m,
                                           const Mat<Model::state_dim, Model::state_dim>& P,
                                           const GaussHermiteRule& rule, GaussianDrift<Model::state_dim>& out) {
  constexpr int n = Model::state_dim;
  Mat<n, n> L;
  if (semidefinite_cholesky(P, L, covariance_tolerance) == Definiteness::indefinite) return false;
  const auto u = Model::Control::zero();
  out = GaussianDrift<n>{Vec<n>::zero(), Mat<n, n>::zero()};
  for_each_cubature_node(rule, m, L, [&](const Vec<n>& x, double w) {
    const auto f = drift_and_jacobian(model, t, x, u);
    out.mean += f.drift * w;
    out.jacobian += f.jacobian * w;
  });
  return true;
}

/// E_N[h], E_N[grad h] by cubature; false when P is not positive semidefinite.
template <class Model>
KOKKOS_INLINE_FUNCTION bool cubature_observation(const Model& model, double t, const Vec<Model::state_dim>& m,
                                                 const Mat<Model::state_dim, Model::state_dim>& P,
                                                 const GaussHermiteRule& rule,
                                                 ObservationLinearization<Model::state_dim, Model::obs_dim>& out) {
  constexpr int n = Model::state_dim, p = Model::obs_dim;
  Mat<n, n> L;
  if (semidefinite_cholesky(P, L, covariance_tolerance) == Definiteness::indefinite) return false;
  out = ObservationLinearization<n, p>{Vec<p>::zero(), Mat<p, n>::zero()};
  for_each_cubature_node(rule, m, L, [&](const Vec<n>& x, double w) {
    out.h += model.observation(t, x) * w;
    out.H += model.observation_jacobian(t, x) * w;
  });
  return true;
}

}  // namespace kushner
