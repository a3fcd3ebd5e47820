// Kalman-Bucy on a linear model is consistent: with the truths following the filter's own model, the mean
// NEES over time and 10^4 members is the state dimension to within 3 standard errors (the bank's step is
// the exact Kalman filter of the Euler-Maruyama truths, so E[NEES] = n at every time, not just as dt -> 0).
// Power: a filter that assumes half the process noise intensity must fail the same test.
// Step pairs (FilterBank::step_pair: the bank scores one step behind so that the particle filter takes two steps per
// call) give the numbers of single steps, and their output times keep their reductions' buffers.
#include "engine/filter_run.hpp"
#include "kernels/filters/filter_list.hpp"
#include "models/linear_model.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>

namespace kushner {
namespace {

using Space = Kokkos::DefaultExecutionSpace;
constexpr std::uint32_t seed = 20261122;
constexpr long num_members = 10000;

template <int N>
Estimate kalman_bucy_nees(const LinearModel<N>& truth, const LinearModel<N>& filter) {
  const TimeGrid grid = make_time_grid(2.0, 0.01, 4);
  const FilterReport report = run_filters(Space(), truth, filter, num_members, seed, grid, {"KB"});
  EXPECT_EQ(report.scores[0].diverged, 0);
  EXPECT_EQ(report.scores[0].nees.members, num_members);
  return report.scores[0].nees;
}

TEST(KalmanBucyConsistency, NeesWithinThreeStandardErrorsOfStateDimension) {
  const LinearModel<1> one;
  const Estimate nees1 = kalman_bucy_nees(one, one);
  EXPECT_LT(std::abs(nees1.value - 1.0), 3.0 * nees1.standard_error) << nees1.value << " +- " << nees1.standard_error;

  LinearModel<3> three;
  three.C = Mat<3, 3>{{{1.0, 0.5, 0.0}, {0.0, 1.0, 0.2}, {0.3, 0.0, 1.0}}};
  const Estimate nees3 = kalman_bucy_nees(three, three);
  EXPECT_LT(std::abs(nees3.value - 3.0), 3.0 * nees3.standard_error) << nees3.value << " +- " << nees3.standard_error;

  LinearModel<3> overconfident = three;  // power: half the process noise intensity in the filter
  overconfident.b = overconfident.b * std::sqrt(0.5);
  const Estimate off = kalman_bucy_nees(three, overconfident);
  EXPECT_GT(off.value - 3.0, 3.0 * off.standard_error) << off.value << " +- " << off.standard_error;
}

/// The same bits, NaN included.
bool same(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

void expect_same_report(const FilterReport& a, const FilterReport& b, double relative) {
  ASSERT_EQ(a.times, b.times);
  ASSERT_EQ(a.filters, b.filters);
  const auto close = [relative](double x, double y) {
    return relative == 0.0 ? same(x, y) : (std::isnan(x) ? std::isnan(y) : std::abs(x - y) <= relative * std::abs(x));
  };
  for (std::size_t t = 0; t < a.times.size(); ++t)
    for (std::size_t f = 0; f < a.filters.size(); ++f) {
      const FilterSnapshot &x = a.series[t][f], &y = b.series[t][f];
      EXPECT_TRUE(close(x.rmse_truth, y.rmse_truth) && close(x.nees, y.nees) && close(x.rmse_ref, y.rmse_ref) &&
                  close(x.rmse_ref_se, y.rmse_ref_se) && x.diverged == y.diverged)
          << a.filters[f] << " at t = " << a.times[t] << ": rmse_truth " << x.rmse_truth << " / " << y.rmse_truth
          << ", rmse_ref " << x.rmse_ref << " / " << y.rmse_ref;
    }
  for (std::size_t f = 0; f < a.filters.size(); ++f) {
    const FilterScores &x = a.scores[f], &y = b.scores[f];
    EXPECT_TRUE(close(x.rmse_truth.value, y.rmse_truth.value) && close(x.nees.value, y.nees.value) &&
                close(x.rmse_ref.value, y.rmse_ref.value) &&
                close(x.rmse_ref.standard_error, y.rmse_ref.standard_error))
        << a.filters[f] << ": rmse_ref " << x.rmse_ref.value << " / " << y.rmse_ref.value;
  }
  for (const char* field : {"mean_ess", "noise_floor"})
    EXPECT_TRUE(close(std::get<double>(*find_field(a.estimators.at("PF"), field)),
                      std::get<double>(*find_field(b.estimators.at("PF"), field))))
        << field;
}

FilterReport run_with_pairs(StepPairs pairs, ParticleKernel kernel, const TimeGrid& grid) {
  ParticleSettings particle;
  particle.particles = 512;
  particle.step_pairs = pairs;
  particle.options.kernel = kernel;
  const LinearModel<1> model;
  return run_filters(Space(), model, model, 300, seed, grid, {"KB", "EKF", "PF", "EXACT"}, {}, particle);
}

std::string step_pairs_field(const FilterReport& report) {
  return std::get<std::string>(*find_field(report.estimators.at("PF"), "step_pairs"));
}

/// How many output times of `grid` fall in the middle of a step pair: pairs run from step 0, two steps at a time,
/// the last step single where the count is odd (engine/filter_run.hpp, without an observer).
long outputs_in_pairs(const TimeGrid& grid) {
  return std::count_if(grid.output_steps.begin(), grid.output_steps.end(),
                       [&](long step) { return step % 2 == 1 && step < grid.steps - grid.steps % 2; });
}

TEST(StepPairs, ScoringOneStepBehindGivesTheNumbersOfSingleSteps) {
  // 47 steps; an output time every 5 steps (some in the middle of a pair, whose metrics the pair queues), then every
  // step an output time (three output times' metrics queued at once); a single last step. Where the particle
  // filter does not fuse a pair its two steps are step() twice, so every score, snapshot and PF figure must be the
  // same bits as with single steps: any term scored against the wrong step's truth, estimate, status, snapshot
  // column or reference mean would change them.
  // (On a GPU the default kernel fuses them: there the first comparison is the second's.)
  for (const int points : {9, 48}) {
    const TimeGrid grid = make_time_grid(0.47, 0.01, points);
    ASSERT_GT(outputs_in_pairs(grid), points == 9 ? 4 : 22);
    const bool fuses = ParticleFilterBank<Space, LinearModel<1>>::fuses_step_pairs({}, 512);
    const FilterReport single = run_with_pairs(StepPairs::never, ParticleKernel::automatic, grid);
    const FilterReport pairs = run_with_pairs(StepPairs::always, ParticleKernel::automatic, grid);
    EXPECT_EQ(step_pairs_field(single), "off");
    EXPECT_EQ(step_pairs_field(pairs), fuses ? "fused" : "unfused");
    expect_same_report(single, pairs, fuses ? 1e-10 : 0.0);
    // The team kernel fuses the two steps into one pass on the host too (as on a GPU): the same numbers but for the
    // last bits of the sums.
    const FilterReport team_single = run_with_pairs(StepPairs::never, ParticleKernel::team, grid);
    const FilterReport team_fused = run_with_pairs(StepPairs::automatic, ParticleKernel::team, grid);
    EXPECT_EQ(step_pairs_field(team_fused), "fused");
    expect_same_report(team_single, team_fused, 1e-10);
  }
}

/// Allocations of the device copies of output reductions' column addresses (kernels/device_addresses.hpp): on a GPU
/// each one waits for the device (a copy from a host vector and a fence), and the host then launches the next kernels
/// onto an idle device.
long address_uploads = 0;
void count_address_uploads(const Kokkos::Tools::SpaceHandle, const char* label, const void*, const std::uint64_t) {
  if (std::strcmp(label, "kushner::device_addresses") == 0) ++address_uploads;
}

TEST(StepPairs, OutputTimesKeepTheirReductionsAddresses) {
  // An output time every 5th step falls in a pair's middle (the kept snapshot columns and statuses are reduced) and
  // at a pair's end (the bank's own) by turns: each kind of output time must find the buffers that reduced it last
  // time, so the uploads are as many for 30 output times as for 10.
  const auto uploads = [](double T) {
    address_uploads = 0;
    Kokkos::Tools::Experimental::set_allocate_data_callback(count_address_uploads);
    run_with_pairs(StepPairs::always, ParticleKernel::automatic,
                   make_time_grid(T, 0.01, static_cast<int>(std::lround(T / 0.05))));
    Kokkos::Tools::Experimental::set_allocate_data_callback(nullptr);
    return address_uploads;
  };
  const long ten_outputs = uploads(0.5), thirty_outputs = uploads(1.5);
  EXPECT_GT(ten_outputs, 0);
  EXPECT_EQ(thirty_outputs, ten_outputs);
}

}  // namespace
}  // namespace kushner
