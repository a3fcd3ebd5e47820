#pragma once
// The seam for a reference to score the filters against, per member: a particle filter's posterior mean
// (SPEC section 7: "distance to the particle-filter conditional mean"), or an exact filter where one exists.
// The filter bank calls advance() right after each of its steps with that step's observation increments,
// then compares every filter's m with mean(); the run reports rmse_ref and its standard error per filter.
#include "kernels/bank.hpp"

#include <string>

namespace kushner {

template <class MemSpace>
class ReferenceMean {
 public:
  virtual ~ReferenceMean() = default;
  /// Names the reference in outputs ("pf", "exact", ...).
  virtual std::string name() const = 0;
  /// Takes step k over [t, t + dt] given dy(member, j), the increments the truths just produced.
  virtual void advance(long k, double t, double dt, const BankVector<MemSpace>& dy) = 0;
  /// (member, i): the reference's current conditional mean; at time 0, its prior mean.
  virtual BankVector<MemSpace> mean() const = 0;
};

}  // namespace kushner
