// On a linear model every filter of the bank is the Kalman-Bucy filter: EKF, EKF-DS, SOF, SOF-B (Jacobians
// constant, Hessians zero), QLF (both ways of computing the expectations), UKF (the unscented transform is exact
// for linear maps), POLY3, POLY4, BILIN, MIXED (polynomials of degree 1), ASRE (A(x) = A at every iterate) and
// KBL (the model is its own linearization). The randomized filters (EnKBF, EnKBF-S) tend to it as their ensembles
// grow (tests/filters/test_ensemble_kalman_bucy_filter.cpp).
// Checked to 1e-10 relative, every step, every member, in dimension 1 and 3, with affine drift and
// observation terms (which the known-input forms of ASRE and the polynomial filters must carry).
#include "engine/filter_bank.hpp"
#include "kernels/filters/filter_list.hpp"
#include "models/linear_model.hpp"
#include "tests/filter_test_helpers.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

namespace kushner {
namespace {

constexpr long num_members = 64;
constexpr long num_steps = 300;
constexpr double dt = 0.01;
constexpr double tolerance = 1e-10;

LinearModel<1> linear_1d() {
  LinearModel<1> model;
  model.a0 = Vec<1>{{0.3}};
  model.A = Mat<1, 1>{{{-0.7}}};
  model.c0 = Vec<1>{{0.1}};
  model.C = Mat<1, 1>{{{2.0}}};
  return model;
}

LinearModel<3> linear_3d() {
  LinearModel<3> model;
  model.a0 = Vec<3>{{0.3, -0.2, 0.1}};
  model.c0 = Vec<3>{{0.1, 0.0, -0.1}};
  model.C = Mat<3, 3>{{{1.0, 0.5, 0.0}, {0.0, 1.0, 0.2}, {0.3, 0.0, 1.0}}};
  model.b = Mat<3, 3>{{{0.5, 0.0, 0.0}, {0.1, 0.4, 0.0}, {0.0, 0.2, 0.6}}};
  model.prior_cov = Mat<3, 3>{{{0.2, 0.05, 0.0}, {0.05, 0.1, 0.02}, {0.0, 0.02, 0.3}}};
  return model;
}

template <class Model>
void expect_every_filter_equals_kalman_bucy(const Model& model, Expectations qlf_expectations) {
  using Space = Kokkos::DefaultExecutionSpace;
  OptionValues settings;
  settings.set("qlf_expectations", std::string(qlf_expectations == Expectations::closed ? "closed" : "cubature"));
  settings.set("gh_nodes", 5L);
  settings.set("asre_max_iterations", 3L);
  const std::vector<std::string> randomized = randomized_filter_names();  // Monte Carlo: tested as N grows
  std::vector<std::string> filters, deterministic;
  for (const auto& name : supported_filters(model))
    if (std::find(randomized.begin(), randomized.end(), name) == randomized.end()) filters.push_back(name);
  for (const auto& name : filter_names<Model>())
    if (std::find(randomized.begin(), randomized.end(), name) == randomized.end()) deterministic.push_back(name);
  ASSERT_EQ(filters, deterministic) << "every filter supports a linear model";
  ASSERT_EQ(randomized, (std::vector<std::string>{"EnKBF", "EnKBF-S"}));  // tests/filters/test_ensemble_kalman_bucy
  FilterBank<Space, Model> bank(Space(), model, model, num_members, 20261122, filters, settings);
  for (long k = 0; k < num_steps; ++k) {
    bank.step(k, dt, false);
    bank.with_slot("KB", [&](const auto& kb) {
      for (const auto& name : filters) {
        if (name == "KB") continue;
        bank.with_slot(name, [&](const auto& slot) {
          ASSERT_LT(test::largest_relative_difference(slot.m, kb.m), tolerance) << name << " m, step " << k;
          ASSERT_LT(test::largest_relative_difference(slot.P, kb.P), tolerance) << name << " P, step " << k;
        });
      }
    });
  }
  for (const auto& name : filters) EXPECT_EQ(bank.scores(name, num_steps + 1).diverged, 0) << name;
}

TEST(FilterBankOnLinearModel, EveryFilterEqualsKalmanBucyIn1D) {
  expect_every_filter_equals_kalman_bucy(linear_1d(), Expectations::closed);
  expect_every_filter_equals_kalman_bucy(linear_1d(), Expectations::cubature);
}

TEST(FilterBankOnLinearModel, EveryFilterEqualsKalmanBucyIn3D) {
  expect_every_filter_equals_kalman_bucy(linear_3d(), Expectations::closed);
  expect_every_filter_equals_kalman_bucy(linear_3d(), Expectations::cubature);
}

/// The comparison can fail: a filter on a slightly different model is far outside the tolerance.
TEST(FilterBankOnLinearModel, DifferentModelIsDetected) {
  using Space = Kokkos::DefaultExecutionSpace;
  LinearModel<3> other = linear_3d();
  other.A(0, 0) += 1e-6;
  FilterBank<Space, LinearModel<3>> a(Space(), linear_3d(), linear_3d(), num_members, 7, {"KB"});
  FilterBank<Space, LinearModel<3>> b(Space(), linear_3d(), other, num_members, 7, {"KB"});
  for (long k = 0; k < 50; ++k) {
    a.step(k, dt, false);
    b.step(k, dt, false);
  }
  a.with_slot("KB", [&](const auto& sa) {
    b.with_slot("KB",
                [&](const auto& sb) { EXPECT_GT(test::largest_relative_difference(sb.m, sa.m), 100 * tolerance); });
  });
}

}  // namespace
}  // namespace kushner
