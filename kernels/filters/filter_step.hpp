#pragma once
// The time discretization every filter of the bank shares. Each filter is a pair of linearizations of the
// continuous-time filter equations
//     dm = a dt + K (dy - h_hat dt),   dP = (J P + P J^T + W - K H P) dt [+ dy terms],   K = P H^T V^{-1}
// (seed 000 (5.27), (5.29); seed 002 (9)-(10); seed 001 (11)-(12)), and one step over [t, t + dt] with the
// increment dy = y(t + dt) - y(t) is
//   1. update with dy, which the truth produced from x(t):   S = V + dt H P H^T,  K = P H^T S^{-1},
//      m <- m + K (dy - h_hat dt),  P <- P - dt K H P;
//   2. Euler prediction with the drift linearized at the updated (m, P):
//      m <- m + a dt,  P <- (I + J dt) P (I + J dt)^T + W dt.
// This is the continuous equations to O(dt) (S -> V), and for a linear model it is the exact Kalman filter of
// the Euler-Maruyama discretization that the truths follow. Both stages keep P symmetric positive
// semidefinite (the update is a Schur complement, the prediction a congruence plus W dt), so a singular P(0)
// (seed 002's car example) stays a valid covariance; only filters whose covariance equation has a dy term
// (SOF, EKF-DS) can lose definiteness, which the bank reports as divergence.
#include "core/linear_algebra.hpp"
#include "core/small_matrix.hpp"
#include "core/status.hpp"

#include <cstdint>

namespace kushner {

/// Pivots within this fraction of the largest variance count as zero (core/linear_algebra.hpp).
constexpr double covariance_tolerance = 1e-10;

/// What one step of one member gives every filter: step k from t = k dt. A discrete-time model's step k: t = k, dt =
/// 1, dy = z[k+1], V = Cov v. `step` keys the random numbers of a filter that draws them (EnKBF): taken from t / dt, a
/// double division, it was computed at every member-step of a bank's GPU step, EnKBF in the bank or not (nvcc hoisted
/// it above the slots' tests, EnKBF and EnKBF-S sharing it; the sine bank's steps x1.03-1.04 without it on an H200:
/// perf/filter_bank.md).
template <int P>
struct StepInput {
  double t, dt;
  std::uint32_t step;
  Vec<P> dy;
  Mat<P, P> V;  // R R^T at t
};

/// Observation at (m, P): predicted observation rate h_hat and its matrix H.
template <int N, int P>
struct ObservationLinearization {
  Vec<P> h;
  Mat<P, N> H;
};

/// Drift at (m, P): mean drift a, covariance-equation matrix J, process-noise intensity W = G G^T.
template <int N>
struct DriftLinearization {
  Vec<N> a;
  Mat<N, N> J;
  Mat<N, N> W;
};

/// G G^T
template <int N, int Q>
KOKKOS_INLINE_FUNCTION Mat<N, N> noise_intensity(const Mat<N, Q>& G) {
  return G * transpose(G);
}

/// Step 1: the update with dy. Returns false when S is not positive definite (m and P are then no update's: a
/// scalar S's is taken whatever S is, below). `weighted_innovation`
/// receives S^{-1} (dy - h_hat dt), the V^{-1} (dy - h_hat dt) of the continuous equations, for filters
/// whose covariance has dy terms.
template <int N, int P>
KOKKOS_INLINE_FUNCTION bool kalman_update(const ObservationLinearization<N, P>& obs, const StepInput<P>& in, Vec<N>& m,
                                          Mat<N, N>& Pm, Vec<P>& weighted_innovation) {
  const Mat<N, P> PHt = Pm * transpose(obs.H);
  const Mat<P, P> S = in.V + (obs.H * PHt) * in.dt;
  PositiveDefiniteSolver<P> solver;
  const bool factored = solver.factor(S);
  // A scalar S's update is taken whatever S is (where it fails, every caller's step fails, and the bank does not keep
  // that step's m and P): a return here was a convergence barrier per filter and member-step on a GPU. A larger S's
  // failed factor has no solves.
  if constexpr (P > 1)
    if (!factored) return false;
  const Vec<P> innovation = in.dy - obs.h * in.dt;
  weighted_innovation = solver.solve(innovation);
  const Mat<N, P> K = solver.right_solve(PHt);  // P H^T S^{-1}
  m += K * innovation;
  Pm = symmetrize(Pm - (K * transpose(PHt)) * in.dt);
  return factored;
}

/// Step 2: the Euler prediction.
template <int N>
KOKKOS_INLINE_FUNCTION void euler_predict(const DriftLinearization<N>& drift, double dt, Vec<N>& m, Mat<N, N>& Pm) {
  m += drift.a * dt;
  Mat<N, N> step = Mat<N, N>::identity() + drift.J * dt;
  Pm = symmetrize(step * Pm * transpose(step) + drift.W * dt);
}

}  // namespace kushner
