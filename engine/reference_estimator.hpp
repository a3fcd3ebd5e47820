#pragma once
// Estimators that are not filters of the bank but run beside it on the same observation increments: the
// particle filter (the reference for the true conditional density, SPEC section 4) and the exact or grid
// filters. The bank scores each like a filter (rmse_truth, nees, diverged) and scores every filter against
// the one chosen as the reference (rmse_ref). Host-side polymorphism only: each implementation runs its own
// kernels, dispatched at compile time on the model.
#include "core/errors.hpp"
#include "core/fields.hpp"
#include "core/status.hpp"
#include "engine/particle_snapshot.hpp"
#include "engine/state_archive.hpp"
#include "kernels/bank.hpp"

#include <optional>
#include <string>
#include <vector>

namespace kushner {

/// The names under which the estimators beside the bank are selected and reported.
inline constexpr const char* particle_filter_name = "PF";
inline constexpr const char* exact_filter_name = "EXACT";

/// Whether `name` is an estimator beside the bank (PF, EXACT) rather than a filter of it.
inline bool is_outside_estimator(const std::string& name) {
  return name == particle_filter_name || name == exact_filter_name;
}

/// An estimate at one time: (member, i), (member, packed k), (member).
template <class MemSpace>
struct EstimateViews {
  BankVector<MemSpace> mean;
  BankSymmetric<MemSpace> covariance;
  BankScalar<Status, MemSpace> status;
};

template <class MemSpace>
class ReferenceEstimator {
 public:
  virtual ~ReferenceEstimator() = default;
  /// The name in outputs and in filter lists (particle_filter_name, exact_filter_name, ...).
  virtual std::string name() const = 0;
  /// Takes step k over [t, t + dt] given dy(member, j), the increments the truths produced over it. Read dy, not
  /// the bank's truths: in a step pair the bank is a step further on (FilterBank::step_pair).
  virtual void advance(long k, double t, double dt, const BankVector<MemSpace>& dy) = 0;
  /// Whether advance_pair takes two steps for less than two advance() calls cost (the particle filter's fused
  /// pass): the bank then scores step k after step k + 1 to call it (FilterBank::step_pair).
  virtual bool advances_in_pairs() const { return false; }
  /// Steps k (increments dy) and k + 1 (dy_next) over [t, t + 2 dt]; afterwards mean(), covariance() and status()
  /// are step k + 1's and first_of_pair() step k's. Only where advances_in_pairs().
  virtual void advance_pair(long /*k*/, double /*t*/, double /*dt*/, const BankVector<MemSpace>& /*dy*/,
                            const BankVector<MemSpace>& /*dy_next*/) {
    KUSHNER_REQUIRE(false, name() << ": does not advance in pairs");
  }
  /// The estimate after the first step of the last advance_pair.
  virtual EstimateViews<MemSpace> first_of_pair() const {
    KUSHNER_REQUIRE(false, name() << ": does not advance in pairs");
    return {};
  }
  /// mean(), covariance() and status() together.
  EstimateViews<MemSpace> estimate() const { return {mean(), covariance(), status()}; }
  /// (member, i): the current conditional mean; before the first step, the prior's.
  virtual BankVector<MemSpace> mean() const = 0;
  /// (member, packed k): the current conditional covariance.
  virtual BankSymmetric<MemSpace> covariance() const = 0;
  /// (member): ok while the member's estimate is usable.
  virtual BankScalar<Status, MemSpace> status() const = 0;
  /// What the summary says about it: "kind", and the estimator's own figures.
  virtual Fields describe() const = 0;
  /// Saves or loads what a checkpoint holds of it (engine/state_archive.hpp). Estimators that only
  /// `kushner reproduce` adds are never checkpointed.
  virtual void visit_state(StateArchive& /*archive*/) { KUSHNER_REQUIRE(false, name() << ": cannot be checkpointed"); }
  /// For an estimator made of particles: a host copy of the chosen members' particles and weights.
  virtual std::optional<ParticleSnapshot> particle_snapshot(const std::vector<int>& /*members*/) const {
    return std::nullopt;
  }
};

}  // namespace kushner
