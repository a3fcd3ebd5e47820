#pragma once
// Ensemble means and variances in a fixed summation order, so that results are bitwise the same on any
// number of threads: each block of `moment_block_size` consecutive members is reduced by one thread in a fixed
// order (block_statistic), and the host merges the blocks in order (Chan et al.). A Kokkos parallel_reduce would
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

/// The BlockStatistic of value(m), m in [begin, end), leaving out non-finite values. Two passes (the sum, then the
/// squared deviations from the block's mean); in each, member m adds into partial sum (m - begin) % 8 and the eight
/// are added in a fixed pairwise order. So no division per member (Welford's recurrence, a chain of dependent
/// divisions, made these reductions the slowest part of an output step on the host and on the GPU), eight
/// independent chains, a loop the host compiler vectorizes, and the same bits on every backend and thread count (up
/// to the multiply-adds a GPU contracts).
template <class Value>
KOKKOS_INLINE_FUNCTION BlockStatistic block_statistic(const Value& value, const int begin, const int end) {
  constexpr int L = 8;
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
  s.count = ((count[0] + count[1]) + (count[2] + count[3])) + ((count[4] + count[5]) + (count[6] + count[7]));
  if (s.count == 0.0) return s;
  s.mean = (((sum[0] + sum[1]) + (sum[2] + sum[3])) + ((sum[4] + sum[5]) + (sum[6] + sum[7]))) / s.count;
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
  s.m2 = ((ss[0] + ss[1]) + (ss[2] + ss[3])) + ((ss[4] + ss[5]) + (ss[6] + ss[7]));
  return s;
}

/// blocks(b, 3 c .. 3 c + 2) = the BlockStatistic of column c over block b: the layout merge_block_statistics reads.
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
  blocks(b, 3 * c) = s.count;
  blocks(b, 3 * c + 1) = s.mean;
  blocks(b, 3 * c + 2) = s.m2;
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

/// One (block, column) pair per index i = c * blocks + b: a column's blocks are independent, and a GPU needs the
/// threads (with one thread per block, 1e6 members gave it 3907 threads, and the moments took most of an output step).
template <class MemSpace>
struct BlockMoments {
  using View = Kokkos::View<const double**, Kokkos::LayoutLeft, MemSpace>;
  View x;
  BlockStatistics<MemSpace> blocks;
  KOKKOS_INLINE_FUNCTION void operator()(const int i) const {
    const int num_blocks = static_cast<int>(blocks.extent(0)), b = i % num_blocks, c = i / num_blocks;
    store_block_statistic(blocks, b, c,
                          block_statistic(FiniteRowValue<View>{x, c}, b * moment_block_size,
                                          block_end(b, static_cast<int>(x.extent(0)))));
  }
};

/// A contiguous member-indexed column at a device address.
struct ColumnValue {
  const double* x;
  KOKKOS_INLINE_FUNCTION double operator()(const int m) const { return x[m]; }
};

/// The moments of several columns in one pass, each column on its own (a member non-finite in one column is left
/// out of that column only): the same bits as BlockMoments of that column alone. Indexed like BlockMoments.
template <class MemSpace>
struct BlockColumnMoments {
  Kokkos::View<const std::uintptr_t*, MemSpace> columns;  // column c's values at (const double*) columns(c)
  int members;
  BlockStatistics<MemSpace> blocks;

  KOKKOS_INLINE_FUNCTION void operator()(const int i) const {
    const int num_blocks = static_cast<int>(blocks.extent(0)), b = i % num_blocks, c = i / num_blocks;
    store_block_statistic(blocks, b, c,
                          block_statistic(ColumnValue{reinterpret_cast<const double*>(columns(c))},
                                          b * moment_block_size, block_end(b, members)));
  }
};

struct EnsembleMoments {
  std::vector<double> mean;      // per column, over finite members
  std::vector<double> variance;  // per column, sample variance (divisor finite members - 1)
  long non_finite = 0;           // members left out
  long members = 0;              // members of every rank, finite or not
};

/// Every rank's block statistics (`local`: this rank's `size` doubles of host rows), merged in block order (Chan et
/// al.) per column into one EnsembleMoments per column. The rows of all ranks, in rank order, are the blocks of the
/// whole ensemble in member order, so the result is the same bits for any number of ranks. Columns are merged side
/// by side (the inner loop), so that their chains of divisions overlap.
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
      const double nb = row[3 * c], mean_b = row[3 * c + 1], m2_b = row[3 * c + 2];
      if (nb == 0) continue;
      const double total = count[c] + nb;
      const double delta = mean_b - mean[c];
      mean[c] += delta * nb / total;
      m2[c] += m2_b + delta * delta * count[c] * nb / total;
      count[c] = total;
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
  Kokkos::parallel_for("kushner::block_moments", Kokkos::RangePolicy<ExecSpace>(space, 0, num_blocks * columns),
                       BlockMoments<MemSpace>{x, blocks});
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

  std::vector<EnsembleMoments> operator()(const ExecSpace& space, const std::vector<Column>& columns) {
    const int num_columns = static_cast<int>(columns.size());
    if (num_columns == 0) return {};
    const int members = static_cast<int>(columns.front().extent(0));
    const int num_blocks = static_cast<int>(moment_blocks(members));
    std::vector<std::uintptr_t> addresses;
    for (int c = 0; c < num_columns; ++c) {
      KUSHNER_REQUIRE(static_cast<int>(columns[c].extent(0)) == members && columns[c].span_is_contiguous(),
                      "column_moments: column " << c << " is not a contiguous column of " << members << " members");
      addresses.push_back(reinterpret_cast<std::uintptr_t>(columns[c].data()));
    }
    const auto& pointers = columns_.update(space, addresses);
    if (blocks_.extent(0) != static_cast<std::size_t>(num_blocks) ||
        blocks_.extent(1) != static_cast<std::size_t>(3 * num_columns)) {
      blocks_ =
          BlockStatistics<MemSpace>(Kokkos::view_alloc(space, Kokkos::WithoutInitializing, "kushner::moment_blocks"),
                                    num_blocks, 3 * num_columns);
      // The blocks themselves in host memory; a page-locked copy of them on a GPU.
      rows_ = Kokkos::create_mirror_view(typename HostStaging<MemSpace>::space(), blocks_);
    }
    Kokkos::parallel_for("kushner::block_column_moments",
                         Kokkos::RangePolicy<ExecSpace>(space, 0, num_blocks * num_columns),
                         BlockColumnMoments<MemSpace>{pointers, members, blocks_});
    space.fence();
    if (rows_.data() != blocks_.data()) Kokkos::deep_copy(rows_, blocks_);
    return merge_block_statistics(rows_.data(), rows_.size(), num_columns, members);
  }

 private:
  using HostRows = Kokkos::View<double**, Kokkos::LayoutRight, typename HostStaging<MemSpace>::space>;
  DeviceAddresses<MemSpace> columns_;
  BlockStatistics<MemSpace> blocks_;
  HostRows rows_;  // blocks_ (on the host) or its page-locked copy
};

}  // namespace kushner
