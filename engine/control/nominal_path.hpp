#pragma once
// The noise-free path of a controlled model under a control, on the closed loop's own discretization (issue 14):
//   x_{k+1} = x_k + drift(t_k, x_k, u_k) dt,   t_k = k dt,   k = 0, ..., steps - 1,
//   J = sum_k running(x_k, u_k) dt + terminal(x_steps)
// (forward Euler; drift includes B u; the cost of kernels/control/quadratic_cost.hpp); a discrete-time model takes
// its transition x_{k+1} = F(k, x_k, u_k) instead (dt = 1). Every deterministic solver
// of engine/control/ (POLY3's nominal path, the direct optimum) scores paths with exactly this sum, so their
// numbers compare with each other and with the closed loop's noise-free members.
#include "kernels/control/gain_schedule.hpp"
#include "kernels/control/quadratic_cost.hpp"

#include <cmath>
#include <vector>

namespace kushner {

/// x[0..steps], u[0..steps-1] and the cost J of that path.
template <int N, int M>
struct NominalPath {
  std::vector<Vec<N>> x;
  std::vector<Vec<M>> u;
  double J = 0.0;
  bool finite = true;  // false when the path escaped (a non-finite state or cost)
};

/// The path under u_k = control(k, x_k) from x0, and its cost.
template <class Model, class Control>
NominalPath<Model::state_dim, Model::control_dim> simulate_path(
    const Model& model, const QuadraticCost<Model::state_dim, Model::control_dim>& cost,
    const Vec<Model::state_dim>& x0, long steps, double dt, Control&& control) {
  constexpr int n = Model::state_dim, m = Model::control_dim;
  NominalPath<n, m> out;
  out.x.resize(steps + 1);
  out.u.resize(steps);
  out.x[0] = x0;
  double J = 0.0;
  for (long k = 0; k < steps; ++k) {
    const double t = k * dt;
    const Vec<m> u = control(k, out.x[k]);
    out.u[k] = u;
    J += cost.running(out.x[k], u) * dt;
    if constexpr (Model::discrete_time)
      out.x[k + 1] = model.transition(t, out.x[k], u);
    else
      out.x[k + 1] = out.x[k] + model.drift(t, out.x[k], u) * dt;
  }
  J += cost.terminal(out.x[steps]);
  out.J = J;
  out.finite = std::isfinite(J);
  for (long k = 0; k <= steps && out.finite; ++k)
    for (int i = 0; i < n; ++i) out.finite = out.finite && std::isfinite(out.x[k][i]);
  return out;
}

/// The path under the affine feedback u_k = -(K_k x_k + k_k) of a gain schedule (LQR, ASRE, POLY3).
template <class Model>
NominalPath<Model::state_dim, Model::control_dim> simulate_feedback(
    const Model& model, const QuadraticCost<Model::state_dim, Model::control_dim>& cost,
    const GainSchedule<Model::state_dim, Model::control_dim>& gains, const Vec<Model::state_dim>& x0, long steps,
    double dt) {
  return simulate_path(model, cost, x0, steps, dt,
                       [&](long k, const Vec<Model::state_dim>& x) { return -(gains.K[k] * x + gains.k[k]); });
}

/// The path under an open-loop control sequence u[0..steps-1].
template <class Model>
NominalPath<Model::state_dim, Model::control_dim> simulate_open_loop(
    const Model& model, const QuadraticCost<Model::state_dim, Model::control_dim>& cost,
    const std::vector<Vec<Model::control_dim>>& u, const Vec<Model::state_dim>& x0, double dt) {
  return simulate_path(model, cost, x0, static_cast<long>(u.size()), dt,
                       [&](long k, const Vec<Model::state_dim>&) { return u[k]; });
}

}  // namespace kushner
