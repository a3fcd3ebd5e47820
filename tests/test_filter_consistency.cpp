// Kalman-Bucy on a linear model is consistent: with the truths following the filter's own model, the mean
// NEES over time and 10^4 members is the state dimension to within 3 standard errors (the bank's step is
// the exact Kalman filter of the Euler-Maruyama truths, so E[NEES] = n at every time, not just as dt -> 0).
// Power: a filter that assumes half the process noise intensity must fail the same test.
#include "engine/filter_run.hpp"
#include "kernels/filters/filter_list.hpp"
#include "models/linear_model.hpp"

#include <gtest/gtest.h>

#include <cmath>

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

}  // namespace
}  // namespace kushner
