// Quantiles and histograms of the particle cloud, on the prior (a known Gaussian) and after weighting
// (against the exact Kalman posterior); and the model -> exact reference mapping.
#include "engine/particle_snapshot.hpp"
#include "kernels/reference/exact_reference.hpp"
#include "models/cubic_oscillator_model.hpp"
#include "models/sine_model.hpp"
#include "tests/reference_comparison.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace kushner {
namespace {

using test::Space;
constexpr int particles = 1 << 14;

TEST(ParticleSnapshot, PriorQuantilesAndHistogramMatchTheGaussianWithinFourStandardErrors) {
  LinearModel<1> model;  // prior N(1, 0.1)
  ParticleFilterBank<Space, LinearModel<1>> pf(Space(), model, 3, particles, 5);
  const ParticleSnapshot snap(pf);
  const double sd = std::sqrt(0.1), phi1 = 0.8413447460685429;  // P(Z < 1)
  const auto q = snap.quantiles(2, 0, {0.5, phi1, 1.0 - phi1});
  // SE of a sample p-quantile: sqrt(p (1 - p) / N) / f(x_p), f the density there.
  const double pdf0 = 1.0 / (sd * std::sqrt(2 * M_PI)), pdf1 = pdf0 * std::exp(-0.5);
  const double se_median = std::sqrt(0.25 / particles) / pdf0,
               se_tail = std::sqrt(phi1 * (1 - phi1) / particles) / pdf1;
  EXPECT_NEAR(q[0], 1.0, 4 * se_median);
  EXPECT_NEAR(q[1], 1.0 + sd, 4 * se_tail);
  EXPECT_NEAR(q[2], 1.0 - sd, 4 * se_tail);
  EXPECT_GT(std::abs(q[1] - (1.0 + 1.1 * sd)), 4 * se_tail);  // power: a 10% wider Gaussian is rejected
  const auto h = snap.histogram(2, 0, 1.0 - 4 * sd, 1.0 + 4 * sd, 40);
  double mass = 0.0;
  for (double d : h) mass += d * (8 * sd / 40);
  EXPECT_NEAR(mass, 1.0, 1e-3);                           // P(|Z| > 4) = 6e-5
  const double bin = 8 * sd / 40, p_center = pdf0 * bin;  // the two bins around the mean
  const double se_bin = std::sqrt(p_center * (1 - p_center) / particles) / bin;
  EXPECT_NEAR(0.5 * (h[19] + h[20]), pdf0, 4 * se_bin + 0.02 * pdf0);  // + curvature of the pdf over a bin
  EXPECT_THROW(snap.quantiles(0, 0, {1.5}), InputError);
  EXPECT_THROW(snap.histogram(0, 0, 1.0, 0.0, 3), InputError);
}

/// A mixture of two Gaussians (weights w, 1 - w; means -2, 2; sd 0.5) on 60 bins over [-4, 4], times 1 + noise.
std::vector<double> mixture_histogram(double w, double noise = 0.0) {
  std::vector<double> h(60);
  auto bell = [](double x, double mean) { return std::exp(-0.5 * (x - mean) * (x - mean) / 0.25); };
  for (int b = 0; b < 60; ++b) {
    const double x = -4.0 + (b + 0.5) * 8.0 / 60;
    h[b] = (w * bell(x, -2.0) + (1 - w) * bell(x, 2.0)) * (1.0 + noise * std::sin(12.9898 * b * b + 78.233));
  }
  return h;
}

TEST(ParticleSnapshot, BimodalityScoreIsTheSecondModesHeightOverTheFirsts) {
  EXPECT_NEAR(bimodality_score(mixture_histogram(0.5)), 1.0, 1e-12);  // two equal modes
  EXPECT_NEAR(bimodality_score(mixture_histogram(0.8)), 0.25, 0.01);  // heights 0.2 : 0.8
  EXPECT_EQ(bimodality_score(mixture_histogram(1.0)), 0.0);           // one Gaussian
  EXPECT_LT(bimodality_score(mixture_histogram(1.0, 0.1)), 0.02);     // with 10% noise per bin: no mode of note
  EXPECT_EQ(bimodality_score(std::vector<double>(60, 1.0)), 0.0);     // flat: no dip, no second mode
  // A Gaussian cloud of 2^14 particles: its sampling noise scores far below the report's threshold 0.25.
  LinearModel<1> model;
  ParticleFilterBank<Space, LinearModel<1>> pf(Space(), model, 3, particles, 5);
  const ParticleSnapshot snap(pf);
  for (int m = 0; m < 3; ++m) EXPECT_LT(snap.bimodality(m, 0), 0.05) << "member " << m;
}

TEST(ParticleSnapshot, PosteriorMedianMatchesKalmanMean) {
  LinearModel<1> model;
  const int members = 4, steps = 50;
  const auto dys = test::record_observations(model, members, steps, 0.01, 3);
  ParticleFilterBank<Space, LinearModel<1>> pf(Space(), model, members, particles, 6);
  KalmanBucyReference<Space, 1> kb(Space(), model, members);
  for (int k = 0; k < steps; ++k) {
    pf.step(k, 0.01, dys[k]);
    kb.step(k, 0.01, dys[k]);
  }
  const ParticleSnapshot snap(pf);
  const auto mean = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), kb.posterior_mean());
  const auto P = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), kb.posterior_covariance());
  const auto ess = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), pf.effective_sample_size());
  for (int m = 0; m < members; ++m) {
    const double sd = std::sqrt(P(m, 0));
    const double se = std::sqrt(0.25 / ess(m)) * sd * std::sqrt(2 * M_PI);  // median of a Gaussian, ESS draws
    EXPECT_NEAR(snap.quantiles(m, 0, {0.5})[0], mean(m, 0), 4 * se) << m;
  }
}

// A snapshot of a few members copies strided slices of the bank (one member's particles, every component);
// it must hold the same numbers as the whole-bank copy -- on a GPU that copy cannot go straight to the host.
TEST(ParticleSnapshot, ChosenMembersHoldTheSameParticlesAsTheWholeBank) {
  LinearModel<2> model;
  ParticleFilterBank<Space, LinearModel<2>> pf(Space(), model, 5, 256, 7);
  const ParticleSnapshot whole(pf), chosen(pf, {3, 1});
  for (int m : {1, 3})
    for (int i = 0; i < 2; ++i) {
      EXPECT_EQ(chosen.quantiles(m, i, {0.1, 0.5, 0.9}), whole.quantiles(m, i, {0.1, 0.5, 0.9})) << m << " " << i;
      EXPECT_EQ(chosen.histogram(m, i, -2.0, 4.0, 12), whole.histogram(m, i, -2.0, 4.0, 12)) << m << " " << i;
    }
  EXPECT_NE(whole.quantiles(1, 0, {0.5}), whole.quantiles(3, 0, {0.5}));  // distinct members, distinct draws
  EXPECT_THROW(chosen.quantiles(0, 0, {0.5}), std::logic_error);          // member 0 was not copied
}

static_assert(std::is_same_v<exact_reference_t<Space, LinearModel<2>>, KalmanBucyReference<Space, 2>>);
static_assert(std::is_same_v<exact_reference_t<Space, BenesModel>, BenesFilter<Space>>);
static_assert(std::is_same_v<exact_reference_t<Space, SineModel>, GridFilter<Space, SineModel>>);
static_assert(std::is_same_v<exact_reference_t<Space, CubicOscillatorModel>, GridFilter<Space, CubicOscillatorModel>>);

}  // namespace
}  // namespace kushner
