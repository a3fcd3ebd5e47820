// Kushner's Markov-chain approximation of the HJB equation (engine/control/hjb_markov_chain.hpp) and its feedback
// table (kernels/control/feedback_table.hpp): the linear limit against the LQR's optimal expected cost at two grids,
// the box, the table run as a closed-loop law, and J* below the LQR policy on the nonlinear sine and cubic oscillator.
#include "engine/control/gain_laws.hpp"
#include "engine/control/hjb_markov_chain.hpp"
#include "models/model_list.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

namespace kushner {
namespace {

template <class Model>
QuadraticCost<Model::state_dim, 1> unit_cost() {
  QuadraticCost<Model::state_dim, 1> cost;
  cost.Q = Mat<Model::state_dim, Model::state_dim>::identity();
  cost.F = Mat<Model::state_dim, Model::state_dim>::identity();
  cost.R(0, 0) = 1.0;
  return cost;
}

template <int N>
HjbOptions<N> grid(int points) {
  HjbOptions<N> o;
  o.points.fill(points);
  return o;
}

// LinearModel<1>: dx = (-0.5 x + u) dt + 0.5 dw, x0 ~ N(1, 0.1), T = 1, cost int x^2 + u^2 + x(T)^2.
TEST(HjbMarkovChain, LinearLimitConvergesToTheLqrExpectedCost) {
  LinearModel<1> model;
  const auto cost = unit_cost<LinearModel<1>>();
  const double T = 1.0;
  const double lqr =
      lqr_solution(model, cost, 2000, T / 2000, Vec<1>::zero()).expected_value(model.x0_mean, model.x0_cov);
  // The upwind chain is first order in h (dt ~ h): the error halves with h, and Richardson's 2 J(h/2) - J(h)
  // removes the leading term.
  double previous = 0.0, coarse_J = 0.0;
  for (int points : {201, 401}) {
    const auto hjb = hjb_markov_chain(model, cost, T, grid<1>(points));
    const double error = std::fabs(hjb.J - lqr);
    std::printf("linear 1-D, %d points (h %.4f, dt %.2e, %ld steps, u bound %.2f): J* %.6f, LQR %.6f, error %.2e\n",
                points, hjb.spacing[0], hjb.dt, hjb.steps, hjb.u_bound, hjb.J, lqr, error);
    EXPECT_EQ(hjb.bound_active_fraction, 0.0);
    EXPECT_LT(error, 0.025 * lqr);
    if (previous > 0.0) {
      EXPECT_LT(error, 0.6 * previous);
      const double richardson = 2.0 * hjb.J - coarse_J;
      std::printf("  Richardson 2 J(h/2) - J(h) = %.6f, error %.2e\n", richardson, std::fabs(richardson - lqr));
      EXPECT_LT(std::fabs(richardson - lqr), 1e-3 * lqr);
    }
    previous = error;
    coarse_J = hjb.J;
  }
}

// The reflecting box does not matter: the box 1.6 times as wide at the same spacing gives the same J*.
TEST(HjbMarkovChain, ResultDoesNotDependOnTheBox) {
  LinearModel<1> model;
  const auto cost = unit_cost<LinearModel<1>>();
  const auto base = hjb_markov_chain(model, cost, 1.0, grid<1>(101));
  HjbOptions<1> wide;
  wide.explicit_box = true;
  const double width = base.spacing[0] * 100;
  wide.lower[0] = base.lower[0] - 0.3 * width;
  wide.upper[0] = base.lower[0] + 1.3 * width;
  wide.points[0] = 161;
  wide.u_bound = base.u_bound;
  const auto wider = hjb_markov_chain(model, cost, 1.0, wide);
  std::printf("box [%.3f, %.3f]: J* %.8f; box [%.3f, %.3f]: J* %.8f\n", base.lower[0], base.lower[0] + width, base.J,
              wide.lower[0], wide.upper[0], wider.J);
  EXPECT_NEAR(wider.spacing[0], base.spacing[0], 1e-12);
  EXPECT_LT(std::fabs(wider.J - base.J), 1e-6 * base.J);
  // ... while a box of +-1 standard deviation does change it: the comparison above can see the wall.
  HjbOptions<1> narrow = grid<1>(101);
  narrow.sds = 1.0;
  narrow.margin = 0.0;
  narrow.u_bound = base.u_bound;
  const auto small = hjb_markov_chain(model, cost, 1.0, narrow);
  std::printf("box [%.3f, %.3f]: J* %.8f\n", small.lower[0], small.lower[0] + 100 * small.spacing[0], small.J);
  EXPECT_GT(std::fabs(small.J - base.J), 1e-3 * base.J);
}

// The table as a closed-loop law: Euler-Maruyama truths from x0 ~ N(1, 0.1) under u = table(step, x), scored as the
// closed loop scores them; the mean cost matches J* within the Monte Carlo error and the time discretization.
TEST(HjbMarkovChain, TabulatedFeedbackRunsAsAClosedLoopLaw) {
  LinearModel<1> model;
  const auto cost = unit_cost<LinearModel<1>>();
  const double T = 1.0;
  const auto hjb = hjb_markov_chain(model, cost, T, grid<1>(201));
  const long steps = 500;
  const double dt = T / steps;
  const auto law = to_device<Kokkos::HostSpace>(hjb.table, dt);
  std::mt19937_64 rng(14);
  std::normal_distribution<double> normal;
  const int paths = 20000;
  double sum = 0.0, sum2 = 0.0;
  for (int p = 0; p < paths; ++p) {
    Vec<1> x{{model.x0_mean[0] + std::sqrt(model.x0_cov(0, 0)) * normal(rng)}};
    double J = 0.0;
    for (long k = 0; k < steps; ++k) {
      const Vec<1> u = law(k, x);
      J += cost.running(x, u) * dt;
      x = x + model.drift(k * dt, x, u) * dt + model.diffusion(k * dt, x) * Vec<1>{{std::sqrt(dt) * normal(rng)}};
    }
    J += cost.terminal(x);
    sum += J;
    sum2 += J * J;
  }
  const double mean = sum / paths, se = std::sqrt((sum2 / paths - mean * mean) / paths);
  std::printf("table as a law: Monte Carlo J %.5f +- %.5f, J* %.5f\n", mean, se, hjb.J);
  // The chain's J* carries its O(h) bias (2 % here); the law it yields is close to optimal for the diffusion
  // itself, whose optimum is the LQR's expected cost.
  const double lqr =
      lqr_solution(model, cost, 2000, T / 2000, Vec<1>::zero()).expected_value(model.x0_mean, model.x0_cov);
  EXPECT_LT(std::fabs(mean - hjb.J), 4.0 * se + 0.025 * hjb.J);
  EXPECT_LT(std::fabs(mean - lqr), 4.0 * se + 0.005 * lqr);
  // The law at the box's centre at t = 0 is the table's entry there (no interpolation error at a node).
  const long centre = 100;
  EXPECT_DOUBLE_EQ(law(0, Vec<1>{{hjb.lower[0] + centre * hjb.spacing[0]}})[0], hjb.table.values[centre]);
}

// On nonlinear models J* is at most the LQR policy's expected cost, both on the same chain (the LQR of the
// linearization at the origin is one admissible feedback), at two grids.
template <class Model>
void below_lqr(const Model& model, const char* label, int coarse, int fine, double T) {
  const auto cost = unit_cost<Model>();
  constexpr int n = Model::state_dim;
  const long lqr_steps = 1000;
  const auto lqr = lqr_solution(model, cost, lqr_steps, T / lqr_steps, Vec<n>::zero());
  const auto lqr_law = [&](double t, const Vec<n>& x) {
    const long k = std::min<long>(lqr_steps, static_cast<long>(t / (T / lqr_steps) + 0.5));
    return -(lqr.gains.K[k] * x + lqr.gains.k[k])[0];
  };
  for (int points : {coarse, fine}) {
    const auto hjb = hjb_markov_chain(model, cost, T, grid<n>(points));
    HjbOptions<n> o = grid<n>(points);
    o.u_bound = hjb.u_bound;
    const auto policy = hjb_markov_chain(model, cost, T, o, lqr_law);
    std::printf(
        "%s, %d points a dimension (dt %.2e, %ld steps, bound active %.3g): J* %.6f, LQR policy on the chain "
        "%.6f, LQR of the linearization %.6f\n",
        label, points, hjb.dt, hjb.steps, hjb.bound_active_fraction, hjb.J, policy.J,
        lqr.expected_value(model.x0_mean, model.x0_cov));
    EXPECT_LE(hjb.J, policy.J + 1e-12);
    EXPECT_EQ(hjb.bound_active_fraction, 0.0);
  }
}

TEST(HjbMarkovChain, SineBelowTheLqrPolicy) { below_lqr(SineModel{}, "sine", 101, 201, 1.0); }

TEST(HjbMarkovChain, CubicOscillatorBelowTheLqrPolicy) {
  CubicOscillatorModel model;
  below_lqr(model, "cubic-oscillator", 41, 81, 1.0);
}

}  // namespace
}  // namespace kushner
