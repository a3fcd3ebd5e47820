// The discrete-time Riccati controller in closed loop (issue 15 part 4), against exact expected costs:
//   the recursion's steady gain = the scalar algebraic Riccati equation's; LQR@state's Monte Carlo J = E V_0(x0)
//   from the recursion, on Gaussian noise and on Clark's bounded noise (the value function holds for any zero-mean
//   noise); LQR@KF's J = E V_0 + sum_k tr(K_k' G_k K_k P_k|k) (certainty equivalence with the Kalman filter's error);
//   and Clark's claim: with the estimation-error weight D = 5 the better estimator (MOM) costs less than KF by many
//   standard errors, with D = 0 the difference is a small part of J.
#include "engine/control/control_run.hpp"
#include "models/clark_linear_model.hpp"
#include "models/linear_discrete_model.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <cstdio>
#include <vector>

namespace kushner {
namespace {

struct MeanSe {
  double mean = 0.0, se = 0.0;
};

MeanSe mean_se(const std::vector<double>& v) {
  double s = 0.0, s2 = 0.0;
  long n = 0;
  for (double x : v)
    if (std::isfinite(x)) s += x, s2 += x * x, ++n;
  const double mean = s / n;
  return {mean, std::sqrt((s2 / n - mean * mean) / (n - 1))};
}

TEST(DiscreteRiccati, SteadyGainSolvesTheAlgebraicRiccatiEquation) {
  const ClarkLinearModel model;  // a = 0.1, b = 1
  QuadraticCost<1, 1> cost;
  cost.Q = cost.F = Mat<1, 1>::identity();
  const auto solution = discrete_lqr_solution(model, cost, 200);
  // S = Q + a^2 S - (a S)^2 / (R + S) with Q = R = 1: S^2 = 1 + a^2 S.
  const double a = model.a, S = 0.5 * (a * a + std::sqrt(a * a * a * a + 4.0));
  EXPECT_NEAR(solution.S[0](0, 0), S, 1e-14);
  EXPECT_NEAR(solution.gains.K[0](0, 0), a * S / (1.0 + S), 1e-14);
  EXPECT_EQ(solution.gains.K[200](0, 0), 0.0);  // no control after the last stage
}

TEST(DiscreteRiccati, LqrAtTheStateCostsTheValueFunction) {
  const Kokkos::DefaultHostExecutionSpace space;
  const TimeGrid grid = make_time_grid(30.0, 1.0, 2);
  {
    LinearDiscreteModel model;  // Gaussian noise, x[0] ~ N(1, 0.1 I)
    QuadraticCost<2, 1> cost;
    cost.Q = Mat<2, 2>::identity();
    cost.F = Mat<2, 2>::diagonal(2.0);
    cost.target = Vec<2>{{0.5, 0.0}};
    const auto report = run_control(space, model, 40000, 7, grid, {{"LQR@state", "LQR", "state"}}, cost);
    const MeanSe J = mean_se(report.controllers[0].cost);
    const double V = discrete_lqr_solution(model, cost, grid.steps).expected_value(model.x0_mean, model.x0_cov);
    std::printf("linear-discrete LQR@state: J = %.5f +- %.5f, E V_0 = %.5f\n", J.mean, J.se, V);
    EXPECT_LT(std::fabs(J.mean - V), 3.0 * J.se);
  }
  {
    const ClarkLinearModel model;  // bounded non-Gaussian noise, x[0] = 0
    QuadraticCost<1, 1> cost;
    cost.Q = cost.F = Mat<1, 1>::identity();
    const auto report = run_control(space, model, 40000, 7, grid, {{"LQR@state", "LQR", "state"}}, cost);
    const MeanSe J = mean_se(report.controllers[0].cost);
    const double V = discrete_lqr_solution(model, cost, grid.steps).expected_value(model.x0_mean, model.x0_cov);
    std::printf("clark-linear LQR@state: J = %.5f +- %.5f, E V_0 = %.5f\n", J.mean, J.se, V);
    EXPECT_LT(std::fabs(J.mean - V), 3.0 * J.se);
  }
}

TEST(DiscreteControl, LqgWithTheKalmanFilterCostsItsExactExpectation) {
  const Kokkos::DefaultHostExecutionSpace space;
  const LinearDiscreteModel model;
  QuadraticCost<2, 1> cost;
  cost.Q = Mat<2, 2>::identity();
  cost.F = Mat<2, 2>::identity();
  const TimeGrid grid = make_time_grid(25.0, 1.0, 2);
  const auto report = run_control(space, model, 40000, 9, grid, {{"LQR@KF", "LQR", "KF"}}, cost);
  const MeanSe J = mean_se(report.controllers[0].cost);
  // E V_0(x0) + sum_k tr(K_k' G_k K_k P_k|k), G_k = R + B' S_{k+1} B, P_k|k the Kalman filter's (P_0|0 = P0).
  const auto lqr = discrete_lqr_solution(model, cost, grid.steps);
  using M2 = Eigen::Matrix2d;
  const M2 F = to_eigen(model.F), H = to_eigen(model.H), W = to_eigen(model.G * transpose(model.G)),
           V = to_eigen(model.R * transpose(model.R));
  const Eigen::Vector2d B = to_eigen(model.B);
  M2 P = to_eigen(model.prior_cov);
  double exact = lqr.expected_value(model.x0_mean, model.x0_cov);
  for (long k = 0; k < grid.steps; ++k) {
    const Eigen::RowVector2d K = to_eigen(lqr.gains.K[k]);
    const double G = cost.R(0, 0) + B.dot(to_eigen(lqr.S[k + 1]) * B);
    exact += G * (K * P * K.transpose())(0, 0);
    const M2 predicted = F * P * F.transpose() + W;
    const M2 gain = predicted * H.transpose() * (H * predicted * H.transpose() + V).inverse();
    P = (M2::Identity() - gain * H) * predicted;
  }
  std::printf("linear-discrete LQR@KF: J = %.5f +- %.5f, exact %.5f\n", J.mean, J.se, exact);
  EXPECT_LT(std::fabs(J.mean - exact), 3.0 * J.se);
}

TEST(DiscreteControl, ClarksEstimationWeightSeparatesTheEstimators) {
  const Kokkos::DefaultHostExecutionSpace space;
  const ClarkLinearModel model;
  const TimeGrid grid = make_time_grid(40.0, 1.0, 2);
  for (double D : {0.0, 5.0}) {
    QuadraticCost<1, 1> cost;
    cost.Q = cost.F = Mat<1, 1>::identity();
    cost.D(0, 0) = D;
    const auto report =
        run_control(space, model, 2000, 3, grid, {{"LQR@KF", "LQR", "KF"}, {"LQR@MOM", "LQR", "MOM"}}, cost);
    std::vector<double> difference(2000);
    for (int i = 0; i < 2000; ++i) difference[i] = report.controllers[0].cost[i] - report.controllers[1].cost[i];
    const MeanSe gap = mean_se(difference), J = mean_se(report.controllers[0].cost);
    std::printf("D = %g: J(LQR@KF) = %.4f, J(LQR@KF) - J(LQR@MOM) = %.4f +- %.4f (paired)\n", D, J.mean, gap.mean,
                gap.se);
    if (D > 0.0)
      EXPECT_GT(gap.mean, 10.0 * gap.se);
    else
      EXPECT_LT(std::fabs(gap.mean), 0.02 * J.mean);
  }
}

}  // namespace
}  // namespace kushner
