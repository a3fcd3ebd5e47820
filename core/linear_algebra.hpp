#pragma once
// Small dense factorizations for one member's covariance: Cholesky, solves, inverse. Device-callable; they
// report failure (not positive definite) through their return value, never by throwing.
#include "core/math.hpp"
#include "core/small_matrix.hpp"

namespace kushner {

/// How a symmetric matrix factored by semidefinite_cholesky turned out.
enum class Definiteness { positive_definite, singular, indefinite };

/// Lower-triangular L with L L^T = A for a positive semidefinite A: a pivot within `tolerance` times the
/// largest diagonal entry of zero counts as zero (its column of L is zero), so singular covariances (a fixed
/// initial state, no process noise) still factor. A pivot below minus that, or a non-finite one, means A is
/// indefinite; L is then partial.
template <int N>
KOKKOS_INLINE_FUNCTION Definiteness semidefinite_cholesky(const Mat<N, N>& A, Mat<N, N>& L, double tolerance) {
  if constexpr (N == 1) {
    // The loops below for N = 1, written out without branches: GCC does not unroll a one-trip loop with several
    // exits before it vectorizes (a loop over members in SIMD lanes, kernels/filters/filter_slot.hpp, then fails),
    // and on a GPU each exit was a branch with its convergence barrier. With tolerance >= 0 the loops' zero,
    // tolerance * max(a, 0), is 0 for a <= 0 (so a < -zero is a < 0) and tolerance * a for a > 0: the same
    // decisions for every a.
    const double a = A(0, 0);
    const bool indefinite = !math::is_finite(a) || a < 0.0;
    const bool singular = !indefinite && a <= tolerance * a;
    const bool definite = !indefinite && !singular;
    L(0, 0) = definite ? math::sqrt(a) : 0.0;
    return definite ? Definiteness::positive_definite : indefinite ? Definiteness::indefinite : Definiteness::singular;
  }
  double scale = 0.0;
  for (int i = 0; i < N; ++i) scale = A(i, i) > scale ? A(i, i) : scale;
  const double zero = tolerance * scale;
  L = Mat<N, N>::zero();
  Definiteness result = Definiteness::positive_definite;
  for (int j = 0; j < N; ++j) {
    double d = A(j, j);
    for (int k = 0; k < j; ++k) d -= L(j, k) * L(j, k);
    if (!math::is_finite(d) || d < -zero) return Definiteness::indefinite;
    if (d <= zero) {
      result = Definiteness::singular;
      continue;
    }
    const double ljj = math::sqrt(d);
    L(j, j) = ljj;
    for (int i = j + 1; i < N; ++i) {
      double s = A(i, j);
      for (int k = 0; k < j; ++k) s -= L(i, k) * L(j, k);
      L(i, j) = s / ljj;
    }
  }
  return result;
}

/// Lower-triangular L with L L^T = A. Returns false (and leaves L partial) when a pivot is not positive
/// or not finite: A is then not (numerically) positive definite. The semidefinite factorization with a zero
/// tolerance, so both give the same L bit for bit where A is positive definite.
template <int N>
KOKKOS_INLINE_FUNCTION bool cholesky(const Mat<N, N>& A, Mat<N, N>& L) {
  return semidefinite_cholesky(A, L, 0.0) == Definiteness::positive_definite;
}

/// Solves L L^T x = b for x, given the Cholesky factor L.
template <int N>
KOKKOS_INLINE_FUNCTION Vec<N> cholesky_solve(const Mat<N, N>& L, const Vec<N>& b) {
  Vec<N> y;
  for (int i = 0; i < N; ++i) {
    double s = b[i];
    for (int k = 0; k < i; ++k) s -= L(i, k) * y[k];
    y[i] = s / L(i, i);
  }
  Vec<N> x;
  for (int i = N - 1; i >= 0; --i) {
    double s = y[i];
    for (int k = i + 1; k < N; ++k) s -= L(k, i) * x[k];
    x[i] = s / L(i, i);
  }
  return x;
}

/// S^{-1} b and C S^{-1} for a symmetric positive definite P x P matrix S (an innovation covariance): a scalar S by
/// one reciprocal, a larger one by its Cholesky factor. A scalar S's Cholesky factor took a square root and two
/// divisions per solve: the reciprocal (with a scalar NEES as e^2 / P) made the sine bank 10-12% faster on a CPU.
template <int P>
struct PositiveDefiniteSolver {
  Mat<P, P> L;           // P > 1: S's Cholesky factor
  double inverse = 0.0;  // P = 1: 1 / S

  /// Whether S is positive definite (cholesky's test; a scalar: finite and > 0); the solves need it.
  KOKKOS_INLINE_FUNCTION bool factor(const Mat<P, P>& S) {
    if constexpr (P == 1) {
      // The reciprocal whatever s is (not used where factor fails): a branch around it was a convergence barrier per
      // filter and member-step on a GPU.
      const double s = S(0, 0);
      inverse = 1.0 / s;
      return math::is_finite(s) && s > 0.0;
    } else {
      return cholesky(S, L);
    }
  }

  KOKKOS_INLINE_FUNCTION Vec<P> solve(const Vec<P>& b) const {
    if constexpr (P == 1)
      return Vec<P>{{b[0] * inverse}};
    else
      return cholesky_solve(L, b);
  }

  /// C S^{-1} (S symmetric: row i is S^{-1} times C's row i), e.g. a Kalman gain P H^T S^{-1}.
  template <int N>
  KOKKOS_INLINE_FUNCTION Mat<N, P> right_solve(const Mat<N, P>& C) const {
    Mat<N, P> K;
    for (int i = 0; i < N; ++i) {
      Vec<P> row;
      for (int l = 0; l < P; ++l) row[l] = C(i, l);
      const Vec<P> k = solve(row);
      for (int l = 0; l < P; ++l) K(i, l) = k[l];
    }
    return K;
  }
};

/// A^{-1} from the Cholesky factor of A (symmetric by construction).
template <int N>
KOKKOS_INLINE_FUNCTION Mat<N, N> cholesky_inverse(const Mat<N, N>& L) {
  Mat<N, N> inv;
  for (int j = 0; j < N; ++j) {
    Vec<N> e = Vec<N>::zero();
    e[j] = 1.0;
    const Vec<N> col = cholesky_solve(L, e);
    for (int i = 0; i < N; ++i) inv(i, j) = col[i];
  }
  return symmetrize(inv);
}

/// x^T A^{-1} x from the Cholesky factor of A: |L^{-1} x|^2.
template <int N>
KOKKOS_INLINE_FUNCTION double cholesky_quadratic_form(const Mat<N, N>& L, const Vec<N>& x) {
  double s = 0.0;
  Vec<N> y;
  for (int i = 0; i < N; ++i) {
    double t = x[i];
    for (int k = 0; k < i; ++k) t -= L(i, k) * y[k];
    y[i] = t / L(i, i);
    s += y[i] * y[i];
  }
  return s;
}

/// x^T A^{-1} x for a positive definite A whose Cholesky factor is L: x^2 / A for N = 1 (one division; L's square root
/// is then left unused, and the compiler drops it), else cholesky_quadratic_form. Every filter's NEES at every step.
template <int N>
KOKKOS_INLINE_FUNCTION double inverse_quadratic_form(const Mat<N, N>& A, const Mat<N, N>& L, const Vec<N>& x) {
  if constexpr (N == 1)
    return x[0] * x[0] / A(0, 0);
  else
    return cholesky_quadratic_form(L, x);
}

/// log N(r; 0, R R^T), the Gaussian log density of a noise R d with d standard normal (R R^T positive definite;
/// -inf when it is not).
template <int N>
KOKKOS_INLINE_FUNCTION double gaussian_log_density(const Mat<N, N>& R, const Vec<N>& r) {
  Mat<N, N> L;
  if (!cholesky(R * transpose(R), L)) return -math::infinity();
  double log_det = 0.0;
  for (int i = 0; i < N; ++i) log_det += 2.0 * math::log(L(i, i));
  return -0.5 * (cholesky_quadratic_form(L, r) + log_det + N * math::log(2.0 * math::pi));
}

template <int N>
KOKKOS_INLINE_FUNCTION bool all_finite(const Vec<N>& x) {
  for (int i = 0; i < N; ++i)
    if (!math::is_finite(x[i])) return false;
  return true;
}
template <int R, int C>
KOKKOS_INLINE_FUNCTION bool all_finite(const Mat<R, C>& m) {
  for (int i = 0; i < R; ++i)
    for (int j = 0; j < C; ++j)
      if (!math::is_finite(m(i, j))) return false;
  return true;
}

}  // namespace kushner
