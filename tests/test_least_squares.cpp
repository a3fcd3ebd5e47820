// Seed 004 (4.9)-(4.17): batch least squares, the recursive gain form and the information form are one estimate;
// on random well-conditioned problems and on the attitude model of §4 they agree to rounding. Bad input is an
// InputError with one line.
#include "core/eigen_helpers.hpp"
#include "core/errors.hpp"
#include "engine/least_squares.hpp"
#include "models/attitude_oscillation_model.hpp"
#include "tests/input_error_expectation.hpp"

#include <gtest/gtest.h>

#include <functional>
#include <random>
#include <string>
#include <vector>

namespace kushner {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

using test::expect_input_error;

MatrixXd random_matrix(std::mt19937_64& rng, long rows, long cols) {
  std::normal_distribution<double> normal;
  MatrixXd m(rows, cols);
  for (long i = 0; i < rows; ++i)
    for (long j = 0; j < cols; ++j) m(i, j) = normal(rng);
  return m;
}

/// Blocks of 1 to 4 rows with correlated noise (R = L L^T + I / 2), observations of a random theta.
std::vector<ObservationBlock> random_blocks(std::mt19937_64& rng, long n, int count, VectorXd& theta) {
  theta = random_matrix(rng, n, 1);
  std::vector<ObservationBlock> blocks;
  for (int k = 0; k < count; ++k) {
    const long m = 1 + k % 4;
    const MatrixXd L = 0.5 * random_matrix(rng, m, m);
    ObservationBlock b{random_matrix(rng, m, n), {}, L * L.transpose() + 0.5 * MatrixXd::Identity(m, m)};
    b.z = b.H * theta + b.R.llt().matrixL() * random_matrix(rng, m, 1);
    blocks.push_back(b);
  }
  return blocks;
}

struct Agreement {
  double rls = 0.0, info = 0.0;  // largest relative difference to batch, theta and P
  int compared = 0;              // blocks compared: those after the gain form started (before, it is the same code)
};

Agreement agreement(const std::vector<ObservationBlock>& blocks, const InformationPrior& prior) {
  RecursiveLeastSquares rls(prior);
  LeastSquaresInformation info(prior);
  Agreement worst;
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    rls.add(blocks[k]);
    info.add(blocks[k]);
    if (!rls.in_gain_form()) continue;
    ++worst.compared;
    const LeastSquaresEstimate b = batch_least_squares(blocks, prior, k + 1), r = rls.estimate(), i = info.estimate();
    worst.rls = std::max({worst.rls, max_relative_difference(r.theta, b.theta), max_relative_difference(r.P, b.P)});
    worst.info = std::max({worst.info, max_relative_difference(i.theta, b.theta), max_relative_difference(i.P, b.P)});
  }
  return worst;
}

TEST(LeastSquares, ThreeFormsAgreeOnRandomProblems) {
  std::mt19937_64 rng(20240615);
  for (int trial = 0; trial < 20; ++trial) {
    const long n = 2 + trial % 6;
    VectorXd theta;
    const std::vector<ObservationBlock> blocks = random_blocks(rng, n, 40, theta);
    const Agreement none = agreement(blocks, InformationPrior::none(n));
    EXPECT_GT(none.compared, 25) << "trial " << trial;
    EXPECT_LT(none.rls, 1e-10) << "trial " << trial << ", no prior";
    EXPECT_LT(none.info, 1e-10) << "trial " << trial << ", no prior";
    const MatrixXd S = random_matrix(rng, n, n);
    const InformationPrior prior =
        InformationPrior::from_moments(random_matrix(rng, n, 1), S * S.transpose() + MatrixXd::Identity(n, n));
    const Agreement with = agreement(blocks, prior);
    EXPECT_EQ(with.compared, 40) << "trial " << trial;
    EXPECT_LT(with.rls, 1e-10) << "trial " << trial << ", with a prior";
    EXPECT_LT(with.info, 1e-10) << "trial " << trial << ", with a prior";
  }
}

TEST(LeastSquares, RecoversThetaFromNoiseFreeObservations) {
  std::mt19937_64 rng(7);
  VectorXd theta;
  std::vector<ObservationBlock> blocks = random_blocks(rng, 5, 12, theta);
  for (auto& b : blocks) b.z = b.H * theta;
  EXPECT_LT(max_relative_difference(batch_least_squares(blocks, InformationPrior::none(5)).theta, theta), 1e-13);
}

TEST(LeastSquares, FirstDeterminedStepIsTheLeastSquaresEstimate) {  // (4.12): no prior, one block that suffices
  std::mt19937_64 rng(11);
  VectorXd theta;
  std::vector<ObservationBlock> blocks = random_blocks(rng, 3, 1, theta);
  blocks[0].H = random_matrix(rng, 5, 3);
  blocks[0].R = 0.3 * MatrixXd::Identity(5, 5);
  blocks[0].z = random_matrix(rng, 5, 1);
  const MatrixXd& H = blocks[0].H;
  const VectorXd expected = (H.transpose() * H).ldlt().solve(H.transpose() * blocks[0].z);
  RecursiveLeastSquares rls(InformationPrior::none(3));
  EXPECT_FALSE(rls.determined());
  rls.add(blocks[0]);
  ASSERT_TRUE(rls.determined());
  EXPECT_TRUE(rls.in_gain_form());
  EXPECT_LT(max_relative_difference(rls.estimate().theta, expected), 1e-12);
}

/// The attitude model's samples every dt over [0, T], stacked `per_block` to a block as in (3.1), (4.7)-(4.8),
/// observing the coefficient corrections x with the sensor's noise.
std::vector<ObservationBlock> attitude_blocks(const AttitudeOscillationModel& model, double T, double dt, int per_block,
                                              const VectorXd& x, std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  std::vector<ObservationBlock> blocks;
  const int samples = static_cast<int>(std::lround(T / dt));
  for (int first = 1; first + per_block - 1 <= samples; first += per_block) {
    ObservationBlock b{MatrixXd(3 * per_block, 15), VectorXd(3 * per_block),
                       model.sigma * model.sigma * MatrixXd::Identity(3 * per_block, 3 * per_block)};
    for (int j = 0; j < per_block; ++j) {
      const double t = (first + j) * dt;
      b.H.middleRows(3 * j, 3) = to_eigen(model.observation_matrix(t));
      for (int i = 0; i < 3; ++i) b.z(3 * j + i) = b.H.row(3 * j + i).dot(x) + model.sigma * normal(rng);
    }
    blocks.push_back(b);
  }
  return blocks;
}

TEST(LeastSquares, ThreeFormsAgreeOnTheAttitudeModel) {
  const AttitudeOscillationModel model;
  std::mt19937_64 rng(3);
  const VectorXd x = 0.02 * random_matrix(rng, 15, 1);
  const std::vector<ObservationBlock> blocks = attitude_blocks(model, 10800.0, 10.0, 6, x, rng);
  const Agreement none = agreement(blocks, InformationPrior::none(15));
  EXPECT_GT(none.compared, 100);  // of 180 blocks: the first third of an orbit leaves the information ill-conditioned
  EXPECT_LT(none.rls, 1e-10);
  EXPECT_LT(none.info, 1e-10);
  const Agreement with =
      agreement(blocks, InformationPrior::from_moments(VectorXd::Zero(15), 4e-4 * MatrixXd::Identity(15, 15)));
  EXPECT_LT(with.rls, 1e-10);
  EXPECT_LT(with.info, 1e-10);
}

TEST(LeastSquares, AttitudeAtTheOrbitalFrequencyLeavesRotationsAboutTheFieldUnseen) {
  AttitudeOscillationModel model;
  model.omega = model.orbit_rate;
  std::mt19937_64 rng(5);
  const std::vector<ObservationBlock> blocks = attitude_blocks(model, 10800.0, 10.0, 6, VectorXd::Zero(15), rng);
  LeastSquaresInformation info(InformationPrior::none(15));
  for (const auto& b : blocks) info.add(b);
  EXPECT_FALSE(info.determined());
  expect_input_error([&] { info.estimate(); }, "singular (rank 12 of 15)");
  expect_input_error([&] { batch_least_squares(blocks, InformationPrior::none(15)); }, "singular (rank 12 of 15)");
}

TEST(LeastSquares, RefusesBadInputWithOneLine) {
  const InformationPrior none = InformationPrior::none(2);
  ObservationBlock one{MatrixXd::Identity(1, 2), VectorXd::Ones(1), MatrixXd::Identity(1, 1)};
  expect_input_error([&] { LeastSquaresInformation(none).estimate(); }, "singular (rank 0 of 2)");
  expect_input_error([&] { batch_least_squares({one}, none); }, "singular (rank 1 of 2)");
  expect_input_error(
      [&] {
        RecursiveLeastSquares rls(none);
        rls.add(one);
        rls.estimate();
      },
      "singular (rank 1 of 2)");
  ObservationBlock wide = one;
  wide.H = MatrixXd::Identity(1, 3);
  expect_input_error([&] { LeastSquaresInformation(none).add(wide); }, "H: is 1x3, expected 1x2");
  ObservationBlock short_z = one;
  short_z.z = VectorXd::Ones(2);
  expect_input_error([&] { batch_least_squares({short_z}, none); }, "block 1: H: is 1x2, expected 2x2");
  ObservationBlock bad_r{MatrixXd::Identity(2, 2), VectorXd::Ones(2), MatrixXd::Identity(2, 2)};
  bad_r.R(1, 1) = -1.0;
  expect_input_error([&] { RecursiveLeastSquares(none).add(bad_r); }, "R: not positive definite (pivot 2)");
  bad_r.R(1, 1) = 1.0;
  bad_r.R(0, 1) = 0.5;
  expect_input_error([&] { batch_least_squares({bad_r}, none); }, "R: not symmetric");
  expect_input_error([&] { InformationPrior::from_moments(VectorXd::Zero(2), -MatrixXd::Identity(2, 2)); },
                     "prior P0: not positive definite (pivot 1)");
  expect_input_error(
      [&] {
        LeastSquaresInformation({MatrixXd::Identity(3, 3), VectorXd::Zero(2)});
      },
      "prior Y: is 3x3, expected 2x2");
}

TEST(AttitudeOscillationModel, JacobianMatchesCentralDifference) {
  const AttitudeOscillationModel model;
  Vec<15> d;
  for (int i = 0; i < 15; ++i) d[i] = 0.05 * std::sin(1.0 + i);  // away from 0, where A's second order shows
  for (const double t : {0.0, 700.0, 2345.0}) {
    const Mat<3, 15> J = model.observation_jacobian(t, d);
    for (int j = 0; j < 15; ++j) {
      const double h = 1e-6;
      Vec<15> up = d, down = d;
      up[j] += h;
      down[j] -= h;
      const Vec<3> diff = (model.observation(t, up) - model.observation(t, down)) * (0.5 / h);
      for (int i = 0; i < 3; ++i) EXPECT_NEAR(J(i, j), diff[i], 1e-9) << "t " << t << " (" << i << ", " << j << ")";
    }
  }
}

TEST(AttitudeOscillationModel, SmallAnglesRotateTheFieldByAlphaCross) {
  // A ~ I - [alpha x] with alpha = (phi, psi, theta) about (x, y, z): the linearization the paper's H(t) is.
  const AttitudeOscillationModel model;
  const double t = 1234.0;
  Vec<15> d = Vec<15>::zero();
  d[0] = 1e-7;   // psi's constant
  d[6] = -2e-7;  // theta's sin wt
  d[12] = 3e-7;  // phi's cos wt
  const Vec<3> a = model.angles(t, d), r = model.reference(t), alpha{{a[2], a[0], a[1]}};
  const Vec<3> cross{
      {alpha[1] * r[2] - alpha[2] * r[1], alpha[2] * r[0] - alpha[0] * r[2], alpha[0] * r[1] - alpha[1] * r[0]}};
  const Vec<3> reading = model.observation(t, d);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(reading[i], r[i] - cross[i], 1e-12) << i;
}

}  // namespace
}  // namespace kushner
