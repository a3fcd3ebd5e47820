#pragma once
// Clark's perturbation loop for a nonlinear discrete-time plant x[k+1] = f(k, x, u) + w (seed 003 ch. III,
// (3.4)-(3.14)): a deterministic nominal path (x_bar, u_bar), the plant's deviations from it linearized,
//   dx[k+1] = A_k dx + B_k du + w,   A_k = df/dx(k, x_bar[k]),
// and the Riccati controller (3.12) of the deviations under the variational cost sum Q dx^2 + R du^2 (3.10):
//   u = u_bar[k] - L_k (x_hat - x_bar[k]),
// x_hat the estimate (a filter linearized along the same path: kernels/filters/nominal_path_filters.hpp).
// The nominal path is the noise-free optimum from the prior mean, found by successive linearization: the affine
// LQR of f linearized along the current path, the nonlinear plant rolled out under that LQR's feedback, until the
// path stops moving. At its fixed point the path satisfies the discrete optimum's necessary conditions (the LQR's
// adjoint equations are the plant's, linearized exactly where the path runs). On a linear plant the loop's law is
// the LQR's (the nominal is the LQR's own noise-free path, and the deviations' gains are its gains).
#include "engine/control/discrete_riccati.hpp"
#include "engine/control/nominal_path.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace kushner {

template <class Model>
struct PerturbationLoop {
  static constexpr int n = Model::state_dim, m = Model::control_dim;
  NominalPath<n, m> nominal;           // x_bar[0..steps], u_bar[0..steps-1], its cost J
  GainSchedule<n, m> deviation_gains;  // L_k of (3.12)
  GainSchedule<n, m> gains;            // the same law on the estimate: u = -(L_k x_hat + l_k)
  int iterations = 0;                  // successive linearizations of the nominal
  double last_change = 0.0;            // max_k |x_bar - previous x_bar|_inf of the last one
  bool converged = false, finite = true;
};

/// The perturbation loop of `model` over `steps` steps from its prior mean.
template <class Model>
PerturbationLoop<Model> perturbation_loop(const Model& model,
                                          const QuadraticCost<Model::state_dim, Model::control_dim>& cost, long steps,
                                          double tolerance = 1e-12, int max_iterations = 200) {
  static constexpr int n = Model::state_dim, m = Model::control_dim;  // static: nvcc's lambdas need no capture
  static_assert(Model::discrete_time, "perturbation_loop: Clark's loop is for discrete-time plants");
  PerturbationLoop<Model> out;
  const auto zero_noise = [](long) { return Mat<n, n>::zero(); };
  // The plant linearized along `path`: x[k+1] ~ A_k x + a_k + B_k u, exact at path[k] for any u (f is affine in u).
  const auto linearized_along = [&](const std::vector<Vec<n>>& path) {
    return [&model, &path](long k) {
      const double t = static_cast<double>(k);
      const Mat<n, n> A = model.transition_jacobian(t, path[k]);
      return AffineCoefficients<n, m>{A, model.transition(t, path[k], Vec<m>::zero()) - A * path[k],
                                      model.control_input(t)};
    };
  };
  out.nominal =
      simulate_path(model, cost, model.prior_mean, steps, 1.0, [](long, const Vec<n>&) { return Vec<m>::zero(); });
  for (int i = 0; i < max_iterations && out.nominal.finite; ++i) {
    const auto lqr = solve_discrete_lqr<n, m>(steps, cost, linearized_along(out.nominal.x), zero_noise);
    if (!lqr.finite) {
      out.finite = false;
      break;
    }
    const auto next = simulate_path(model, cost, model.prior_mean, steps, 1.0,
                                    [&](long k, const Vec<n>& x) { return -(lqr.gains.K[k] * x + lqr.gains.k[k]); });
    double change = 0.0, scale = 1.0;
    for (long k = 0; k <= steps; ++k)
      for (int j = 0; j < n; ++j) {
        change = std::max(change, std::fabs(next.x[k][j] - out.nominal.x[k][j]));
        scale = std::max(scale, std::fabs(next.x[k][j]));
      }
    out.iterations = i + 1;
    out.last_change = change;
    out.nominal = next;
    if (!std::isfinite(change)) break;
    if (change <= tolerance * scale) {
      out.converged = true;
      break;
    }
  }
  out.finite = out.finite && out.nominal.finite;
  if (!out.finite) return out;
  // (3.12): the deviations' Riccati controller, cost sum Q dx^2 + R du^2 (+ F dx[N]^2), no target.
  QuadraticCost<n, m> variational = cost;
  variational.target = Vec<n>::zero();
  const auto deviations = solve_discrete_lqr<n, m>(
      steps, variational,
      [&](long k) {
        const double t = static_cast<double>(k);
        return AffineCoefficients<n, m>{model.transition_jacobian(t, out.nominal.x[k]), Vec<n>::zero(),
                                        model.control_input(t)};
      },
      zero_noise);
  out.finite = deviations.finite;
  out.deviation_gains = deviations.gains;
  out.gains = deviations.gains;
  for (long k = 0; k < steps; ++k)  // u_bar - L (x_hat - x_bar) = -(L x_hat + (-u_bar - L x_bar))
    out.gains.k[k] = -(out.nominal.u[k] + deviations.gains.K[k] * out.nominal.x[k]);
  return out;
}

}  // namespace kushner
