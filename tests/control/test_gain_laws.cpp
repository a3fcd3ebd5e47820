// The Riccati gain laws (engine/control/): the affine LQR against the scalar closed form, and ASRE's limits.
#include "engine/control/gain_laws.hpp"
#include "models/model_list.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace kushner {
namespace {

// Scalar dx = (a x + b u) dt, cost int (q x^2 + r u^2) dt: S solves -S' = 2 a S + q - b^2 S^2 / r, which over a
// long horizon reaches the algebraic Riccati solution (a + sqrt(a^2 + q b^2 / r)) r / b^2.
TEST(GainLaws, ScalarLqrReachesTheAlgebraicRiccatiSolution) {
  LinearModel<1> model;
  model.A(0, 0) = 0.3;
  model.B(0, 0) = 2.0;
  ModelCost<LinearModel<1>> cost;
  cost.Q(0, 0) = 1.5;
  cost.R(0, 0) = 0.5;
  const auto solution = lqr_solution(model, cost, 20000, 1e-3, Vec<1>::zero());
  const double a = 0.3, b = 2.0, q = 1.5, r = 0.5;
  const double stationary = (a + std::sqrt(a * a + q * b * b / r)) * r / (b * b);
  EXPECT_NEAR(solution.S[0](0, 0), stationary, 1e-10);
  EXPECT_NEAR(solution.gains.K[0](0, 0), b * stationary / r, 1e-9);
  EXPECT_TRUE(solution.finite);
}

// With a target, the affine part: for a = 0, b = 1, Q = 0, the control that moves x to x* with cost
// F (x(T) - x*)^2 + r int u^2 is constant, u = F (x* - x0) / (r + F T), and V(0, x0) = F r (x* - x0)^2 / (r + F T).
TEST(GainLaws, TargetedLqrMatchesTheMinimumEnergyTransfer) {
  LinearModel<1> model;
  model.A(0, 0) = 0.0;
  model.B(0, 0) = 1.0;
  model.b(0, 0) = 0.0;
  ModelCost<LinearModel<1>> cost;
  cost.F(0, 0) = 2.0;
  cost.R(0, 0) = 0.5;
  cost.target[0] = 1.0;
  const double T = 1.0, x0 = 0.25, F = 2.0, r = 0.5;
  const auto solution = lqr_solution(model, cost, 1000, 1e-3, Vec<1>::zero());
  const double u0 = -(solution.gains.K[0](0, 0) * x0 + solution.gains.k[0][0]);
  EXPECT_NEAR(u0, F * (1.0 - x0) / (r + F * T), 1e-10);
  const double V = solution.expected_value(Vec<1>{{x0}}, Mat<1, 1>::zero());
  EXPECT_NEAR(V, F * r * (1.0 - x0) * (1.0 - x0) / (r + F * T), 1e-10);
}

TEST(GainLaws, AsreEqualsLqrOnALinearModel) {
  LinearModel<2> model;
  ModelCost<LinearModel<2>> cost;
  cost.Q = Mat<2, 2>::identity();
  cost.F = Mat<2, 2>::diagonal(3.0);
  const auto lqr = lqr_solution(model, cost, 500, 2e-3, Vec<2>::zero());
  const auto asre = asre_solution(model, cost, 500, 2e-3);
  EXPECT_TRUE(asre.converged);
  EXPECT_LE(asre.iterations, 2);
  for (long k = 0; k <= 500; ++k)
    for (int j = 0; j < 2; ++j) EXPECT_NEAR(asre.riccati.gains.K[k](0, j), lqr.gains.K[k](0, j), 1e-12);
}

TEST(GainLaws, AsreConvergesOnTheCar) {
  CarModel car;
  car.prior_mean = Vec<2>{{0.1, 0.1}};
  ModelCost<CarModel> cost;
  cost.F(0, 0) = 1.0;
  cost.target[0] = 1.0;
  const auto asre = asre_solution(car, cost, 300, 1e-3);
  EXPECT_TRUE(asre.converged) << "iterations " << asre.iterations << ", last change " << asre.last_change;
  EXPECT_GT(asre.nominal.back()[0], car.prior_mean[0]);  // the car turns towards phi* = 1
}

}  // namespace
}  // namespace kushner
