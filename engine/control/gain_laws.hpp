#pragma once
// The gain laws of the closed loop that come from Riccati equations, computed once on the host and shared by
// every member (only the estimate they are applied to differs):
//   LQR   the affine LQR of the model linearized at a point (the origin unless set): A = df/dx(x_lin),
//         a = f(x_lin) - A x_lin, B = control_input;
//   ASRE  Cimen & Banks' approximating sequence of Riccati equations (seed 001 Theorem 3 (i), Remark 3): the
//         model factored as f = A(x) x + b (drift_sdc), iteration i solves the LQR of dx = (A(x^[i-1](t)) x + b
//         + B u) dt and propagates that time-varying linear system under its own feedback from the prior mean
//         to get x^[i]; x^[-1] = x0. The iteration runs on the nominal (noise-free) path from the prior mean;
//         each member then applies the converged time-varying gains to its own estimate (separation).
#include "core/errors.hpp"
#include "engine/control/discrete_riccati.hpp"
#include "engine/control/riccati.hpp"
#include "models/model_traits.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace kushner {

template <class Model>
using ModelCost = QuadraticCost<Model::state_dim, Model::control_dim>;

template <class Model>
using ModelGains = GainSchedule<Model::state_dim, Model::control_dim>;

/// W = G G^T at (t, x).
template <class Model>
Mat<Model::state_dim, Model::state_dim> noise_intensity_at(const Model& model, double t,
                                                           const Vec<Model::state_dim>& x) {
  const auto G = model.diffusion(t, x);
  return G * transpose(G);
}

/// LQR of the model linearized at x_lin.
template <class Model>
RiccatiSolution<Model::state_dim, Model::control_dim> lqr_solution(const Model& model, const ModelCost<Model>& cost,
                                                                   long steps, double dt,
                                                                   const Vec<Model::state_dim>& x_lin) {
  constexpr int n = Model::state_dim, m = Model::control_dim;
  const auto u0 = Model::Control::zero();
  return solve_affine_lqr<n, m>(steps, dt, cost, noise_intensity_at(model, 0.0, x_lin), [&](long k) {
    const double t = k * dt;
    const auto f = drift_and_jacobian(model, t, x_lin, u0);
    return AffineCoefficients<n, m>{f.jacobian, f.drift - f.jacobian * x_lin, model.control_input(t)};
  });
}

/// The Riccati controller of a discrete-time model linearized at the origin: A = dF/dx(k, 0), a = F(k, 0, 0),
/// B = control_input(k), W = Cov w (seed 003 (2.5)-(2.7); (3.12) for the perturbation loop's linear part).
template <class Model>
RiccatiSolution<Model::state_dim, Model::control_dim> discrete_lqr_solution(const Model& model,
                                                                            const ModelCost<Model>& cost, long steps) {
  constexpr int n = Model::state_dim, m = Model::control_dim;
  const Vec<n> origin = Vec<n>::zero();
  return solve_discrete_lqr<n, m>(
      steps, cost,
      [&](long k) {
        const double t = static_cast<double>(k);
        return AffineCoefficients<n, m>{model.transition_jacobian(t, origin),
                                        model.transition(t, origin, Model::Control::zero()), model.control_input(t)};
      },
      [&](long k) { return model.process_noise_covariance(static_cast<double>(k)); });
}

/// The ASRE iteration's result: the converged gains, the nominal path they produce, and how it converged.
template <class Model>
struct AsreSolution {
  RiccatiSolution<Model::state_dim, Model::control_dim> riccati;
  std::vector<Vec<Model::state_dim>> nominal;  // x^[i](k dt) of the last iteration
  int iterations = 0;
  double last_change = 0.0;  // max_k |x^[i] - x^[i-1]|_inf of the last iteration
  bool converged = false;
};

template <class Model>
AsreSolution<Model> asre_solution(const Model& model, const ModelCost<Model>& cost, long steps, double dt,
                                  double tolerance = 1e-10, int max_iterations = 100) {
  constexpr int n = Model::state_dim, m = Model::control_dim;
  static_assert(ModelTraits<Model>::sdc, "asre_solution: the model has no factorization f = A(x) x + b");
  AsreSolution<Model> out;
  std::vector<Vec<n>> previous(steps + 1, model.prior_mean);  // Remark 3: x^[-1] = x0
  for (int i = 0; i < max_iterations; ++i) {
    out.riccati =
        solve_affine_lqr<n, m>(steps, dt, cost, noise_intensity_at(model, 0.0, model.prior_mean), [&](long k) {
          const double t = k * dt;
          const SdcDrift<n> f = drift_sdc(model, t, previous[k]);
          return AffineCoefficients<n, m>{f.A, f.b, model.control_input(t)};
        });
    std::vector<Vec<n>> path(steps + 1);
    path[0] = model.prior_mean;
    for (long k = 0; k < steps; ++k) {
      const double t = k * dt;
      const SdcDrift<n> f = drift_sdc(model, t, previous[k]);
      const Vec<m> u = -(out.riccati.gains.K[k] * path[k] + out.riccati.gains.k[k]);
      path[k + 1] = path[k] + (f.A * path[k] + f.b + model.control_input(t) * u) * dt;
    }
    double change = 0.0, scale = 1.0;
    for (long k = 0; k <= steps; ++k)
      for (int j = 0; j < n; ++j) {
        change = std::max(change, std::fabs(path[k][j] - previous[k][j]));
        scale = std::max(scale, std::fabs(path[k][j]));
      }
    out.iterations = i + 1;
    out.last_change = change;
    out.nominal = path;
    previous = path;
    if (!out.riccati.finite || !std::isfinite(change)) break;
    if (change <= tolerance * scale) {
      out.converged = true;
      break;
    }
  }
  return out;
}

}  // namespace kushner
