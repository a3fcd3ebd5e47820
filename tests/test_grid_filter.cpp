// The grid (point-mass) filter: against the exact Kalman filter on linear models (1-D, 2-D), and against the
// particle filter on the sine model (the acceptance test: agreement within 4 Monte Carlo standard errors of
// the conditional mean) and the cubic oscillator.
#include "engine/particle_filter_bank.hpp"
#include "kernels/reference/grid_filter.hpp"
#include "kernels/reference/kalman_bucy_reference.hpp"
#include "models/cubic_oscillator_model.hpp"
#include "models/linear_model.hpp"
#include "models/sine_model.hpp"
#include "tests/reference_comparison.hpp"

#include <gtest/gtest.h>

namespace kushner {
namespace {

using test::Space;

template <class Estimator>
double worst_resolution(const Estimator& grid) {
  const auto r = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), grid.min_resolution());
  double worst = 1e300;
  for (int m = 0; m < r.extent_int(0); ++m) worst = std::min(worst, r(m));
  return worst;
}

template <int N>
double grid_error_against_kalman(const LinearModel<N>& model, int points, int members, int steps, double dt,
                                 double* posterior_sd) {
  const auto dys = test::record_observations(model, members, steps, dt, 97);
  KalmanBucyReference<Space, N> kb(Space(), model, members);
  const auto exact = test::replay(kb, dys, dt);
  GridFilter<Space, LinearModel<N>> grid(Space(), model, members, GridOptions{points});
  const auto approx = test::replay(grid, dys, dt);
  EXPECT_GT(worst_resolution(grid), 1.0);
  const auto P = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), kb.posterior_covariance());
  *posterior_sd = std::sqrt(P(0, 0));
  double worst = 0.0;
  for (std::size_t j = 0; j < exact.data.size(); ++j) worst = std::max(worst, std::abs(exact.data[j] - approx.data[j]));
  return worst;
}

TEST(GridFilter, LinearOneDimensionalMatchesKalman) {
  // Same discrete model, quadrature error only: the Gaussian kernel at sigma/h > 1 aliases at ~e^{-20}.
  LinearModel<1> model;
  double sd = 0.0;
  const double error = grid_error_against_kalman(model, 256, 4, 200, 0.01, &sd);
  RecordProperty("linear_1d_error_over_sd", std::to_string(error / sd));
  EXPECT_LT(error, 1e-6 * sd) << "posterior sd " << sd;
}

TEST(GridFilter, LinearTwoDimensionalMatchesKalman) {
  LinearModel<2> model;
  double sd = 0.0;
  const double error = grid_error_against_kalman(model, 128, 2, 100, 0.01, &sd);
  RecordProperty("linear_2d_error_over_sd", std::to_string(error / sd));
  EXPECT_LT(error, 1e-5 * sd) << "posterior sd " << sd;
}

/// The particle filter's posterior mean from `replicates` independent seeds on the same observations,
/// against a grid: z = (mean over replicates - grid) / (replicate SE) at every step and member.
struct Agreement {
  double bias, bias_se, rms_z;
};
template <class Model>
Agreement pf_against_grid(const Model& model, const Model& grid_model, int members, int particles, int replicates,
                          int steps, double dt, int points, double* resolution) {
  const auto dys = test::record_observations(model, members, steps, dt, 96);
  GridFilter<Space, Model> grid(Space(), grid_model, members, GridOptions{points});
  const auto g = test::replay(grid, dys, dt);
  *resolution = worst_resolution(grid);
  std::vector<test::Trajectory> runs;
  for (int r = 0; r < replicates; ++r) {
    ParticleFilterBank<Space, Model> pf(Space(), model, members, particles, 1000 + r);
    runs.push_back(test::replay(pf, dys, dt));
  }
  const std::size_t size = g.data.size();
  std::vector<double> run_bias(replicates, 0.0);
  double z2 = 0.0;
  for (std::size_t j = 0; j < size; ++j) {
    double mean = 0.0, var = 0.0;
    for (const auto& run : runs) mean += run.data[j] / replicates;
    for (const auto& run : runs) var += (run.data[j] - mean) * (run.data[j] - mean) / (replicates - 1);
    z2 += (mean - g.data[j]) * (mean - g.data[j]) / (var / replicates);
    for (int r = 0; r < replicates; ++r) run_bias[r] += (runs[r].data[j] - g.data[j]) / size;
  }
  double bias = 0.0, var = 0.0;
  for (double b : run_bias) bias += b / replicates;
  for (double b : run_bias) var += (b - bias) * (b - bias) / (replicates - 1);
  return {bias, std::sqrt(var / replicates), std::sqrt(z2 / size)};
}

// z of a pure Monte Carlo difference is Student t with R - 1 = 7 degrees of freedom: E z^2 = 7/5, RMS 1.18.
// RMS z < 2 therefore also rejects a grid that is off by about 1.6 Monte Carlo standard errors everywhere.
constexpr int replicates = 8;

TEST(GridFilter, SineAgreesWithParticleFilterWithinFourMonteCarloStandardErrors) {
  SineModel model;
  double resolution = 0.0;
  const auto a = pf_against_grid(model, model, 6, 8192, replicates, 200, 0.01, 256, &resolution);
  RecordProperty("sine", "bias " + std::to_string(a.bias) + " +- " + std::to_string(a.bias_se) + ", RMS z " +
                             std::to_string(a.rms_z) + ", resolution " + std::to_string(resolution));
  EXPECT_GT(resolution, 1.0);
  EXPECT_LT(std::abs(a.bias), 4.0 * a.bias_se) << a.bias << " SE " << a.bias_se;
  EXPECT_LT(a.rms_z, 2.0);
  SineModel off = model;  // power: a grid for q = 1.1 must be told apart
  off.q = 1.1;
  const auto b = pf_against_grid(model, off, 6, 8192, replicates, 200, 0.01, 256, &resolution);
  EXPECT_GT(b.rms_z, 2.0);
}

TEST(GridFilter, CubicOscillatorAgreesWithParticleFilter) {
  // Inside the well (seed 000's x(0) = (15, 10) escapes to infinity at t ~ 0.34: models/cubic_oscillator_model.hpp).
  CubicOscillatorModel model;
  model.q = 0.5;
  model.set_initial_law(Vec<2>{{1.0, 0.5}}, Mat<2, 2>::diagonal(0.09));
  double resolution = 0.0;
  const auto a = pf_against_grid(model, model, 3, 8192, replicates, 150, 0.01, 96, &resolution);
  RecordProperty("cubic", "bias " + std::to_string(a.bias) + " +- " + std::to_string(a.bias_se) + ", RMS z " +
                              std::to_string(a.rms_z) + ", resolution " + std::to_string(resolution));
  EXPECT_GT(resolution, 1.0);
  EXPECT_LT(std::abs(a.bias), 4.0 * a.bias_se) << a.bias << " SE " << a.bias_se;
  EXPECT_LT(a.rms_z, 2.0);
}

}  // namespace
}  // namespace kushner
