#pragma once
// rmse_ref: the root mean squared distance between a filter's estimate and the particle-filter posterior
// mean (the approximation error against the true conditional density, SPEC section 7), accumulated over
// steps per member on the device and reduced over members on the host in member order (deterministic).
//   rmse_ref    = sqrt( mean over members m of D_m ),  D_m = mean over steps of |m_f - m_PF|^2
//   rmse_ref_se = SE(mean D_m) / (2 rmse_ref)          (delta method; members are independent)
// Members whose estimate or reference is not finite at a step are counted in `excluded`, not in the sums.
#include "kernels/bank.hpp"
#include "kernels/errors.hpp"
#include "kernels/math.hpp"

#include <Kokkos_Core.hpp>

#include <cmath>

namespace kushner {

template <class MemSpace>
struct AccumulateSquaredDistance {
  BankVector<MemSpace> estimate, reference;
  BankScalar<double, MemSpace> sum;
  BankScalar<int, MemSpace> count, excluded;
  KOKKOS_INLINE_FUNCTION void operator()(const int member) const {
    double d2 = 0.0;
    for (int i = 0; i < static_cast<int>(estimate.extent(1)); ++i) {
      const double d = estimate(member, i) - reference(member, i);
      d2 += d * d;
    }
    if (!math::is_finite(d2)) {
      excluded(member) += 1;
      return;
    }
    sum(member) += d2;
    count(member) += 1;
  }
};

struct ReferenceDistance {
  double rmse_ref = 0.0, rmse_ref_se = 0.0;
  long excluded = 0;  // member-steps left out (non-finite)
};

template <class ExecSpace>
class ReferenceDistanceAccumulator {
 public:
  using MemSpace = typename ExecSpace::memory_space;
  ReferenceDistanceAccumulator(const ExecSpace& space, int num_members)
      : space_(space), sum_("kushner::rmse_ref_sum", num_members), count_("kushner::rmse_ref_count", num_members),
        excluded_("kushner::rmse_ref_excluded", num_members) {}

  /// Adds one step: estimate and reference are (member, i) of the same shape.
  void add(const BankVector<MemSpace>& estimate, const BankVector<MemSpace>& reference) {
    KUSHNER_REQUIRE(estimate.extent(0) == sum_.extent(0) && reference.extent(0) == sum_.extent(0) &&
                        estimate.extent(1) == reference.extent(1),
                    "estimate and reference must both be (members, state_dim)");
    Kokkos::parallel_for("kushner::accumulate_reference_distance",
                         Kokkos::RangePolicy<ExecSpace>(space_, 0, sum_.extent(0)),
                         AccumulateSquaredDistance<MemSpace>{estimate, reference, sum_, count_, excluded_});
  }

  ReferenceDistance result() const {
    space_.fence();
    const auto sum = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), sum_);
    const auto count = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), count_);
    const auto excluded = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), excluded_);
    ReferenceDistance r;
    double mean = 0.0, m2 = 0.0;
    long n = 0;
    for (int m = 0; m < sum.extent_int(0); ++m) {  // Welford, member order
      r.excluded += excluded(m);
      if (count(m) == 0) continue;
      const double d = sum(m) / count(m);
      ++n;
      const double delta = d - mean;
      mean += delta / n;
      m2 += delta * (d - mean);
    }
    r.rmse_ref = std::sqrt(mean);
    r.rmse_ref_se = (n > 1 && mean > 0.0) ? std::sqrt(m2 / (n - 1) / n) / (2.0 * r.rmse_ref) : 0.0;
    return r;
  }

 private:
  ExecSpace space_;
  BankScalar<double, MemSpace> sum_;
  BankScalar<int, MemSpace> count_, excluded_;
};

}  // namespace kushner
