#pragma once
// The affine linear-quadratic regulator on the run's time grid, the workhorse of every gain law (LQR, ASRE):
// for dx = (A(t) x + a(t) + B(t) u) dt + G dw and the cost of kernels/control/quadratic_cost.hpp, the value
// function is V(t, x) = x^T S x + 2 s^T x + c with, backwards from S(T) = F, s(T) = -F x*, c(T) = x*^T F x*,
//   -dS/dt = A^T S + S A + Q - S B R^-1 B^T S,
//   -ds/dt = (A - B R^-1 B^T S)^T s + S a - Q x*,
//   -dc/dt = x*^T Q x* + 2 s^T a - s^T B R^-1 B^T s + tr(S G G^T),
// and the optimal feedback u = -R^-1 B^T (S x + s) (Kwakernaak & Sivan 1972, ch. 3; SPEC section 5). Solved by
// classical RK4 over each grid step, with the coefficients at the step's midpoint taken as the mean of its ends
// (exact for time-invariant coefficients, second order for coefficients sampled on the grid).
#include "core/eigen_dense.hpp"
#include "core/eigen_helpers.hpp"
#include "core/errors.hpp"
#include "kernels/control/gain_schedule.hpp"
#include "kernels/control/quadratic_cost.hpp"

#include <cmath>
#include <vector>

namespace kushner {

/// The coefficients of the affine model at one time: dx = (A x + a + B u) dt.
template <int N, int M>
struct AffineCoefficients {
  Mat<N, N> A;
  Vec<N> a;
  Mat<N, M> B;
};

/// S, s, c at the grid times 0, dt, ..., steps dt, and the feedback gains K = R^-1 B^T S, k = R^-1 B^T s.
template <int N, int M>
struct RiccatiSolution {
  std::vector<Mat<N, N>> S;
  std::vector<Vec<N>> s;
  std::vector<double> c;
  GainSchedule<N, M> gains;
  bool finite = true;  // false when the backward solve escaped to infinity (a finite escape time)

  /// E[V(0, x0)] for x0 ~ N(mean, cov): the optimal expected cost with full state information.
  double expected_value(const Vec<N>& mean, const Mat<N, N>& cov) const {
    const Eigen::Matrix<double, N, N> S0 = to_eigen(S[0]);
    const Eigen::Matrix<double, N, 1> mu = Eigen::Map<const Eigen::Matrix<double, N, 1>>(mean.v);
    const Eigen::Matrix<double, N, 1> s0 = Eigen::Map<const Eigen::Matrix<double, N, 1>>(s[0].v);
    return mu.dot(S0 * mu) + (S0 * to_eigen(cov)).trace() + 2.0 * s0.dot(mu) + c[0];
  }
};

/// Solves the affine LQR backwards over `steps` steps of `dt`; coefficients(k) gives A, a, B at time k dt
/// (k = 0, ..., steps); W = G G^T enters c only.
template <int N, int M, class Coefficients>
RiccatiSolution<N, M> solve_affine_lqr(long steps, double dt, const QuadraticCost<N, M>& cost, const Mat<N, N>& W,
                                       Coefficients&& coefficients) {
  using MatN = Eigen::Matrix<double, N, N>;
  using VecN = Eigen::Matrix<double, N, 1>;
  using MatNM = Eigen::Matrix<double, N, M>;
  KUSHNER_REQUIRE(steps >= 1 && dt > 0.0, "solve_affine_lqr: steps " << steps << ", dt " << dt);
  const MatN Q = to_eigen(cost.Q), F = to_eigen(cost.F), Wn = to_eigen(W);
  const Eigen::Matrix<double, M, M> Rinv = to_eigen(cost.R).inverse();
  const VecN target = Eigen::Map<const VecN>(cost.target.v);
  struct Coeff {
    MatN A;
    VecN a;
    MatNM B;
  };
  auto at = [&](long k) {
    const AffineCoefficients<N, M> c = coefficients(k);
    return Coeff{to_eigen(c.A), Eigen::Map<const VecN>(c.a.v), to_eigen(c.B)};
  };
  struct State {
    MatN S;
    VecN s;
    double c;
  };
  // d/dt of (S, s, c), the negated right-hand sides above.
  auto rate = [&](const Coeff& k, const State& x) {
    const MatN BRB = k.B * Rinv * k.B.transpose();
    State d;
    d.S = -(k.A.transpose() * x.S + x.S * k.A + Q - x.S * BRB * x.S);
    d.s = -((k.A - BRB * x.S).transpose() * x.s + x.S * k.a - Q * target);
    d.c = -(target.dot(Q * target) + 2.0 * x.s.dot(k.a) - x.s.dot(BRB * x.s) + (x.S * Wn).trace());
    return d;
  };
  auto axpy = [](const State& x, double h, const State& d) {
    return State{x.S + h * d.S, x.s + h * d.s, x.c + h * d.c};
  };

  RiccatiSolution<N, M> out;
  out.S.resize(steps + 1);
  out.s.resize(steps + 1);
  out.c.resize(steps + 1);
  out.gains.K.resize(steps + 1);
  out.gains.k.resize(steps + 1);
  State x{F, -F * target, target.dot(F * target)};
  Coeff upper = at(steps);
  auto record = [&](long k, const State& v, const Coeff& co) {
    const MatN Ssym = 0.5 * (v.S + v.S.transpose());
    out.S[k] = from_eigen<N, N>(Ssym);
    for (int i = 0; i < N; ++i) out.s[k][i] = v.s(i);
    out.c[k] = v.c;
    const Eigen::Matrix<double, M, N> K = Rinv * co.B.transpose() * Ssym;
    const Eigen::Matrix<double, M, 1> kk = Rinv * co.B.transpose() * v.s;
    out.gains.K[k] = from_eigen<M, N>(K);
    for (int i = 0; i < M; ++i) out.gains.k[k][i] = kk(i);
    out.finite = out.finite && Ssym.allFinite() && v.s.allFinite() && std::isfinite(v.c);
  };
  record(steps, x, upper);
  for (long k = steps - 1; k >= 0; --k) {
    const Coeff lower = at(k);
    const Coeff mid{0.5 * (lower.A + upper.A), 0.5 * (lower.a + upper.a), 0.5 * (lower.B + upper.B)};
    const double h = -dt;  // backwards in time
    const State k1 = rate(upper, x);
    const State k2 = rate(mid, axpy(x, 0.5 * h, k1));
    const State k3 = rate(mid, axpy(x, 0.5 * h, k2));
    const State k4 = rate(lower, axpy(x, h, k3));
    x = State{x.S + (h / 6.0) * (k1.S + 2.0 * k2.S + 2.0 * k3.S + k4.S),
              x.s + (h / 6.0) * (k1.s + 2.0 * k2.s + 2.0 * k3.s + k4.s),
              x.c + (h / 6.0) * (k1.c + 2.0 * k2.c + 2.0 * k3.c + k4.c)};
    x.S = 0.5 * (x.S + x.S.transpose());
    record(k, x, lower);
    upper = lower;
  }
  return out;
}

}  // namespace kushner
