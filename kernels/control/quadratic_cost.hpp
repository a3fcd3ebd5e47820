#pragma once
// The cost every controller is scored by (issue 14, SPEC section 5): for a target state x* (0 unless set),
//   J = (x(T) - x*)^T F (x(T) - x*) + integral_0^T [(x - x*)^T Q (x - x*) + u^T R u] dt,
// with F, Q positive semidefinite and R positive definite (checked where they are read). The seeds' forms are
// special cases: Basin's (phi(T) - phi*)^2 + 10 int u^2 dt (002 (14)) is F = diag(1, 0), x* = (phi*, 0), Q = 0,
// R = 10; terminal-only costs have Q = 0. No factor 1/2: where a seed writes one, its J is half of ours.
#include "core/small_matrix.hpp"

namespace kushner {

template <int N, int M>
struct QuadraticCost {
  Mat<N, N> F = Mat<N, N>::zero();  // terminal weight
  Mat<N, N> Q = Mat<N, N>::zero();  // running state weight
  Mat<M, M> R = Mat<M, M>::identity();
  Vec<N> target = Vec<N>::zero();

  KOKKOS_INLINE_FUNCTION double running(const Vec<N>& x, const Vec<M>& u) const {
    const Vec<N> e = x - target;
    return dot(e, Q * e) + dot(u, R * u);
  }
  KOKKOS_INLINE_FUNCTION double control_energy(const Vec<M>& u) const { return dot(u, u); }
  KOKKOS_INLINE_FUNCTION double terminal(const Vec<N>& x) const {
    const Vec<N> e = x - target;
    return dot(e, F * e);
  }
};

}  // namespace kushner
