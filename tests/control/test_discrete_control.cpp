// The discrete-time Riccati controller in closed loop (issue 15 part 4), against exact expected costs:
//   the recursion's steady gain = the scalar algebraic Riccati equation's; LQR@state's Monte Carlo J = E V_0(x0)
//   from the recursion, on Gaussian noise and on Clark's bounded noise (the value function holds for any zero-mean
//   noise); LQR@KF's J = E V_0 + sum_k tr(K_k' G_k K_k P_k|k) (certainty equivalence with the Kalman filter's error);
//   and Clark's claim: with the estimation-error weight D = 5 the better estimator (MOM) costs less than KF by many
//   standard errors, with D = 0 the difference is a small part of J.
// Clark's perturbation loop (ch. III): on a linear plant LQR-NOM is the LQR and KF-NOM, MOM-NOM are KF, MOM (a
// quintic plant with its nonlinear terms set to zero against clark-linear, member by member); on the quintic plant
// the nominal path is the noise-free optimum (the cost's gradient in the nominal controls vanishes); and at
// Table 3.1's smallest plant noise the moment filter in the loop estimates better than the Kalman filter.
// Clark's specific optimal controller (ch. IV): LQR@MOM-SPEC's estimation error below the midpoint's, above the
// moment filter's on the measurements (his Fig. 4.4: 40% below the midpoint's).
#include "core/eigen_dense.hpp"
#include "engine/control/control_run.hpp"
#include "engine/control/perturbation_loop.hpp"
#include "models/clark_linear_model.hpp"
#include "models/clark_quintic_model.hpp"
#include "models/linear_discrete_model.hpp"

#include <gtest/gtest.h>

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

/// Clark's quintic plant with its nonlinear terms zero and b = 1: clark-linear's system, bit for bit.
ClarkQuinticModel linear_quintic() {
  ClarkQuinticModel model;
  model.a1 = 0.1;
  model.a3 = model.a5 = 0.0;
  model.b = 1.0;
  model.w.bound = 1.0;
  return model;
}

TEST(PerturbationLoop, OnALinearPlantItIsTheLqr) {
  ClarkLinearModel model;
  model.set_initial_law(Vec<1>{{2.0}}, Mat<1, 1>::zero());
  QuadraticCost<1, 1> cost;
  cost.Q = cost.F = Mat<1, 1>::identity();
  cost.target = Vec<1>{{0.5}};
  const long steps = 40;
  const auto loop = perturbation_loop(model, cost, steps);
  const auto lqr = discrete_lqr_solution(model, cost, steps);
  ASSERT_TRUE(loop.converged && loop.finite);
  EXPECT_LE(loop.iterations, 3);  // the first linearization is exact
  for (long k = 0; k < steps; ++k) {
    EXPECT_NEAR(loop.gains.K[k](0, 0), lqr.gains.K[k](0, 0), 1e-14) << k;
    EXPECT_NEAR(loop.gains.k[k][0], lqr.gains.k[k][0], 1e-13) << k;
  }
  EXPECT_NEAR(loop.nominal.x[1][0], 0.1 * 2.0 - (lqr.gains.K[0](0, 0) * 2.0 + lqr.gains.k[0][0]), 1e-14);
}

TEST(PerturbationLoop, TheNominalPathIsTheNoiseFreeOptimum) {
  ClarkQuinticModel model;
  model.b = 0.2;  // a control strong enough to bend the path
  model.set_initial_law(Vec<1>{{2.5}}, Mat<1, 1>::zero());
  QuadraticCost<1, 1> cost;
  cost.Q = cost.R = cost.F = Mat<1, 1>::diagonal(2.0);
  const long steps = 60;
  const auto loop = perturbation_loop(model, cost, steps);
  ASSERT_TRUE(loop.converged && loop.finite);
  const auto J_of = [&](const std::vector<Vec<1>>& u) {
    return simulate_open_loop(model, cost, u, model.prior_mean, 1.0).J;
  };
  EXPECT_NEAR(J_of(loop.nominal.u), loop.nominal.J, 1e-12 * loop.nominal.J);
  // Central differences of J in each nominal control: zero at the optimum; at u = 0 they are not.
  const double h = 1e-4;
  double largest = 0.0, at_zero = 0.0;
  const std::vector<Vec<1>> zero(steps, Vec<1>::zero());
  for (long k = 0; k < steps; k += 7) {
    for (const auto* base : {&loop.nominal.u, &zero}) {
      auto plus = *base, minus = *base;
      plus[k][0] += h;
      minus[k][0] -= h;
      const double gradient = std::fabs(J_of(plus) - J_of(minus)) / (2.0 * h);
      if (base == &zero)
        at_zero = std::max(at_zero, gradient);
      else
        largest = std::max(largest, gradient);
    }
  }
  std::printf("nominal J %.6f after %d linearizations; largest |dJ/du_k| %.2e there, %.2e at u = 0\n", loop.nominal.J,
              loop.iterations, largest, at_zero);
  EXPECT_GT(at_zero, 0.1);
  EXPECT_LT(largest, 1e-6 * at_zero);
}

TEST(PerturbationLoop, OnALinearPlantItsFiltersAreKfAndMom) {
  const Kokkos::DefaultHostExecutionSpace space;
  ClarkLinearModel linear;
  ClarkQuinticModel quintic = linear_quintic();
  linear.set_initial_law(Vec<1>{{1.5}}, Mat<1, 1>::zero());
  quintic.set_initial_law(Vec<1>{{1.5}}, Mat<1, 1>::zero());
  QuadraticCost<1, 1> cost;
  cost.Q = cost.F = Mat<1, 1>::identity();
  cost.D(0, 0) = 1.0;
  const TimeGrid grid = make_time_grid(30.0, 1.0, 2);
  const long members = 300;
  const auto a = run_control(space, linear, members, 5, grid, {{"KF", "LQR", "KF"}, {"MOM", "LQR", "MOM"}}, cost);
  const auto b = run_control(space, quintic, members, 5, grid,
                             {{"KF-NOM", "LQR-NOM", "KF-NOM"}, {"MOM-NOM", "LQR-NOM", "MOM-NOM"}}, cost);
  for (int c = 0; c < 2; ++c) {
    double largest = 0.0;
    for (long i = 0; i < members; ++i) {
      largest = std::max(largest, std::fabs(a.controllers[c].cost[i] - b.controllers[c].cost[i]) /
                                      std::fabs(a.controllers[c].cost[i]));
      largest = std::max(largest, std::fabs(a.controllers[c].squared_error[i] - b.controllers[c].squared_error[i]) /
                                      (1e-300 + std::fabs(a.controllers[c].squared_error[i])));
    }
    std::printf("%s: largest relative difference of J and the squared error per member %.2e\n",
                b.controllers[c].spec.name.c_str(), largest);
    EXPECT_LT(largest, 1e-10);
    EXPECT_EQ(b.controllers[c].estimator_diverged, 0);
  }
}

TEST(PerturbationLoop, TheMomentFilterInTheLoopBeatsTheKalmanFilterAtLowPlantNoise) {
  const Kokkos::DefaultHostExecutionSpace space;
  ClarkQuinticModel model;
  model.w.bound = 1.08 * 0.05;  // Table 3.1's first column
  QuadraticCost<1, 1> cost;
  cost.Q = cost.R = cost.F = Mat<1, 1>::diagonal(2.0);
  const TimeGrid grid = make_time_grid(100.0, 1.0, 2);
  const long members = 400;
  const auto report =
      run_control(space, model, members, 11, grid,
                  {{"LQR-NOM@KF-NOM", "LQR-NOM", "KF-NOM"}, {"LQR-NOM@MOM-NOM", "LQR-NOM", "MOM-NOM"}}, cost);
  std::vector<double> difference(members);
  for (long i = 0; i < members; ++i)
    difference[i] = report.controllers[0].squared_error[i] - report.controllers[1].squared_error[i];
  const MeanSe gap = mean_se(difference), kf = mean_se(report.controllers[0].squared_error),
               mom = mean_se(report.controllers[1].squared_error);
  std::printf("sigma_w = 0.05: estimation error KF-NOM %.5f, MOM-NOM %.5f (x T); paired difference %.5f +- %.5f\n",
              kf.mean / grid.steps, mom.mean / grid.steps, gap.mean / grid.steps, gap.se / grid.steps);
  EXPECT_GT(gap.mean, 5.0 * gap.se);
  EXPECT_EQ(report.controllers[1].estimator_diverged, 0);
}

TEST(SpecificOptimalController, CorrectsTheMidpointEstimate) {
  const Kokkos::DefaultHostExecutionSpace space;
  const ClarkLinearModel model;
  QuadraticCost<1, 1> cost;
  cost.Q = cost.F = Mat<1, 1>::identity();
  const TimeGrid grid = make_time_grid(100.0, 1.0, 2);
  const long members = 1000;
  const auto report = run_control(
      space, model, members, 13, grid,
      {{"LQR@MOM-MID", "LQR", "MOM-MID"}, {"LQR@MOM-SPEC", "LQR", "MOM-SPEC"}, {"LQR@MOM", "LQR", "MOM"}}, cost);
  MeanSe error[3], J[3];
  for (int c = 0; c < 3; ++c) {
    error[c] = mean_se(report.controllers[c].squared_error);
    J[c] = mean_se(report.controllers[c].cost);
    EXPECT_EQ(report.controllers[c].estimator_diverged, 0) << report.controllers[c].spec.name;
  }
  std::vector<double> spec_gain(members), mom_gain(members);
  for (long i = 0; i < members; ++i) {
    spec_gain[i] = report.controllers[0].squared_error[i] - report.controllers[1].squared_error[i];
    mom_gain[i] = report.controllers[1].squared_error[i] - report.controllers[2].squared_error[i];
  }
  const MeanSe below_mid = mean_se(spec_gain), above_mom = mean_se(mom_gain);
  const double T = grid.steps;
  std::printf(
      "estimation error (mean over k): MOM-MID %.4f, MOM-SPEC %.4f (%.1f%% below MOM-MID), MOM %.4f; "
      "J %.3f, %.3f, %.3f\n",
      error[0].mean / T, error[1].mean / T, 100.0 * below_mid.mean / error[0].mean, error[2].mean / T, J[0].mean,
      J[1].mean, J[2].mean);
  EXPECT_GT(below_mid.mean, 5.0 * below_mid.se);
  EXPECT_GT(above_mom.mean, 5.0 * above_mom.se);
}

}  // namespace
}  // namespace kushner
