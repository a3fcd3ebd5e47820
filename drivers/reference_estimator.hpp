#pragma once
// Estimators that are not filters of the bank but run beside it on the same observation increments: the
// particle filter (the reference for the true conditional density, SPEC section 4) and the exact or grid
// filters. The bank scores each like a filter (rmse_truth, nees, diverged) and scores every filter against
// the one chosen as the reference (rmse_ref). Host-side polymorphism only: each implementation runs its own
// kernels, dispatched at compile time on the model.
#include "kernels/bank.hpp"
#include "kernels/status.hpp"

#include <nlohmann/json.hpp>

#include <string>

namespace kushner {

template <class MemSpace>
class ReferenceEstimator {
 public:
  virtual ~ReferenceEstimator() = default;
  /// The name in outputs and on the command line ("PF", "EXACT").
  virtual std::string name() const = 0;
  /// Takes step k over [t, t + dt] given dy(member, j), the increments the truths just produced.
  virtual void advance(long k, double t, double dt, const BankVector<MemSpace>& dy) = 0;
  /// (member, i): the current conditional mean; before the first step, the prior's.
  virtual BankVector<MemSpace> mean() const = 0;
  /// (member, packed k): the current conditional covariance.
  virtual BankSymmetric<MemSpace> covariance() const = 0;
  /// (member): ok while the member's estimate is usable.
  virtual BankScalar<Status, MemSpace> status() const = 0;
  /// What summary.json says about it: {"kind": ..., and the estimator's own figures}.
  virtual nlohmann::json describe() const = 0;
};

}  // namespace kushner
