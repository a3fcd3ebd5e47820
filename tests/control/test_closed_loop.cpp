// The closed loop (engine/control/): LQG against its exact expected cost, ASRE@ASRE against LQG, and the
// separation made explicit (a better estimator gives a lower cost under the same law).
#include "core/eigen_dense.hpp"
#include "engine/control/control_run.hpp"
#include "engine/control/cost_reference.hpp"
#include "models/model_list.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numeric>
#include <vector>

namespace kushner {
namespace {

struct MeanSe {
  double mean = 0.0, se = 0.0;
  long count = 0;
};

MeanSe mean_se(const std::vector<double>& v) {
  MeanSe r;
  double s = 0.0, s2 = 0.0;
  for (double x : v)
    if (std::isfinite(x)) s += x, s2 += x * x, ++r.count;
  r.mean = s / r.count;
  r.se = std::sqrt((s2 / r.count - r.mean * r.mean) / (r.count - 1));
  return r;
}

// The expected cost of LQR@KB on a linear model, exactly as the loop simulates it: the truth's Euler-Maruyama
// step, the Kalman filter of that discretization (kernels/filters/filter_step.hpp: update with dy, then predict),
// u_k = -(K_k m_k + k_k) from the estimate at t_k, cost sum_k running(x_k, u_k) dt + terminal(x_N). The estimate
// m_k and its error e_k = x_k - m_k are independent Gaussians, e_k ~ N(0, P_k), so with M_k = E[m m^T], mu_k = E[m]:
//   E running = tr(Q (M_k + P_k)) + u terms,  m_{k+1} = (I + A dt)(m_k + G_k nu_k) + B u_k dt,
// nu_k = dy_k - C m_k dt ~ N(0, dt S_k), S_k = V + dt C P_k C^T, G_k = P_k C^T S_k^-1, independent of m_k.
double discrete_lqg_cost(const LinearModel<2>& model, const QuadraticCost<2, 1>& cost, const GainSchedule<2, 1>& gains,
                         long steps, double dt) {
  using M2 = Eigen::Matrix2d;
  using V2 = Eigen::Vector2d;
  const M2 A = to_eigen(model.A), C = to_eigen(model.C), G = to_eigen(model.b), R = to_eigen(model.R);
  const M2 W = G * G.transpose(), V = R * R.transpose(), Q = to_eigen(cost.Q), F = to_eigen(cost.F);
  const Eigen::Vector2d B = to_eigen(model.B);
  const double Ru = cost.R(0, 0);
  const M2 I = M2::Identity(), Phi = I + A * dt;
  V2 mu(model.prior_mean[0], model.prior_mean[1]);
  M2 Mm = mu * mu.transpose(), P = to_eigen(model.prior_cov);
  double J = 0.0;
  for (long k = 0; k < steps; ++k) {
    const Eigen::RowVector2d L = to_eigen(gains.K[k]);
    const double l = gains.k[k][0];
    // u = -(L m + l): E[u^2] = L M L^T + 2 l L mu + l^2
    const double Eu2 = (L * Mm * L.transpose())(0, 0) + 2.0 * l * (L * mu)(0, 0) + l * l;
    J += ((Q * (Mm + P)).trace() + Ru * Eu2) * dt;
    const M2 S = V + dt * C * P * C.transpose();
    const M2 Gk = P * C.transpose() * S.inverse();
    const M2 Pplus = P - dt * Gk * C * P;
    const M2 closed = Phi - dt * B * L;  // m_{k+1} = Phi (m + G nu) - B (L m + l) dt
    const V2 mu_next = closed * mu - B * l * dt;
    const M2 noise = Phi * Gk * (dt * S) * Gk.transpose() * Phi.transpose();
    Mm = closed * Mm * closed.transpose() + noise - (closed * mu) * (B * l * dt).transpose() -
         (B * l * dt) * (closed * mu).transpose() + (B * l * dt) * (B * l * dt).transpose();
    mu = mu_next;
    P = Phi * Pplus * Phi.transpose() + W * dt;
  }
  J += (F * (Mm + P)).trace();
  return J;
}

// The continuous-time LQG expected cost, E V(0, x0) + int_0^T tr(S B R^-1 B^T S P) dt, with V from the control
// Riccati equation (riccati.hpp) and P from the Kalman-Bucy Riccati equation, both by RK4 on a fine step h.
double continuous_lqg_cost(const LinearModel<2>& model, const QuadraticCost<2, 1>& cost, double T, double h) {
  using M2 = Eigen::Matrix2d;
  const long steps = std::lround(T / h);
  const auto control = lqr_solution(model, cost, steps, h, Vec<2>::zero());
  const M2 A = to_eigen(model.A), C = to_eigen(model.C), G = to_eigen(model.b), R = to_eigen(model.R);
  const M2 W = G * G.transpose(), Vinv = (R * R.transpose()).inverse();
  const Eigen::Vector2d B = to_eigen(model.B);
  const double Ru = cost.R(0, 0);
  auto rate = [&](const M2& P) { return M2(A * P + P * A.transpose() + W - P * C.transpose() * Vinv * C * P); };
  auto integrand = [&](long k, const M2& P) {
    const M2 S = to_eigen(control.S[k]);
    return (S * B * B.transpose() * S * P).trace() / Ru;
  };
  M2 P = to_eigen(model.prior_cov);
  double integral = 0.0;
  for (long k = 0; k < steps; ++k) {  // trapezoid in time, RK4 for P
    const M2 k1 = rate(P), k2 = rate(P + 0.5 * h * k1), k3 = rate(P + 0.5 * h * k2), k4 = rate(P + h * k3);
    const M2 next = P + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    integral += 0.5 * h * (integrand(k, P) + integrand(k + 1, next));
    P = next;
  }
  return control.expected_value(model.prior_mean, model.prior_cov) + integral;
}

TEST(ClosedLoop, LqgMatchesItsExactExpectedCost) {
  const Kokkos::DefaultHostExecutionSpace space;
  LinearModel<2> model;
  QuadraticCost<2, 1> cost;
  cost.Q = Mat<2, 2>::identity();
  cost.F = Mat<2, 2>::identity();
  const double T = 1.0, dt = 2e-3;
  const long members = 100000;
  const TimeGrid grid = make_time_grid(T, dt, 2);
  const auto report = run_control(space, model, members, 11, grid, {{"LQG", "LQR", "KB"}}, cost);
  const MeanSe J = mean_se(report.controllers[0].cost);
  const auto solution = lqr_solution(model, cost, grid.steps, dt, Vec<2>::zero());
  const double exact = discrete_lqg_cost(model, cost, solution.gains, grid.steps, dt);
  EXPECT_EQ(J.count, members);
  EXPECT_LT(std::fabs(J.mean - exact), 3.0 * J.se) << "J " << J.mean << " +- " << J.se << ", exact " << exact;
  // The continuous-time LQG cost E V(0, x0) + int tr(S B R^-1 B^T S P) dt (S: control Riccati, P: Kalman-Bucy
  // error covariance) is the dt -> 0 limit of both: within O(dt), here 1%.
  const double continuous = continuous_lqg_cost(model, cost, T, dt / 10.0);
  EXPECT_NEAR(exact, continuous, 0.01 * continuous) << "exact discrete " << exact << ", continuous " << continuous;
  std::printf(
      "LQG: Monte Carlo J = %.6f +- %.6f (%ld members), exact for the Euler scheme %.6f, continuous-time "
      "%.6f\n",
      J.mean, J.se, members, exact, continuous);
}

TEST(ClosedLoop, AsreAtAsreEqualsLqgOnALinearModel) {
  const Kokkos::DefaultHostExecutionSpace space;
  LinearModel<2> model;
  QuadraticCost<2, 1> cost;
  cost.Q = Mat<2, 2>::identity();
  cost.F = Mat<2, 2>::diagonal(2.0);
  const TimeGrid grid = make_time_grid(1.0, 5e-3, 2);
  const auto report = run_control(space, model, 500, 3, grid, {{"LQG", "LQR", "KB"}, {"ASRE-C", "ASRE", "ASRE"}}, cost);
  const auto& lqg = report.controllers[0].cost;
  const auto& asre = report.controllers[1].cost;
  for (long member = 0; member < 500; ++member)
    ASSERT_NEAR(asre[member], lqg[member], 1e-10 * std::fabs(lqg[member])) << "member " << member;
}

TEST(ClosedLoop, NoControlCostsMoreThanLqrWithTheState) {
  const Kokkos::DefaultHostExecutionSpace space;
  SineModel model;
  QuadraticCost<1, 1> cost;
  cost.Q(0, 0) = 1.0;
  cost.F(0, 0) = 1.0;
  const TimeGrid grid = make_time_grid(2.0, 1e-2, 2);
  const auto report =
      run_control(space, model, 2000, 5, grid, {{"NONE@state", "NONE", "state"}, {"LQR@state", "LQR", "state"}}, cost);
  std::vector<double> diff(2000);
  for (int i = 0; i < 2000; ++i) diff[i] = report.controllers[0].cost[i] - report.controllers[1].cost[i];
  const MeanSe d = mean_se(diff);
  EXPECT_GT(d.mean, 5.0 * d.se) << "NONE - LQR = " << d.mean << " +- " << d.se;
}

// Certainty equivalence with the true conditional mean: under the same law, the particle filter's estimate controls
// no worse than the EKF's (within 3 paired standard errors), and the HJB reference J* (full information) is below
// every controller (none beats it by more than 3 standard errors plus J*'s own discretization error).
TEST(ClosedLoop, ParticleEstimateControlsNoWorseThanEkfAndNobodyBeatsTheHjbOptimum) {
  const Kokkos::DefaultHostExecutionSpace space;
  SineModel model;
  model.r = 2.0;  // a hard regime: the observation says little, the estimators differ
  model.set_initial_law(Vec<1>{{0.0}}, Mat<1, 1>{{{4.0}}});
  QuadraticCost<1, 1> cost;
  cost.Q(0, 0) = 1.0;
  cost.F(0, 0) = 1.0;
  const TimeGrid grid = make_time_grid(2.0, 1e-2, 2);
  ParticleSettings particle;
  particle.particles = 512;
  const long members = 1000;
  const auto report = run_control(space, model, members, 9, grid,
                                  {{"LQR@EKF", "LQR", "EKF"},
                                   {"LQR@PF", "LQR", "PF"},
                                   {"LQR@state", "LQR", "state"},
                                   {"HJB@state", "HJB", "state"},
                                   {"HJB@PF", "HJB", "PF"}},
                                  cost, {}, particle);
  std::vector<double> diff(members);
  for (long i = 0; i < members; ++i) diff[i] = report.controllers[1].cost[i] - report.controllers[0].cost[i];
  const MeanSe d = mean_se(diff);
  EXPECT_LT(d.mean, 3.0 * d.se) << "J(LQR@PF) - J(LQR@EKF) = " << d.mean << " +- " << d.se;
  const auto reference = cost_reference(model, cost, grid, "hjb");
  ASSERT_TRUE(reference.has_value());
  for (const auto& run : report.controllers) {
    const MeanSe J = mean_se(run.cost);
    EXPECT_GT(J.mean, reference->J - 3.0 * J.se - reference->error)
        << run.spec.name << ": J " << J.mean << " +- " << J.se << ", J* " << reference->J << " (error "
        << reference->error << ")";
  }
}

}  // namespace
}  // namespace kushner
