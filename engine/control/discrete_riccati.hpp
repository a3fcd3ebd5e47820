#pragma once
// The affine LQR of a discrete-time model, the Riccati controller of seed 003 (2.5)-(2.7): for
// x[k+1] = A_k x + a_k + B_k u + w, E w = 0, Cov w = W_k, and the cost of kernels/control/quadratic_cost.hpp
// summed over the steps (dt = 1: sum_{k<N} (x-x*)'Q(x-x*) + u'Ru, plus (x[N]-x*)'F(x[N]-x*)), the value function
// is V_k(x) = x'S_k x + 2 s_k'x + c_k with S_N = F, s_N = -F x*, c_N = x*'F x*, and backwards
//   G = R + B'S B,  K = G^-1 B'S A,  k = G^-1 B'(S a + s)                       (S, s, c at k + 1)
//   S_k = Q + A'S A - K'G K,  s_k = -Q x* + A'(S a + s) - K'G k,
//   c_k = x*'Q x* + a'S a + 2 s'a - k'G k + c + tr(S W),
// and the optimal feedback u = -(K x + k). With full state information this is optimal for any zero-mean
// independent noise, Gaussian or not (the noise enters c only); with an estimate, it is the separation controller.
#include "core/eigen_dense.hpp"
#include "core/eigen_helpers.hpp"
#include "core/errors.hpp"
#include "engine/control/riccati.hpp"

#include <cmath>
#include <vector>

namespace kushner {

/// Solves the discrete affine LQR over `steps` steps; coefficients(k) gives A, a, B of step k -> k + 1 and
/// noise(k) its Cov w. The result's gains at k = steps are zero (no control after the last step).
template <int N, int M, class Coefficients, class Noise>
RiccatiSolution<N, M> solve_discrete_lqr(long steps, const QuadraticCost<N, M>& cost, Coefficients&& coefficients,
                                         Noise&& noise) {
  using MatN = Eigen::Matrix<double, N, N>;
  using VecN = Eigen::Matrix<double, N, 1>;
  using MatM = Eigen::Matrix<double, M, M>;
  KUSHNER_REQUIRE(steps >= 1, "solve_discrete_lqr: steps " << steps);
  const MatN Q = to_eigen(cost.Q), F = to_eigen(cost.F);
  const MatM R = to_eigen(cost.R);
  const VecN target = Eigen::Map<const VecN>(cost.target.v);
  RiccatiSolution<N, M> out;
  out.S.resize(steps + 1);
  out.s.resize(steps + 1);
  out.c.resize(steps + 1);
  out.gains.K.assign(steps + 1, Mat<M, N>::zero());
  out.gains.k.assign(steps + 1, Vec<M>::zero());
  MatN S = F;
  VecN s = -F * target;
  double c = target.dot(F * target);
  auto record = [&](long k) {
    out.S[k] = from_eigen<N, N>(S);
    for (int i = 0; i < N; ++i) out.s[k][i] = s(i);
    out.c[k] = c;
    out.finite = out.finite && S.allFinite() && s.allFinite() && std::isfinite(c);
  };
  record(steps);
  for (long k = steps - 1; k >= 0; --k) {
    const AffineCoefficients<N, M> co = coefficients(k);
    const MatN A = to_eigen(co.A);
    const VecN a = Eigen::Map<const VecN>(co.a.v);
    const Eigen::Matrix<double, N, M> B = to_eigen(co.B);
    const MatM G = R + B.transpose() * S * B;
    const Eigen::LDLT<MatM> solver(G);
    const Eigen::Matrix<double, M, N> K = solver.solve(B.transpose() * S * A);
    const VecN Sa_s = S * a + s;
    const Eigen::Matrix<double, M, 1> kk = solver.solve(B.transpose() * Sa_s);
    const double c_next =
        target.dot(Q * target) + a.dot(S * a) + 2.0 * s.dot(a) - kk.dot(G * kk) + c + (S * to_eigen(noise(k))).trace();
    const MatN S_next = Q + A.transpose() * S * A - K.transpose() * G * K;
    s = -Q * target + A.transpose() * Sa_s - K.transpose() * G * kk;
    S = 0.5 * (S_next + S_next.transpose());
    c = c_next;
    out.gains.K[k] = from_eigen<M, N>(K);
    for (int i = 0; i < M; ++i) out.gains.k[k][i] = kk(i);
    record(k);
  }
  return out;
}

}  // namespace kushner
