#pragma once
// Input checks for the host's dynamic-size Eigen matrices (sampled data, least squares): one-line InputErrors
// that name the matrix, as a user reads them. The fixed-size models' checks are core/eigen_helpers.hpp's.
#include "core/eigen_dense.hpp"

#include <string>

namespace kushner {

/// InputError unless `m` is rows x cols (a negative size: any) and finite.
void check_dense_shape(const std::string& name, const Eigen::MatrixXd& m, long rows, long cols);

/// InputError unless `m` is square, finite, symmetric and positive definite; the message names the first
/// Cholesky pivot (1-based) that fails.
void check_dense_positive_definite(const std::string& name, const Eigen::MatrixXd& m);

}  // namespace kushner
