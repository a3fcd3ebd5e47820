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
#include "core/portability.hpp"
#include "kernels/bank.hpp"
#include "kernels/device_addresses.hpp"
#include "kernels/host_copy.hpp"
#include "kernels/queue_mark.hpp"

#include <Kokkos_Core.hpp>

#include <cstddef>
#include <cstdint>
#include <limits>
#include <type_traits>
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

namespace detail {
/// f(j, m) for m in [begin, end), in member order, j = (m - begin) % moment_lanes: how each of block_statistic's
/// passes visits a block's members.
template <class F>
KOKKOS_INLINE_FUNCTION void for_block_lanes(const int begin, const int end, const F& f) {
  constexpr int L = moment_lanes;
  int m0 = begin;
  for (; m0 + L <= end; m0 += L)
    for (int j = 0; j < L; ++j) f(j, m0 + j);
  for (int j = 0; m0 + j < end; ++j) f(j, m0 + j);
}

/// add(j, value(m)) in for_block_lanes' order: how each of block_statistic's passes adds a block into its lanes.
template <class Value, class Add>
KOKKOS_INLINE_FUNCTION void add_block_lanes(const Value& value, const int begin, const int end, const Add& add) {
  for_block_lanes(begin, end, [&](const int j, const int m) { add(j, value(m)); });
}

/// The lanes' squared deviations of the finite values from `mean`, pairwise added (a non-finite value adds nothing).
template <class Value>
KOKKOS_INLINE_FUNCTION double masked_block_squared_deviations(const Value& value, const int begin, const int end,
                                                              const double mean) {
  constexpr int L = moment_lanes;
  double ss[L];
  for (int j = 0; j < L; ++j) ss[j] = 0.0;
  add_block_lanes(value, begin, end, [&](const int j, const double v) {
    const double d = math::is_finite(v) ? v - mean : 0.0;
    ss[j] += d * d;
  });
  return pairwise_sum<L>(ss);
}

/// block_statistic's unmasked passes for G values of each member at once (values(m, v) sets v[0 .. G - 1]), each pass
/// visiting a member once for all of them: the same sums in the same order as block_statistic of each value alone.
/// False, s as it was, where the block is empty or a value's total is not finite (the masked passes take it then).
template <int G, class Values>
KOKKOS_INLINE_FUNCTION bool unmasked_block_statistics(const Values& values, const int begin, const int end,
                                                      BlockStatistic (&s)[G]) {
  constexpr int L = moment_lanes;
  if (end <= begin) return false;
  double sum[G][L];
  for (int g = 0; g < G; ++g)
    for (int j = 0; j < L; ++j) sum[g][j] = 0.0;
  for_block_lanes(begin, end, [&](const int j, const int m) {
    double v[G];
    values(m, v);
    for (int g = 0; g < G; ++g) sum[g][j] += v[g];
  });
  const double count = static_cast<double>(end - begin);
  double mean[G];
  for (int g = 0; g < G; ++g) {
    const double total = pairwise_sum<L>(sum[g]);
    if (!math::is_finite(total)) return false;
    mean[g] = total / count;
  }
  double ss[G][L];
  for (int g = 0; g < G; ++g)
    for (int j = 0; j < L; ++j) ss[g][j] = 0.0;
  for_block_lanes(begin, end, [&](const int j, const int m) {
    double v[G];
    values(m, v);
    for (int g = 0; g < G; ++g) {
      const double d = v[g] - mean[g];
      ss[g][j] += d * d;
    }
  });
  for (int g = 0; g < G; ++g) s[g] = {count, mean[g], pairwise_sum<L>(ss[g])};
  return true;
}
}  // namespace detail

/// The BlockStatistic of value(m), m in [begin, end), leaving out non-finite values. Two passes (the sum, then the
/// squared deviations from the block's mean); in each, member m adds into lane (m - begin) % 32, in member order,
/// and the lanes are added by pairwise_sum. So no division per member (Welford's recurrence, a chain of dependent
/// divisions, made these reductions the slowest part of an output step on the host and on the GPU), 32 independent
/// chains (a loop the host compiler vectorizes, and on a GPU one lane per thread of a warp: team_block_statistic),
/// and the same bits on every backend and thread count (up to the multiply-adds a GPU contracts).
/// A block whose values are all finite (every block but those with a diverged member) takes the passes unmasked
/// (detail::unmasked_block_statistics): a non-finite value leaves its lane's sum, and so the lanes' total, infinite or
/// NaN for good, so a finite total means every value was finite, and then the masked passes would add the same values
/// in the same order: the same bits, with the count end - begin. The unmasked passes took half the time of the masked
/// ones on the host (an output step's reductions, perf/filter_bank.md); a total that overflowed takes the masked
/// passes too.
template <class Value>
KOKKOS_INLINE_FUNCTION BlockStatistic block_statistic(const Value& value, const int begin, const int end) {
  constexpr int L = moment_lanes;
  BlockStatistic s[1];
  if (detail::unmasked_block_statistics([&](const int m, double(&v)[1]) { v[0] = value(m); }, begin, end, s))
    return s[0];
  double count[L], sum[L];
  for (int j = 0; j < L; ++j) count[j] = sum[j] = 0.0;
  detail::add_block_lanes(value, begin, end, [&](const int j, const double v) {
    const bool finite = math::is_finite(v);
    count[j] += finite ? 1.0 : 0.0;
    sum[j] += finite ? v : 0.0;
  });
  BlockStatistic masked;
  masked.count = pairwise_sum<L>(count);
  if (masked.count == 0.0) return masked;
  masked.mean = pairwise_sum<L>(sum) / masked.count;
  masked.m2 = detail::masked_block_squared_deviations(value, begin, end, masked.mean);
  return masked;
}

/// Members per lane in a block: a lane's values of a block fit in registers.
constexpr int moment_lane_members = moment_block_size / moment_lanes;
static_assert(moment_block_size % moment_lanes == 0, "a block is whole lanes");

#if KUSHNER_CUDA_DEVICE_PASS
/// pairwise_sum<moment_lanes> over the lanes of a warp (lane j's x is a[j]), on every lane: shuffles down by 1, 2,
/// 4, 8 and 16 add the same pairs in the same tree (after offset d, lane j, a multiple of 2 d, holds the tree's sum
/// of a[j .. j + 2 d)).
__device__ inline double warp_pairwise_sum(double x) {
  static_assert(moment_lanes == 32, "one lane per thread of a warp");
  KUSHNER_DEVICE_UNROLL
  for (int offset = 1; offset < moment_lanes; offset *= 2) x += __shfl_down_sync(0xffffffffu, x, offset);
  return __shfl_sync(0xffffffffu, x, 0);
}

/// The BlockStatistic of a warp whose lane holds `count` and `sum` of its values and whose squared deviations from a
/// mean are `deviations(mean)`: the lanes meet by warp_pairwise_sum (every lane returns it).
template <class Deviations>
__device__ BlockStatistic warp_statistic(const double count, const double sum, const Deviations& deviations) {
  BlockStatistic s;
  s.count = warp_pairwise_sum(count);
  const double total = warp_pairwise_sum(sum);  // every lane takes part in a shuffle
  if (s.count == 0.0) return s;
  s.mean = total / s.count;
  s.m2 = warp_pairwise_sum(deviations(s.mean));
  return s;
}

/// block_statistic by the 32 lanes of a warp, lane j this thread (each lane adds the values of block_statistic's
/// lane j): the same sums in the same order, so the same bits up to the multiply-adds nvcc contracts. Each lane
/// loads its (up to) moment_lane_members values at once and keeps them in registers for the second pass; the lanes
/// meet by shuffles. As there, a whole block whose total is finite takes the passes unmasked (the masked ones would add
/// the same values in the same order), with no test of its positions. A block shorter than moment_block_size (a rank's
/// last) takes the masked passes, its positions past the end read as NaN: they add zero to every sum, as
/// block_statistic's shorter loop adds nothing. (Testing every position in the unmasked passes too, with
/// warp_block_count's tree of double shuffles, cost a GPU segment's output step 388 extra instructions per member-step
/// against 292 now: perf/filter_bank.md.) A position past the end loads the block's last value (no branch keeps the
/// reads from going out at once). (The first team form, which loaded a lane's values one after another, four at a time
/// as nvcc unrolled the loop, loaded them again for the second pass, and had every thread add the 32 lanes from team
/// scratch, took 49-67 us for 8 columns of 1e6 members on an H200, 2.8-3.9x a read of them.)
template <class Value>
__device__ BlockStatistic warp_block_statistic(const int j, const Value& value, const int begin, const int end) {
  constexpr int L = moment_lanes, K = moment_lane_members;
  const int n = end - begin;
  double v[K];
  if (n == moment_block_size) {
    double sum = 0.0;
    KUSHNER_DEVICE_UNROLL
    for (int k = 0; k < K; ++k) v[k] = value(begin + j + k * L);
    KUSHNER_DEVICE_UNROLL
    for (int k = 0; k < K; ++k) sum += v[k];
    const double total = warp_pairwise_sum(sum);  // the same on every lane, so the branch below is the warp's
    if (math::is_finite(total)) {
      BlockStatistic s;
      s.count = static_cast<double>(n);
      // The mean by a multiply: total / 2^8 and total 2^-8 round the same number, so the same bits, without a double
      // division's ~40 instructions and their latency between the two passes of every column (output steps of a GPU
      // segment x1.012: perf/filter_bank.md).
      static_assert((moment_block_size & (moment_block_size - 1)) == 0, "a power of two");
      s.mean = total * (1.0 / moment_block_size);
      double ss = 0.0;
      KUSHNER_DEVICE_UNROLL
      for (int k = 0; k < K; ++k) {
        const double d = v[k] - s.mean;
        ss += d * d;
      }
      s.m2 = warp_pairwise_sum(ss);
      return s;
    }
  } else {
    KUSHNER_DEVICE_UNROLL
    for (int k = 0; k < K; ++k) {
      const bool in = j + k * L < n;
      v[k] = value(in ? begin + j + k * L : end - 1);  // no branch
      if (!in) v[k] = math::quiet_nan();
    }
  }
  double count = 0.0, sum = 0.0;
  KUSHNER_DEVICE_UNROLL
  for (int k = 0; k < K; ++k) {
    const bool finite = math::is_finite(v[k]);
    count += finite ? 1.0 : 0.0;
    sum += finite ? v[k] : 0.0;
  }
  return warp_statistic(count, sum, [&](const double mean) {
    double ss = 0.0;
    KUSHNER_DEVICE_UNROLL
    for (int k = 0; k < K; ++k) {
      const double d = math::is_finite(v[k]) ? v[k] - mean : 0.0;
      ss += d * d;
    }
    return ss;
  });
}

/// The members m in [begin, end) with counted(m), by the 32 lanes of a warp (lane j this thread, its members as in
/// warp_block_statistic). A position past the end asks about the block's last member and is not counted, so every
/// lane's reads are unconditional and go out at once (nvcc kept a branch before each read of a && chain: one read at
/// a time). An integer: any order gives the same count, so the lanes meet in one warp reduction (sm_80 and newer, as
/// every target of a CUDA build) rather than a tree of double shuffles.
template <class Counted>
__device__ int warp_block_count(const int j, const Counted& counted, const int begin, const int end) {
  bool in[moment_lane_members], yes[moment_lane_members];
  KUSHNER_DEVICE_UNROLL
  for (int k = 0; k < moment_lane_members; ++k) {
    const int m = begin + j + k * moment_lanes;
    in[k] = m < end;
    yes[k] = counted(in[k] ? m : end - 1);
  }
  unsigned count = 0;
  KUSHNER_DEVICE_UNROLL
  for (int k = 0; k < moment_lane_members; ++k) count += in[k] && yes[k] ? 1u : 0u;
  return static_cast<int>(__reduce_add_sync(0xffffffffu, count));
}
#endif

/// warp_block_statistic's lanes for any Kokkos team (the host's, where the tests run it): lane j a TeamThreadRange
/// index, the values and the lanes' sums in team scratch (`scratch`: block_team_scratch_bytes), the lanes added by
/// pairwise_sum, the tree of warp_pairwise_sum. Every thread of the team returns the statistic.
template <class Team, class Value>
KOKKOS_INLINE_FUNCTION BlockStatistic team_block_statistic(const Team& team, const Value& value, const int begin,
                                                           const int end, double* scratch) {
  constexpr int L = moment_lanes, K = moment_lane_members;
  double* const lanes = scratch;           // 3 L: counts, sums, squared deviations
  double* const values = scratch + 3 * L;  // K L: the block's values, member begin + i at i
  Kokkos::parallel_for(Kokkos::TeamThreadRange(team, L), [&](const int j) {
    double v[K], count = 0.0, sum = 0.0;
    for (int k = 0; k < K; ++k) v[k] = begin + j + k * L < end ? value(begin + j + k * L) : math::quiet_nan();
    for (int k = 0; k < K; ++k) {
      const bool finite = math::is_finite(v[k]);
      count += finite ? 1.0 : 0.0;
      sum += finite ? v[k] : 0.0;
      values[k * L + j] = v[k];
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
    for (int k = 0; k < K; ++k) {
      const double v = values[k * L + j];
      const double d = math::is_finite(v) ? v - s.mean : 0.0;
      ss += d * d;
    }
    lanes[2 * L + j] = ss;
  });
  team.team_barrier();
  s.m2 = pairwise_sum<L>(lanes + 2 * L);
  return s;
}

/// The members m in [begin, end) with counted(m), by any Kokkos team (its team reduction). Every thread returns it.
template <class Team, class Counted>
KOKKOS_INLINE_FUNCTION int team_block_count(const Team& team, const Counted& counted, const int begin, const int end) {
  int count = 0;
  Kokkos::parallel_reduce(
      Kokkos::TeamThreadRange(team, begin, end), [&](const int m, int& n) { n += counted(m) ? 1 : 0; }, count);
  return count;
}

/// The work tag of the block reductions' team forms (block_team_policy).
struct BlockTeams {};

/// Team scratch of team_block_statistic: its lanes' three sums and the block's values.
constexpr std::size_t block_team_scratch_bytes = sizeof(double) * (3 * moment_lanes + moment_block_size);

/// Warps per team of the block reductions on a GPU, one (block, column) pair each: teams of one warp, 32 threads
/// per CUDA block, let an SM hold at most 32 warps (half of an H200's 64) of these short, latency-bound warps.
constexpr int block_team_warps = 8;

/// Whether the block reductions run their team forms by default: on a device, where a team is block_team_warps
/// warps, one (block, column) pair each; on the host one thread, one pair per team (team_block_statistic's form, the
/// tests' check of the warps' sums).
template <class MemSpace>
constexpr bool block_teams_by_default = !Kokkos::SpaceAccessibility<Kokkos::HostSpace, MemSpace>::accessible;

/// The team policy of the block reductions' team forms (their operator() tagged BlockTeams) over `pairs` (block,
/// column) pairs.
template <class ExecSpace>
Kokkos::TeamPolicy<ExecSpace, BlockTeams> block_team_policy(const ExecSpace& space, int pairs) {
  if constexpr (block_teams_by_default<typename ExecSpace::memory_space>)
    return Kokkos::TeamPolicy<ExecSpace, BlockTeams>(space, (pairs + block_team_warps - 1) / block_team_warps,
                                                     block_team_warps * moment_lanes);
  else
    return Kokkos::TeamPolicy<ExecSpace, BlockTeams>(space, pairs, 1)
        .set_scratch_size(0, Kokkos::PerTeam(block_team_scratch_bytes));
}

/// The BlockStatistic of column c of C over block b is blocks(b, c) (count), blocks(b, C + c) (mean) and
/// blocks(b, 2 C + c) (m2); the block's count of counted column s is blocks(b, 3 C + s) (BlockColumnStatistics'
/// Counted). The layout merge_block_statistics reads, each of its sums a run over the columns.
template <class MemSpace>
using BlockStatistics = Kokkos::View<double**, Kokkos::LayoutRight, MemSpace>;

/// Blocks of moment_block_size members that `members` members fill (the last may be short).
KOKKOS_INLINE_FUNCTION constexpr long moment_blocks(const long members) {
  return (members + moment_block_size - 1) / moment_block_size;
}

KOKKOS_INLINE_FUNCTION int block_end(const int b, const int members) {
  return b * moment_block_size + moment_block_size < members ? b * moment_block_size + moment_block_size : members;
}

/// Column c's BlockStatistic in a block's row of `columns` statistics (BlockStatistics' layout).
KOKKOS_INLINE_FUNCTION void store_block_row(double* row, const int columns, const int c, const BlockStatistic& s) {
  row[c] = s.count;
  row[columns + c] = s.mean;
  row[2 * columns + c] = s.m2;
}

template <class MemSpace>
KOKKOS_INLINE_FUNCTION void store_block_statistic(const BlockStatistics<MemSpace>& blocks, const int columns,
                                                  const int b, const int c, const BlockStatistic& s) {
  store_block_row(&blocks(b, 0), columns, c, s);
}

/// NaN where member m's row of x has a non-finite entry, 0 elsewhere (FiniteRowValue). `Columns`: x's number of
/// columns, where known at compile time (-1: x.extent(1)).
template <int Columns, class View>
KOKKOS_INLINE_FUNCTION double row_poison(const View& x, const int m) {
  // x * 0 is 0 for a finite x and NaN for an infinite or NaN one, so `poison` is NaN exactly where the row has a
  // non-finite entry, and adding it changes nothing else (a -0 becomes +0, which adds the same to every sum of
  // block_statistic). Arithmetic with a compile-time count, not a chain of bools: only so do the host's lanes
  // vectorize (2 columns of 1e6 members, both passes: 0.9 ms against 10 ms on the development machine).
  const int columns = Columns >= 0 ? Columns : static_cast<int>(x.extent(1));
  double poison = 0.0;
  for (int c = 0; c < columns; ++c) poison += x(m, c) * 0.0;
  return poison;
}

/// Column c of x where every column of the member's row is finite, NaN elsewhere: ensemble_moments leaves a
/// member with any non-finite entry out of every column. `Columns`: x's number of columns, where known at compile
/// time (-1: x.extent(1)).
template <class View, int Columns = -1>
struct FiniteRowValue {
  View x;
  int column;
  KOKKOS_INLINE_FUNCTION double operator()(const int m) const { return x(m, column) + row_poison<Columns>(x, m); }
};

/// block_statistic of FiniteRowValue<View, Columns>{x, c} for every column c, the same bits, each pass reading a
/// member's row once for all its columns (a column at a time, each pass read the row and took its poison once per
/// column: the cubic oscillator's truth segment spent 9% of its time in its two columns' statistics). A block with a
/// non-finite value or total takes block_statistic column by column.
template <int Columns, class View>
KOKKOS_INLINE_FUNCTION void finite_row_block_statistics(const View& x, const int begin, const int end,
                                                        BlockStatistic (&s)[Columns]) {
  const auto row = [&](const int m, double(&v)[Columns]) {
    const double poison = row_poison<Columns>(x, m);
    for (int c = 0; c < Columns; ++c) v[c] = x(m, c) + poison;
  };
  if (detail::unmasked_block_statistics(row, begin, end, s)) return;
  for (int c = 0; c < Columns; ++c) s[c] = block_statistic(FiniteRowValue<View, Columns>{x, c}, begin, end);
}

/// The columns of a bank x(member, column), each as FiniteRowValue (ensemble_moments).
template <class View, int Columns = -1>
struct FiniteRows {
  View x;
  KOKKOS_INLINE_FUNCTION FiniteRowValue<View, Columns> operator()(const int c) const { return {x, c}; }
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

/// What block reductions count besides their moments: counted(s, m) says whether member m counts in counted column
/// s, of counted.columns(), and on a GPU warp_count(j, s, begin, end) is a warp's count of a block (filters'
/// divergences: NotOkMembers, kernels/filters/filter_metrics.hpp). Here: nothing.
struct NothingCounted {
  KOKKOS_INLINE_FUNCTION int columns() const { return 0; }
  KOKKOS_INLINE_FUNCTION bool operator()(int, int) const { return false; }
#if KUSHNER_CUDA_DEVICE_PASS
  /// A warp's count of column s in [begin, end) (NotOkMembers::warp_count).
  __device__ int warp_count(int, int, int, int) const { return 0; }
#endif
};

/// The BlockStatistic of every (block, column) pair of `columns` (columns(c): column c's values, value(m)), and the
/// count of every (block, counted column s) pair: one launch for all of an output step's reductions. A column's blocks
/// are independent, and a GPU needs the threads (one thread per block gave 1e6 members 3907 threads, and the moments
/// took most of an output step). Two forms, the same bits: one thread per pair (the host's: its lanes are vector
/// lanes), or teams (block_team_policy: on a GPU a warp per pair, warp_block_statistic; with one thread per pair a
/// GPU's warp read 32 blocks 2 KB apart, 123 us for 12 columns of 1e6 members on an H100, 2.4x a read of them).
/// Counts are integer sums: any order gives the same count.
/// Pair i of the one-thread form is block i / P, column (or counted column) i % P, P = num_columns + counted columns:
/// a host thread's share of the pairs is then whole blocks, the members the bank's own kernels gave that thread. With
/// the pairs column after column, a thread read every member of its columns (and FiniteRowValue reads every column),
/// so each line of the bank sat in both cores' caches, and the next step's writes waited for the other core to let
/// go of it: the cubic oscillator's `simulate` (2 columns, 1e6 members, an output every step, 2 threads) took 1.6 s
/// against 1.0 s with 5 outputs on the 2-core development machine (how much depends on where its cores sit:
/// perf/filter_bank.md).
template <class Columns, class MemSpace, class Counted = NothingCounted>
struct BlockColumnStatistics {
  Columns columns;
  int num_columns;
  Counted counted;
  int members;
  BlockStatistics<MemSpace> blocks;  // (block, 3 num_columns + counted.columns())

  KOKKOS_INLINE_FUNCTION void operator()(const int i) const {
    const int pairs_per_block = num_columns + counted.columns(), b = i / pairs_per_block, c = i % pairs_per_block;
    const int begin = b * moment_block_size, end = block_end(b, members);
    if (c < num_columns) {
      store_block_statistic(blocks, num_columns, b, c, block_statistic(columns(c), begin, end));
    } else {
      int count = 0;
      for (int m = begin; m < end; ++m) count += counted(c - num_columns, m) ? 1 : 0;
      blocks(b, 2 * num_columns + c) = count;
    }
  }

  /// The team form: pair i = c * blocks + b, so a GPU's neighbouring warps read neighbouring blocks of a column.
  template <class Team>
  KOKKOS_INLINE_FUNCTION void operator()(BlockTeams, const Team& team) const {
    const int num_blocks = static_cast<int>(blocks.extent(0));
#if KUSHNER_CUDA_DEVICE_PASS
    if constexpr (block_teams_by_default<MemSpace>) {  // a pair per warp: no team barrier, only shuffles
      const int i = team.league_rank() * block_team_warps + team.team_rank() / moment_lanes;
      const int j = team.team_rank() % moment_lanes, b = i % num_blocks, c = i / num_blocks;
      if (c >= num_columns + counted.columns()) return;  // the whole warp: the last team's spare warps
      const int begin = b * moment_block_size, end = block_end(b, members);
      if (c < num_columns) {
        const BlockStatistic s = warp_block_statistic(j, columns(c), begin, end);
        if (j == 0) store_block_statistic(blocks, num_columns, b, c, s);
      } else {
        const int count = counted.warp_count(j, c - num_columns, begin, end);
        if (j == 0) blocks(b, 2 * num_columns + c) = count;
      }
      return;
    }
#endif
    const int i = team.league_rank(), b = i % num_blocks, c = i / num_blocks;
    const int begin = b * moment_block_size, end = block_end(b, members);
    if (c < num_columns) {
      const std::ptrdiff_t bytes = block_team_scratch_bytes;  // a copy: get_shmem takes a reference
      double* scratch = static_cast<double*>(team.team_shmem().get_shmem(bytes));
      const BlockStatistic s = team_block_statistic(team, columns(c), begin, end, scratch);
      Kokkos::single(Kokkos::PerTeam(team), [&]() { store_block_statistic(blocks, num_columns, b, c, s); });
    } else {
      const int s = c - num_columns;
      const int count = team_block_count(
          team, [&](const int m) { return counted(s, m); }, begin, end);
      Kokkos::single(Kokkos::PerTeam(team), [&]() { blocks(b, 2 * num_columns + c) = count; });
    }
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

/// merge_block_statistics' result: per column its moments, per counted column its count, over every rank.
struct MergedBlocks {
  std::vector<EnsembleMoments> moments;
  std::vector<long> counts;
};

/// A block row's terms in the merged moments of its column c (BlockStatistics' layout: counts n_b, then means, then
/// m2s): n_b mean_b in the mean's sum (an empty block's mean is 0), and m2_b + n_b (mean_b - mean)^2 in the m2's.
KOKKOS_INLINE_FUNCTION double block_row_sum(const double* row, const int columns, const int c) {
  return row[c] * row[columns + c];
}
KOKKOS_INLINE_FUNCTION double block_row_spread(const double* row, const int columns, const int c, const double mean) {
  const double delta = row[columns + c] - mean;
  return row[c] > 0.0 ? row[2 * columns + c] + row[c] * (delta * delta) : 0.0;
}

/// The BlockStatistic of columns c0 .. c0 + G - 1 over `blocks` rows (BlockStatistics' layout, `width` doubles each,
/// `columns` block statistics per row), into merged[0 .. G): per column its count, its mean sum_b n_b mean_b / n, then
/// its m2 = sum_b (m2_b + n_b (mean_b - mean)^2). Block b adds into lane b % moment_lanes, in block order, and the
/// lanes are added by pairwise_sum, as block_statistic adds members: independent chains, no division per block (Chan et
/// al.'s pairwise update has two on the chain from one block to the next: 115 us for 3907 blocks of 12 columns on the
/// host), and the order of warp_merge_block_column, so a GPU's merge gives the same bits (up to the multiply-adds it
/// contracts). G columns side by side (contiguous in a row: vector lanes on the host): 8 columns of 3907 blocks took 31
/// us here with G = 8, 100 us a column at a time (one chain per column, block after block: 28 us).
template <int G>
KOKKOS_INLINE_FUNCTION void merge_block_columns(const double* rows, const long blocks, const int width,
                                                const int columns, const int c0, BlockStatistic* merged) {
  constexpr int L = moment_lanes;
  double count[L][G], sum[L][G], ss[L][G];
  for (int j = 0; j < L; ++j)
    for (int g = 0; g < G; ++g) count[j][g] = sum[j][g] = ss[j][g] = 0.0;
  const long whole = blocks - blocks % L;  // the lanes' full rounds, then the rest: a fixed trip count unrolls
  for (long b0 = 0; b0 < blocks; b0 += L) {
    const int n = b0 < whole ? L : static_cast<int>(blocks - whole);
    for (int j = 0; j < n; ++j) {
      const double* const row = rows + (b0 + j) * width + c0;
      for (int g = 0; g < G; ++g) {
        count[j][g] += row[g];
        sum[j][g] += block_row_sum(row, columns, g);
      }
    }
  }
  double lanes[L];
  for (int g = 0; g < G; ++g) {
    for (int j = 0; j < L; ++j) lanes[j] = count[j][g];
    merged[g].count = pairwise_sum<L>(lanes);
    for (int j = 0; j < L; ++j) lanes[j] = sum[j][g];
    merged[g].mean = merged[g].count == 0.0 ? 0.0 : pairwise_sum<L>(lanes) / merged[g].count;
  }
  for (long b0 = 0; b0 < blocks; b0 += L) {
    const int n = b0 < whole ? L : static_cast<int>(blocks - whole);
    for (int j = 0; j < n; ++j) {
      const double* const row = rows + (b0 + j) * width + c0;
      for (int g = 0; g < G; ++g) ss[j][g] += block_row_spread(row, columns, g, merged[g].mean);
    }
  }
  for (int g = 0; g < G; ++g) {
    for (int j = 0; j < L; ++j) lanes[j] = ss[j][g];
    merged[g].m2 = pairwise_sum<L>(lanes);
  }
}

/// Counted column s's count summed over `blocks` rows (integers: any order gives the same sum).
KOKKOS_INLINE_FUNCTION double merge_block_count(const double* rows, const long blocks, const int width,
                                                const int columns, const int s) {
  double count = 0.0;
  for (long b = 0; b < blocks; ++b) count += rows[b * width + 3 * columns + s];
  return count;
}

#if KUSHNER_CUDA_DEVICE_PASS
/// Column c's merge_block_columns by the 32 lanes of a warp (lane j this thread adds merge_block_columns' lane j);
/// every lane returns it.
__device__ inline BlockStatistic warp_merge_block_column(const int j, const double* rows, const long blocks,
                                                         const int width, const int columns, const int c) {
  double count = 0.0, sum = 0.0;
  for (long b = j; b < blocks; b += moment_lanes) {
    const double* const row = rows + b * width;
    count += row[c];
    sum += block_row_sum(row, columns, c);
  }
  return warp_statistic(count, sum, [&](const double mean) {
    double ss = 0.0;
    for (long b = j; b < blocks; b += moment_lanes) ss += block_row_spread(rows + b * width, columns, c, mean);
    return ss;
  });
}

/// merge_block_count by the 32 lanes of a warp; every lane returns it.
__device__ inline double warp_merge_block_count(const int j, const double* rows, const long blocks, const int width,
                                                const int columns, const int s) {
  double count = 0.0;
  for (long b = j; b < blocks; b += moment_lanes) count += rows[b * width + 3 * columns + s];
  return warp_pairwise_sum(count);
}
#endif

/// The merged moments of `columns` columns and `counted` counts from their sums (a row in BlockStatistics' layout:
/// merge_block_columns' count, mean and m2 of column c at c, columns + c, 2 columns + c; merge_block_count's count s
/// at 3 columns + s), over `all_members` members of every rank.
inline MergedBlocks merged_blocks(const double* sums, const int columns, const int counted, const long all_members) {
  MergedBlocks result;
  for (int c = 0; c < columns; ++c) {
    const double count = sums[c], mean = sums[columns + c], m2 = sums[2 * columns + c];
    result.moments.push_back({{count > 0 ? mean : std::numeric_limits<double>::quiet_NaN()},
                              {count > 1 ? m2 / (count - 1) : std::numeric_limits<double>::quiet_NaN()},
                              all_members - static_cast<long>(count),
                              all_members});
  }
  for (int s = 0; s < counted; ++s) result.counts.push_back(static_cast<long>(sums[3 * columns + s]));
  return result;
}

/// merge_block_columns<G> over columns c, c + G, ... while G columns are left, into sums (a row in BlockStatistics'
/// layout); returns the first column left. Groups of 8, then 4, then 1 give every column the same sums.
template <int G>
int merge_column_groups(const double* rows, const long blocks, const int width, const int columns, int c,
                        double* sums) {
  BlockStatistic merged[G];
  for (; c + G <= columns; c += G) {
    merge_block_columns<G>(rows, blocks, width, columns, c, merged);
    for (int g = 0; g < G; ++g) store_block_row(sums, columns, c + g, merged[g]);
  }
  return c;
}

/// Every rank's block rows (`local`: this rank's `size` doubles of host rows, `columns` block statistics and
/// `counted` counts per row: BlockStatistics' layout), merged per column into one EnsembleMoments per column
/// (merge_block_columns) and the counts summed. The rows of all ranks, in rank order, are the blocks of the whole
/// ensemble in member order, so the result is the same bits for any number of ranks.
inline MergedBlocks merge_block_statistics(const double* local, std::size_t size, int columns, int counted,
                                           long members) {
  const int width = 3 * columns + counted;
  std::vector<double> gathered;  // one process reads its own rows, uncopied (1 MB: 1e6 members, 12 columns)
  const double* all = local;
  std::size_t all_size = size;
  if (collective::ranks() > 1) {  // the same branch on every rank
    gathered = collective::gather(std::vector<double>(local, local + size));
    all = gathered.data();
    all_size = gathered.size();
  }
  const long all_blocks = static_cast<long>(all_size) / width;
  std::vector<double> sums(width);
  int c = merge_column_groups<8>(all, all_blocks, width, columns, 0, sums.data());
  c = merge_column_groups<4>(all, all_blocks, width, columns, c, sums.data());
  merge_column_groups<1>(all, all_blocks, width, columns, c, sums.data());
  for (int s = 0; s < counted; ++s) sums[3 * columns + s] = merge_block_count(all, all_blocks, width, columns, s);
  return merged_blocks(sums.data(), columns, counted, collective::sum(members));
}

/// merge_block_statistics of several outputs' rows where they are (one process: no gather), a (output, column or
/// counted column) pair i = o (columns + counted) + c each: rows (output, block, width) of `blocks` blocks, sums
/// (output, width) as merged_blocks reads them. A GPU bank's segment (FilterBankTeamSegment) leaves up to 32 outputs'
/// rows at once: only their sums cross the bus, and the host does not merge thousands of rows per output between
/// launches. Two forms, the same bits: a thread per pair (operator()(i), the host's), or a warp per pair (a team of
/// moment_lanes threads, operator()(BlockTeams, team), on a GPU; a thread per pair there, 3907 blocks one after another
/// in each of 192 threads for 16 outputs of 12 columns and 4 counts, took 4.4 ms per segment on an H200, more than the
/// segment's 16 steps).
template <class MemSpace>
struct MergeBlockRows {
  Kokkos::View<const double*, MemSpace> rows;
  int blocks, columns, counted;
  Kokkos::View<double**, Kokkos::LayoutRight, MemSpace> sums;

  KOKKOS_INLINE_FUNCTION void operator()(const int i) const {
    const int width = 3 * columns + counted, o = i / (columns + counted), c = i % (columns + counted);
    const double* const r = rows.data() + static_cast<std::size_t>(o) * blocks * width;
    if (c < columns) {
      BlockStatistic merged;
      merge_block_columns<1>(r, blocks, width, columns, c, &merged);
      store_block_row(&sums(o, 0), columns, c, merged);
    } else
      sums(o, 2 * columns + c) = merge_block_count(r, blocks, width, columns, c - columns);
  }

  template <class Team>
  KOKKOS_INLINE_FUNCTION void operator()(BlockTeams, const Team& team) const {
#if KUSHNER_CUDA_DEVICE_PASS
    const int i = team.league_rank(), j = team.team_rank();
    const int width = 3 * columns + counted, o = i / (columns + counted), c = i % (columns + counted);
    const double* const r = rows.data() + static_cast<std::size_t>(o) * blocks * width;
    if (c < columns) {
      const BlockStatistic s = warp_merge_block_column(j, r, blocks, width, columns, c);
      if (j == 0) store_block_row(&sums(o, 0), columns, c, s);
    } else {
      const double count = warp_merge_block_count(j, r, blocks, width, columns, c - columns);
      if (j == 0) sums(o, 2 * columns + c) = count;
    }
#else
    (void)team;  // the host takes operator()(i)
#endif
  }
};

/// Launches `merge` over the pairs of its first `outputs` outputs: a warp per pair on a GPU, a thread per pair on the
/// host.
template <class ExecSpace>
void merge_block_rows(const ExecSpace& space, const MergeBlockRows<typename ExecSpace::memory_space>& merge,
                      const int outputs) {
  const int pairs = outputs * (merge.columns + merge.counted);
  if constexpr (block_teams_by_default<typename ExecSpace::memory_space>)
    Kokkos::parallel_for("kushner::merge_block_rows",
                         Kokkos::TeamPolicy<ExecSpace, BlockTeams>(space, pairs, moment_lanes), merge);
  else
    Kokkos::parallel_for("kushner::merge_block_rows", Kokkos::RangePolicy<ExecSpace>(space, 0, pairs), merge);
}

/// ensemble_moments of a bank's `columns` columns from its block rows (host rows, BlockStatistics' layout: `size`
/// doubles, 3 columns per row, FiniteRowValue's values) over its `members` members, merged over every rank (a
/// collective call).
inline EnsembleMoments moments_of_block_rows(const double* rows, const std::size_t size, const int columns,
                                             const long members) {
  const std::vector<EnsembleMoments> per_column = merge_block_statistics(rows, size, columns, 0, members).moments;
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

/// A reduction's block rows (BlockStatistics) and their copy on the host, kept by a caller that reduces banks of the
/// same shape again and again (an output step after another): on a GPU an allocation and its release each wait for
/// the device, and a copy to pageable host memory goes through a staging buffer of the driver's.
template <class MemSpace>
class MomentRows {
 public:
  using HostRows = Kokkos::View<double**, Kokkos::LayoutRight, typename HostStaging<MemSpace>::space>;

  /// Rows of `blocks` blocks of `width` doubles, allocated (on `space`) only when the shape changes.
  template <class ExecSpace>
  const BlockStatistics<MemSpace>& rows(const ExecSpace& space, const int blocks, const int width) {
    if (rows_.extent(0) != static_cast<std::size_t>(blocks) || rows_.extent(1) != static_cast<std::size_t>(width)) {
      // Allocated on `space`, not on the default execution space: with a few members on Serial, an OpenMP fork and
      // join per call cost more than the moments (kushner reproduce's one-member runs).
      rows_ = BlockStatistics<MemSpace>(
          Kokkos::view_alloc(space, Kokkos::WithoutInitializing, "kushner::moment_blocks"), blocks, width);
      host_ = Kokkos::create_mirror_view(typename HostStaging<MemSpace>::space(), rows_);  // the rows, or a pinned copy
    }
    return rows_;
  }

  /// Queues the rows' copy to host() on `space` (nothing to copy where they are host memory).
  template <class ExecSpace>
  void copy_to_host(const ExecSpace& space) const {
    if (host_.data() != rows_.data()) Kokkos::deep_copy(space, host_, rows_);
  }
  const HostRows& host() const { return host_; }

 private:
  BlockStatistics<MemSpace> rows_;
  HostRows host_;
};

/// Mean and sample variance of every column of x(member, column) over members, its block rows in `rows`.
template <class ExecSpace, class View>
EnsembleMoments ensemble_moments(const ExecSpace& space, const View& x, MomentRows<typename View::memory_space>& rows) {
  using MemSpace = typename View::memory_space;
  const int members = static_cast<int>(x.extent(0));
  const int columns = static_cast<int>(x.extent(1));
  const int num_blocks = static_cast<int>(moment_blocks(members));
  const BlockStatistics<MemSpace>& blocks = rows.rows(space, num_blocks, 3 * columns);
  const auto launch = [&](auto fixed_columns) {
    using Rows = FiniteRows<View, decltype(fixed_columns)::value>;
    launch_block_statistics("kushner::block_moments", space, num_blocks * columns, block_teams_by_default<MemSpace>,
                            BlockColumnStatistics<Rows, MemSpace>{{x}, columns, {}, members, blocks});
  };
  switch (columns) {  // the models' state sizes at compile time (FiniteRowValue)
    case 1: launch(std::integral_constant<int, 1>{}); break;
    case 2: launch(std::integral_constant<int, 2>{}); break;
    case 3: launch(std::integral_constant<int, 3>{}); break;
    case 4: launch(std::integral_constant<int, 4>{}); break;
    default: launch(std::integral_constant<int, -1>{});
  }
  rows.copy_to_host(space);
  space.fence();
  return moments_of_block_rows(rows.host().data(), rows.host().size(), columns, members);
}

/// ensemble_moments with rows of its own (a single reduction). Their host copy is page-locked on a GPU too: allocated
/// for one call it still took 0.66x the time of a pageable one (perf/bench_simulate_truth's BM_Moments, H200, 1e6
/// members: 68 against 104 us; rows kept from call to call 36 us).
template <class ExecSpace, class View>
EnsembleMoments ensemble_moments(const ExecSpace& space, const View& x) {
  MomentRows<typename View::memory_space> rows;
  return ensemble_moments(space, x, rows);
}

}  // namespace kushner

namespace kushner {

/// ensemble_moments of each of `columns` (contiguous member-indexed columns of equal length, e.g. subviews (ALL, c)
/// of LayoutLeft banks), bit for bit, and optionally counts of members (a Counted of BlockColumnStatistics), in one
/// launch over the blocks, one copy and one gather over the ranks. Keeps its device and host buffers from call to
/// call (a bank's output steps call it with the same columns every time): on a GPU an allocation and its release
/// each wait for the device.
template <class ExecSpace>
class ColumnMoments {
 public:
  using MemSpace = typename ExecSpace::memory_space;
  using Column = Kokkos::View<const double*, MemSpace>;

  /// `teams`: run BlockColumnStatistics' team form (a GPU's default; the tests run it on the host as well).
  explicit ColumnMoments(bool teams = block_teams_by_default<MemSpace>) : teams_(teams) {}

  std::vector<EnsembleMoments> operator()(const ExecSpace& space, const std::vector<Column>& columns) {
    start(space, columns);
    return finish().moments;
  }

  /// Queues the moments of `columns` and the counts of `counted` over the same members on `space`: the kernel and,
  /// on a GPU, the copy of its rows to the host. finish() waits for them and merges.
  template <class Counted = NothingCounted>
  void start(const ExecSpace& space, const std::vector<Column>& columns, const Counted& counted = {}) {
    num_columns_ = static_cast<int>(columns.size());
    num_counted_ = counted.columns();
    KUSHNER_REQUIRE(num_columns_ > 0 || num_counted_ == 0, "column_moments: counts without a column");
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
    const BlockStatistics<MemSpace>& blocks = rows_.rows(space, num_blocks, 3 * num_columns_ + num_counted_);
    launch_block_statistics("kushner::block_column_moments", space, num_blocks * (num_columns_ + num_counted_), teams_,
                            BlockColumnStatistics<ColumnAddresses<MemSpace>, MemSpace, Counted>{
                                {pointers}, num_columns_, counted, members_, blocks});
    rows_.copy_to_host(space);
    done_.record(space);
  }

  /// The moments and counts start() queued, per column, over every rank (a collective call). Waits for start()'s work
  /// only, not for what was queued on the space after it.
  MergedBlocks finish() {
    if (num_columns_ == 0) return {};
    done_.wait();
    return merge_block_statistics(rows_.host().data(), rows_.host().size(), num_columns_, num_counted_, members_);
  }

 private:
  DeviceAddresses<MemSpace> columns_;
  MomentRows<MemSpace> rows_;
  bool teams_;
  int num_columns_ = 0, num_counted_ = 0, members_ = 0;  // of the last start()
  QueueMark<ExecSpace> done_;                            // after the last start()'s copy
};

}  // namespace kushner
