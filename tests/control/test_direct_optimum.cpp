// The direct open-loop optimum (engine/control/direct_optimum.hpp): its adjoint gradient against finite differences,
// the exact discrete LQR on a linear model, and "never above" POLY3, LQR and ASRE on Basin's car data.
#include "engine/control/direct_optimum.hpp"
#include "engine/control/gain_laws.hpp"
#include "engine/control/poly3_regulator.hpp"
#include "models/model_list.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace kushner {
namespace {

template <class Car>
Car basin_car() {
  Car car;
  car.v = 17.0;
  car.l = 2.0;
  car.u = 0.0;
  car.prior_mean = Vec<2>{{0.1, 0.1}};
  return car;
}
QuadraticCost<2, 1> basin_cost() {
  QuadraticCost<2, 1> cost;
  cost.F(0, 0) = 1.0;
  cost.target[0] = 1.0;
  return cost;
}
const Vec<2> basin_x0{{0.1, 0.1}};

TEST(DirectOptimum, AdjointGradientMatchesFiniteDifferences) {
  const auto car = basin_car<CarModel>();
  auto cost = basin_cost();
  cost.Q(1, 1) = 0.7;
  cost.R(0, 0) = 0.5;
  const long steps = 40;
  const double dt = 2.5e-3;
  Eigen::VectorXd u(steps);
  for (long k = 0; k < steps; ++k) u(k) = 3.0 * std::sin(0.3 * k) + 1.0;
  Eigen::VectorXd g;
  direct_cost_gradient(car, cost, basin_x0, dt, u, &g);
  double worst = 0.0;
  for (long k = 0; k < steps; ++k) {
    const double h = 1e-5;
    Eigen::VectorXd up = u, dn = u;
    up(k) += h;
    dn(k) -= h;
    const double fd = (direct_cost_gradient(car, cost, basin_x0, dt, up, nullptr) -
                       direct_cost_gradient(car, cost, basin_x0, dt, dn, nullptr)) /
                      (2.0 * h);
    worst = std::max(worst, std::fabs(fd - g(k)) / std::max(1e-3, std::fabs(g(k))));
  }
  std::printf("gradient: worst relative difference to central differences %.3g\n", worst);
  EXPECT_LT(worst, 1e-7);
}

// On a linear model the direct optimum is the discrete Riccati solution of the same Euler scheme (to the gradient
// tolerance), and the continuous LQR's value differs from it by O(dt).
TEST(DirectOptimum, EqualsTheEulerDiscreteLqrOnALinearModel) {
  LinearModel<2> model;
  model.a0 = Vec<2>{{0.3, 0.0}};
  model.b = Mat<2, 2>::zero();  // noise-free: the continuous value has no tr(S W) term
  QuadraticCost<2, 1> cost;
  cost.Q = Mat<2, 2>::identity();
  cost.F = Mat<2, 2>::diagonal(2.0);
  cost.R(0, 0) = 0.3;
  cost.target = Vec<2>{{0.5, -0.5}};
  const Vec<2> x0{{1.0, 1.5}};
  double previous_gap = 0.0;
  for (long steps : {100L, 200L}) {
    const double dt = 1.0 / steps;
    const auto direct = direct_optimum(model, cost, x0, steps, dt);
    const double discrete = euler_lqr(model, cost, steps, dt).value(x0);
    const double continuous =
        lqr_solution(model, cost, steps, dt, Vec<2>::zero()).expected_value(x0, Mat<2, 2>::zero());
    std::printf(
        "linear, dt %g: direct J %.12f (%d iterations, gradient %.2g), Euler discrete LQR %.12f, continuous "
        "LQR %.12f\n",
        dt, direct.J, direct.iterations, direct.gradient_norm, discrete, continuous);
    ASSERT_TRUE(direct.converged) << direct.reason;
    EXPECT_NEAR(direct.J, discrete, 1e-10 * discrete);
    const double gap = std::fabs(direct.J - continuous);
    if (previous_gap > 0.0) {
      EXPECT_GT(previous_gap / gap, 1.7);  // first order in dt
      EXPECT_LT(previous_gap / gap, 2.3);
    }
    previous_gap = gap;
  }
}

// Basin's regulator data: the direct optimum is never above POLY3 (both readings of the diagonal term), the LQR of
// the linearization at the origin or ASRE, all simulated noise-free with the same scheme from the same x0. Without
// Basin's diagonal term POLY3's converged path satisfies Pontryagin's conditions (poly3_regulator.hpp): it must
// reach the direct J to O(dt).
template <class Car>
void never_above(const char* label) {
  const auto car = basin_car<Car>();
  const auto cost = basin_cost();
  const long steps = 100;
  const double dt = 1e-3;
  const auto direct = direct_optimum(car, cost, basin_x0, steps, dt);
  ASSERT_TRUE(direct.converged) << direct.reason;
  const auto lqr =
      simulate_feedback(car, cost, lqr_solution(car, cost, steps, dt, Vec<2>::zero()).gains, basin_x0, steps, dt);
  const auto asre =
      simulate_feedback(car, cost, asre_solution(car, cost, steps, dt).riccati.gains, basin_x0, steps, dt);
  Poly3Options with, without;
  without.diagonal_term = false;
  const auto poly = poly3_regulator(car, cost, basin_x0, steps, dt, with);
  const auto pmp = poly3_regulator(car, cost, basin_x0, steps, dt, without);
  ASSERT_TRUE(poly.exact.converged && pmp.exact.converged);
  std::printf(
      "%s: direct J %.8f (%d iterations, phi(T) %.5f) <= POLY3 %.8f, POLY3 without diag(S) %.8f, LQR %.8f, "
      "ASRE %.8f\n",
      label, direct.J, direct.iterations, direct.path.x.back()[0], poly.applied.J, pmp.applied.J, lqr.J, asre.J);
  const double slack = 1e-12;
  EXPECT_LE(direct.J, poly.applied.J + slack);
  EXPECT_LE(direct.J, pmp.applied.J + slack);
  EXPECT_LE(direct.J, lqr.J + slack);
  EXPECT_LE(direct.J, asre.J + slack);
  EXPECT_LT(pmp.applied.J - direct.J, 1e-3 * direct.J);
}

TEST(DirectOptimum, NeverAboveTheGainLawsOnCarTaylor3) { never_above<CarTaylor3Model>("car-taylor3"); }
TEST(DirectOptimum, NeverAboveTheGainLawsOnCar) { never_above<CarModel>("car"); }

}  // namespace
}  // namespace kushner
