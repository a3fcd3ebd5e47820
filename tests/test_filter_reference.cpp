// The reference seam (engine/reference_estimator.hpp) that the particle filter plugs into: with the truths
// themselves as the "reference", every filter's rmse_ref equals its rmse_truth exactly, and a reference that
// is off by a constant shows up as that offset. An estimator added to the bank is scored like a filter.
#include "engine/filter_bank.hpp"
#include "models/sine_model.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace kushner {
namespace {

using Space = Kokkos::DefaultExecutionSpace;
using MemSpace = Space::memory_space;

/// The truths, shifted by `offset`, as a reference mean.
class ShiftedTruth : public ReferenceEstimator<MemSpace> {
 public:
  ShiftedTruth(BankVector<MemSpace> truth, double offset)
      : truth_(truth),
        mean_("shifted_truth", truth.extent(0), truth.extent(1)),
        covariance_("shifted_truth_cov", truth.extent(0), packed_size(static_cast<int>(truth.extent(1)))),
        status_("shifted_truth_status", truth.extent(0)),
        offset_(offset) {
    Kokkos::deep_copy(covariance_, 1.0);  // a 1-D bank: P = 1
    copy();
  }
  std::string name() const override { return "SHIFTED"; }
  void advance(long, double, double, const BankVector<MemSpace>&) override { copy(); }
  BankVector<MemSpace> mean() const override { return mean_; }
  BankSymmetric<MemSpace> covariance() const override { return covariance_; }
  BankScalar<Status, MemSpace> status() const override { return status_; }
  Fields describe() const override { return {{"kind", std::string("test")}}; }

 private:
  void copy() {
    Kokkos::deep_copy(mean_, truth_);
    const auto host = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mean_);
    for (std::size_t i = 0; i < host.extent(0); ++i) host(i, 0) += offset_;
    Kokkos::deep_copy(mean_, host);
  }
  BankVector<MemSpace> truth_, mean_;
  BankSymmetric<MemSpace> covariance_;
  BankScalar<Status, MemSpace> status_;
  double offset_;
};

template <class Bank>
FilterScores run(Bank& bank, ReferenceEstimator<MemSpace>& reference, long steps, const char* filter) {
  bank.set_reference(&reference);
  for (long k = 0; k < steps; ++k) bank.step(k, 0.01, k + 1 == steps);
  return bank.scores(filter, steps + 1);
}

TEST(FilterReference, TruthAsReferenceGivesRmseRefEqualToRmseTruth) {
  const SineModel model;
  FilterBank<Space, SineModel> bank(Space(), model, model, 1000, 9, {"EKF", "QLF"});
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
  FilterBank<Space, SineModel> bank(Space(), model, model, 1000, 9, {"EKF"});
  ShiftedTruth shifted(bank.truths().state(), 10.0);
  const FilterScores ekf = run(bank, shifted, 200, "EKF");
  EXPECT_NEAR(ekf.rmse_ref.value, 10.0, 2 * ekf.rmse_truth.value);
  EXPECT_GT(ekf.rmse_ref.value, 5.0);
}

TEST(FilterReference, AddedEstimatorIsScoredLikeAFilter) {
  // The shifted truth as an outside estimator beside the bank: its rmse_truth is the shift exactly, its NEES
  // the shift squared (P = 1), and since it is not the reference it gets no rmse_ref.
  const SineModel model;
  FilterBank<Space, SineModel> bank(Space(), model, model, 100, 9, {"EKF"});
  ShiftedTruth shifted(bank.truths().state(), 0.5);
  bank.add_estimator(&shifted);
  for (long k = 0; k < 50; ++k) bank.step(k, 0.01, k + 1 == 50);
  const FilterScores s = bank.scores("SHIFTED", 51);
  EXPECT_NEAR(s.rmse_truth.value, 0.5, 1e-12);
  EXPECT_NEAR(s.nees.value, 0.25, 1e-12);
  EXPECT_TRUE(std::isnan(s.rmse_ref.value));
  EXPECT_EQ(s.diverged, 0);
  EXPECT_NEAR(bank.snapshot("SHIFTED").rmse_truth, 0.5, 1e-12);
}

}  // namespace
}  // namespace kushner
