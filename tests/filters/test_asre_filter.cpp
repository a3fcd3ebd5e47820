// ASRE (seed 001 Theorem 2) as the bank runs it:
// - causality: with the explicit step, iterate I equals the state-dependent-coefficient filter (A evaluated at
//   the filter's own estimate) on the first I + 1 steps -- checked against a host implementation of that
//   filter, which then departs from iterate I (so the check can fail);
// - the iteration over the horizon stops per member at the first iterate that changed less than the
//   tolerance; on a linear model that is iterate 1 (A(x) = A: iterate 1 repeats iterate 0);
// - an unreachable tolerance leaves every member at the maximum and reports it as not converged.
#include "engine/filter_run.hpp"
#include "models/linear_model.hpp"
#include "models/sine_model.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace kushner {
namespace {

using Space = Kokkos::DefaultExecutionSpace;

TEST(AsreFilter, IterateIEqualsTheCausalSdcFilterOnTheFirstIPlusOneSteps) {
  const SineModel model;
  constexpr long members = 16;
  constexpr int iterations = 5;
  constexpr double dt = 0.01;
  OptionValues settings;
  settings.set("asre_max_iterations", static_cast<long>(iterations));
  FilterBank<Space, SineModel> bank(Space(), model, model, members, 3, {"ASRE"}, settings);
  std::vector<double> m(members, model.prior_mean[0]), P(members, model.prior_cov(0, 0));
  const double r2 = model.r * model.r, q2 = model.q * model.q;
  for (long k = 0; k < 30; ++k) {
    bank.step(k, dt, false);
    const auto dy = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), bank.truths().observations());
    double difference = 0.0;
    bank.with_slot("ASRE", [&](const auto& slot) {
      const auto asre = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), slot.m);
      for (long i = 0; i < members; ++i) {  // the SDC filter: update, then predict with A(m_k) = -sin(m_k) / m_k
        const double A = -std::sin(m[i]) / m[i];
        const double K = P[i] / (r2 + dt * P[i]);
        const double mu = m[i] + K * (dy(i, 0) - m[i] * dt), Pu = P[i] - dt * K * P[i];
        m[i] = mu + A * mu * dt;
        P[i] = (1 + A * dt) * (1 + A * dt) * Pu + q2 * dt;
        difference = std::max(difference, std::abs(asre(i, 0) - m[i]) / std::abs(m[i]));
      }
    });
    if (k + 1 <= iterations + 1) {  // a few ulps: a GPU contracts the bank's products into FMAs, the host does not
      EXPECT_LT(difference, 1e-13) << "step " << k;
    }
    if (k + 1 == 30) {
      EXPECT_GT(difference, 1e-9) << "iterate " << iterations << " still equal to the SDC filter";
    }
  }
}

TEST(AsreFilter, StopsAtTheFirstIterateWithinTheTolerance) {
  const TimeGrid grid = make_time_grid(2.0, 0.01, 2);
  const auto iterations = [](const FilterReport& report, const char* key) {
    return std::get<long>(*find_field(report.filter_fields.at("ASRE"), std::string("iterations.") + key));
  };
  OptionValues settings;
  const FilterReport sine = run_filters(Space(), SineModel{}, SineModel{}, 500, 5, grid, {"ASRE"}, settings);
  EXPECT_EQ(iterations(sine, "not_converged"), 0);
  EXPECT_GE(iterations(sine, "min"), 2);  // sin(x)/x is not constant: iterate 1 differs from iterate 0
  EXPECT_LT(iterations(sine, "max"), iterations(sine, "max_iterations"));
  EXPECT_EQ(iterations(sine, "max_iterations"), 30) << "the declared default";
  EXPECT_EQ(sine.scores[0].diverged, 0);

  const FilterReport linear =
      run_filters(Space(), LinearModel<2>{}, LinearModel<2>{}, 500, 5, grid, {"ASRE"}, settings);
  EXPECT_EQ(iterations(linear, "min"), 1);
  EXPECT_EQ(iterations(linear, "max"), 1);

  settings.set("asre_tolerance", 1e-300);
  settings.set("asre_max_iterations", 4L);
  const FilterReport never = run_filters(Space(), SineModel{}, SineModel{}, 500, 5, grid, {"ASRE"}, settings);
  EXPECT_EQ(iterations(never, "not_converged"), 500);
  EXPECT_EQ(iterations(never, "min"), 4);
}

}  // namespace
}  // namespace kushner
