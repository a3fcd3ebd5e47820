#pragma once
// Ensemble means and variances in a fixed summation order, so that results are bitwise the same on any
// number of threads: each block of `moment_block_size` consecutive members is reduced in a fixed order
// (block_statistic), and the host merges the blocks in order (merge_block_statistics). A Kokkos parallel_reduce would
// combine partial sums in an order that depends on the thread count. Members with a non-finite entry (a path that
// escaped to infinity) are left out and counted. A run split over MPI ranks splits at block boundaries
// (engine/member_share.hpp): the blocks of every rank are gathered and merged in the same order, so the moments
// are the same bits for any number of ranks as well.
#include "core/collectives.hpp"
#include "core/errors.hpp"
#include "core/math.hpp"
#include "kernels/bank.hpp"
#include "kernels/device_addresses.hpp"
#include "kernels/host_copy.hpp"
#include "kernels/queue_mark.hpp"

#include <Kokkos_Core.hpp>

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace kushner {

constexpr int moment_block_size = 256;

/// Finite values, their mean and their sum of squared deviations from it, over one block of members.
struct BlockStatistic {
  double count = 0.0;
  double mean = 0.0;
  double m2 = 0.0;
};

/// Partial sums of a block statistic: member m of the block adds into lane (m - begin) % moment_lanes.
constexpr int moment_lanes = 32;

/// a[0] + ... + a[N - 1] as a balanced tree, (first half) + (second half): the fixed order the lanes are added in.
template <int N>
KOKKOS_INLINE_FUNCTION double pairwise_sum(const double* a) {
  if constexpr (N == 1)
    return a[0];
  else
    return pairwise_sum<N / 2>(a) + pairwise_sum<N - N / 2>(a + N / 2);
}

/// The BlockStatistic of value(m), m in [begin, end), leaving out non-finite values. Two passes (the sum, then the
/// squared deviations from the block's mean); in each, member m adds into lane (m - begin) % 32, in member order,
/// and the lanes are added by pairwise_sum. So no division per member (Welford's recurrence, a chain of dependent
/// divisions, made these reductions the slowest part of an output step on the host and on the GPU), 32 independent
/// chains (a loop the host compiler vectorizes, and on a GPU one lane per thread of a warp: team_block_statistic),
/// and the same bits on every backend and thread count (up to the multiply-adds a GPU contracts).
template <class Value>
KOKKOS_INLINE_FUNCTION BlockStatistic block_statistic(const Value& value, const int begin, const int end) {
  constexpr int L = moment_lanes;
  double count[L], sum[L];
  for (int j = 0; j < L; ++j) count[j] = sum[j] = 0.0;
  int m0 = begin;
  for (; m0 + L <= end; m0 += L)
    for (int j = 0; j < L; ++j) {
      const double v = value(m0 + j);
      const bool finite = math::is_finite(v);
      count[j] += finite ? 1.0 : 0.0;
      sum[j] += finite ? v : 0.0;
    }
  for (int j = 0; m0 + j < end; ++j) {
    const double v = value(m0 + j);
    const bool finite = math::is_finite(v);
    count[j] += finite ? 1.0 : 0.0;
    sum[j] += finite ? v : 0.0;
  }
  BlockStatistic s;
  s.count = pairwise_sum<L>(count);
  if (s.count == 0.0) return s;
  s.mean = pairwise_sum<L>(sum) / s.count;
  double ss[L];
  for (int j = 0; j < L; ++j) ss[j] = 0.0;
  m0 = begin;
  for (; m0 + L <= end; m0 += L)
    for (int j = 0; j < L; ++j) {
      const double v = value(m0 + j);
      const double d = math::is_finite(v) ? v - s.mean : 0.0;
      ss[j] += d * d;
    }
  for (int j = 0; m0 + j < end; ++j) {
    const double v = value(m0 + j);
    const double d = math::is_finite(v) ? v - s.mean : 0.0;
    ss[j] += d * d;
  }
  s.m2 = pairwise_sum<L>(ss);
  return s;
}

/// block_statistic by a team, one lane per thread (a GPU's warp: at each member step its 32 threads read 32
/// consecutive values), the lanes meeting in `lanes` (team scratch of 3 moment_lanes doubles): the same sums in
/// the same order, so the same bits. Every thread of the team returns the statistic.
template <class Team, class Value>
KOKKOS_INLINE_FUNCTION BlockStatistic team_block_statistic(const Team& team, const Value& value, const int begin,
                                                           const int end, double* lanes) {
  constexpr int L = moment_lanes;
  Kokkos::parallel_for(Kokkos::TeamThreadRange(team, L), [&](const int j) {
    double count = 0.0, sum = 0.0;
    for (int m = begin + j; m < end; m += L) {
      const double v = value(m);
      const bool finite = math::is_finite(v);
      count += finite ? 1.0 : 0.0;
      sum += finite ? v : 0.0;
    }
    lanes[j] = count;
    lanes[L + j] = sum;
  });
  team.team_barrier();
  BlockStatistic s;
  s.count = pairwise_sum<L>(lanes);
  if (s.count == 0.0) return s;  // the same branch in every thread
  s.mean = pairwise_sum<L>(lanes + L) / s.count;
  Kokkos::parallel_for(Kokkos::TeamThreadRange(team, L), [&](const int j) {
    double ss = 0.0;
    for (int m = begin + j; m < end; m += L) {
      const double v = value(m);
      const double d = math::is_finite(v) ? v - s.mean : 0.0;
      ss += d * d;
    }
    lanes[2 * L + j] = ss;
  });
  team.team_barrier();
  s.m2 = pairwise_sum<L>(lanes + 2 * L);
  return s;
}

/// The work tag of the block reductions' team forms (block_team_policy).
struct BlockTeams {};

/// Team scratch of team_block_statistic.
constexpr std::size_t block_team_scratch_bytes = sizeof(double) * 3 * moment_lanes;

/// The team policy of the block reductions' team forms (their operator() tagged BlockTeams): one team per (block,
/// column) pair, a lane per thread on a GPU (one warp), one thread on the host.
template <class ExecSpace>
Kokkos::TeamPolicy<ExecSpace, BlockTeams> block_team_policy(const ExecSpace& space, int pairs) {
  using MemSpace = typename ExecSpace::memory_space;
  const int team_size = Kokkos::SpaceAccessibility<Kokkos::HostSpace, MemSpace>::accessible ? 1 : moment_lanes;
  return Kokkos::TeamPolicy<ExecSpace, BlockTeams>(space, pairs, team_size)
      .set_scratch_size(0, Kokkos::PerTeam(block_team_scratch_bytes));
}

/// Whether the block reductions run their team forms by default: on a device (BlockColumnStatistics says why).
template <class MemSpace>
constexpr bool block_teams_by_default = !Kokkos::SpaceAccessibility<Kokkos::HostSpace, MemSpace>::accessible;

/// The BlockStatistic of column c of C over block b is blocks(b, c) (count), blocks(b, C + c) (mean) and
/// blocks(b, 2 C + c) (m2): the layout merge_block_statistics reads, each of its sums a run over the columns.
template <class MemSpace>
using BlockStatistics = Kokkos::View<double**, Kokkos::LayoutRight, MemSpace>;

/// Blocks of moment_block_size members that `members` members fill (the last may be short).
KOKKOS_INLINE_FUNCTION constexpr long moment_blocks(const long members) {
  return (members + moment_block_size - 1) / moment_block_size;
}

KOKKOS_INLINE_FUNCTION int block_end(const int b, const int members) {
  return b * moment_block_size + moment_block_size < members ? b * moment_block_size + moment_block_size : members;
}

template <class MemSpace>
KOKKOS_INLINE_FUNCTION void store_block_statistic(const BlockStatistics<MemSpace>& blocks, const int b, const int c,
                                                  const BlockStatistic& s) {
  const int columns = static_cast<int>(blocks.extent(1)) / 3;
  blocks(b, c) = s.count;
  blocks(b, columns + c) = s.mean;
  blocks(b, 2 * columns + c) = s.m2;
}

/// Column c of x where every column of the member's row is finite, NaN elsewhere: ensemble_moments leaves a
/// member with any non-finite entry out of every column.
template <class View>
struct FiniteRowValue {
  View x;
  int column;
  KOKKOS_INLINE_FUNCTION double operator()(const int m) const {
    bool finite = true;
    for (int c = 0; c < static_cast<int>(x.extent(1)); ++c) finite = finite && math::is_finite(x(m, c));
    return finite ? x(m, column) : math::quiet_nan();
  }
};

/// The columns of a bank x(member, column), each as FiniteRowValue (ensemble_moments).
template <class View>
struct FiniteRows {
  View x;
  KOKKOS_INLINE_FUNCTION FiniteRowValue<View> operator()(const int c) const { return {x, c}; }
};

/// A contiguous member-indexed column at a device address.
struct ColumnValue {
  const double* x;
  KOKKOS_INLINE_FUNCTION double operator()(const int m) const { return x[m]; }
};

/// Contiguous member-indexed columns at device addresses, each on its own (a member non-finite in one column is left
/// out of that column only: ColumnMoments).
template <class MemSpace>
struct ColumnAddresses {
  Kokkos::View<const std::uintptr_t*, MemSpace> addresses;  // column c's values at (const double*) addresses(c)
  KOKKOS_INLINE_FUNCTION ColumnValue operator()(const int c) const {
    return {reinterpret_cast<const double*>(addresses(c))};
  }
};

/// The BlockStatistic of every (block, column) pair of `columns` (columns(c): column c's values, value(m)), pair
/// i = c * blocks + b: a column's blocks are independent, and a GPU needs the threads (one thread per block gave
/// 1e6 members 3907 threads, and the moments took most of an output step). Two forms, the same bits: one thread per
/// pair (the host's: its lanes are vector lanes), or a team per pair (block_team_policy: a GPU's, where one thread
/// per pair walks its block alone, 32 threads of a warp 32 blocks apart; that form took 123 us for 12 columns of
/// 1e6 members on an H100, 2.4x a read of them).
template <class Columns, class MemSpace>
struct BlockColumnStatistics {
  Columns columns;
  int members;
  BlockStatistics<MemSpace> blocks;

  KOKKOS_INLINE_FUNCTION void operator()(const int i) const {
    const int num_blocks = static_cast<int>(blocks.extent(0)), b = i % num_blocks, c = i / num_blocks;
    store_block_statistic(blocks, b, c, block_statistic(columns(c), b * moment_block_size, block_end(b, members)));
  }

  template <class Team>
  KOKKOS_INLINE_FUNCTION void operator()(BlockTeams, const Team& team) const {
    const int i = team.league_rank();
    const int num_blocks = static_cast<int>(blocks.extent(0)), b = i % num_blocks, c = i / num_blocks;
    const std::ptrdiff_t bytes = block_team_scratch_bytes;  // a copy: get_shmem takes a reference
    double* lanes = static_cast<double*>(team.team_shmem().get_shmem(bytes));
    const BlockStatistic s =
        team_block_statistic(team, columns(c), b * moment_block_size, block_end(b, members), lanes);
    Kokkos::single(Kokkos::PerTeam(team), [&]() { store_block_statistic(blocks, b, c, s); });
  }
};

/// Launches `kernel` (a BlockColumnStatistics) over `pairs` pairs in its team form or its one-thread form.
template <class ExecSpace, class Kernel>
void launch_block_statistics(const char* name, const ExecSpace& space, int pairs, bool teams, const Kernel& kernel) {
  if (teams)
    Kokkos::parallel_for(name, block_team_policy(space, pairs), kernel);
  else
    Kokkos::parallel_for(name, Kokkos::RangePolicy<ExecSpace>(space, 0, pairs), kernel);
}

struct EnsembleMoments {
  std::vector<double> mean;      // per column, over finite members
  std::vector<double> variance;  // per column, sample variance (divisor finite members - 1)
  long non_finite = 0;           // members left out
  long members = 0;              // members of every rank, finite or not
};

/// Every rank's block statistics (`local`: this rank's `size` doubles of host rows), merged per column into one
/// EnsembleMoments per column: the count, the mean sum_b n_b mean_b / n, then m2 = sum_b (m2_b + n_b (mean_b -
/// mean)^2), each sum over the blocks in order. The rows of all ranks, in rank order, are the blocks of the whole
/// ensemble in member order, so the result is the same bits for any number of ranks. No division per block (Chan et
/// al.'s pairwise update has two, on the chain from one block to the next: 115 us for 3907 blocks of 12 columns on
/// the host, a third of a GPU bank's output step); each sum runs over the columns side by side.
inline std::vector<EnsembleMoments> merge_block_statistics(const double* local, std::size_t size, int columns,
                                                           long members) {
  const int width = 3 * columns;
  std::vector<double> gathered;  // one process reads its own rows, uncopied (1 MB: 1e6 members, 12 columns)
  const double* all = local;
  std::size_t all_size = size;
  if (collective::ranks() > 1) {  // the same branch on every rank
    gathered = collective::gather(std::vector<double>(local, local + size));
    all = gathered.data();
    all_size = gathered.size();
  }
  const long all_blocks = static_cast<long>(all_size) / width;
  const long all_members = collective::sum(members);
  std::vector<double> count(columns, 0.0), mean(columns, 0.0), m2(columns, 0.0);
  for (long b = 0; b < all_blocks; ++b) {
    const double* row = all + b * width;
    for (int c = 0; c < columns; ++c) {
      count[c] += row[c];
      mean[c] += row[c] * row[columns + c];  // an empty block's mean is 0
    }
  }
  for (int c = 0; c < columns; ++c) mean[c] /= count[c];
  for (long b = 0; b < all_blocks; ++b) {
    const double* row = all + b * width;
    for (int c = 0; c < columns; ++c) {
      const double delta = row[columns + c] - mean[c];
      m2[c] += row[c] > 0.0 ? row[2 * columns + c] + row[c] * (delta * delta) : 0.0;
    }
  }
  std::vector<EnsembleMoments> result;
  for (int c = 0; c < columns; ++c)
    result.push_back({{count[c] > 0 ? mean[c] : std::numeric_limits<double>::quiet_NaN()},
                      {count[c] > 1 ? m2[c] / (count[c] - 1) : std::numeric_limits<double>::quiet_NaN()},
                      all_members - static_cast<long>(count[c]),
                      all_members});
  return result;
}

/// Mean and sample variance of every column of x(member, column) over members.
template <class ExecSpace, class View>
EnsembleMoments ensemble_moments(const ExecSpace& space, const View& x) {
  using MemSpace = typename View::memory_space;
  const int members = static_cast<int>(x.extent(0));
  const int columns = static_cast<int>(x.extent(1));
  const int num_blocks = static_cast<int>(moment_blocks(members));
  // Allocated on `space`, not on the default execution space: with a few members on Serial, an OpenMP fork and
  // join per call cost more than the moments (kushner reproduce's one-member runs).
  BlockStatistics<MemSpace> blocks(Kokkos::view_alloc(space, Kokkos::WithoutInitializing, "kushner::moment_blocks"),
                                   num_blocks, 3 * columns);
  launch_block_statistics("kushner::block_moments", space, num_blocks * columns, block_teams_by_default<MemSpace>,
                          BlockColumnStatistics<FiniteRows<View>, MemSpace>{{x}, members, blocks});
  space.fence();
  const auto rows = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), blocks);
  const std::vector<EnsembleMoments> per_column = merge_block_statistics(rows.data(), rows.size(), columns, members);
  // Every rank has the same columns, so every rank takes the same branch of this collective call.
  const long all_members = per_column.empty() ? collective::sum(members) : per_column.front().members;
  EnsembleMoments result{{}, {}, all_members, all_members};
  for (const auto& mo : per_column) {
    result.mean.push_back(mo.mean[0]);
    result.variance.push_back(mo.variance[0]);
    result.non_finite = mo.non_finite;  // the same in every column
  }
  return result;
}

}  // namespace kushner

namespace kushner {

/// ensemble_moments of each of `columns` (contiguous member-indexed columns of equal length, e.g. subviews (ALL, c)
/// of LayoutLeft banks), bit for bit, in one pass over the blocks and one gather over the ranks. Keeps its device
/// and host buffers from call to call (a bank's output steps call it with the same columns every time): on a GPU an
/// allocation and its release each wait for the device.
template <class ExecSpace>
class ColumnMoments {
 public:
  using MemSpace = typename ExecSpace::memory_space;
  using Column = Kokkos::View<const double*, MemSpace>;

  /// `teams`: run BlockColumnStatistics' team form (a GPU's default; the tests run it on the host as well).
  explicit ColumnMoments(bool teams = block_teams_by_default<MemSpace>) : teams_(teams) {}

  std::vector<EnsembleMoments> operator()(const ExecSpace& space, const std::vector<Column>& columns) {
    start(space, columns);
    return finish();
  }

  /// Queues the moments of `columns` on `space`: the kernel and, on a GPU, the copy of its rows to the host.
  /// finish() waits for them and merges.
  void start(const ExecSpace& space, const std::vector<Column>& columns) {
    num_columns_ = static_cast<int>(columns.size());
    if (num_columns_ == 0) return;
    members_ = static_cast<int>(columns.front().extent(0));
    const int num_blocks = static_cast<int>(moment_blocks(members_));
    std::vector<std::uintptr_t> addresses;
    for (int c = 0; c < num_columns_; ++c) {
      KUSHNER_REQUIRE(static_cast<int>(columns[c].extent(0)) == members_ && columns[c].span_is_contiguous(),
                      "column_moments: column " << c << " is not a contiguous column of " << members_ << " members");
      addresses.push_back(reinterpret_cast<std::uintptr_t>(columns[c].data()));
    }
    const auto& pointers = columns_.update(space, addresses);
    if (blocks_.extent(0) != static_cast<std::size_t>(num_blocks) ||
        blocks_.extent(1) != static_cast<std::size_t>(3 * num_columns_)) {
      blocks_ =
          BlockStatistics<MemSpace>(Kokkos::view_alloc(space, Kokkos::WithoutInitializing, "kushner::moment_blocks"),
                                    num_blocks, 3 * num_columns_);
      // The blocks themselves in host memory; a page-locked copy of them on a GPU.
      rows_ = Kokkos::create_mirror_view(typename HostStaging<MemSpace>::space(), blocks_);
    }
    launch_block_statistics("kushner::block_column_moments", space, num_blocks * num_columns_, teams_,
                            BlockColumnStatistics<ColumnAddresses<MemSpace>, MemSpace>{{pointers}, members_, blocks_});
    if (rows_.data() != blocks_.data()) Kokkos::deep_copy(space, rows_, blocks_);
    done_.record(space);
  }

  /// The moments start() queued, per column, over every rank (a collective call). Waits for start()'s work only, not
  /// for what was queued on the space after it.
  std::vector<EnsembleMoments> finish() {
    if (num_columns_ == 0) return {};
    done_.wait();
    return merge_block_statistics(rows_.data(), rows_.size(), num_columns_, members_);
  }

 private:
  using HostRows = Kokkos::View<double**, Kokkos::LayoutRight, typename HostStaging<MemSpace>::space>;
  DeviceAddresses<MemSpace> columns_;
  BlockStatistics<MemSpace> blocks_;
  HostRows rows_;  // blocks_ (on the host) or its page-locked copy
  bool teams_;
  int num_columns_ = 0, members_ = 0;  // of the last start()
  QueueMark<ExecSpace> done_;          // after the last start()'s copy
};

}  // namespace kushner
