#pragma once
// Eigen on the host: conversions from and to the small fixed-size matrices, the covariance check every input
// goes through, and the square root that samples a Gaussian with a possibly singular covariance.
#include "core/eigen_dense.hpp"
#include "core/errors.hpp"
#include "core/small_matrix.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace kushner {

template <int R, int C>
Eigen::Matrix<double, R, C> to_eigen(const Mat<R, C>& m) {
  Eigen::Matrix<double, R, C> e;
  for (int i = 0; i < R; ++i)
    for (int j = 0; j < C; ++j) e(i, j) = m(i, j);
  return e;
}

template <int R, int C>
Mat<R, C> from_eigen(const Eigen::Matrix<double, R, C>& e) {
  Mat<R, C> m;
  for (int i = 0; i < R; ++i)
    for (int j = 0; j < C; ++j) m(i, j) = e(i, j);
  return m;
}

/// Throws InputError unless `m` is symmetric and positive definite (or semidefinite when `allow_singular`).
/// The message names the parameter and the first failing Cholesky pivot (1-based), as users read it.
template <int N>
void check_covariance(const std::string& name, const Mat<N, N>& m, bool allow_singular) {
  const Eigen::Matrix<double, N, N> e = to_eigen(m);
  KUSHNER_INPUT_REQUIRE(e.allFinite(), name << ": not finite");
  const double scale = std::max(1.0, e.cwiseAbs().maxCoeff());
  KUSHNER_INPUT_REQUIRE((e - e.transpose()).cwiseAbs().maxCoeff() <= 1e-12 * scale, name << ": not symmetric");
  if (allow_singular) {
    const double smallest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, N, N>>(e).eigenvalues().minCoeff();
    KUSHNER_INPUT_REQUIRE(smallest >= -1e-12 * scale,
                          name << ": not positive semidefinite (smallest eigenvalue " << smallest << ")");
    return;
  }
  Eigen::Matrix<double, N, N> work = e;
  for (int j = 0; j < N; ++j) {  // plain Cholesky, to name the pivot that fails
    double d = work(j, j);
    for (int k = 0; k < j; ++k) d -= work(j, k) * work(j, k);
    KUSHNER_INPUT_REQUIRE(d > 0.0, name << ": not positive definite (pivot " << j + 1 << ")");
    work(j, j) = std::sqrt(d);
    for (int i = j + 1; i < N; ++i) {
      double s = work(i, j);
      for (int k = 0; k < j; ++k) s -= work(i, k) * work(j, k);
      work(i, j) = s / work(j, j);
    }
  }
}

/// A symmetric square root S (S S^T = m) of a positive semidefinite matrix, by eigendecomposition, so that
/// a singular covariance (e.g. a fixed initial state) can still be sampled.
template <int N>
Mat<N, N> covariance_square_root(const Mat<N, N>& m) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, N, N>> solver(to_eigen(m));
  const Eigen::Matrix<double, N, 1> roots = solver.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  const Eigen::Matrix<double, N, N> s = solver.eigenvectors() * roots.asDiagonal() * solver.eigenvectors().transpose();
  return from_eigen<N, N>(s);
}

}  // namespace kushner
