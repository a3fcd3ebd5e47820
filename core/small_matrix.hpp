#pragma once
// Fixed-size vectors and matrices for one ensemble member: models and filters work on these (registers on a
// GPU), kernels gather them from the SoA bank and scatter them back. Sizes are compile-time; Vec<0> (an
// uncontrolled model's control) holds a dummy element so that it stays a valid type. The scalar is double unless
// said: the particle filter's fp32 steps a particle in float where its model's dynamics take float (convert<T>).
#include <Kokkos_Core.hpp>

namespace kushner {

namespace detail {
/// T in a context that does not deduce it: `v * 2` scales a Vec<N, double> by 2.0.
template <class T>
struct NonDeduced {
  using type = T;
};
}  // namespace detail
template <class T>
using ScalarOf = typename detail::NonDeduced<T>::type;

template <int N, class T = double>
struct Vec {
  T v[N > 0 ? N : 1];

  KOKKOS_INLINE_FUNCTION static Vec zero() {
    Vec r;
    for (int i = 0; i < (N > 0 ? N : 1); ++i) r.v[i] = T(0);
    return r;
  }
  KOKKOS_INLINE_FUNCTION static Vec constant(T c) {
    Vec r;
    for (int i = 0; i < (N > 0 ? N : 1); ++i) r.v[i] = c;
    return r;
  }
  KOKKOS_INLINE_FUNCTION T& operator[](int i) { return v[i]; }
  KOKKOS_INLINE_FUNCTION const T& operator[](int i) const { return v[i]; }
};

/// R x C matrix, row-major.
template <int R, int C, class T = double>
struct Mat {
  T a[R][C];

  KOKKOS_INLINE_FUNCTION static Mat zero() {
    Mat m;
    for (int i = 0; i < R; ++i)
      for (int j = 0; j < C; ++j) m.a[i][j] = T(0);
    return m;
  }
  KOKKOS_INLINE_FUNCTION static Mat identity() {
    static_assert(R == C, "identity: square matrices only");
    Mat m = zero();
    for (int i = 0; i < R; ++i) m.a[i][i] = T(1);
    return m;
  }
  KOKKOS_INLINE_FUNCTION static Mat diagonal(T d) { return identity() * d; }
  KOKKOS_INLINE_FUNCTION T& operator()(int i, int j) { return a[i][j]; }
  KOKKOS_INLINE_FUNCTION const T& operator()(int i, int j) const { return a[i][j]; }

  KOKKOS_INLINE_FUNCTION friend Mat operator*(const Mat& m, T s) {
    Mat r;
    for (int i = 0; i < R; ++i)
      for (int j = 0; j < C; ++j) r.a[i][j] = m.a[i][j] * s;
    return r;
  }
};

// ---- vector arithmetic ---------------------------------------------------------------------------------------
template <int N, class T>
KOKKOS_INLINE_FUNCTION Vec<N, T> operator+(const Vec<N, T>& x, const Vec<N, T>& y) {
  Vec<N, T> r;
  for (int i = 0; i < N; ++i) r[i] = x[i] + y[i];
  return r;
}
template <int N, class T>
KOKKOS_INLINE_FUNCTION Vec<N, T> operator-(const Vec<N, T>& x, const Vec<N, T>& y) {
  Vec<N, T> r;
  for (int i = 0; i < N; ++i) r[i] = x[i] - y[i];
  return r;
}
template <int N, class T>
KOKKOS_INLINE_FUNCTION Vec<N, T> operator-(const Vec<N, T>& x) {
  Vec<N, T> r;
  for (int i = 0; i < N; ++i) r[i] = -x[i];
  return r;
}
template <int N, class T>
KOKKOS_INLINE_FUNCTION Vec<N, T> operator*(const Vec<N, T>& x, ScalarOf<T> s) {
  Vec<N, T> r;
  for (int i = 0; i < N; ++i) r[i] = x[i] * s;
  return r;
}
template <int N, class T>
KOKKOS_INLINE_FUNCTION Vec<N, T> operator*(ScalarOf<T> s, const Vec<N, T>& x) {
  return x * s;
}
template <int N, class T>
KOKKOS_INLINE_FUNCTION Vec<N, T>& operator+=(Vec<N, T>& x, const Vec<N, T>& y) {
  for (int i = 0; i < N; ++i) x[i] += y[i];
  return x;
}
template <int N, class T>
KOKKOS_INLINE_FUNCTION T dot(const Vec<N, T>& x, const Vec<N, T>& y) {
  T s = T(0);
  for (int i = 0; i < N; ++i) s += x[i] * y[i];
  return s;
}

// ---- matrix arithmetic ---------------------------------------------------------------------------------------
template <int R, int C, class T>
KOKKOS_INLINE_FUNCTION Mat<R, C, T> operator+(const Mat<R, C, T>& x, const Mat<R, C, T>& y) {
  Mat<R, C, T> r;
  for (int i = 0; i < R; ++i)
    for (int j = 0; j < C; ++j) r(i, j) = x(i, j) + y(i, j);
  return r;
}
template <int R, int C, class T>
KOKKOS_INLINE_FUNCTION Mat<R, C, T> operator-(const Mat<R, C, T>& x, const Mat<R, C, T>& y) {
  Mat<R, C, T> r;
  for (int i = 0; i < R; ++i)
    for (int j = 0; j < C; ++j) r(i, j) = x(i, j) - y(i, j);
  return r;
}
template <int R, int C, class T>
KOKKOS_INLINE_FUNCTION Mat<R, C, T> operator*(ScalarOf<T> s, const Mat<R, C, T>& m) {
  return m * s;
}
template <int R, int C, class T>
KOKKOS_INLINE_FUNCTION Mat<R, C, T>& operator+=(Mat<R, C, T>& x, const Mat<R, C, T>& y) {
  for (int i = 0; i < R; ++i)
    for (int j = 0; j < C; ++j) x(i, j) += y(i, j);
  return x;
}
template <int R, int K, int C, class T>
KOKKOS_INLINE_FUNCTION Mat<R, C, T> operator*(const Mat<R, K, T>& x, const Mat<K, C, T>& y) {
  Mat<R, C, T> r;
  for (int i = 0; i < R; ++i)
    for (int j = 0; j < C; ++j) {
      T s = T(0);
      for (int k = 0; k < K; ++k) s += x(i, k) * y(k, j);
      r(i, j) = s;
    }
  return r;
}
template <int R, int C, class T>
KOKKOS_INLINE_FUNCTION Vec<R, T> operator*(const Mat<R, C, T>& m, const Vec<C, T>& x) {
  Vec<R, T> r;
  for (int i = 0; i < R; ++i) {
    T s = T(0);
    for (int j = 0; j < C; ++j) s += m(i, j) * x[j];
    r[i] = s;
  }
  return r;
}
template <int R, int C, class T>
KOKKOS_INLINE_FUNCTION Mat<C, R, T> transpose(const Mat<R, C, T>& m) {
  Mat<C, R, T> r;
  if constexpr (R == 1 && C == 1) {  // no one-trip loop: see semidefinite_cholesky (core/linear_algebra.hpp)
    r(0, 0) = m(0, 0);
  } else {
    for (int i = 0; i < R; ++i)
      for (int j = 0; j < C; ++j) r(j, i) = m(i, j);
  }
  return r;
}
/// x y^T
template <int R, int C, class T>
KOKKOS_INLINE_FUNCTION Mat<R, C, T> outer(const Vec<R, T>& x, const Vec<C, T>& y) {
  Mat<R, C, T> r;
  for (int i = 0; i < R; ++i)
    for (int j = 0; j < C; ++j) r(i, j) = x[i] * y[j];
  return r;
}
/// (M + M^T) / 2 with M's diagonal as it is: (a + a) / 2 is a for every a below half the largest number, and the
/// add and multiply it took per diagonal entry were ~48 of the sine bank's ~1400 instructions per member-step on a GPU
/// (a 1-D filter's step symmetrizes three times). Covariance updates symmetrize so that round-off never makes P
/// asymmetric. Loops without a test of i against j: one (a select per entry) kept GCC from vectorizing the host's
/// member lanes (filter_lanes).
template <int N, class T>
KOKKOS_INLINE_FUNCTION Mat<N, N, T> symmetrize(const Mat<N, N, T>& m) {
  Mat<N, N, T> r;
  for (int i = 0; i < N; ++i) {
    r(i, i) = m(i, i);
    for (int j = i + 1; j < N; ++j) r(i, j) = r(j, i) = T(0.5) * (m(i, j) + m(j, i));
  }
  return r;
}
template <int N, class T>
KOKKOS_INLINE_FUNCTION T trace(const Mat<N, N, T>& m) {
  T s = T(0);
  for (int i = 0; i < N; ++i) s += m(i, i);
  return s;
}

/// x in the scalar U (float where the particle filter's fp32 steps a particle; the identity for U = T).
template <class U, int N, class T>
KOKKOS_INLINE_FUNCTION Vec<N, U> convert(const Vec<N, T>& x) {
  Vec<N, U> r;
  for (int i = 0; i < (N > 0 ? N : 1); ++i) r[i] = static_cast<U>(x[i]);
  return r;
}
template <class U, int R, int C, class T>
KOKKOS_INLINE_FUNCTION Mat<R, C, U> convert(const Mat<R, C, T>& m) {
  Mat<R, C, U> r;
  for (int i = 0; i < R; ++i)
    for (int j = 0; j < C; ++j) r(i, j) = static_cast<U>(m(i, j));
  return r;
}

}  // namespace kushner
