#include "engine/least_squares.hpp"

#include "core/errors.hpp"
#include "engine/dense_checks.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace kushner {

namespace {

/// Below this reciprocal condition number the information does not determine theta: 1e-12 leaves rounding
/// (1e-16 relative) amplified at most 1e12-fold, the estimate still good to about four digits.
constexpr double singular_rcond = 1e-12;
/// The gain form starts once the information's reciprocal condition number is above this: its start, P = Y^-1,
/// carries an error of about eps / rcond that no later block removes (no forgetting), so it must be small.
constexpr double gain_form_rcond = 1e-4;

bool well_conditioned(const Eigen::MatrixXd& Y) {
  if (Y.isZero(0.0)) return false;
  const Eigen::LLT<Eigen::MatrixXd> llt(Y);
  return llt.info() == Eigen::Success && llt.rcond() > gain_form_rcond;
}

void check_block(const ObservationBlock& b, long n, const std::string& where) {
  const long m = b.z.size();
  KUSHNER_INPUT_REQUIRE(m > 0, where << ": z is empty");
  check_dense_shape(where + ": H", b.H, m, n);
  check_dense_shape(where + ": z", b.z, m, 1);
  check_dense_positive_definite(where + ": R", b.R);
  check_dense_shape(where + ": R", b.R, m, m);
}

void check_prior(const InformationPrior& prior) {
  const long n = prior.y.size();
  KUSHNER_INPUT_REQUIRE(n > 0, "least squares: the prior has no parameters (y is empty)");
  check_dense_shape("least squares: prior Y", prior.Y, n, n);
  check_dense_shape("least squares: prior y", prior.y, n, 1);
  const double scale = std::max(1.0, prior.Y.cwiseAbs().maxCoeff());
  KUSHNER_INPUT_REQUIRE((prior.Y - prior.Y.transpose()).cwiseAbs().maxCoeff() <= 1e-12 * scale,
                        "least squares: prior Y not symmetric");
  if (prior.Y.isZero(0.0)) return;
  const double smallest = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(prior.Y).eigenvalues().minCoeff();
  KUSHNER_INPUT_REQUIRE(smallest >= -1e-12 * scale,
                        "least squares: prior Y not positive semidefinite (smallest eigenvalue " << smallest << ")");
}

/// Numerical rank of a symmetric positive semidefinite Y: eigenvalues above singular_rcond times the largest.
long numerical_rank(const Eigen::MatrixXd& Y) {
  const Eigen::VectorXd lambda = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(Y).eigenvalues();
  const double largest = lambda.cwiseAbs().maxCoeff();
  return (lambda.array() > singular_rcond * largest).count();
}

[[noreturn]] void throw_undetermined(long rank, long n) {
  throw InputError("least squares: the information matrix is singular (rank " + std::to_string(rank) + " of " +
                   std::to_string(n) + "): the observations so far do not determine theta");
}

Eigen::MatrixXd inverse_lower(const Eigen::MatrixXd& L) {
  return L.triangularView<Eigen::Lower>().solve(Eigen::MatrixXd::Identity(L.rows(), L.cols()));
}

}  // namespace

InformationPrior InformationPrior::none(long n) {
  KUSHNER_INPUT_REQUIRE(n > 0, "least squares: need at least one parameter (got " << n << ")");
  return {Eigen::MatrixXd::Zero(n, n), Eigen::VectorXd::Zero(n)};
}

InformationPrior InformationPrior::from_moments(const Eigen::VectorXd& theta0, const Eigen::MatrixXd& P0) {
  check_dense_shape("least squares: prior theta0", theta0, -1, 1);
  check_dense_positive_definite("least squares: prior P0", P0);
  check_dense_shape("least squares: prior P0", P0, theta0.size(), theta0.size());
  const Eigen::LLT<Eigen::MatrixXd> llt(P0);
  const Eigen::MatrixXd Y = llt.solve(Eigen::MatrixXd::Identity(P0.rows(), P0.cols()));
  return {0.5 * (Y + Y.transpose()), llt.solve(theta0)};
}

LeastSquaresEstimate batch_least_squares(const std::vector<ObservationBlock>& blocks, const InformationPrior& prior,
                                         std::size_t count) {
  check_prior(prior);
  const long n = prior.y.size();
  count = std::min(count, blocks.size());
  // The prior as rows S theta = b with S^T S = Y0, S^T b = y0 (S = Lambda^1/2 V^T over Y0's nonzero eigenvalues).
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> prior_eigen(prior.Y);
  const double largest = prior_eigen.eigenvalues().cwiseAbs().maxCoeff();
  std::vector<long> kept;
  for (long i = 0; i < n; ++i)
    if (prior_eigen.eigenvalues()(i) > singular_rcond * largest && largest > 0.0) kept.push_back(i);
  long rows = static_cast<long>(kept.size());
  for (std::size_t k = 0; k < count; ++k) {
    check_block(blocks[k], n, "least squares: block " + std::to_string(k + 1));
    rows += blocks[k].z.size();
  }
  Eigen::MatrixXd A(rows, n);
  Eigen::VectorXd b(rows);
  long row = 0;
  for (long i : kept) {
    const double root = std::sqrt(prior_eigen.eigenvalues()(i));
    const Eigen::VectorXd v = prior_eigen.eigenvectors().col(i);
    A.row(row) = root * v.transpose();
    b(row) = v.dot(prior.y) / root;
    ++row;
  }
  for (std::size_t k = 0; k < count; ++k) {  // whitened: L^-1 z = L^-1 H theta + white noise, R = L L^T
    const ObservationBlock& block = blocks[k];
    const Eigen::LLT<Eigen::MatrixXd> llt(block.R);
    const long m = block.z.size();
    A.middleRows(row, m) = llt.matrixL().solve(block.H);
    b.segment(row, m) = llt.matrixL().solve(block.z);
    row += m;
  }
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
  // The pivots are about the singular values of A, whose squares are the information's eigenvalues.
  qr.setThreshold(std::sqrt(singular_rcond));
  if (qr.rank() < n) throw_undetermined(qr.rank(), n);
  // P = (A^T A)^-1 = Pi (R^T R)^-1 Pi^T with A Pi = Q R.
  const Eigen::MatrixXd Rqr = qr.matrixR().topLeftCorner(n, n).triangularView<Eigen::Upper>();
  const Eigen::MatrixXd Rinv = Rqr.triangularView<Eigen::Upper>().solve(Eigen::MatrixXd::Identity(n, n));
  const Eigen::MatrixXd Pperm = Rinv * Rinv.transpose();
  const auto& perm = qr.colsPermutation();
  const Eigen::MatrixXd P = perm * Pperm * perm.transpose();
  return {qr.solve(b), 0.5 * (P + P.transpose())};
}

LeastSquaresInformation::LeastSquaresInformation(const InformationPrior& prior) : Y_(prior.Y), y_(prior.y) {
  check_prior(prior);
}

void LeastSquaresInformation::add(const ObservationBlock& block) {
  check_block(block, y_.size(), "information filter: block");
  const Eigen::LLT<Eigen::MatrixXd> llt(block.R);
  const Eigen::MatrixXd Rinv_H = llt.solve(block.H);
  Y_ += block.H.transpose() * Rinv_H;  // (4.11): P_N^-1 = P_{N-1}^-1 + H^T R^-1 H
  Y_ = 0.5 * (Y_ + Y_.transpose());
  y_ += Rinv_H.transpose() * block.z;  // (4.16): P_N^-1 x_N = P_{N-1}^-1 x_{N-1} + H^T R^-1 z
}

bool LeastSquaresInformation::determined() const {
  if (Y_.isZero(0.0)) return false;
  const Eigen::LLT<Eigen::MatrixXd> llt(Y_);
  return llt.info() == Eigen::Success && llt.rcond() > singular_rcond;
}

long LeastSquaresInformation::rank() const { return numerical_rank(Y_); }

LeastSquaresEstimate LeastSquaresInformation::estimate() const {
  if (!determined()) throw_undetermined(numerical_rank(Y_), y_.size());
  const Eigen::LLT<Eigen::MatrixXd> llt(Y_);
  const Eigen::MatrixXd Linv = inverse_lower(llt.matrixL());
  return {llt.solve(y_), Linv.transpose() * Linv};
}

RecursiveLeastSquares::RecursiveLeastSquares(const InformationPrior& prior) : start_(prior) {
  if (well_conditioned(start_.information())) {
    const LeastSquaresEstimate e = start_.estimate();
    estimate_ = {e.theta, e.P};
    started_ = true;
  }
}

void RecursiveLeastSquares::add(const ObservationBlock& block) {
  if (started_) {
    estimate_ = update_gain_form(estimate_, block.H, block.z, block.R);  // (4.9): (2.18) with Phi = I, Q = 0
    return;
  }
  start_.add(block);
  if (well_conditioned(start_.information())) {  // (4.12): the first step is the least-squares estimate itself
    const LeastSquaresEstimate e = start_.estimate();
    estimate_ = {e.theta, e.P};
    started_ = true;
  }
}

LeastSquaresEstimate RecursiveLeastSquares::estimate() const {
  if (!started_) return start_.estimate();  // (4.12) until the gain form starts; throws while undetermined
  return {estimate_.x, estimate_.P};
}

double max_relative_difference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  KUSHNER_REQUIRE(a.rows() == b.rows() && a.cols() == b.cols(),
                  "max_relative_difference: " << a.rows() << "x" << a.cols() << " vs " << b.rows() << "x" << b.cols());
  const double scale = b.cwiseAbs().maxCoeff();
  const double diff = (a - b).cwiseAbs().maxCoeff();
  return scale > 0.0 ? diff / scale : diff;
}

}  // namespace kushner
