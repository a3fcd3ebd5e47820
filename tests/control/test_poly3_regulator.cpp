// Basin's polynomial regulator (engine/control/poly3_regulator.hpp): the linear limit (LQR), the sweep against the
// Newton solve on Basin's regulator data and on a mild case, and the printed reading against the paper's numbers.
#include "engine/control/gain_laws.hpp"
#include "engine/control/poly3_regulator.hpp"
#include "models/model_list.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace kushner {
namespace {

double max_path_difference(const std::vector<Vec<2>>& a, const std::vector<Vec<2>>& b) {
  double d = 0.0;
  for (size_t k = 0; k < a.size(); ++k)
    for (int i = 0; i < 2; ++i) d = std::max(d, std::fabs(a[k][i] - b[k][i]));
  return d;
}

double max_gain_difference(const GainSchedule<2, 1>& a, const GainSchedule<2, 1>& b) {
  double d = 0.0;
  for (long k = 0; k < a.size(); ++k) {
    for (int j = 0; j < 2; ++j) d = std::max(d, std::fabs(a.K[k](0, j) - b.K[k](0, j)));
    d = std::max(d, std::fabs(a.k[k][0] - b.k[k][0]));
  }
  return d;
}

/// Basin's regulator example (002 control paper section 5): v = 17, l = 2, T = 0.1, phi(0) = delta(0) = 0.1,
/// J = 1/2 (phi(T) - 1)^2 + 1/2 int u^2: ours (no 1/2) is F = diag(1, 0), x* = (1, 0), R = 1, Q = 0.
template <class Car>
Car basin_car() {
  Car car;
  car.v = 17.0;
  car.l = 2.0;
  car.u = 0.0;  // no open-loop steering rate: u is the control
  return car;
}
QuadraticCost<2, 1> basin_cost() {
  QuadraticCost<2, 1> cost;
  cost.F(0, 0) = 1.0;
  cost.target[0] = 1.0;
  cost.R(0, 0) = 1.0;
  return cost;
}
const Vec<2> basin_x0{{0.1, 0.1}};

TEST(Poly3Regulator, EqualsLqrOnALinearModel) {
  LinearModel<2> model;
  model.a0 = Vec<2>{{0.2, -0.1}};
  ModelCost<LinearModel<2>> cost;
  cost.Q = Mat<2, 2>::identity();
  cost.F = Mat<2, 2>::diagonal(3.0);
  cost.R(0, 0) = 0.5;
  cost.target = Vec<2>{{0.5, -0.25}};
  const long steps = 400;
  const double dt = 2.5e-3;
  const auto lqr = lqr_solution(model, cost, steps, dt, Vec<2>::zero());
  const auto poly = poly3_regulator(model, cost, Vec<2>{{1.0, 0.5}}, steps, dt);
  EXPECT_TRUE(poly.sweep.converged) << poly.sweep.reason;
  EXPECT_TRUE(poly.exact.converged) << poly.exact.reason;
  EXPECT_LE(poly.sweep.iterations, 3);  // S, s do not depend on the path: one sweep, one to confirm
  EXPECT_LT(max_gain_difference(poly.gains, lqr.gains), 1e-10);
  EXPECT_NEAR(poly.S[0](0, 1), lqr.S[0](0, 1), 1e-10);
}

// The Newton solve converges on Basin's data; the sweep either converges to the same path or says why not.
TEST(Poly3Regulator, SweepAndNewtonOnBasinsRegulatorData) {
  const auto car = basin_car<CarTaylor3Model>();
  const long steps = 100;
  const double dt = 1e-3;
  for (bool diagonal : {true, false}) {
    Poly3Options options;
    options.diagonal_term = diagonal;
    const auto poly = poly3_regulator(car, basin_cost(), basin_x0, steps, dt, options);
    std::printf("basin data, diagonal term %d: sweep %s after %d (residual %.3g); exact %s after %d (residual %.3g)\n",
                diagonal, poly.sweep.reason.c_str(), poly.sweep.iterations, poly.sweep.residual,
                poly.exact.reason.c_str(), poly.exact.iterations, poly.exact.residual);
    std::printf("  phi(T) %.6f delta(T) %.6f J %.6f; S(0) = [%.6g %.6g %.6g], s(0) = [%.6g %.6g]\n",
                poly.nominal.x.back()[0], poly.nominal.x.back()[1], poly.nominal.J, poly.S[0](0, 0), poly.S[0](0, 1),
                poly.S[0](1, 1), poly.s[0][0], poly.s[0][1]);
    ASSERT_TRUE(poly.exact.converged) << poly.exact.reason;
    EXPECT_LE(poly.exact.residual, 1e-12);
    if (poly.sweep.converged)
      EXPECT_LT(max_path_difference(poly.sweep_path, poly.exact_path), 1e-8);
    else
      EXPECT_FALSE(poly.sweep.reason.empty());
    // The regulator turns the car towards phi* = 1 and beats doing nothing (J = (1 - phi(T))^2 with u = 0).
    const double phi_free = 0.1 + 17.0 / 2.0 * (0.1 + 0.001 / 3.0) * 0.1;
    EXPECT_GT(poly.nominal.x.back()[0], phi_free);
    EXPECT_LT(poly.nominal.J, (1.0 - phi_free) * (1.0 - phi_free));
  }
}

// A mild case (a slower car, a longer horizon): the sweep converges, and to the Newton solution.
TEST(Poly3Regulator, SweepAgreesWithNewtonOnAMildCase) {
  auto car = basin_car<CarTaylor3Model>();
  car.v = 1.0;
  car.l = 1.0;
  auto cost = basin_cost();
  cost.R(0, 0) = 2.0;
  cost.Q(1, 1) = 0.5;
  const auto poly = poly3_regulator(car, cost, Vec<2>{{0.1, 0.3}}, 500, 2e-3);
  std::printf("mild case: sweep %s after %d, exact %s after %d, |sweep - exact| = %.3g\n", poly.sweep.reason.c_str(),
              poly.sweep.iterations, poly.exact.reason.c_str(), poly.exact.iterations,
              max_path_difference(poly.sweep_path, poly.exact_path));
  ASSERT_TRUE(poly.sweep.converged) << poly.sweep.reason;
  ASSERT_TRUE(poly.exact.converged) << poly.exact.reason;
  EXPECT_LT(max_path_difference(poly.sweep_path, poly.exact_path), 1e-8);
  // The nominal path is the design model's path under the schedule: on car-taylor3, `applied` is the same path.
  EXPECT_LT(max_path_difference(poly.nominal.x, poly.applied.x), 1e-14);
}

// The car (tan) is designed on its Taylor model: the same gains as car-taylor3, applied to tan.
TEST(Poly3Regulator, CarIsDesignedOnItsTaylorModel) {
  const auto taylor = poly3_regulator(basin_car<CarTaylor3Model>(), basin_cost(), basin_x0, 100, 1e-3);
  const auto car = poly3_regulator(basin_car<CarModel>(), basin_cost(), basin_x0, 100, 1e-3);
  ASSERT_TRUE(car.exact.converged) << car.exact.reason;
  EXPECT_LT(max_gain_difference(car.gains, taylor.gains), 1e-12);
  EXPECT_GT(car.applied.x.back()[0], car.nominal.x.back()[0]);  // tan(d) > d + d^3/3 for d > 0
  std::printf("car: J on the Taylor model %.6f, applied to tan %.6f (phi(T) %.6f)\n", car.nominal.J, car.applied.J,
              car.applied.x.back()[0]);
}

// Basin's printed reading of the linear regulator (12): Q(0) = (1.025, 0.87, 0.74) (002 control paper, L1957).
TEST(Poly3Regulator, PrintedReadingReproducesBasinsLinearQ0) {
  LinearModel<2> model;
  model.A = Mat<2, 2>{{{0.0, 8.5}, {0.0, 0.0}}};
  model.B = Mat<2, 1>{{{0.0}, {1.0}}};
  Poly3Options options;
  options.reading = Poly3Reading::printed_general;
  const auto poly = poly3_regulator(model, basin_cost(), basin_x0, 1000, 1e-4, options);
  ASSERT_TRUE(poly.exact.converged) << poly.exact.reason;
  std::printf("printed linear: Q(0) = [%.4f %.4f %.4f], phi(T) %.4f\n", poly.S[0](0, 0), poly.S[0](0, 1),
              poly.S[0](1, 1), poly.nominal.x.back()[0]);
  EXPECT_NEAR(poly.S[0](0, 0), 1.025, 0.005);
  EXPECT_NEAR(poly.S[0](0, 1), 0.87, 0.01);
  EXPECT_NEAR(poly.S[0](1, 1), 0.74, 0.01);
  // u = +R^-1 B^T Q x: K = -(q21, q22), no affine term.
  EXPECT_DOUBLE_EQ(poly.gains.K[0](0, 0), -poly.S[0](1, 0));
  EXPECT_DOUBLE_EQ(poly.gains.K[0](0, 1), -poly.S[0](1, 1));
  EXPECT_EQ(poly.gains.k[0][0], 0.0);
}

// Basin's printed car equations on his data (v = 17, l = 2, T = 0.1). The general printed form (7) and (23) have
// solutions; (11), whose cubic terms carry 3 v/l in dq12 and 6 v/l in dq22, escapes to infinity backwards from
// Q(T) = diag(1, 0) within T = 0.1 (the paper reports Q(0) = (1.32, 16, 1640): already near the escape), and both
// solvers must say so rather than return numbers. The readings must differ where their coefficients do.
TEST(Poly3Regulator, PrintedCarReadings) {
  const auto car = basin_car<CarTaylor3Model>();
  double q0[2][3];
  const Poly3Reading readings[2] = {Poly3Reading::printed_general, Poly3Reading::printed_car_eq23};
  for (int r = 0; r < 2; ++r) {
    Poly3Options options;
    options.reading = readings[r];
    const auto poly = poly3_regulator(car, basin_cost(), basin_x0, 100, 1e-3, options);
    ASSERT_TRUE(poly.sweep.converged && poly.exact.converged) << poly.sweep.reason << " / " << poly.exact.reason;
    std::printf(
        "%s: sweep %d, exact %d iterations; Q(0) = [%.4g %.4g %.4g]; phi(T) %.4f, J %.4f (ours, 2x Basin's), "
        "applied to tan: phi(T) %.4f J %.4f\n",
        poly3_reading_name(readings[r]), poly.sweep.iterations, poly.exact.iterations, poly.S[0](0, 0), poly.S[0](0, 1),
        poly.S[0](1, 1), poly.nominal.x.back()[0], poly.nominal.J, poly.applied.x.back()[0], poly.applied.J);
    EXPECT_LT(max_path_difference(poly.sweep_path, poly.exact_path), 1e-8);
    q0[r][0] = poly.S[0](0, 0);
    q0[r][1] = poly.S[0](0, 1);
    q0[r][2] = poly.S[0](1, 1);
  }
  EXPECT_GT(std::fabs(q0[1][1] - q0[0][1]), 1e-3);
  EXPECT_GT(std::fabs(q0[1][2] - q0[0][2]), 1e-3);
  for (double dt : {1e-3, 1e-4}) {
    Poly3Options options;
    options.reading = Poly3Reading::printed_car_eq11;
    const auto poly =
        poly3_regulator(car, basin_cost(), basin_x0, static_cast<long>(std::lround(0.1 / dt)), dt, options);
    std::printf("printed-car-eq11, dt %g: sweep: %s; exact: %s\n", dt, poly.sweep.reason.c_str(),
                poly.exact.reason.c_str());
    EXPECT_FALSE(poly.converged());
    EXPECT_NE(poly.sweep.reason.find("escaped to infinity"), std::string::npos) << poly.sweep.reason;
    EXPECT_NE(poly.exact.reason.find("escaped to infinity"), std::string::npos) << poly.exact.reason;
  }
}

}  // namespace
}  // namespace kushner
