// UKF: one step written out from its sigma points with non-default weights (alpha = 1, beta = 2, kappa = 2: the
// three points m, m +- sqrt(3 P) of weights 2/3, 1/6, 1/6 and the covariance weight 2/3 + 2 on the centre), on
// Sunahara's sine model. The default rule on a nonlinear observation is checked in
// tests/test_filter_single_step.cpp (cubic sensor), the linear limit UKF = KB to 1e-10 in
// tests/test_filter_linear_equivalence.cpp.
#include "engine/filter_bank.hpp"
#include "models/sine_model.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace kushner {
namespace {

using Space = Kokkos::DefaultExecutionSpace;

TEST(UnscentedKalmanFilter, OneStepFromThreeSigmaPoints) {
  const SineModel model;
  const double dt = 0.01, r = model.r, q = model.q;
  OptionValues settings;
  settings.set("ukf_alpha", 1.0);
  settings.set("ukf_beta", 2.0);
  settings.set("ukf_kappa", 2.0);
  FilterBank<Space, SineModel> bank(Space(), model, model, 1, 5, {"UKF"}, settings);
  bank.step(0, dt, false);
  const double dy = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), bank.truths().observations())(0, 0);
  double m_bank = 0.0, P_bank = 0.0;
  bank.with_slot("UKF", [&](const auto& slot) {
    m_bank = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), slot.m)(0, 0);
    P_bank = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), slot.P)(0, 0);
  });
  const double m0 = model.prior_mean[0], P0 = model.prior_cov(0, 0);
  // Update: h = x is linear, so h_bar = m0, C_xh = C_hh = P0 (2 (1/6) 3 P0).
  const double S = r * r + dt * P0, m = m0 + P0 / S * (dy - m0 * dt), P = P0 - dt * P0 * P0 / S;
  // Prediction: the points through x - sin(x) dt.
  const double d = std::sqrt(3.0 * P);
  const auto euler = [&](double x) { return x - std::sin(x) * dt; };
  const double y0 = euler(m), yp = euler(m + d), ym = euler(m - d);
  const double mean = 2.0 / 3.0 * y0 + (yp + ym) / 6.0;
  const double cov = (2.0 / 3.0 + 2.0) * (y0 - mean) * (y0 - mean) +
                     ((yp - mean) * (yp - mean) + (ym - mean) * (ym - mean)) / 6.0 + q * q * dt;
  EXPECT_NEAR(m_bank, mean, 1e-13 * std::abs(mean));
  EXPECT_NEAR(P_bank, cov, 1e-13 * cov);
  // Power: the default rule (two points m +- sqrt(P), centre weight 0) gives another P.
  FilterBank<Space, SineModel> plain(Space(), model, model, 1, 5, {"UKF"});
  plain.step(0, dt, false);
  plain.with_slot("UKF", [&](const auto& slot) {
    EXPECT_GT(std::abs(Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), slot.P)(0, 0) - cov), 1e-9);
  });
}

TEST(UnscentedKalmanFilter, WeightsSumToOne) {
  // alpha = 1/2, kappa = 0 on n = 1: lambda = -3/4, c = 1/4, w_m0 = -3, w_j = 2.
  const auto f = UnscentedKalmanFilter<SineModel, Kokkos::HostSpace>::with_parameters(0.5, 0.0, 0.0);
  EXPECT_NEAR(f.wm0 + 2 * f.wj, 1.0, 1e-15);
  EXPECT_NEAR(f.scale * f.scale, 0.25, 1e-15);
}

}  // namespace
}  // namespace kushner
