#pragma once
// The deterministic open-loop optimum by a direct method (issue 14 part 4): decision variables u_0..u_{steps-1},
// the cost of the closed loop's own noise-free discretization (nominal_path.hpp),
//   x_{k+1} = x_k + drift(t_k, x_k, u_k) dt,   J(u) = sum_k [(x_k - x*)^T Q (x_k - x*) + u_k^T R u_k] dt
//                                                     + (x_N - x*)^T F (x_N - x*),
// its exact discrete adjoint gradient
//   lambda_N = 2 F (x_N - x*),   lambda_k = 2 Q (x_k - x*) dt + (I + dt df/dx(t_k, x_k))^T lambda_{k+1},
//   dJ/du_k = dt (2 R u_k + B(t_k)^T lambda_{k+1})                     (drift = f + B u: d drift/du = B),
// and L-BFGS (two-loop recursion, memory `memory`) with a strong-Wolfe line search (bracketing and zoom by safeguarded
// quadratic interpolation, Nocedal & Wright 2006, Algorithms 3.5-3.6, c1 = 1e-4, c2 = 0.9). It stops when the gradient
// of the continuous-time functional, max_k |dJ/du_k| / dt = max_k |2 R u_k + B^T lambda_{k+1}|, is at most
// `gradient_tolerance`. The minimum is over open-loop sequences from one x0, so it is never above the noise-free J of
// any feedback law (LQR, ASRE, POLY3) simulated from that x0 with the same scheme: the reference they are held to.
//
// euler_lqr() is the exact minimum of the same discrete problem for a linear model: the discrete-time Riccati
// recursion of the Euler scheme (x_{k+1} = (I + A dt) x_k + a0 dt + B dt u_k, stage cost dt [...]), which the direct
// optimum must equal to rounding; the continuous LQR (riccati.hpp) differs from both by O(dt).
#include "core/eigen_dense.hpp"
#include "core/eigen_helpers.hpp"
#include "core/errors.hpp"
#include "engine/control/nominal_path.hpp"
#include "kernels/control/quadratic_cost.hpp"
#include "models/model_traits.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <string>
#include <vector>

namespace kushner {

struct DirectOptions {
  double gradient_tolerance = 1e-9;  // on max_k |2 R u_k + B^T lambda_{k+1}|
  int max_iterations = 5000;
  int memory = 20;
};

template <int N, int M>
struct DirectOptimum {
  std::vector<Vec<M>> u;   // u_0..u_{steps-1}
  NominalPath<N, M> path;  // the path under u and its J
  double J = 0.0;
  int iterations = 0;
  int evaluations = 0;         // cost-and-gradient evaluations
  double gradient_norm = 0.0;  // max_k |dJ/du_k| / dt at the end
  bool converged = false;
  std::string reason;
};

/// J(u) and its gradient (flat: u_k's M entries at k M) by the discrete adjoint.
template <class Model>
double direct_cost_gradient(const Model& model, const QuadraticCost<Model::state_dim, Model::control_dim>& cost,
                            const Vec<Model::state_dim>& x0, double dt, const Eigen::VectorXd& u,
                            Eigen::VectorXd* gradient) {
  constexpr int n = Model::state_dim, m = Model::control_dim;
  using VecN = Eigen::Matrix<double, n, 1>;
  const long steps = u.size() / m;
  std::vector<Vec<n>> x(steps + 1);
  x[0] = x0;
  auto control = [&](long k) {
    Vec<m> c;
    for (int i = 0; i < m; ++i) c[i] = u(k * m + i);
    return c;
  };
  double J = 0.0;
  for (long k = 0; k < steps; ++k) {
    const Vec<m> uk = control(k);
    J += cost.running(x[k], uk) * dt;
    x[k + 1] = x[k] + model.drift(k * dt, x[k], uk) * dt;
  }
  J += cost.terminal(x[steps]);
  if (!gradient) return J;
  gradient->resize(u.size());
  const Eigen::Matrix<double, n, n> Q = to_eigen(cost.Q), F = to_eigen(cost.F);
  const Eigen::Matrix<double, m, m> R = to_eigen(cost.R);
  const VecN target = Eigen::Map<const VecN>(cost.target.v);
  auto eig = [](const Vec<n>& v) { return VecN(Eigen::Map<const VecN>(v.v)); };
  VecN lambda = 2.0 * F * (eig(x[steps]) - target);
  for (long k = steps - 1; k >= 0; --k) {
    const double t = k * dt;
    const Vec<m> uk = control(k);
    const Eigen::Matrix<double, m, 1> ue = Eigen::Map<const Eigen::Matrix<double, m, 1>>(uk.v);
    const Eigen::Matrix<double, m, 1> g = dt * (2.0 * R * ue + to_eigen(model.control_input(t)).transpose() * lambda);
    for (int i = 0; i < m; ++i) (*gradient)(k * m + i) = g(i);
    const Eigen::Matrix<double, n, n> A = to_eigen(model.drift_jacobian(t, x[k], uk));
    lambda =
        2.0 * dt * Q * (eig(x[k]) - target) + (Eigen::Matrix<double, n, n>::Identity() + dt * A).transpose() * lambda;
  }
  return J;
}

/// Minimizes J(u) from the initial guess u_start (zeros when empty) over `steps` steps of `dt`.
template <class Model>
DirectOptimum<Model::state_dim, Model::control_dim> direct_optimum(
    const Model& model, const QuadraticCost<Model::state_dim, Model::control_dim>& cost,
    const Vec<Model::state_dim>& x0, long steps, double dt, const DirectOptions& options = {},
    const std::vector<Vec<Model::control_dim>>& u_start = {}) {
  constexpr int n = Model::state_dim, m = Model::control_dim;
  KUSHNER_REQUIRE(steps >= 1 && dt > 0.0, "direct_optimum: steps " << steps << ", dt " << dt);
  using VecX = Eigen::VectorXd;
  DirectOptimum<n, m> out;
  VecX u = VecX::Zero(steps * m);
  if (!u_start.empty()) {
    KUSHNER_REQUIRE(static_cast<long>(u_start.size()) == steps, "direct_optimum: u_start has " << u_start.size());
    for (long k = 0; k < steps; ++k)
      for (int i = 0; i < m; ++i) u(k * m + i) = u_start[k][i];
  }
  auto evaluate = [&](const VecX& v, VecX& g) {
    ++out.evaluations;
    return direct_cost_gradient(model, cost, x0, dt, v, &g);
  };
  auto gnorm = [&](const VecX& g) { return g.cwiseAbs().maxCoeff() / dt; };
  VecX g;
  double f = evaluate(u, g);
  std::deque<VecX> S, Y;
  std::deque<double> rho;
  out.reason = "not converged";
  for (int it = 0;; ++it) {
    out.iterations = it;
    out.gradient_norm = gnorm(g);
    if (!std::isfinite(f) || !g.allFinite()) {
      out.reason = "the cost or its gradient is not finite (the path escaped)";
      break;
    }
    if (out.gradient_norm <= options.gradient_tolerance) {
      out.converged = true;
      out.reason = "converged";
      break;
    }
    if (it >= options.max_iterations) {
      out.reason = "not converged in " + std::to_string(it) + " iterations";
      break;
    }
    // Two-loop recursion: d = -H g.
    VecX q = g;
    std::vector<double> alpha(S.size());
    for (int i = static_cast<int>(S.size()) - 1; i >= 0; --i) {
      alpha[i] = rho[i] * S[i].dot(q);
      q -= alpha[i] * Y[i];
    }
    if (!S.empty()) q *= S.back().dot(Y.back()) / Y.back().squaredNorm();
    for (size_t i = 0; i < S.size(); ++i) {
      const double beta = rho[i] * Y[i].dot(q);
      q += (alpha[i] - beta) * S[i];
    }
    VecX d = -q;
    double slope = g.dot(d);
    if (!(slope < 0.0)) {  // not a descent direction: restart from steepest descent
      S.clear();
      Y.clear();
      rho.clear();
      d = -g;
      slope = g.dot(d);
    }
    // Strong Wolfe line search.
    const double c1 = 1e-4, c2 = 0.9;
    double step = S.empty() ? std::min(1.0, 1.0 / std::max(1e-300, g.cwiseAbs().maxCoeff())) : 1.0;
    double lo = 0.0, f_lo = f, slope_lo = slope, hi = 0.0, f_hi = 0.0;
    bool bracketed = false, found = false;
    VecX u_new, g_new;
    double f_new = f;
    auto try_step = [&](double a) {
      u_new = u + a * d;
      f_new = evaluate(u_new, g_new);
      return g_new.dot(d);
    };
    for (int ls = 0; ls < 60 && !found; ++ls) {
      if (bracketed) {  // zoom: quadratic interpolation safeguarded to the middle of [lo, hi]
        const double a_lo = lo, a_hi = hi;
        double trial = 0.5 * (a_lo + a_hi);
        const double dd = a_hi - a_lo;
        const double quad = (f_hi - f_lo - slope_lo * dd) / (dd * dd);
        if (quad > 0.0) {
          const double candidate = a_lo - slope_lo / (2.0 * quad);
          const double left = std::min(a_lo, a_hi), right = std::max(a_lo, a_hi);
          if (candidate > left + 0.1 * (right - left) && candidate < right - 0.1 * (right - left)) trial = candidate;
        }
        step = trial;
      }
      const double slope_new = try_step(step);
      // Sufficient decrease, relaxed by a rounding allowance of J (Hager & Zhang's approximate Wolfe conditions):
      // near the minimum the decrease c1 a slope falls below the rounding of J and only the slope still tells.
      const double allowance = 1e-14 * std::fabs(f);
      if (!std::isfinite(f_new) || f_new > f + c1 * step * slope + allowance ||
          (bracketed && f_new > f_lo + allowance)) {
        hi = step;
        f_hi = std::isfinite(f_new) ? f_new : std::numeric_limits<double>::max();
        bracketed = true;
        if (!std::isfinite(f_new)) f_hi = 1e300;
        continue;
      }
      if (std::fabs(slope_new) <= -c2 * slope) {
        found = true;
        break;
      }
      if (bracketed) {
        if (slope_new * (hi - lo) >= 0.0) {
          hi = lo;
          f_hi = f_lo;
        }
        lo = step;
        f_lo = f_new;
        slope_lo = slope_new;
      } else {
        if (slope_new >= 0.0) {
          hi = lo;
          f_hi = f_lo;
          lo = step;
          f_lo = f_new;
          slope_lo = slope_new;
          bracketed = true;
        } else {
          lo = step;
          f_lo = f_new;
          slope_lo = slope_new;
          step *= 2.0;
        }
      }
      if (bracketed && std::fabs(hi - lo) <= 1e-16 * std::max(1.0, std::fabs(lo))) break;
    }
    if (!found) {
      // Accept the best sufficient decrease seen (lo) when the Wolfe curvature test could not be met at rounding
      // level; stop when nothing decreases J.
      if (lo > 0.0 && f_lo < f) {
        try_step(lo);
      } else {
        out.reason = "the line search found no decrease (gradient " + std::to_string(out.gradient_norm) +
                     "): at the level of rounding";
        break;
      }
    }
    const VecX s = u_new - u, y = g_new - g;
    const double sy = s.dot(y);
    if (sy > 1e-300) {
      S.push_back(s);
      Y.push_back(y);
      rho.push_back(1.0 / sy);
      if (static_cast<int>(S.size()) > options.memory) {
        S.pop_front();
        Y.pop_front();
        rho.pop_front();
      }
    }
    u = u_new;
    g = g_new;
    f = f_new;
  }
  out.u.resize(steps);
  for (long k = 0; k < steps; ++k)
    for (int i = 0; i < m; ++i) out.u[k][i] = u(k * m + i);
  out.path = simulate_open_loop(model, cost, out.u, x0, dt);
  out.J = out.path.J;
  return out;
}

/// The exact minimum of the Euler-discretized linear-quadratic problem: V_k(x) = x^T P_k x + 2 p_k^T x + r_k.
template <int N, int M>
struct EulerLqr {
  std::vector<Eigen::Matrix<double, N, N>> P;
  std::vector<Eigen::Matrix<double, N, 1>> p;
  std::vector<double> r;
  double value(const Vec<N>& x) const {
    const Eigen::Matrix<double, N, 1> e = Eigen::Map<const Eigen::Matrix<double, N, 1>>(x.v);
    return e.dot(P[0] * e) + 2.0 * p[0].dot(e) + r[0];
  }
};

template <class Model>
EulerLqr<Model::state_dim, Model::control_dim> euler_lqr(
    const Model& model, const QuadraticCost<Model::state_dim, Model::control_dim>& cost, long steps, double dt) {
  constexpr int n = Model::state_dim, m = Model::control_dim;
  static_assert(ModelTraits<Model>::linear, "euler_lqr: a linear model only");
  using MatN = Eigen::Matrix<double, n, n>;
  using VecN = Eigen::Matrix<double, n, 1>;
  EulerLqr<n, m> out;
  out.P.resize(steps + 1);
  out.p.resize(steps + 1);
  out.r.resize(steps + 1);
  const MatN Q = to_eigen(cost.Q), F = to_eigen(cost.F);
  const Eigen::Matrix<double, m, m> R = to_eigen(cost.R);
  const VecN xs = Eigen::Map<const VecN>(cost.target.v);
  out.P[steps] = F;
  out.p[steps] = -F * xs;
  out.r[steps] = xs.dot(F * xs);
  for (long k = steps - 1; k >= 0; --k) {
    const double t = k * dt;
    const auto lf = model.linear_form(t);
    const MatN Phi = MatN::Identity() + dt * to_eigen(lf.A);
    const VecN c = dt * VecN(Eigen::Map<const VecN>(lf.a0.v));
    const Eigen::Matrix<double, n, m> Gam = dt * to_eigen(model.control_input(t));
    const MatN& P = out.P[k + 1];
    const VecN w = P * c + out.p[k + 1];
    const Eigen::Matrix<double, m, m> H = dt * R + Gam.transpose() * P * Gam;
    const auto Hlu = H.partialPivLu();
    const Eigen::Matrix<double, m, n> GP = Gam.transpose() * P * Phi;
    out.P[k] = dt * Q + Phi.transpose() * P * Phi - GP.transpose() * Hlu.solve(GP);
    out.P[k] = 0.5 * (out.P[k] + out.P[k].transpose()).eval();
    const Eigen::Matrix<double, m, 1> Gw = Gam.transpose() * w;
    out.p[k] = -dt * Q * xs + Phi.transpose() * w - GP.transpose() * Hlu.solve(Gw);
    out.r[k] = dt * xs.dot(Q * xs) + c.dot(P * c) + 2.0 * out.p[k + 1].dot(c) + out.r[k + 1] - Gw.dot(Hlu.solve(Gw));
  }
  return out;
}

}  // namespace kushner
