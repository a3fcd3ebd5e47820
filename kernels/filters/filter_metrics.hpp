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

/// counts(b, s) = members of block b (moment_block_size members) whose truth is ok and whose status in column s is
/// not: one (block, column) pair per index i = s * blocks + b, like the moments' blocks. (For 1e6 members and 4
/// filters on an H100, a Kokkos array reduction over members took 197 us per call; this takes 64 us.)
template <class MemSpace>
struct BlockNotOkCounts {
  Kokkos::View<const std::uintptr_t*, MemSpace> statuses;  // column s at (const Status*) statuses(s)
  BankScalar<Status, MemSpace> truth_status;
  Kokkos::View<int**, Kokkos::LayoutRight, MemSpace> counts;

  KOKKOS_INLINE_FUNCTION void operator()(const int i) const {
    const int num_blocks = static_cast<int>(counts.extent(0)), b = i % num_blocks, s = i / num_blocks;
    const Status* status = reinterpret_cast<const Status*>(statuses(s));
    const int end = block_end(b, static_cast<int>(truth_status.extent(0)));
    int count = 0;
    for (int m = b * moment_block_size; m < end; ++m)
      count += truth_status(m) == Status::ok && status[m] != Status::ok ? 1 : 0;
    counts(b, s) = count;
  }
};

/// For each of `statuses` (filters of one bank): count_status of not_positive_definite plus that of non_finite
/// among the members whose truth is ok, over every rank; one kernel and one copy for all of them. Keeps its device
/// list of the columns and its buffers from call to call, like ColumnMoments.
template <class ExecSpace>
class DivergedCounts {
 public:
  using MemSpace = typename ExecSpace::memory_space;

  std::vector<long> operator()(const ExecSpace& space, const std::vector<BankScalar<Status, MemSpace>>& statuses,
                               const BankScalar<Status, MemSpace>& truth_status) {
    std::vector<long> totals(statuses.size(), 0);
    if (statuses.empty()) return totals;
    std::vector<std::uintptr_t> addresses;
    for (const auto& s : statuses) {
      KUSHNER_REQUIRE(s.extent(0) == truth_status.extent(0), "DivergedCounts: a status column of another bank");
      addresses.push_back(reinterpret_cast<std::uintptr_t>(s.data()));
    }
    const int members = static_cast<int>(truth_status.extent(0));
    const int num_blocks = static_cast<int>(moment_blocks(members));
    const int columns = static_cast<int>(statuses.size());
    if (counts_.extent(0) != static_cast<std::size_t>(num_blocks) || counts_.extent(1) != statuses.size()) {
      counts_ = decltype(counts_)(Kokkos::view_alloc(space, Kokkos::WithoutInitializing, "kushner::diverged_counts"),
                                  num_blocks, columns);
      // The counts themselves in host memory; a page-locked copy of them on a GPU.
      host_ = Kokkos::create_mirror_view(typename HostStaging<MemSpace>::space(), counts_);
    }
    Kokkos::parallel_for("kushner::diverged_counts", Kokkos::RangePolicy<ExecSpace>(space, 0, num_blocks * columns),
                         BlockNotOkCounts<MemSpace>{columns_.update(space, addresses), truth_status, counts_});
    space.fence();
    if (host_.data() != counts_.data()) Kokkos::deep_copy(host_, counts_);
    for (int b = 0; b < num_blocks; ++b)
      for (int s = 0; s < columns; ++s) totals[s] += host_(b, s);
    for (auto& t : totals) t = collective::sum(t);  // every rank, the same calls in the same order
    return totals;
  }

 private:
  using HostCounts = Kokkos::View<int**, Kokkos::LayoutRight, typename HostStaging<MemSpace>::space>;
  DeviceAddresses<MemSpace> columns_;
  Kokkos::View<int**, Kokkos::LayoutRight, MemSpace> counts_;
  HostCounts host_;
};

}  // namespace kushner
