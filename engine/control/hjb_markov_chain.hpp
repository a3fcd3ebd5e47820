#pragma once
// The optimal expected cost J* and feedback of a fully observed stochastic problem of dimension 1-2,
//   dx = (f(t, x) + B u) dt + G dw,   J = E[(x(T) - x*)^T F (x(T) - x*) + int (x - x*)^T Q (x - x*) + u^T R u dt],
// by Kushner's Markov-chain approximation (Kushner & Dupuis 2001, ch. 5, 12): on a box grid of spacings h_i, with a
// fixed time step dt, the locally consistent upwind chain
//   p(x -> x +- h_i e_i | u) = dt (W_ii / 2 + h_i b_i^{+-}) / h_i^2,   p(x -> x) = 1 - sum,   b = f(t, x) + B u,
// W = G G^T (diagonal: checked), with dt chosen so that p(x -> x) >= 1 - safety for every node and |u| <= u_bound.
// The dynamic programme runs backwards from V(T, x) = terminal(x):
//   V(t_k, x) = min_{|u| <= u_bound} [ running(x, u) dt + sum_y p(x -> y | u) V(t_{k+1}, y) ],
// the running cost on [t_k, t_k+1) charged at (x_k, u_k) as the closed loop scores it. For one control (M = 1) the
// bracket is r u^2 + sum_i b_i(u) (b_i >= 0 ? D+_i V : D-_i V) + terms free of u, piecewise quadratic in u with kinks
// where some b_i(u) = 0: it is minimized exactly, interval by interval (no control grid needed). Boundary:
// REFLECTING — a move that would leave the box is replaced by staying (V outside := V at the wall, a Neumann
// condition); the box is chosen wide enough that this does not matter (the tests widen it and compare).
// Box (default): around the model's noise-free, uncontrolled Euler path from x0_mean, widened on each side by
// `sds` standard deviations sqrt(x0_cov_ii + W_ii T) plus `margin`. The control bound (default): 3 times the largest
// |u| of the LQR (linearized at the origin) over the box's nodes and the horizon, plus 1; the fraction of node updates
// whose minimizer sits on the bound is reported (it should be 0 where the bound is not meant to bind).
// J* = E V(0, x0), x0 ~ N(x0_mean, x0_cov), by tensor Gauss-Hermite quadrature (20 points a dimension) of the
// multilinear interpolant of V(0, .). The feedback u*(t, x) is kept at `table_rows` uniformly spaced times
// (kernels/control/feedback_table.hpp).
#include "core/eigen_dense.hpp"
#include "core/eigen_helpers.hpp"
#include "core/errors.hpp"
#include "engine/control/gain_laws.hpp"
#include "kernels/control/feedback_table.hpp"
#include "kernels/control/quadratic_cost.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <vector>

namespace kushner {

template <int N>
struct HjbOptions {
  std::array<int, N> points{};  // grid points a dimension (default 101)
  double sds = 5.0;             // auto box: standard deviations each side
  double margin = 0.5;          // auto box: extra width each side
  bool explicit_box = false;    // use lower/upper below instead of the auto box
  std::array<double, N> lower{}, upper{};
  double u_bound = 0.0;   // 0: automatic (see above)
  double safety = 0.9;    // dt = safety * min over nodes of 1 / sum_i (W_ii + h_i |b_i|) / h_i^2
  long table_rows = 100;  // rows of the feedback table (the chain's steps are a multiple of it)
  HjbOptions() { points.fill(101); }
};

template <int N>
struct HjbSolution {
  std::array<double, N> lower{}, spacing{};
  std::array<int, N> points{};
  std::vector<double> V0;  // V(0, node), nodes row-major (dimension 0 slowest)
  double J = 0.0;          // E V(0, x0), x0 ~ N(x0_mean, x0_cov)
  FeedbackTable<N, 1> table;
  double dt = 0.0;  // the chain's time step
  long steps = 0;
  double u_bound = 0.0;
  double bound_active_fraction = 0.0;  // node updates whose minimizer is +-u_bound

  /// V(0, x) by multilinear interpolation (clamped to the box).
  double value(const Vec<N>& x) const {
    int base[N];
    double w[N];
    for (int d = 0; d < N; ++d) {
      double s = std::clamp((x[d] - lower[d]) / spacing[d], 0.0, points[d] - 1.0);
      int i = std::min(static_cast<int>(s), points[d] - 2);
      base[d] = i;
      w[d] = s - i;
    }
    double v = 0.0;
    for (int corner = 0; corner < (1 << N); ++corner) {
      double weight = 1.0;
      long node = 0;
      for (int d = 0; d < N; ++d) {
        const int bit = (corner >> d) & 1;
        weight *= bit ? w[d] : 1.0 - w[d];
        node = node * points[d] + base[d] + bit;
      }
      if (weight != 0.0) v += weight * V0[node];
    }
    return v;
  }
};

/// Probabilists' Gauss-Hermite nodes and weights (weights sum to 1) by Golub-Welsch.
inline void gauss_hermite(int n, std::vector<double>& nodes, std::vector<double>& weights) {
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(n, n);
  for (int k = 1; k < n; ++k) J(k, k - 1) = J(k - 1, k) = std::sqrt(static_cast<double>(k));
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(J);
  nodes.resize(n);
  weights.resize(n);
  for (int i = 0; i < n; ++i) {
    nodes[i] = eig.eigenvalues()(i);
    weights[i] = eig.eigenvectors()(0, i) * eig.eigenvectors()(0, i);
  }
}

/// A feedback law (t, x) -> u of one control, for hjb_markov_chain to evaluate. Named through a class template's
/// member: with the std::function spelled out in the parameter list (Vec<Model::state_dim>), nvcc's front end found
/// no matching template for a lambda argument, where GCC takes it (CUDA 13).
template <int N>
struct HjbPolicyOf {
  using type = std::function<double(double, const Vec<N>&)>;
};

/// Solves the chain's dynamic programme over [0, T]. With `policy` (a function (t, x) -> u), evaluates that policy
/// (clamped to the bound) on the same chain instead of minimizing: its J is then the policy's expected cost.
template <class Model>
HjbSolution<Model::state_dim> hjb_markov_chain(const Model& model,
                                               const QuadraticCost<Model::state_dim, Model::control_dim>& cost,
                                               double T, const HjbOptions<Model::state_dim>& options = {},
                                               const typename HjbPolicyOf<Model::state_dim>::type& policy = nullptr) {
  constexpr int n = Model::state_dim, m = Model::control_dim;
  static_assert(n >= 1 && n <= 2, "hjb_markov_chain: dimension 1 or 2");
  static_assert(m == 1, "hjb_markov_chain: one control (exact piecewise-quadratic minimization)");
  KUSHNER_INPUT_REQUIRE(T > 0.0, "HJB: the horizon must be positive");
  HjbSolution<n> out;
  const Mat<n, n> W = noise_intensity_at(model, 0.0, model.x0_mean);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      KUSHNER_INPUT_REQUIRE(i == j || W(i, j) == 0.0, "HJB: the noise intensity G G^T must be diagonal");

  // The box.
  if (options.explicit_box) {
    for (int d = 0; d < n; ++d) {
      out.lower[d] = options.lower[d];
      out.spacing[d] = (options.upper[d] - options.lower[d]) / (options.points[d] - 1);
    }
  } else {
    Vec<n> lo = model.x0_mean, hi = model.x0_mean, x = model.x0_mean;
    const long path_steps = 200;
    for (long k = 0; k < path_steps; ++k) {
      x = x + model.drift(k * T / path_steps, x, Vec<m>::zero()) * (T / path_steps);
      for (int d = 0; d < n; ++d) {
        lo[d] = std::min(lo[d], x[d]);
        hi[d] = std::max(hi[d], x[d]);
      }
    }
    for (int d = 0; d < n; ++d) {
      const double sd = std::sqrt(model.x0_cov(d, d) + W(d, d) * T);
      out.lower[d] = lo[d] - options.sds * sd - options.margin;
      out.spacing[d] = (hi[d] + options.sds * sd + options.margin - out.lower[d]) / (options.points[d] - 1);
    }
  }
  out.points = options.points;
  long nodes = 1;
  for (int d = 0; d < n; ++d) {
    KUSHNER_INPUT_REQUIRE(out.points[d] >= 3 && out.spacing[d] > 0.0, "HJB: bad grid in dimension " << d);
    nodes *= out.points[d];
  }
  auto node_x = [&](long node) {
    Vec<n> x;
    for (int d = n - 1; d >= 0; --d) {
      x[d] = out.lower[d] + (node % out.points[d]) * out.spacing[d];
      node /= out.points[d];
    }
    return x;
  };
  long stride[n];
  stride[n - 1] = 1;
  for (int d = n - 2; d >= 0; --d) stride[d] = stride[d + 1] * out.points[d + 1];

  // The control bound.
  out.u_bound = options.u_bound;
  if (out.u_bound <= 0.0) {
    const long lqr_steps = 100;
    const auto lqr = lqr_solution(model, cost, lqr_steps, T / lqr_steps, Vec<n>::zero());
    double largest = 0.0;
    for (long k = 0; k <= lqr_steps; k += 10)
      for (long node = 0; node < nodes; ++node) {
        const Vec<n> x = node_x(node);
        largest = std::max(largest, std::fabs((lqr.gains.K[k] * x + lqr.gains.k[k])[0]));
      }
    out.u_bound = 3.0 * largest + 1.0;
  }
  const double U = out.u_bound;

  // The time step: p(x -> x) >= 1 - safety at every node, time and admissible u (f sampled at t = 0 and T).
  double rate = 0.0;
  const Mat<n, m> B0 = model.control_input(0.0);
  for (long node = 0; node < nodes; ++node) {
    const Vec<n> x = node_x(node);
    for (double t : {0.0, T}) {
      const Vec<n> f = model.drift(t, x, Vec<m>::zero());
      double r = 0.0;
      for (int d = 0; d < n; ++d) {
        const double h = out.spacing[d];
        r += (W(d, d) + h * (std::fabs(f[d]) + std::fabs(B0(d, 0)) * U)) / (h * h);
      }
      rate = std::max(rate, r);
    }
  }
  const long rows = std::max<long>(1, options.table_rows);
  const long per_row = std::max<long>(1, static_cast<long>(std::ceil(T * rate / options.safety / rows)));
  out.steps = per_row * rows;
  out.dt = T / out.steps;
  const double dt = out.dt;

  out.table.rows = rows + 1;
  out.table.row_dt = T / rows;
  for (int d = 0; d < n; ++d) {
    out.table.lower[d] = out.lower[d];
    out.table.spacing[d] = out.spacing[d];
    out.table.points[d] = out.points[d];
  }
  out.table.values.assign((rows + 1) * nodes, 0.0);

  const Eigen::Matrix<double, n, n> Qc = to_eigen(cost.Q);
  const double r = cost.R(0, 0);
  KUSHNER_INPUT_REQUIRE(r > 0.0, "HJB: R must be positive");
  std::vector<double> V(nodes), next(nodes);
  for (long node = 0; node < nodes; ++node) V[node] = cost.terminal(node_x(node));
  long active = 0;
  for (long k = out.steps - 1; k >= 0; --k) {
    const double t = k * dt;
    const Mat<n, m> B = model.control_input(t);
    const bool record = k % per_row == 0;
    for (long node = 0; node < nodes; ++node) {
      const Vec<n> x = node_x(node);
      const Vec<n> f = model.drift(t, x, Vec<m>::zero());
      double Dp[n], Dm[n], diffusion = 0.0;
      long rest = node;
      int index[n];
      for (int d = n - 1; d >= 0; --d) {
        index[d] = rest % out.points[d];
        rest /= out.points[d];
      }
      for (int d = 0; d < n; ++d) {
        const double h = out.spacing[d];
        const double up = index[d] + 1 < out.points[d] ? V[node + stride[d]] : V[node];  // reflecting
        const double down = index[d] > 0 ? V[node - stride[d]] : V[node];
        Dp[d] = (up - V[node]) / h;
        Dm[d] = (V[node] - down) / h;
        diffusion += 0.5 * W(d, d) * (up - 2.0 * V[node] + down) / (h * h);
      }
      // g(u) = r u^2 + sum_d b_d(u) (b_d >= 0 ? D+ : D-), b_d(u) = f_d + B_d u.
      auto g = [&](double u) {
        double s = r * u * u;
        for (int d = 0; d < n; ++d) {
          const double b = f[d] + B(d, 0) * u;
          s += b * (b >= 0.0 ? Dp[d] : Dm[d]);
        }
        return s;
      };
      double best_u;
      if (policy) {
        best_u = std::clamp(policy(t, x), -U, U);
      } else {
        double kinks[n + 2];
        int count = 0;
        kinks[count++] = -U;
        kinks[count++] = U;
        for (int d = 0; d < n; ++d)
          if (B(d, 0) != 0.0) {
            const double kink = -f[d] / B(d, 0);
            if (kink > -U && kink < U) kinks[count++] = kink;
          }
        // At most n + 2 values: an insertion sort (std::sort's, beyond its 16-element threshold, is code GCC 12 warns
        // about for an array this small).
        for (int i = 1; i < count; ++i)
          for (int j = i; j > 0 && kinks[j] < kinks[j - 1]; --j) std::swap(kinks[j], kinks[j - 1]);
        best_u = kinks[0];
        double best = g(best_u);
        for (int i = 0; i + 1 < count; ++i) {
          const double a = kinks[i], b = kinks[i + 1];
          if (b <= a) continue;
          const double mid = 0.5 * (a + b);
          double c = 0.0;  // slope of the linear part on (a, b)
          for (int d = 0; d < n; ++d) {
            const double bd = f[d] + B(d, 0) * mid;
            c += B(d, 0) * (bd >= 0.0 ? Dp[d] : Dm[d]);
          }
          for (double cand : {std::clamp(-c / (2.0 * r), a, b), b}) {
            const double v = g(cand);
            if (v < best) {
              best = v;
              best_u = cand;
            }
          }
        }
        if (std::fabs(best_u) >= U) ++active;
      }
      const Vec<n> e = x - cost.target;
      const double state_cost = Eigen::Map<const Eigen::Matrix<double, n, 1>>(e.v).dot(
          Qc * Eigen::Map<const Eigen::Matrix<double, n, 1>>(e.v));
      next[node] = V[node] + dt * (state_cost + diffusion + g(best_u));
      if (record) out.table.values[(k / per_row) * nodes + node] = best_u;
    }
    std::swap(V, next);
  }
  for (long node = 0; node < nodes; ++node)
    out.table.values[rows * nodes + node] = out.table.values[(rows - 1) * nodes + node];
  out.V0 = V;
  out.bound_active_fraction = policy ? 0.0 : static_cast<double>(active) / (static_cast<double>(nodes) * out.steps);

  // J* = E V(0, x0) by Gauss-Hermite quadrature.
  std::vector<double> z, w;
  gauss_hermite(20, z, w);
  const Eigen::Matrix<double, n, n> L = to_eigen(covariance_square_root(model.x0_cov));
  double J = 0.0;
  if constexpr (n == 1) {
    for (size_t i = 0; i < z.size(); ++i) J += w[i] * out.value(Vec<1>{{model.x0_mean[0] + L(0, 0) * z[i]}});
  } else {
    for (size_t i = 0; i < z.size(); ++i)
      for (size_t j = 0; j < z.size(); ++j) {
        const Eigen::Vector2d p = L * Eigen::Vector2d(z[i], z[j]);
        J += w[i] * w[j] * out.value(Vec<2>{{model.x0_mean[0] + p(0), model.x0_mean[1] + p(1)}});
      }
  }
  out.J = J;
  return out;
}

}  // namespace kushner
