#pragma once
// Structured descriptions of a model's drift that particular filters need, returned by the models that have
// them (plain data, device-callable evaluation so tests can check them against drift()):
//   LinearForm           f = a0 + A x, G, h = c0 + C x                       (Kalman-Bucy)
//   PowerPolynomial      f = a0 + sum_k a_k x^k, x^k componentwise           (Basin POLY3/POLY4, seed 002 (9), (12))
//   QuadraticPolynomial  f_k = a0_k + sum_i a1_ki x_i + sum c x_i x_j       (Basin bilinear, seed 002 ACC03 (13))
//   SdcDrift             f = A(x) x + b                                      (Cimen-Banks ASRE, seed 001 (4))
//   GaussianDrift        E_N[f], E_N[grad f] under x ~ N(m, P)               (Sunahara QLF, seed 000 (5.3)-(5.4))
// and of a nonlinear observation:
//   SdcObservation       h = C(x) x + c0                                     (Cimen-Banks ASRE, seed 001 (5))
//   GaussianObservation  E_N[h], E_N[grad h] under x ~ N(m, P)               (Sunahara QLF, seed 000 (5.9)-(5.10))
#include "core/small_matrix.hpp"

namespace kushner {

template <int N, int P>
struct LinearForm {
  Vec<N> a0;
  Mat<N, N> A;
  Vec<P> c0;
  Mat<P, N> C;
};

/// f(x) = a[0] + sum_{k=1..Degree} coefficient[k] x^k with x^k the componentwise power; coefficient[0] unused.
template <int N, int Degree>
struct PowerPolynomial {
  static constexpr int degree = Degree;
  Vec<N> a0;
  Mat<N, N> coefficient[Degree + 1];

  KOKKOS_INLINE_FUNCTION static PowerPolynomial zero() {
    PowerPolynomial p;
    p.a0 = Vec<N>::zero();
    for (int k = 0; k <= Degree; ++k) p.coefficient[k] = Mat<N, N>::zero();
    return p;
  }
  KOKKOS_INLINE_FUNCTION Vec<N> operator()(const Vec<N>& x) const {
    Vec<N> f = a0, power = x;
    for (int k = 1; k <= Degree; ++k) {
      f += coefficient[k] * power;
      for (int i = 0; i < N; ++i) power[i] *= x[i];
    }
    return f;
  }
};

/// The terms of p up to degree D (all of p when its degree is at most D). Only for a p whose higher
/// coefficients are known to vanish (a run-time polynomial whose model_facts() say so).
template <int D, int N, int Degree>
KOKKOS_INLINE_FUNCTION PowerPolynomial<N, (D < Degree ? D : Degree)> truncated(const PowerPolynomial<N, Degree>& p) {
  constexpr int degree = D < Degree ? D : Degree;
  PowerPolynomial<N, degree> r;
  r.a0 = p.a0;
  for (int k = 0; k <= degree; ++k) r.coefficient[k] = p.coefficient[k];
  return r;
}

/// One bilinear term c x_i x_j of component k (i == j allowed).
struct QuadraticTerm {
  int k, i, j;
  double c;
};

/// f_k(x) = a0_k + sum_i a1_ki x_i + sum over the terms of component k of c x_i x_j. Terms stand for the
/// symmetric tensor a2_kij = a2_kji = c / 2 (i != j) or a2_kii = c, so that only the nonzero entries are stored.
template <int N, int MaxTerms>
struct QuadraticPolynomial {
  Vec<N> a0;
  Mat<N, N> a1;
  int num_terms = 0;
  QuadraticTerm term[MaxTerms > 0 ? MaxTerms : 1];

  KOKKOS_INLINE_FUNCTION void add(int k, int i, int j, double c) { term[num_terms++] = QuadraticTerm{k, i, j, c}; }
  KOKKOS_INLINE_FUNCTION Vec<N> operator()(const Vec<N>& x) const {
    Vec<N> f = a0 + a1 * x;
    for (int t = 0; t < num_terms; ++t) f[term[t].k] += term[t].c * x[term[t].i] * x[term[t].j];
    return f;
  }
};

/// f(x) = A x + b: a state-dependent-coefficient factorization with the known input b (needed when f(0) != 0).
template <int N>
struct SdcDrift {
  Mat<N, N> A;
  Vec<N> b;
};

/// f(x) and its Jacobian at one point, from a model that computes them together (drift_and_jacobian).
template <int N>
struct DriftAndJacobian {
  Vec<N> drift;
  Mat<N, N> jacobian;
};

/// f(x), its Jacobian and the Hessian of each component f_i at one point, from a model that computes them together
/// (drift_derivatives: the second-order filters' drift).
template <int N>
struct DriftDerivatives {
  Vec<N> drift;
  Mat<N, N> jacobian;
  Mat<N, N> hessian[N];
};

/// Gaussian expectations of the drift under x ~ N(m, P): mean = E[f(x)], jacobian = E[grad f(x)], which by
/// Stein's lemma equals Sunahara's E[(f - a)(x - m)^T] P^{-1} (seed 000 (5.12b)) and needs no P^{-1}.
template <int N>
struct GaussianDrift {
  Vec<N> mean;
  Mat<N, N> jacobian;
};

/// h(x) = C(x) x + c0: a state-dependent-coefficient factorization of the observation (seed 001 (5)).
template <int N, int P>
struct SdcObservation {
  Mat<P, N> C;
  Vec<P> c0;
};

/// Gaussian expectations of the observation under x ~ N(m, P): mean = E[h(x)] (seed 000 (5.9)), jacobian =
/// E[grad h(x)] (= H2 of (5.10) by Stein's lemma).
template <int N, int P>
struct GaussianObservation {
  Vec<P> mean;
  Mat<P, N> jacobian;
};

}  // namespace kushner
