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
#include "kernels/host_copy.hpp"
#include "kernels/queue_mark.hpp"

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

/// counts(s) = members whose truth is ok and whose status in column s is not: one thread per member, an atomic add
/// where a member counts (a diverged filter: rare). Integer adds, so any order gives the same count. (For 1e6
/// members and 4 filters on an H100: a Kokkos array reduction over members took 197 us per call, a thread per
/// 256-member block and column 64 us, a team per block and column 46 us on an H200.)
template <class MemSpace>
struct NotOkCounts {
  Kokkos::View<const std::uintptr_t*, MemSpace> statuses;  // column s at (const Status*) statuses(s)
  BankScalar<Status, MemSpace> truth_status;
  Kokkos::View<int*, MemSpace> counts;

  KOKKOS_INLINE_FUNCTION void operator()(const int m) const {
    if (truth_status(m) != Status::ok) return;
    for (int s = 0; s < static_cast<int>(counts.extent(0)); ++s)
      if (reinterpret_cast<const Status*>(statuses(s))[m] != Status::ok) Kokkos::atomic_increment(&counts(s));
  }
};

/// For each of `statuses` (filters of one bank): count_status of not_positive_definite plus that of non_finite
/// among the members whose truth is ok, over every rank; one kernel (after zeroing the counters) and one copy for all
/// of them. Keeps its device list of the columns and its buffers from call to call, like ColumnMoments.
template <class ExecSpace>
class DivergedCounts {
 public:
  using MemSpace = typename ExecSpace::memory_space;

  std::vector<long> operator()(const ExecSpace& space, const std::vector<BankScalar<Status, MemSpace>>& statuses,
                               const BankScalar<Status, MemSpace>& truth_status) {
    start(space, statuses, truth_status);
    return finish();
  }

  /// Queues the counts on `space` (kernel and copy to the host), like ColumnMoments::start; finish() waits and sums.
  void start(const ExecSpace& space, const std::vector<BankScalar<Status, MemSpace>>& statuses,
             const BankScalar<Status, MemSpace>& truth_status) {
    columns_count_ = static_cast<int>(statuses.size());
    if (columns_count_ == 0) return;
    std::vector<std::uintptr_t> addresses;
    for (const auto& s : statuses) {
      KUSHNER_REQUIRE(s.extent(0) == truth_status.extent(0), "DivergedCounts: a status column of another bank");
      addresses.push_back(reinterpret_cast<std::uintptr_t>(s.data()));
    }
    if (counts_.extent(0) != statuses.size()) {
      counts_ = Kokkos::View<int*, MemSpace>(Kokkos::view_alloc(space, "kushner::diverged_counts"), columns_count_);
      // The counts themselves in host memory; a page-locked copy of them on a GPU.
      host_ = Kokkos::create_mirror_view(typename HostStaging<MemSpace>::space(), counts_);
    }
    Kokkos::deep_copy(space, counts_, 0);
    Kokkos::parallel_for("kushner::diverged_counts",
                         Kokkos::RangePolicy<ExecSpace>(space, 0, static_cast<long>(truth_status.extent(0))),
                         NotOkCounts<MemSpace>{columns_.update(space, addresses), truth_status, counts_});
    if (host_.data() != counts_.data()) Kokkos::deep_copy(space, host_, counts_);
    done_.record(space);
  }

  /// The counts start() queued, per status column, over every rank (a collective call); like
  /// ColumnMoments::finish, waits for start()'s work only.
  std::vector<long> finish() {
    std::vector<long> totals(columns_count_, 0);
    if (columns_count_ == 0) return totals;
    done_.wait();
    for (int s = 0; s < columns_count_; ++s) totals[s] = collective::sum(static_cast<long>(host_(s)));
    return totals;
  }

 private:
  using HostCounts = Kokkos::View<int*, typename HostStaging<MemSpace>::space>;
  DeviceAddresses<MemSpace> columns_;
  Kokkos::View<int*, MemSpace> counts_;
  HostCounts host_;
  int columns_count_ = 0;  // of the last start()
  QueueMark<ExecSpace> done_;
};

}  // namespace kushner
