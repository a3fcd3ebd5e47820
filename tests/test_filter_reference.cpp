// The reference-mean seam (drivers/reference_mean.hpp) that a particle filter plugs into: with the truths
// themselves as the "reference", every filter's rmse_ref equals its rmse_truth exactly, and a reference that
// is off by a constant shows up as that offset.
#include "drivers/filter_bank.hpp"
#include "models/sine_model.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace kushner {
namespace {

using Space = Kokkos::DefaultExecutionSpace;
using MemSpace = Space::memory_space;

/// The truths, shifted by `offset`, as a reference mean.
class ShiftedTruth : public ReferenceMean<MemSpace> {
 public:
  ShiftedTruth(BankVector<MemSpace> truth, double offset)
      : truth_(truth), mean_("shifted_truth", truth.extent(0), truth.extent(1)), offset_(offset) {
    copy();
  }
  std::string name() const override { return "shifted-truth"; }
  void advance(long, double, double, const BankVector<MemSpace>&) override { copy(); }
  BankVector<MemSpace> mean() const override { return mean_; }

 private:
  void copy() {
    Kokkos::deep_copy(mean_, truth_);
    const auto host = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mean_);
    for (std::size_t i = 0; i < host.extent(0); ++i) host(i, 0) += offset_;
    Kokkos::deep_copy(mean_, host);
  }
  BankVector<MemSpace> truth_, mean_;
  double offset_;
};

template <class Bank>
FilterScores run(Bank& bank, ReferenceMean<MemSpace>& reference, long steps, const char* filter) {
  bank.set_reference(&reference);
  for (long k = 0; k < steps; ++k) bank.step(k, 0.01, k + 1 == steps);
  return bank.scores(filter, steps + 1);
}

TEST(FilterReference, TruthAsReferenceGivesRmseRefEqualToRmseTruth) {
  const SineModel model;
  FilterBank<Space, SineModel> bank(Space(), model, model, 1000, 9, {"EKF", "QLF"}, FilterConfig{});
  ShiftedTruth truth(bank.truths().state(), 0.0);
  const FilterScores ekf = run(bank, truth, 200, "EKF");
  EXPECT_EQ(ekf.rmse_ref.value, ekf.rmse_truth.value);
  EXPECT_EQ(ekf.rmse_ref.standard_error, ekf.rmse_truth.standard_error);
  const FilterScores qlf = bank.scores("QLF", 201);
  EXPECT_EQ(qlf.rmse_ref.value, qlf.rmse_truth.value);
  EXPECT_EQ(bank.snapshot("QLF").rmse_ref, bank.snapshot("QLF").rmse_truth);
}

TEST(FilterReference, ShiftedReferenceShowsTheShift) {
  const SineModel model;
  FilterBank<Space, SineModel> bank(Space(), model, model, 1000, 9, {"EKF"}, FilterConfig{});
  ShiftedTruth shifted(bank.truths().state(), 10.0);
  const FilterScores ekf = run(bank, shifted, 200, "EKF");
  EXPECT_NEAR(ekf.rmse_ref.value, 10.0, 2 * ekf.rmse_truth.value);
  EXPECT_GT(ekf.rmse_ref.value, 5.0);
}

}  // namespace
}  // namespace kushner
