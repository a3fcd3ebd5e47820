#pragma once
// A constant parameter vector theta observed in blocks z_k = H_k theta + v_k, v_k ~ N(0, R_k) independent,
// with prior information (Y0, y0) = (P0^-1, P0^-1 theta0), Y0 = 0 for none: seed 004 (4.8)-(4.17). The three
// estimators below are the same estimate (4.17) computed three ways, which is what (4.9)-(4.17) show:
//   batch_least_squares      the weighted least-squares problem as a whole, by QR of the whitened rows;
//   RecursiveLeastSquares    the filter's gain form (4.9), one block at a time (the Kalman update with Phi = I);
//   LeastSquaresInformation  the information form (4.11), (4.16): Y += H^T R^-1 H, y += H^T R^-1 z.
// Host code (Eigen). Bad input (shapes, a R_k that is not positive definite, an estimate asked for while the
// information is singular) is an InputError with a one-line message.
#include "core/eigen_dense.hpp"
#include "engine/sampled_data.hpp"

#include <cstddef>
#include <vector>

namespace kushner {

/// One block of observations: a sample, or several stacked as in (3.1) (rows: the block's samples' rows).
struct ObservationBlock {
  Eigen::MatrixXd H;  // m x n
  Eigen::VectorXd z;  // m
  Eigen::MatrixXd R;  // m x m, positive definite
};

/// Prior information on theta: Y = P0^-1 (positive semidefinite), y = P0^-1 theta0.
struct InformationPrior {
  Eigen::MatrixXd Y;
  Eigen::VectorXd y;
  /// No prior: Y = 0, y = 0 (the paper's x0 = 0, P0^-1 = 0 before (4.12)).
  static InformationPrior none(long n);
  /// From a mean and a positive definite covariance (InputError otherwise).
  static InformationPrior from_moments(const Eigen::VectorXd& theta0, const Eigen::MatrixXd& P0);
};

/// theta and its error covariance P = Y^-1.
struct LeastSquaresEstimate {
  Eigen::VectorXd theta;
  Eigen::MatrixXd P;
};

/// The weighted least-squares estimate (4.17) from the prior and blocks[0 .. count) (count = blocks.size() when
/// larger): each block whitened by its R's Cholesky factor, the prior by a square root of Y0, and the stacked
/// rows solved by column-pivoting Householder QR, so the normal equations' matrix H^T R^-1 H (whose condition
/// number is the square of the rows') is never formed. InputError when the rows do not determine theta.
LeastSquaresEstimate batch_least_squares(const std::vector<ObservationBlock>& blocks, const InformationPrior& prior,
                                         std::size_t count = static_cast<std::size_t>(-1));

/// The information form (4.11), (4.13), (4.16): sums of H^T R^-1 H and H^T R^-1 z; the estimate solves
/// Y theta = y by Cholesky.
class LeastSquaresInformation {
 public:
  explicit LeastSquaresInformation(const InformationPrior& prior);
  void add(const ObservationBlock& block);
  /// Whether Y is numerically nonsingular (its reciprocal condition number above 1e-12).
  bool determined() const;
  /// Y's numerical rank: its eigenvalues above 1e-12 times the largest.
  long rank() const;
  /// InputError naming Y's numerical rank when it is singular.
  LeastSquaresEstimate estimate() const;
  const Eigen::MatrixXd& information() const { return Y_; }
  const Eigen::VectorXd& information_vector() const { return y_; }

 private:
  Eigen::MatrixXd Y_;
  Eigen::VectorXd y_;
};

/// The gain form (4.9): theta += K (z - H theta), K = P H^T (H P H^T + R)^-1, P -= K H P. It needs a finite P,
/// and its start's error stays in every later estimate: from a well-conditioned prior it starts at once;
/// otherwise (no prior, Y0 = 0) it accumulates the first blocks in information form, which is the least-squares
/// estimate (4.12) as soon as they determine theta, until their information is well conditioned (reciprocal
/// condition number above 1e-4), and continues in gain form from there.
class RecursiveLeastSquares {
 public:
  explicit RecursiveLeastSquares(const InformationPrior& prior);
  void add(const ObservationBlock& block);
  bool determined() const { return started_ || start_.determined(); }
  /// Whether it runs in gain form already.
  bool in_gain_form() const { return started_; }
  /// InputError while the blocks so far do not determine theta.
  LeastSquaresEstimate estimate() const;

 private:
  LeastSquaresInformation start_;
  bool started_ = false;
  GaussianEstimate estimate_;
};

/// max_i |a_i - b_i| / max_i |b_i| (0 when both are zero): the agreement figure of the three estimators.
double max_relative_difference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b);

}  // namespace kushner
