// FilterBank::start_segment (a host bank's steps taken several at a time, each block of members through all of them:
// kernels/filters/filter_bank_segment.hpp) against the same bank stepped one step at a time: the snapshots of every
// output step, the watched members at each output time, and all the bank holds at the end (truths, each filter's m,
// P, status, score sums and snapshot columns) are the same bits. For sine with every filter it supports (lanes that
// write the block's sink, and EnKBF and ASRE, which step member by member into the snapshot columns), the cubic
// sensor (SOF loses positive definiteness on some members: the divergence counts), and a discrete-time model. 1190
// members: four whole blocks of 256 and a short one of 166 (a block goes in runs of 128 members, its steps one at a
// time in chunks of 32: the short block's runs of 128 and 38 against chunks of 32 and one of 6). The same for the team
// form (a GPU's segments), on the host and, where the build has one, on the device. Then run_filters, which takes
// segments from 4096 members, against a bank stepped by hand.
#include "engine/filter_run.hpp"
#include "kernels/filters/filter_list.hpp"
#include "models/cubic_sensor_model.hpp"
#include "models/linear_discrete_model.hpp"
#include "models/sine_model.hpp"
#include "tests/filter_test_helpers.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

namespace kushner {
namespace {

using test::same_bits;

using Space = Kokkos::DefaultHostExecutionSpace;
using MemSpace = Space::memory_space;
using DeviceSpace = Kokkos::DefaultExecutionSpace;
constexpr bool have_device = !std::is_same<DeviceSpace, Space>::value;

/// The same bits (`relative` 0), or both NaN or within `relative` of each other (a GPU's two kernels: nvcc may contract
/// multiply-adds differently in each).
bool matches(double a, double b, double relative) {
  if (relative == 0.0 || same_bits(a, b)) return same_bits(a, b);
  if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b);
  return std::abs(a - b) <= relative * std::max(std::abs(a), std::abs(b));
}

void expect_same_snapshots(const std::vector<FilterSnapshot>& steps, const std::vector<FilterSnapshot>& segments,
                           const std::string& where, double relative = 0.0) {
  ASSERT_EQ(steps.size(), segments.size()) << where;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    const FilterSnapshot &a = steps[i], &b = segments[i];
    EXPECT_TRUE(matches(a.rmse_truth, b.rmse_truth, relative))
        << where << " filter " << i << ": " << a.rmse_truth << " vs " << b.rmse_truth;
    EXPECT_TRUE(matches(a.rmse_truth_se, b.rmse_truth_se, relative)) << where << " filter " << i;
    EXPECT_TRUE(matches(a.nees, b.nees, relative)) << where << " filter " << i << ": " << a.nees << " vs " << b.nees;
    EXPECT_TRUE(matches(a.nees_se, b.nees_se, relative)) << where << " filter " << i;
    EXPECT_TRUE(matches(a.rmse_ref, b.rmse_ref, relative)) << where << " filter " << i;
    EXPECT_EQ(a.diverged, b.diverged) << where << " filter " << i;
  }
}

template <class View>
void expect_same_view(const View& a, const View& b, const std::string& what, double relative = 0.0) {
  const auto ha = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), a);
  const auto hb = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), b);
  ASSERT_EQ(ha.span(), hb.span()) << what;
  long differ = 0;
  for (std::size_t i = 0; i < ha.span(); ++i) {
    if constexpr (std::is_same<typename View::non_const_value_type, double>::value)
      differ += matches(ha.data()[i], hb.data()[i], relative) ? 0 : 1;
    else
      differ += ha.data()[i] == hb.data()[i] ? 0 : 1;
  }
  EXPECT_EQ(differ, 0) << what << ": entries that differ";
}

/// f(view) for each view an observer reads of a member, in order: the truths, then each filter's m and P.
template <class Bank, class F>
void for_each_observed_view(const Bank& bank, const std::vector<std::string>& filters, const F& f) {
  f(bank.truths().state());
  for (const auto& name : filters)
    bank.with_slot(name, [&](const auto& slot) {
      f(slot.m);
      f(slot.P);
    });
}

/// The values of `member` an observer at an output time reads.
template <class Bank>
std::vector<double> member_values(const Bank& bank, const std::vector<std::string>& filters, long member) {
  std::vector<double> values;
  for_each_observed_view(bank, filters, [&](const auto& view) {
    const auto row = host_copy(Kokkos::subview(view, member, Kokkos::ALL));
    for (std::size_t i = 0; i < row.extent(0); ++i) values.push_back(row(i));
  });
  return values;
}

/// Steps [0, sum of `segments`) with output steps at the ends of steps `output_ends` (k + 1 for step k), one step at a
/// time and in segments of the given sizes, members `watched` read at each output time (a segment copies their
/// elements as it takes an output step); then everything compared:
/// the same bits on the host (`teams`: the team form of a GPU's segments), within `relative` on a device.
template <class Model, class BankSpace = Space>
void expect_segments_match_steps(const Model& model, const std::vector<std::string>& filters, double dt,
                                 const std::vector<int>& segments, const std::vector<long>& output_ends,
                                 bool teams = false, double relative = 0.0) {
  constexpr long members = 1190;
  const std::vector<long> watched{0, 700};
  const Seed seed(20261128);
  using Bank = FilterBank<BankSpace, Model>;
  Bank steps(BankSpace(), model, model, members, seed, filters);
  Bank segmented(BankSpace(), model, model, members, seed, filters);
  segmented.set_segment_teams(teams);
  long total = 0;
  for (const int size : segments) total += size;
  const auto is_output = [&](long end) {
    return std::find(output_ends.begin(), output_ends.end(), end) != output_ends.end();
  };

  std::vector<std::vector<FilterSnapshot>> step_snapshots;
  std::vector<std::vector<double>> step_watched;
  for (long k = 0; k < total; ++k) {
    const bool record = is_output(k + 1);
    steps.step(k, dt, record);
    if (!record) continue;
    step_snapshots.push_back(steps.snapshots(filters));
    for (const long member : watched) step_watched.push_back(member_values(steps, filters, member));
  }
  ASSERT_EQ(step_snapshots.size(), output_ends.size());

  // As run_filters takes them: a segment finished once the next one is started (its outputs' sums then in the other
  // half of the team form's buffers).
  std::vector<std::vector<FilterSnapshot>> segment_snapshots;
  std::vector<std::vector<double>> segment_watched;
  const std::vector<WatchedElement> elements = segmented.member_elements(watched, filters);
  const auto finish_segment = [&] {
    for (const auto& output : segmented.finish_segment()) {
      segment_snapshots.push_back(output.snapshots);
      ASSERT_EQ(output.watched.size(), elements.size());
      const std::size_t per_member = elements.size() / watched.size();
      for (std::size_t i = 0; i < watched.size(); ++i)
        segment_watched.emplace_back(output.watched.begin() + i * per_member,
                                     output.watched.begin() + (i + 1) * per_member);
    }
  };
  long k = 0;
  for (const int size : segments) {
    std::vector<char> outputs(size);
    for (int s = 0; s < size; ++s) outputs[s] = is_output(k + s + 1) ? 1 : 0;
    segmented.start_segment(k, dt, outputs, filters, elements);
    if (k > 0) finish_segment();
    k += size;
  }
  finish_segment();
  ASSERT_EQ(segment_snapshots.size(), step_snapshots.size());
  for (std::size_t o = 0; o < step_snapshots.size(); ++o)
    expect_same_snapshots(step_snapshots[o], segment_snapshots[o], "output at step " + std::to_string(output_ends[o]),
                          relative);
  ASSERT_EQ(segment_watched.size(), step_watched.size());
  for (std::size_t i = 0; i < step_watched.size(); ++i) {
    ASSERT_EQ(segment_watched[i].size(), step_watched[i].size());
    for (std::size_t j = 0; j < step_watched[i].size(); ++j)
      EXPECT_TRUE(matches(segment_watched[i][j], step_watched[i][j], relative))
          << "watched member " << watched[i % watched.size()] << " at output " << i / watched.size() << ", value " << j;
  }

  expect_same_view(steps.truths().state(), segmented.truths().state(), "truths", relative);
  expect_same_view(steps.truths().observations(), segmented.truths().observations(), "observations", relative);
  expect_same_view(steps.truth_status(), segmented.truth_status(), "truth status");
  for (const auto& name : filters) {
    steps.with_slot(name, [&](const auto& a) {
      segmented.with_slot(name, [&](const auto& b) {
        expect_same_view(a.m, b.m, name + " m", relative);
        expect_same_view(a.P, b.P, name + " P", relative);
        expect_same_view(a.status, b.status, name + " status");
        expect_same_view(a.score, b.score, name + " score sums", relative);
        expect_same_view(a.snapshot, b.snapshot, name + " snapshot columns", relative);
      });
    });
    const FilterScores a = steps.scores(name, total + 1), b = segmented.scores(name, total + 1);
    EXPECT_TRUE(matches(a.rmse_truth.value, b.rmse_truth.value, relative)) << name;
    EXPECT_TRUE(matches(a.nees.value, b.nees.value, relative)) << name;
    EXPECT_EQ(a.diverged, b.diverged) << name;
  }
}

TEST(FilterBankSegments, SineWithEveryFilterGivesTheNumbersOfStepsOneAtATime) {
  // Outputs: at a segment's first step, inside it, at its end, two in a row; the last one before the last step.
  expect_segments_match_steps(SineModel{}, supported_filters(SineModel{}), 1e-2, {16, 3, 16, 5},
                              {1, 2, 7, 16, 17, 19, 30, 31, 38});
}

TEST(FilterBankSegments, DivergingMembersAreCountedAsOneStepAtATimeCountsThem) {
  const CubicSensorModel model;
  expect_segments_match_steps(model, {"SOF", "SOF-B", "EKF"}, 1e-2, {16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16},
                              {16, 50, 100, 150, 192});
  FilterBank<Space, CubicSensorModel> bank(Space(), model, model, 1100, Seed(20261128), {"SOF"});
  for (long k = 0; k < 192; ++k) bank.step(k, 1e-2, false);
  EXPECT_GT(bank.scores("SOF", 193).diverged, 0) << "no member diverged: the counts were not tested";
}

TEST(FilterBankSegments, DiscreteTimeModelGivesTheNumbersOfStepsOneAtATime) {
  expect_segments_match_steps(LinearDiscreteModel{}, supported_filters(LinearDiscreteModel{}), 1.0, {16, 9},
                              {1, 5, 16, 24});
}

// The team form (a GPU's segments: FilterBankTeamSegment, its rows merged by MergeBlockRows) run on the host, one
// thread per team: the same bits as a step at a time.
TEST(FilterBankSegments, TeamFormGivesTheNumbersOfStepsOneAtATime) {
  expect_segments_match_steps(SineModel{}, supported_filters(SineModel{}), 1e-2, {16, 3, 16, 5},
                              {1, 2, 7, 16, 17, 19, 30, 31, 38}, true);
  expect_segments_match_steps(CubicSensorModel{}, {"SOF", "SOF-B", "EKF"}, 1e-2,
                              {16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16}, {16, 50, 100, 150, 192}, true);
  expect_segments_match_steps(LinearDiscreteModel{}, supported_filters(LinearDiscreteModel{}), 1.0, {16, 9},
                              {1, 5, 16, 24}, true);
}

// On a GPU (skipped where the default space is the host's): the team form's kernel against the step kernel; each
// kernel compiled on its own, so equal to rounding.
TEST(FilterBankSegments, GpuSegmentsGiveTheNumbersOfStepsOneAtATime) {
  if constexpr (!have_device) {
    GTEST_SKIP() << "no device execution space in this build";
  } else {
    constexpr double relative = 1e-11;
    expect_segments_match_steps<SineModel, DeviceSpace>(SineModel{}, supported_filters(SineModel{}), 1e-2,
                                                        {16, 3, 16, 5}, {1, 2, 7, 16, 17, 19, 30, 31, 38}, true,
                                                        relative);
    expect_segments_match_steps<CubicSensorModel, DeviceSpace>(CubicSensorModel{}, {"SOF", "SOF-B", "EKF"}, 1e-2,
                                                               {16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16},
                                                               {16, 50, 100, 150, 192}, true, relative);
    expect_segments_match_steps<LinearDiscreteModel, DeviceSpace>(
        LinearDiscreteModel{}, supported_filters(LinearDiscreteModel{}), 1.0, {16, 9}, {1, 5, 16, 24}, true, relative);
  }
}

/// The observer's view of run_filters' watched members (copied by the segments at each output step), and the report,
/// against a bank stepped one step at a time.
TEST(FilterBankSegments, RunFiltersTakesSegmentsWithTheNumbersOfStepsOneAtATime) {
  constexpr long members = segment_min_members + 300;
  const std::vector<std::string> filters{"EKF", "SOF", "QLF", "KBL"};
  const TimeGrid grid = make_time_grid(0.05, 1e-3, 20);  // 50 steps, outputs every 2
  const std::uint32_t seed = 11;
  const std::vector<long> watched{2, members - 1};
  using Bank = FilterBank<Space, SineModel>;
  const auto watched_values = [&](const Bank& bank) {
    std::vector<double> values;
    for (const long m : watched) {
      const std::vector<double> v = member_values(bank, filters, m);
      values.insert(values.end(), v.begin(), v.end());
    }
    return values;
  };
  std::vector<std::vector<double>> seen;
  long copied_by_segments = 0;
  OutputObserver<Space, SineModel> observer{
      [&](double, const Bank& bank, const auto&, const std::vector<double>* values) {
        seen.push_back(values ? *values : watched_values(bank));
        copied_by_segments += values ? 1 : 0;
      },
      [&](const Bank& bank) { return bank.member_elements(watched, filters); }};
  const FilterReport report =
      run_filters(Space(), SineModel{}, SineModel{}, members, seed, grid, filters, {}, {}, {}, observer);

  Bank bank(Space(), SineModel{}, SineModel{}, members, member_share(members).seed(seed), filters);
  std::vector<std::vector<double>> expected{watched_values(bank)};
  std::vector<std::vector<FilterSnapshot>> series{bank.snapshots(filters)};
  std::vector<double> times{0.0};
  for (long k = 0, o = 1; k < grid.steps; ++k) {
    const bool record = grid.output_steps[o] == k + 1;
    bank.step(k, grid.dt, record);
    if (!record) continue;
    ++o;
    series.push_back(bank.snapshots(filters));
    times.push_back((k + 1) * grid.dt);
    expected.push_back(watched_values(bank));
  }
  ASSERT_EQ(report.times.size(), times.size());
  for (std::size_t o = 0; o < times.size(); ++o) {
    EXPECT_TRUE(same_bits(report.times[o], times[o])) << o;
    expect_same_snapshots(series[o], report.series[o], "output " + std::to_string(o));
  }
  ASSERT_EQ(seen.size(), expected.size());
  for (std::size_t i = 0; i < seen.size(); ++i) {
    ASSERT_EQ(seen[i].size(), expected[i].size()) << "observer's read " << i;
    for (std::size_t j = 0; j < seen[i].size(); ++j)
      EXPECT_TRUE(same_bits(seen[i][j], expected[i][j])) << "observer's read " << i << ", value " << j;
  }
  EXPECT_EQ(copied_by_segments, static_cast<long>(times.size()) - 1) << "run_filters took no segments";
  for (std::size_t f = 0; f < filters.size(); ++f) {
    const FilterScores s = bank.scores(filters[f], grid.steps + 1);
    EXPECT_TRUE(same_bits(report.scores[f].rmse_truth.value, s.rmse_truth.value)) << filters[f];
    EXPECT_TRUE(same_bits(report.scores[f].nees.value, s.nees.value)) << filters[f];
  }
}

}  // namespace
}  // namespace kushner
