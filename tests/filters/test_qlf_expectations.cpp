// QLF's two ways of computing Gaussian expectations agree, and agree with the polynomial filters:
// - the Gauss-Hermite rule integrates polynomials of degree <= 2K - 1 exactly;
// - on the sine model, closed form (seed 000 (6.4)-(6.5)) and cubature with 20 nodes, to 1e-9 every step;
// - on the cubic oscillator (cubic drift, linear observation), QLF closed form (6.14), QLF cubature and POLY3
//   (Stein's lemma: the same filter), to 1e-9 every step; likewise on the car's Taylor model, whose P(0) is
//   singular (the cubature takes a semidefinite square root);
// - power: too few nodes (exact only to degree 1) is far from the closed form on both models.
#include "engine/filter_bank.hpp"
#include "models/car_model.hpp"
#include "models/cubic_oscillator_model.hpp"
#include "models/sine_model.hpp"
#include "tests/filter_test_helpers.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace kushner {
namespace {

using Space = Kokkos::DefaultExecutionSpace;
constexpr long num_members = 200;
constexpr double agreement = 1e-9;

double double_factorial(int k) { return k <= 1 ? 1.0 : k * double_factorial(k - 2); }

TEST(GaussHermiteRule, IntegratesPolynomialsOfDegreeBelowTwiceTheNodesExactly) {
  for (int nodes : {1, 2, 5, 8, 20, 40}) {
    const GaussHermiteRule rule = make_gauss_hermite_rule(nodes);
    for (int k = 0; k <= std::min(2 * nodes - 1, 24); ++k) {
      double sum = 0.0, absolute = 0.0;  // absolute: the scale of the rounding errors in sum
      for (int q = 0; q < nodes; ++q) {
        sum += rule.weight[q] * std::pow(rule.node[q], k);
        absolute += rule.weight[q] * std::pow(std::abs(rule.node[q]), k);
      }
      const double exact = k % 2 == 1 ? 0.0 : double_factorial(k - 1);
      EXPECT_NEAR(sum, exact, 1e-13 * absolute) << nodes << " nodes, E[Z^" << k << "]";
    }
    if (2 * nodes <= 24) {  // and not beyond: the rule's first wrong moment is E[Z^{2K}]
      double sum = 0.0;
      for (int q = 0; q < nodes; ++q) sum += rule.weight[q] * std::pow(rule.node[q], 2 * nodes);
      EXPECT_GT(std::abs(sum - double_factorial(2 * nodes - 1)), 1e-3) << nodes << " nodes";
    }
  }
}

TEST(GaussHermiteRule, RefusesOrdersOutsideItsTable) {
  EXPECT_THROW(make_gauss_hermite_rule(0), std::logic_error);  // --gh-nodes is checked where it is read
  EXPECT_THROW(make_gauss_hermite_rule(max_gauss_hermite_nodes + 1), std::logic_error);
}

TEST(GaussianExpectations, SineClosedFormMatchesCubatureAtRandomPoints) {
  const SineModel model;
  const GaussHermiteRule rule = make_gauss_hermite_rule(20);
  for (double m : {-3.0, -0.4, 0.0, 1.0, 2.5})
    for (double p : {1e-6, 0.1, 1.0, 3.0}) {
      const Mat<1, 1> P{{{p}}};
      GaussianDrift<1> cubature;
      ASSERT_TRUE(cubature_drift(model, 0.0, Vec<1>{{m}}, P, rule, cubature));
      const GaussianDrift<1> closed = closed_form_drift(model, 0.0, Vec<1>{{m}}, P);
      EXPECT_NEAR(cubature.mean[0], closed.mean[0], 1e-13) << m << " " << p;
      EXPECT_NEAR(cubature.jacobian(0, 0), closed.jacobian(0, 0), 1e-13) << m << " " << p;
    }
}

/// Two banks on the same truths (same seed), differing only in the QLF settings; calls check(a, b) every step.
template <class Model, class Check>
void run_side_by_side(const Model& model, const std::vector<std::string>& filters, const OptionValues& a_config,
                      const OptionValues& b_config, long steps, double dt, Check&& check) {
  FilterBank<Space, Model> a(Space(), model, model, num_members, 11, filters, a_config);
  FilterBank<Space, Model> b(Space(), model, model, num_members, 11, filters, b_config);
  for (long k = 0; k < steps; ++k) {
    a.step(k, dt, false);
    b.step(k, dt, false);
    check(a, b, k);
  }
}

OptionValues qlf(Expectations e, int nodes) {
  OptionValues settings;
  settings.set("qlf_expectations", std::string(e == Expectations::closed ? "closed" : "cubature"));
  settings.set("gh_nodes", static_cast<long>(nodes));
  return settings;
}

template <class Bank>
double qlf_difference(const Bank& a, const Bank& b, const char* a_filter = "QLF") {
  double worst = 0.0;
  a.with_slot(a_filter, [&](const auto& sa) {
    b.with_slot("QLF", [&](const auto& sb) {
      worst = std::max(test::largest_relative_difference(sa.m, sb.m), test::largest_relative_difference(sa.P, sb.P));
    });
  });
  return worst;
}

TEST(QuasiLinearFilter, SineClosedFormAndTwentyNodeCubatureAgreeEveryStep) {
  double worst = 0.0;
  run_side_by_side(SineModel{}, {"QLF"}, qlf(Expectations::closed, 8), qlf(Expectations::cubature, 20), 1000, 1e-3,
                   [&](const auto& a, const auto& b, long k) {
                     const double d = qlf_difference(a, b);
                     worst = std::max(worst, d);
                     ASSERT_LT(d, agreement) << "step " << k;
                   });
  EXPECT_GT(worst, 0.0) << "two computations that never differ by a rounding error: is cubature in use?";
}

TEST(QuasiLinearFilter, CubicOscillatorQlfBothWaysAndPoly3AgreeEveryStep) {
  run_side_by_side(CubicOscillatorModel{}, {"QLF", "POLY3"}, qlf(Expectations::closed, 8),
                   qlf(Expectations::cubature, 4), 1000, 1e-3, [&](const auto& a, const auto& b, long k) {
                     ASSERT_LT(qlf_difference(a, b), agreement) << "closed vs cubature, step " << k;
                     ASSERT_LT(qlf_difference(a, b, "POLY3"), agreement) << "POLY3 vs cubature, step " << k;
                     ASSERT_LT(qlf_difference(a, a, "POLY3"), agreement) << "POLY3 vs closed, step " << k;
                   });
}

TEST(QuasiLinearFilter, CarTaylorModelWithSingularPriorAgreesWithPoly3) {
  run_side_by_side(CarTaylor3Model{}, {"QLF", "POLY3"}, qlf(Expectations::closed, 8), qlf(Expectations::cubature, 3),
                   500, 1e-3, [&](const auto& a, const auto& b, long k) {
                     ASSERT_LT(qlf_difference(a, b), agreement) << "closed vs cubature, step " << k;
                     ASSERT_LT(qlf_difference(a, b, "POLY3"), agreement) << "POLY3 vs cubature, step " << k;
                   });
}

TEST(QuasiLinearFilter, OneNodeCubatureIsDetectedAsDifferent) {
  double sine = 0.0, cubic = 0.0;
  run_side_by_side(SineModel{}, {"QLF"}, qlf(Expectations::closed, 8), qlf(Expectations::cubature, 1), 200, 1e-3,
                   [&](const auto& a, const auto& b, long) { sine = std::max(sine, qlf_difference(a, b)); });
  run_side_by_side(CubicOscillatorModel{}, {"QLF"}, qlf(Expectations::closed, 8), qlf(Expectations::cubature, 1), 200,
                   1e-3, [&](const auto& a, const auto& b, long) { cubic = std::max(cubic, qlf_difference(a, b)); });
  EXPECT_GT(sine, 1e3 * agreement);
  EXPECT_GT(cubic, 1e3 * agreement);
}

}  // namespace
}  // namespace kushner
