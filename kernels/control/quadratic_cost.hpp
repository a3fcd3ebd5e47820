#pragma once
// The cost every controller is scored by (issue 14, SPEC section 5): for a target state x* (0 unless set),
//   J = (x(T) - x*)^T F (x(T) - x*) + integral_0^T [(x - x*)^T Q (x - x*) + u^T R u] dt,
// with F, Q positive semidefinite and R positive definite (checked where they are read). The seeds' forms are
// special cases: Basin's (phi(T) - phi*)^2 + 10 int u^2 dt (002 (14)) is F = diag(1, 0), x* = (phi*, 0), Q = 0,
// R = 10; terminal-only costs have Q = 0. No factor 1/2: where a seed writes one, its J is half of ours.
// Clark's estimation-error term (seed 003 (2.3)) adds (x - x_hat)^T D (x - x_hat) to the running cost, x_hat the
// estimate the law reads; D = 0 unless set. For a discrete-time model the integral is the sum over steps (dt = 1).
#include "core/small_matrix.hpp"

namespace kushner {

template <int N, int M>
struct QuadraticCost {
  Mat<N, N> F = Mat<N, N>::zero();  // terminal weight
  Mat<N, N> Q = Mat<N, N>::zero();  // running state weight
  Mat<M, M> R = Mat<M, M>::identity();
  Vec<N> target = Vec<N>::zero();
  Mat<N, N> D = Mat<N, N>::zero();  // estimation-error weight

  KOKKOS_INLINE_FUNCTION double running(const Vec<N>& x, const Vec<M>& u) const {
    const Vec<N> e = x - target;
    return dot(e, Q * e) + dot(u, R * u);
  }
  KOKKOS_INLINE_FUNCTION double estimation_penalty(const Vec<N>& x, const Vec<N>& estimate) const {
    const Vec<N> e = x - estimate;
    return dot(e, D * e);
  }
  /// Whether D is not zero (the reference solvers' cost has no estimation term).
  bool weighs_estimation() const {
    for (int i = 0; i < N; ++i)
      for (int j = 0; j < N; ++j)
        if (D(i, j) != 0.0) return true;
    return false;
  }
  KOKKOS_INLINE_FUNCTION double control_energy(const Vec<M>& u) const { return dot(u, u); }
  KOKKOS_INLINE_FUNCTION double terminal(const Vec<N>& x) const {
    const Vec<N> e = x - target;
    return dot(e, F * e);
  }
};

}  // namespace kushner
