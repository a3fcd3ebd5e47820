// The particle filter against exact references: its posterior mean's RMS distance to the exact posterior
// mean shrinks like N^{-1/2} (fitted slope in [-0.6, -0.4] over N = 2^8 .. 2^16) and, at N = 2^16, its bias
// is within 4 Monte Carlo standard errors of zero -- for the linear model (1-D and 2-D, against the Kalman
// filter of the same discretization) and the Benes model (against the closed form), in every precision (fp64;
// mixed: normals drawn in fp32; fp32: also the particles and log-weights stored in float). Power: the same runs must
// reject a reference that is slightly wrong (a drift offset, a shifted prior).
#include "engine/particle_filter_bank.hpp"
#include "kernels/reference/benes_filter.hpp"
#include "kernels/reference/kalman_bucy_reference.hpp"
#include "models/benes_model.hpp"
#include "models/linear_model.hpp"
#include "tests/reference_comparison.hpp"

#include <gtest/gtest.h>

#include <iostream>
#include <string>
#include <type_traits>

namespace kushner {
namespace {

using test::Space;

constexpr int members = 32, steps = 100;
constexpr double dt = 0.01;
const std::vector<double> particle_counts = {256, 1024, 4096, 16384, 65536};

struct Convergence {
  std::vector<double> rms;  // per particle count
  double slope;
  std::vector<test::Bias> bias;  // per component, at the largest count
  std::vector<test::Bias> wrong_bias;
  double wrong_slope;
};

/// Runs the particle filter at every count on the same observations and compares with `exact` and `wrong`.
template <class Model>
Convergence converge(const Model& model, ParticlePrecision precision, const std::vector<BankVector<test::Mem>>& dys,
                     const test::Trajectory& exact, const test::Trajectory& wrong) {
  ParticleFilterOptions options;
  options.precision = precision;
  Convergence c;
  std::vector<double> wrong_rms;
  test::Trajectory largest;
  for (double n : particle_counts) {
    largest = with_particle_storage(precision, [&](auto* stored) {
      using Real = std::remove_pointer_t<decltype(stored)>;
      ParticleFilterBank<Space, Model, Real> pf(Space(), model, members, static_cast<int>(n), 4321, options);
      return test::replay(pf, dys, dt);
    });
    c.rms.push_back(test::rms_distance(largest, exact));
    wrong_rms.push_back(test::rms_distance(largest, wrong));
  }
  c.slope = test::log_log_slope(particle_counts, c.rms);
  c.wrong_slope = test::log_log_slope(particle_counts, wrong_rms);
  for (int i = 0; i < exact.dim; ++i) {
    c.bias.push_back(test::member_bias(largest, exact, i));
    c.wrong_bias.push_back(test::member_bias(largest, wrong, i));
  }
  return c;
}

void expect_converges(const Convergence& c, const std::string& what) {
  std::string summary = "slope " + std::to_string(c.slope) + ", wrong-reference slope " + std::to_string(c.wrong_slope);
  for (std::size_t i = 0; i < c.bias.size(); ++i)
    summary += "; bias[" + std::to_string(i) + "] " + std::to_string(c.bias[i].mean) + " +- " +
               std::to_string(c.bias[i].standard_error) + " (wrong: " + std::to_string(c.wrong_bias[i].mean) + ")";
  ::testing::Test::RecordProperty(what, summary);
  std::cout << what << ": " << summary << "\n";
  EXPECT_GE(c.slope, -0.6) << what << ": RMS " << ::testing::PrintToString(c.rms);
  EXPECT_LE(c.slope, -0.4) << what << ": RMS " << ::testing::PrintToString(c.rms);
  for (std::size_t i = 0; i < c.bias.size(); ++i)
    EXPECT_LT(std::abs(c.bias[i].mean), 4.0 * c.bias[i].standard_error)
        << what << " component " << i << ": bias " << c.bias[i].mean << " SE " << c.bias[i].standard_error;
  // Power: against the wrong reference the distance stops shrinking and the bias shows.
  EXPECT_GT(c.wrong_slope, -0.4) << what;
  double worst = 0.0;
  for (const auto& b : c.wrong_bias) worst = std::max(worst, std::abs(b.mean) / b.standard_error);
  EXPECT_GT(worst, 4.0) << what;
}

template <int N>
void linear_model_case(ParticlePrecision precision) {
  LinearModel<N> model;
  const auto dys = test::record_observations(model, members, steps, dt, 99);
  KalmanBucyReference<Space, N> kb(Space(), model, members);
  const auto exact = test::replay(kb, dys, dt);
  LinearModel<N> off = model;  // a drift offset of 0.1 in every component
  off.a0 = Vec<N>::constant(0.1);
  KalmanBucyReference<Space, N> kb_off(Space(), off, members);
  const auto wrong = test::replay(kb_off, dys, dt);
  const auto c = converge(model, precision, dys, exact, wrong);
  expect_converges(c, std::string(N == 1 ? "linear 1-D " : "linear 2-D ") + to_string(precision));
}

void benes_case(ParticlePrecision precision) {
  BenesModel model;
  const auto dys = test::record_observations(model, members, steps, dt, 98);
  BenesFilter<Space> exact_filter(Space(), model, members);
  const auto exact = test::replay(exact_filter, dys, dt);
  BenesModel off = model;  // prior mean 0.5 -> 0.8
  off.prior_mean[0] += 0.3;
  BenesFilter<Space> off_filter(Space(), off, members);
  const auto wrong = test::replay(off_filter, dys, dt);
  const auto c = converge(model, precision, dys, exact, wrong);
  expect_converges(c, std::string("benes ") + to_string(precision));
}

TEST(ParticleFilterAgainstKalman, LinearOneDimensionalConvergesAtRootNWithoutBias) {
  linear_model_case<1>(ParticlePrecision::fp64);
}
TEST(ParticleFilterAgainstKalman, LinearTwoDimensionalConvergesAtRootNWithoutBias) {
  linear_model_case<2>(ParticlePrecision::fp64);
}
TEST(ParticleFilterAgainstBenes, ClosedFormConvergesAtRootNWithoutBias) { benes_case(ParticlePrecision::fp64); }

// The mixed precision: the same test on the same observations.
TEST(MixedPrecisionParticleFilterAgainstKalman, LinearOneDimensionalConvergesAtRootNWithoutBias) {
  linear_model_case<1>(ParticlePrecision::mixed);
}
TEST(MixedPrecisionParticleFilterAgainstKalman, LinearTwoDimensionalConvergesAtRootNWithoutBias) {
  linear_model_case<2>(ParticlePrecision::mixed);
}
TEST(MixedPrecisionParticleFilterAgainstBenes, ClosedFormConvergesAtRootNWithoutBias) {
  benes_case(ParticlePrecision::mixed);
}

// The fp32 precision (particles and log-weights stored in float): the same test on the same observations.
TEST(Fp32ParticleFilterAgainstKalman, LinearOneDimensionalConvergesAtRootNWithoutBias) {
  linear_model_case<1>(ParticlePrecision::fp32);
}
TEST(Fp32ParticleFilterAgainstKalman, LinearTwoDimensionalConvergesAtRootNWithoutBias) {
  linear_model_case<2>(ParticlePrecision::fp32);
}
TEST(Fp32ParticleFilterAgainstBenes, ClosedFormConvergesAtRootNWithoutBias) { benes_case(ParticlePrecision::fp32); }

TEST(KalmanBucyReference, ConvergesToTheStationaryRiccatiSolutionAsDtShrinks) {
  // 1-D: dP/dt = 2 a P + b^2 - P^2 / r^2 has the positive root P = r^2 (a + sqrt(a^2 + b^2 / r^2)). The
  // discrete filter's stationary P must approach it with error O(dt).
  LinearModel<1> model;
  const double a = model.A(0, 0), b = model.b(0, 0), r = model.R(0, 0);
  const double riccati = r * r * (a + std::sqrt(a * a + b * b / (r * r)));
  double previous_error = 0.0;
  for (double h : {1e-2, 5e-3, 2.5e-3}) {
    KalmanBucyReference<Space, 1> kb(Space(), model, 1);
    BankVector<test::Mem> dy("dy", 1, 1);
    for (int k = 0; k < static_cast<int>(20.0 / h); ++k) kb.step(k, h, dy);
    const auto P = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), kb.posterior_covariance());
    const double error = std::abs(P(0, 0) - riccati);
    EXPECT_LT(error, 2.0 * h * riccati) << "dt " << h;
    if (previous_error > 0.0) {
      EXPECT_NEAR(previous_error / error, 2.0, 0.3) << "dt " << h;  // first order
    }
    previous_error = error;
  }
}

TEST(BenesFilter, TimeZeroMomentsAreThePrior) {
  BenesModel model;
  BenesFilter<Space> f(Space(), model, 2);
  const auto m = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), f.posterior_mean());
  const auto v = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), f.posterior_covariance());
  EXPECT_NEAR(m(1, 0), 0.5, 1e-12);
  EXPECT_NEAR(v(1, 0), 1.0, 1e-10);
}

}  // namespace
}  // namespace kushner
