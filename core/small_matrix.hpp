#pragma once
// Fixed-size vectors and matrices for one ensemble member: models and filters work on these (registers on a
// GPU), kernels gather them from the SoA bank and scatter them back. Sizes are compile-time; Vec<0> (an
// uncontrolled model's control) holds a dummy element so that it stays a valid type.
#include <Kokkos_Core.hpp>

namespace kushner {

template <int N>
struct Vec {
  double v[N > 0 ? N : 1];

  KOKKOS_INLINE_FUNCTION static Vec zero() {
    Vec r;
    for (int i = 0; i < (N > 0 ? N : 1); ++i) r.v[i] = 0.0;
    return r;
  }
  KOKKOS_INLINE_FUNCTION static Vec constant(double c) {
    Vec r;
    for (int i = 0; i < (N > 0 ? N : 1); ++i) r.v[i] = c;
    return r;
  }
  KOKKOS_INLINE_FUNCTION double& operator[](int i) { return v[i]; }
  KOKKOS_INLINE_FUNCTION const double& operator[](int i) const { return v[i]; }
};

/// R x C matrix, row-major.
template <int R, int C>
struct Mat {
  double a[R][C];

  KOKKOS_INLINE_FUNCTION static Mat zero() {
    Mat m;
    for (int i = 0; i < R; ++i)
      for (int j = 0; j < C; ++j) m.a[i][j] = 0.0;
    return m;
  }
  KOKKOS_INLINE_FUNCTION static Mat identity() {
    static_assert(R == C, "identity: square matrices only");
    Mat m = zero();
    for (int i = 0; i < R; ++i) m.a[i][i] = 1.0;
    return m;
  }
  KOKKOS_INLINE_FUNCTION static Mat diagonal(double d) { return identity() * d; }
  KOKKOS_INLINE_FUNCTION double& operator()(int i, int j) { return a[i][j]; }
  KOKKOS_INLINE_FUNCTION const double& operator()(int i, int j) const { return a[i][j]; }

  KOKKOS_INLINE_FUNCTION friend Mat operator*(const Mat& m, double s) {
    Mat r;
    for (int i = 0; i < R; ++i)
      for (int j = 0; j < C; ++j) r.a[i][j] = m.a[i][j] * s;
    return r;
  }
};

// ---- vector arithmetic ---------------------------------------------------------------------------------------
template <int N>
KOKKOS_INLINE_FUNCTION Vec<N> operator+(const Vec<N>& x, const Vec<N>& y) {
  Vec<N> r;
  for (int i = 0; i < N; ++i) r[i] = x[i] + y[i];
  return r;
}
template <int N>
KOKKOS_INLINE_FUNCTION Vec<N> operator-(const Vec<N>& x, const Vec<N>& y) {
  Vec<N> r;
  for (int i = 0; i < N; ++i) r[i] = x[i] - y[i];
  return r;
}
template <int N>
KOKKOS_INLINE_FUNCTION Vec<N> operator-(const Vec<N>& x) {
  Vec<N> r;
  for (int i = 0; i < N; ++i) r[i] = -x[i];
  return r;
}
template <int N>
KOKKOS_INLINE_FUNCTION Vec<N> operator*(const Vec<N>& x, double s) {
  Vec<N> r;
  for (int i = 0; i < N; ++i) r[i] = x[i] * s;
  return r;
}
template <int N>
KOKKOS_INLINE_FUNCTION Vec<N> operator*(double s, const Vec<N>& x) {
  return x * s;
}
template <int N>
KOKKOS_INLINE_FUNCTION Vec<N>& operator+=(Vec<N>& x, const Vec<N>& y) {
  for (int i = 0; i < N; ++i) x[i] += y[i];
  return x;
}
template <int N>
KOKKOS_INLINE_FUNCTION double dot(const Vec<N>& x, const Vec<N>& y) {
  double s = 0.0;
  for (int i = 0; i < N; ++i) s += x[i] * y[i];
  return s;
}

// ---- matrix arithmetic ---------------------------------------------------------------------------------------
template <int R, int C>
KOKKOS_INLINE_FUNCTION Mat<R, C> operator+(const Mat<R, C>& x, const Mat<R, C>& y) {
  Mat<R, C> r;
  for (int i = 0; i < R; ++i)
    for (int j = 0; j < C; ++j) r(i, j) = x(i, j) + y(i, j);
  return r;
}
template <int R, int C>
KOKKOS_INLINE_FUNCTION Mat<R, C> operator-(const Mat<R, C>& x, const Mat<R, C>& y) {
  Mat<R, C> r;
  for (int i = 0; i < R; ++i)
    for (int j = 0; j < C; ++j) r(i, j) = x(i, j) - y(i, j);
  return r;
}
template <int R, int C>
KOKKOS_INLINE_FUNCTION Mat<R, C> operator*(double s, const Mat<R, C>& m) {
  return m * s;
}
template <int R, int C>
KOKKOS_INLINE_FUNCTION Mat<R, C>& operator+=(Mat<R, C>& x, const Mat<R, C>& y) {
  for (int i = 0; i < R; ++i)
    for (int j = 0; j < C; ++j) x(i, j) += y(i, j);
  return x;
}
template <int R, int K, int C>
KOKKOS_INLINE_FUNCTION Mat<R, C> operator*(const Mat<R, K>& x, const Mat<K, C>& y) {
  Mat<R, C> r;
  for (int i = 0; i < R; ++i)
    for (int j = 0; j < C; ++j) {
      double s = 0.0;
      for (int k = 0; k < K; ++k) s += x(i, k) * y(k, j);
      r(i, j) = s;
    }
  return r;
}
template <int R, int C>
KOKKOS_INLINE_FUNCTION Vec<R> operator*(const Mat<R, C>& m, const Vec<C>& x) {
  Vec<R> r;
  for (int i = 0; i < R; ++i) {
    double s = 0.0;
    for (int j = 0; j < C; ++j) s += m(i, j) * x[j];
    r[i] = s;
  }
  return r;
}
template <int R, int C>
KOKKOS_INLINE_FUNCTION Mat<C, R> transpose(const Mat<R, C>& m) {
  Mat<C, R> r;
  if constexpr (R == 1 && C == 1) {  // no one-trip loop: see semidefinite_cholesky (core/linear_algebra.hpp)
    r(0, 0) = m(0, 0);
  } else {
    for (int i = 0; i < R; ++i)
      for (int j = 0; j < C; ++j) r(j, i) = m(i, j);
  }
  return r;
}
/// x y^T
template <int R, int C>
KOKKOS_INLINE_FUNCTION Mat<R, C> outer(const Vec<R>& x, const Vec<C>& y) {
  Mat<R, C> r;
  for (int i = 0; i < R; ++i)
    for (int j = 0; j < C; ++j) r(i, j) = x[i] * y[j];
  return r;
}
/// (M + M^T) / 2: covariance updates symmetrize so that round-off never makes P asymmetric.
template <int N>
KOKKOS_INLINE_FUNCTION Mat<N, N> symmetrize(const Mat<N, N>& m) {
  Mat<N, N> r;
  for (int i = 0; i < N; ++i)
    for (int j = 0; j < N; ++j) r(i, j) = 0.5 * (m(i, j) + m(j, i));
  return r;
}
template <int N>
KOKKOS_INLINE_FUNCTION double trace(const Mat<N, N>& m) {
  double s = 0.0;
  for (int i = 0; i < N; ++i) s += m(i, i);
  return s;
}

}  // namespace kushner
