// A bank filter driven to divergence: Schwartz's SOF on the cubic sensor (seed 000 Table 2 row [9]: the
// covariance has the dy-driven term P h'' P V^{-1} (dy - h_bar dt), h'' = 6 x, which no positive-definiteness
// guard bounds) loses positive definiteness on a share of the members, while SOF-B (the same filter without that
// term) does not. The test checks what the bank promises for such members: they are counted (`diverged`, by
// status), frozen (their m, P do not move again), and left out of every metric (the bank's rmse_truth and
// rmse_ref equal the ones recomputed from the members still running). Power: recomputed with the frozen members
// put back, both metrics differ from the reported ones, so the exclusion is what the check sees.
#include "engine/filter_bank.hpp"
#include "models/cubic_sensor_model.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace kushner {
namespace {

using Space = Kokkos::DefaultExecutionSpace;
using MemSpace = Space::memory_space;
constexpr long num_members = 500;
constexpr long num_steps = 400;
constexpr double dt = 0.01;

/// The truths themselves as the reference, so that rmse_ref is scored too.
class TruthReference final : public ReferenceEstimator<MemSpace> {
 public:
  explicit TruthReference(BankVector<MemSpace> truth)
      : truth_(truth), covariance_("truth_cov", truth.extent(0), 1), status_("truth_ref_status", truth.extent(0)) {
    Kokkos::deep_copy(covariance_, 1.0);
  }
  std::string name() const override { return "TRUTH"; }
  void advance(long, double, double, const BankVector<MemSpace>&) override {}
  BankVector<MemSpace> mean() const override { return truth_; }
  BankSymmetric<MemSpace> covariance() const override { return covariance_; }
  BankScalar<Status, MemSpace> status() const override { return status_; }
  Fields describe() const override { return {{"kind", std::string("test")}}; }

 private:
  BankVector<MemSpace> truth_;
  BankSymmetric<MemSpace> covariance_;
  BankScalar<Status, MemSpace> status_;
};

template <class View>
auto host(const View& v) {
  return Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), v);
}

TEST(FilterDivergence, DivergedMembersAreCountedFrozenAndLeftOutOfTheMetrics) {
  const CubicSensorModel model;
  FilterBank<Space, CubicSensorModel> bank(Space(), model, model, num_members, 20261125, {"SOF", "SOF-B"});
  TruthReference reference(bank.truths().state());
  bank.set_reference(&reference);
  for (long k = 0; k < num_steps; ++k) bank.step(k, dt, false);

  std::vector<double> frozen_m;
  std::vector<char> diverged_before;
  long diverged_by_status = 0;
  bank.with_slot("SOF", [&](const auto& slot) {
    const auto status = host(slot.status);
    const auto m = host(slot.m);
    for (long i = 0; i < num_members; ++i) {
      diverged_by_status += status(i) != Status::ok;
      diverged_before.push_back(status(i) != Status::ok);
      frozen_m.push_back(m(i, 0));
    }
  });
  const FilterScores sof = bank.scores("SOF", num_steps + 1);
  ASSERT_GT(diverged_by_status, 0) << "SOF did not diverge on the cubic sensor: the test needs a diverging filter";
  EXPECT_EQ(sof.diverged, diverged_by_status);
  EXPECT_EQ(sof.rmse_truth.members, num_members - diverged_by_status);
  EXPECT_EQ(bank.scores("SOF-B", num_steps + 1).diverged, 0);

  // Frozen: 50 more steps move no member that had diverged before them.
  for (long k = num_steps; k < num_steps + 50; ++k) bank.step(k, dt, false);
  bank.with_slot("SOF", [&](const auto& slot) {
    const auto m = host(slot.m);
    long moved_diverged = 0, moved_running = 0;
    for (long i = 0; i < num_members; ++i) {
      if (diverged_before[i] && m(i, 0) != frozen_m[i]) ++moved_diverged;
      if (!diverged_before[i] && m(i, 0) != frozen_m[i]) ++moved_running;
    }
    EXPECT_EQ(moved_diverged, 0);
    EXPECT_EQ(moved_running, num_members - diverged_by_status);  // the check can see a moving member
  });
  const long points = num_steps + 51;
  const FilterScores after = bank.scores("SOF", points);

  // Left out: the metrics recomputed from the per-member sums of the running members only.
  bank.with_slot("SOF", [&](const auto& slot) {
    const auto status = host(slot.status);
    const auto score = host(slot.score);
    double running = 0.0, all = 0.0;
    long count = 0;
    for (long i = 0; i < num_members; ++i) {
      const double mse = score(i, squared_error_sum) / points;
      all += mse / num_members;
      if (status(i) == Status::ok) running += mse, ++count;
    }
    running /= count;
    EXPECT_NEAR(after.rmse_truth.value, std::sqrt(running), 1e-12 * std::sqrt(running));
    EXPECT_NEAR(after.rmse_ref.value, std::sqrt(running), 1e-12 * std::sqrt(running));  // the truth is the reference
    // Power: with the frozen members put back the numbers differ by far more than that tolerance.
    EXPECT_GT(std::abs(std::sqrt(all) - after.rmse_truth.value), 1e-6 * after.rmse_truth.value)
        << "the diverged members' errors equal the others': the exclusion is not tested";
  });
}

}  // namespace
}  // namespace kushner
