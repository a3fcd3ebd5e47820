// Seed 004 §2: the exact discretization of dx = A x dt + G dw (Van Loan) against closed forms and quadrature
// computed independently, and the discrete filter (2.18)-(2.19) against the Kalman-Bucy Riccati equation (2.4).
#include "core/errors.hpp"
#include "engine/sampled_data.hpp"
#include "tests/input_error_expectation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>

namespace kushner {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

/// exp(M) by its Taylor series (60 terms; |M| <= 2 here): independent of Eigen's Pade approximant.
MatrixXd taylor_exp(const MatrixXd& M) {
  MatrixXd sum = MatrixXd::Identity(M.rows(), M.cols()), term = sum;
  for (int k = 1; k < 60; ++k) {
    term = term * M / k;
    sum += term;
  }
  return sum;
}

double relative(const MatrixXd& a, const MatrixXd& b) {
  return (a - b).cwiseAbs().maxCoeff() / b.cwiseAbs().maxCoeff();
}

/// One RK4 step of dP/dt = f(P).
MatrixXd rk4(const std::function<MatrixXd(const MatrixXd&)>& f, const MatrixXd& P, double h) {
  const MatrixXd k1 = f(P), k2 = f(P + 0.5 * h * k1), k3 = f(P + 0.5 * h * k2), k4 = f(P + h * k3);
  return P + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
}

using test::expect_input_error;

TEST(SampledData, ScalarTransitionAndNoiseMatchClosedForms) {
  for (const double a : {-0.7, 0.3, -4.0}) {
    const double g = 0.8, dt = 0.25;
    const DiscreteTransition d = discretize(MatrixXd::Constant(1, 1, a), MatrixXd::Constant(1, 1, g), dt);
    EXPECT_NEAR(d.Phi(0, 0), std::exp(a * dt), 1e-14 * std::exp(a * dt)) << "a = " << a;
    const double q = g * g * std::expm1(2.0 * a * dt) / (2.0 * a);  // int_0^dt e^{2 a s} g^2 ds
    EXPECT_NEAR(d.Qd(0, 0), q, 1e-13 * q) << "a = " << a;
  }
}

TEST(SampledData, TwoStateNoiseMatchesSimpsonQuadrature) {
  MatrixXd A(2, 2), G(2, 2);
  A << 0.0, 1.0, -2.0, -0.5;
  G << 0.3, 0.0, 0.1, 0.8;
  const double dt = 0.7;
  const DiscreteTransition d = discretize(A, G, dt);
  EXPECT_LT(relative(d.Phi, taylor_exp(A * dt)), 1e-13);
  const int intervals = 2000;  // Simpson's error ~ (dt/intervals)^4: far below 1e-12
  const double h = dt / intervals;
  MatrixXd sum = MatrixXd::Zero(2, 2);
  for (int i = 0; i <= intervals; ++i) {
    const MatrixXd E = taylor_exp(A * (i * h));
    const double weight = (i == 0 || i == intervals) ? 1.0 : (i % 2 == 1 ? 4.0 : 2.0);
    sum += weight * E * G * G.transpose() * E.transpose();
  }
  const MatrixXd simpson = sum * h / 3.0;
  EXPECT_LT(relative(d.Qd, simpson), 1e-11) << d.Qd << "\nvs\n" << simpson;
}

TEST(SampledData, PredictionEqualsTheCovarianceOdeOverOneInterval) {
  MatrixXd A(3, 3), G(3, 2), P0(3, 3);
  A << -0.2, 1.0, 0.0, -1.0, -0.3, 0.5, 0.0, 0.2, -1.5;
  G << 0.5, 0.0, 0.0, 0.3, 0.2, 0.1;
  P0 << 1.0, 0.2, 0.0, 0.2, 0.5, 0.1, 0.0, 0.1, 0.3;
  const double dt = 1.3;
  const GaussianEstimate predicted = predict({VectorXd::Zero(3), P0}, discretize(A, G, dt));
  const MatrixXd GGt = G * G.transpose();
  MatrixXd P = P0;
  const int steps = 4000;
  for (int i = 0; i < steps; ++i)
    P = rk4(
        [&](const MatrixXd& p) {
          MatrixXd r = A * p + p * A.transpose() + GGt;
          return r;
        },
        P, dt / steps);
  EXPECT_LT(relative(predicted.P, P), 1e-11);
}

TEST(SampledData, NoiseMatchesTheLyapunovClosedFormAtShortAndLongIntervals) {
  // For a stable A, Qd = Pinf - Phi Pinf Phi^T with A Pinf + Pinf A^T + G G^T = 0 (solved here by Kronecker
  // products): at dt = 40 the block exponential alone would cancel catastrophically (it holds e^{80}).
  MatrixXd A(2, 2), G(2, 1);
  A << -1.0, 0.5, 0.0, -2.0;
  G << 0.4, 1.0;
  const MatrixXd I = MatrixXd::Identity(2, 2);
  MatrixXd K(4, 4);  // vec(A P + P A^T) = (I (x) A + A (x) I) vec(P), column-major vec
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) K.block(2 * i, 2 * j, 2, 2) = I(i, j) * A + A(i, j) * I;
  const MatrixXd GGt = G * G.transpose();
  const VectorXd vec_pinf = K.lu().solve(-Eigen::Map<const VectorXd>(GGt.data(), 4));
  const MatrixXd Pinf = Eigen::Map<const MatrixXd>(vec_pinf.data(), 2, 2);
  for (const double dt : {0.05, 1.0, 40.0}) {
    const DiscreteTransition d = discretize(A, G, dt);
    EXPECT_LT(relative(d.Qd, Pinf - d.Phi * Pinf * d.Phi.transpose()), 1e-12) << "dt = " << dt;
  }
}

TEST(SampledData, GainAndInformationFormsGiveTheSameUpdate) {
  MatrixXd P(3, 3), H(2, 3), R(2, 2);
  P << 2.0, 0.3, -0.1, 0.3, 1.0, 0.2, -0.1, 0.2, 0.7;
  H << 1.0, 0.0, 0.5, 0.2, -1.0, 0.3;
  R << 0.4, 0.1, 0.1, 0.3;
  VectorXd x(3), z(2);
  x << 0.1, -0.2, 0.3;
  z << 0.7, -0.4;
  const GaussianEstimate gain = update_gain_form({x, P}, H, z, R);
  const GaussianEstimate info = update_information_form({x, P}, H, z, R);
  EXPECT_LT(relative(gain.x, info.x), 1e-13);
  EXPECT_LT(relative(gain.P, info.P), 1e-13);
}

/// P(T) of the discrete filter (2.11), (2.14), (2.17)-(2.18) at interval dt, against the Riccati equation (2.4)
/// integrated by RK4 at a fine step: the relative difference.
double discrete_riccati_gap(double dt) {
  MatrixXd A(2, 2), G(2, 1), H(1, 2), R(1, 1), P0(2, 2);
  A << 0.0, 1.0, -1.0, -0.4;
  G << 0.0, 0.6;
  H << 1.0, 0.0;
  R << 0.09;
  P0 << 1.0, 0.0, 0.0, 1.0;
  const double T = 2.0;
  MatrixXd P = P0;
  const int fine = 20000;
  const MatrixXd GGt = G * G.transpose(), Rinv = R.inverse();
  for (int i = 0; i < fine; ++i)
    P = rk4(
        [&](const MatrixXd& p) {
          MatrixXd r = A * p + p * A.transpose() + GGt - p * H.transpose() * Rinv * H * p;
          return r;
        },
        P, T / fine);
  const DiscreteTransition transition = discretize(A, G, dt);
  const MatrixXd Rk = averaged_observation_noise(R, dt);
  GaussianEstimate e{VectorXd::Zero(2), P0};
  const int steps = static_cast<int>(std::lround(T / dt));
  for (int k = 0; k < steps; ++k) e = update_gain_form(predict(e, transition), H, VectorXd::Zero(1), Rk);
  return relative(e.P, P);
}

TEST(SampledData, DiscreteFilterConvergesToTheKalmanBucyRiccatiAtFirstOrder) {
  const double coarse = discrete_riccati_gap(0.02), fine = discrete_riccati_gap(0.01);
  EXPECT_LT(fine, 0.02) << "dt = 0.01";
  EXPECT_NEAR(coarse / fine, 2.0, 0.3) << coarse << " at dt = 0.02, " << fine << " at dt = 0.01";
}

TEST(SampledData, RefusesBadInputWithOneLine) {
  const MatrixXd A = MatrixXd::Identity(2, 2), G = MatrixXd::Identity(2, 2);
  expect_input_error([&] { discretize(A, G, 0.0); }, "discretize: dt must be positive (got 0)");
  expect_input_error([&] { discretize(MatrixXd::Zero(2, 3), G, 0.1); }, "discretize: A: is 2x3, expected 2x2");
  expect_input_error([&] { discretize(A, MatrixXd::Zero(3, 1), 0.1); }, "discretize: G: is 3x1, expected 2xany");
  MatrixXd R(2, 2);
  R << 1.0, 2.0, 2.0, 1.0;
  expect_input_error([&] { averaged_observation_noise(R, 0.1); }, "R: not positive definite (pivot 2)");
  expect_input_error(
      [&] {
        update_gain_form({VectorXd::Zero(2), A}, MatrixXd::Zero(2, 3), VectorXd::Zero(2), A);
      },
      "update: H: is 2x3, expected 2x2");
}

}  // namespace
}  // namespace kushner
