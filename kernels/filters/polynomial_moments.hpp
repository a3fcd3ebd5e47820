#pragma once
// Exact Gaussian expectations E_N[f] and E_N[grad f], x ~ N(m, P), of polynomial drifts. These are the mean
// drift and the covariance-equation matrix of Basin's polynomial filters (seed 002 filter paper (9)-(10) and
// (12)-(13); ACC03 (13)-(14)) and, by Stein's lemma, Sunahara's quasi-linear a and B (seed 000 (5.3)-(5.4)).
#include "models/drift_forms.hpp"

namespace kushner {

/// Componentwise powers, p = diag(P) (seed 002 (5)-(7)):
///   E[x^2] = p + m^2,  E[x^3] = 3 p m + m^3,  E[x^4] = 3 p^2 + 6 p m^2 + m^4;
/// and E[d(x_j^k)/dx_j] = k E[x_j^(k-1)], so E_N[grad f] = sum_k k a_k diag(E[x^(k-1)]) (J3, J4 of seed 002 (10),
/// (13)).
template <int N, int Degree>
KOKKOS_INLINE_FUNCTION GaussianDrift<N> gaussian_drift(const PowerPolynomial<N, Degree>& poly, const Vec<N>& m,
                                                       const Mat<N, N>& P) {
  static_assert(Degree <= 4, "gaussian_drift: Gaussian moments are written out up to degree 4");
  // moment[k][j] = E[x_j^k], k = 0 .. 4
  double moment[5][N];
  for (int j = 0; j < N; ++j) {
    const double mj = m[j], pj = P(j, j), m2 = mj * mj;
    moment[0][j] = 1.0;
    moment[1][j] = mj;
    moment[2][j] = pj + m2;
    moment[3][j] = 3.0 * pj * mj + m2 * mj;
    moment[4][j] = 3.0 * pj * pj + 6.0 * pj * m2 + m2 * m2;
  }
  GaussianDrift<N> g{poly.a0, Mat<N, N>::zero()};
  for (int k = 1; k <= Degree; ++k)
    for (int i = 0; i < N; ++i)
      for (int j = 0; j < N; ++j) {
        g.mean[i] += poly.coefficient[k](i, j) * moment[k][j];
        g.jacobian(i, j) += k * poly.coefficient[k](i, j) * moment[k - 1][j];
      }
  return g;
}

/// Bilinear terms: E[x_i x_j] = m_i m_j + P_ij; the Jacobian is affine, so E_N[grad f] = grad f(m)
/// (seed 002 ACC03 (13)-(14): a1 + 2 a2 m with a2 symmetric).
template <int N, int MaxTerms>
KOKKOS_INLINE_FUNCTION GaussianDrift<N> gaussian_drift(const QuadraticPolynomial<N, MaxTerms>& poly, const Vec<N>& m,
                                                       const Mat<N, N>& P) {
  GaussianDrift<N> g{poly.a0 + poly.a1 * m, poly.a1};
  for (int t = 0; t < poly.num_terms; ++t) {
    const QuadraticTerm& q = poly.term[t];
    g.mean[q.k] += q.c * (m[q.i] * m[q.j] + P(q.i, q.j));
    g.jacobian(q.k, q.i) += q.c * m[q.j];
    g.jacobian(q.k, q.j) += q.c * m[q.i];
  }
  return g;
}

}  // namespace kushner
