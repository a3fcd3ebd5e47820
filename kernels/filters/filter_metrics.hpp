#pragma once
// Per-member metric kernels behind the bank's reports: time averages of the accumulated errors (NaN for a
// member that is not scored, so that ensemble_moments leaves it out and counts it) and status counts.
// Integer counts are order-independent, so a parallel_reduce keeps them deterministic.
#include "core/collectives.hpp"
#include "core/errors.hpp"
#include "core/math.hpp"
#include "core/status.hpp"
#include "kernels/bank.hpp"
#include "kernels/device_addresses.hpp"
#include "kernels/ensemble_moments.hpp"
#include "kernels/filters/filter_slot.hpp"

#include <Kokkos_Core.hpp>

#include <cstdint>
#include <vector>

namespace kushner {

/// Columns of MemberScores::out.
enum MemberScoreColumn : int {
  member_mean_squared_error = 0,
  member_mean_nees = 1,
  member_mean_squared_reference_error = 2,
  num_member_score_columns = 3
};

template <class MemSpace>
struct MemberScores {
  BankVector<MemSpace> score;  // (member, ScoreColumn)
  BankScalar<Status, MemSpace> status, truth_status;
  BankVector<MemSpace> out;  // (member, MemberScoreColumn)
  double points;             // time points accumulated
  bool has_reference;
  BankScalar<Status, MemSpace> reference_status;  // with has_reference: a member whose reference diverged has no
                                                  // rmse_ref (its sum stopped growing when the reference froze)

  KOKKOS_INLINE_FUNCTION void operator()(const int member) const {
    const bool scored = status(member) == Status::ok && truth_status(member) == Status::ok;
    const double nan = math::quiet_nan();
    out(member, member_mean_squared_error) = scored ? score(member, squared_error_sum) / points : nan;
    out(member, member_mean_nees) =
        scored && score(member, nees_points) > 0 ? score(member, nees_sum) / score(member, nees_points) : nan;
    out(member, member_mean_squared_reference_error) = scored && has_reference && reference_status(member) == Status::ok
                                                           ? score(member, reference_squared_error_sum) / points
                                                           : nan;
  }
};

/// Members with status `which` among those whose truth is ok (all members when truth_status is empty): a
/// filter that fails because its truth escaped to infinity has not diverged, its member just left the run.
template <class MemSpace>
struct CountStatus {
  BankScalar<Status, MemSpace> status, truth_status;
  Status which;
  KOKKOS_INLINE_FUNCTION void operator()(const int member, long& count) const {
    const bool counted = truth_status.extent(0) == 0 || truth_status(member) == Status::ok;
    count += counted && status(member) == which ? 1 : 0;
  }
};

template <class ExecSpace, class MemSpace>
long count_status(const ExecSpace& space, const BankScalar<Status, MemSpace>& status, Status which,
                  const BankScalar<Status, MemSpace>& truth_status = {}) {
  long count = 0;
  Kokkos::parallel_reduce("kushner::count_status", Kokkos::RangePolicy<ExecSpace>(space, 0, status.extent(0)),
                          CountStatus<MemSpace>{status, truth_status, which}, count);
  return collective::sum(count);  // over every rank's members
}

/// The divergences of a bank's filters as a Counted of its snapshot moments (BlockColumnStatistics, ColumnMoments):
/// member m counts in column s where its truth is ok and status column s is not, so a column's count is count_status
/// of not_positive_definite plus that of non_finite among the members whose truth is ok. Counted in the moments'
/// launch, per block, and summed with their rows: no launch, zeroing or atomic add of their own (on an H200, 1e6
/// members, 4 filters: a separate kernel with atomic adds took 24 us per output step and its zeroing 13 us).
template <class MemSpace>
struct NotOkMembers {
  Kokkos::View<const std::uintptr_t*, MemSpace> statuses;  // column s at (const Status*) statuses(s)
  BankScalar<Status, MemSpace> truth_status;

  /// A member counts where its truth is ok and its filter's status is not (both read: no branch between the reads,
  /// warp_block_count).
  KOKKOS_INLINE_FUNCTION static bool counts(const Status truth, const Status status) {
    return (truth == Status::ok) & (status != Status::ok);
  }

  KOKKOS_INLINE_FUNCTION int columns() const { return static_cast<int>(statuses.extent(0)); }
  KOKKOS_INLINE_FUNCTION bool operator()(const int s, const int m) const {
    return counts(truth_status(m), reinterpret_cast<const Status*>(statuses(s))[m]);
  }
  /// The members first .. first + 7 that count in column s (first a multiple of 8): each byte column read as one
  /// 64-bit word, its bytes tested at once (nonzero_bytes). On a GPU a warp counts a whole block so
  /// (warp_count): a read and test of each byte, 13 instructions per member and column, were a sixth of what an
  /// output step added to a segment of the sine bank (perf/filter_bank.md).
  KOKKOS_INLINE_FUNCTION int count_eight(const int s, const int first) const {
    static_assert(sizeof(Status) == 1 && static_cast<int>(Status::ok) == 0, "a status byte: ok is zero");
    const std::uint64_t status = *reinterpret_cast<const std::uint64_t*>(statuses(s) + first);
    const std::uint64_t truth = *reinterpret_cast<const std::uint64_t*>(truth_status.data() + first);
    const std::uint64_t counted = nonzero_bytes(status) & ~nonzero_bytes(truth);
#if KUSHNER_CUDA_DEVICE_PASS
    return __popcll(counted);
#else
    return __builtin_popcountll(counted);
#endif
  }

  /// The high bit of each byte of x that is not zero, the other bits clear: a byte's low seven bits plus 0x7f carry
  /// into its high bit where any is set, and never out of the byte.
  KOKKOS_INLINE_FUNCTION static std::uint64_t nonzero_bytes(const std::uint64_t x) {
    constexpr std::uint64_t low7 = 0x7f7f7f7f7f7f7f7full;
    return (((x & low7) + low7) | x) & ~low7;
  }

#if KUSHNER_CUDA_DEVICE_PASS
  /// The members m in [begin, end) that count in column s, by the 32 lanes of a warp (lane j this thread), every
  /// lane returning it: a whole block whose columns are 8-byte aligned by count_eight, lane j members begin + 8 j ..
  /// begin + 8 j + 7 (an integer: any order gives the same count); else a member at a time (warp_block_count).
  __device__ int warp_count(const int j, const int s, const int begin, const int end) const {
    static_assert(moment_block_size == 8 * moment_lanes, "a lane counts eight members of a block");
    const bool aligned = ((statuses(s) | reinterpret_cast<std::uintptr_t>(truth_status.data())) & 7u) == 0;
    if (end - begin == moment_block_size && aligned)
      return static_cast<int>(__reduce_add_sync(0xffffffffu, count_eight(s, begin + 8 * j)));
    return warp_block_count(
        j, [&](const int m) { return (*this)(s, m); }, begin, end);
  }
#endif

  /// The members m in [begin, end) that count in column s, on the host (FilterBankSegment): one plain loop over the
  /// two byte columns (operator() looks column s up for every member).
  int count(const int s, const int begin, const int end) const {
    const Status* const status = reinterpret_cast<const Status*>(statuses(s));
    const Status* const truth = truth_status.data();
    int count = 0;
    for (int m = begin; m < end; ++m) count += counts(truth[m], status[m]);
    return count;
  }
};

/// NotOkMembers of status columns of one bank; keeps its device list of the columns from call to call (a bank
/// counts the same columns at every output step).
template <class MemSpace>
class DivergedMembers {
 public:
  template <class ExecSpace>
  NotOkMembers<MemSpace> operator()(const ExecSpace& space, const std::vector<BankScalar<Status, MemSpace>>& statuses,
                                    const BankScalar<Status, MemSpace>& truth_status) {
    std::vector<std::uintptr_t> addresses;
    for (const auto& s : statuses) {
      KUSHNER_REQUIRE(s.extent(0) == truth_status.extent(0), "DivergedMembers: a status column of another bank");
      addresses.push_back(reinterpret_cast<std::uintptr_t>(s.data()));
    }
    return {columns_.update(space, addresses), truth_status};
  }

 private:
  DeviceAddresses<MemSpace> columns_;
};

}  // namespace kushner
