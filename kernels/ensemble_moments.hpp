#pragma once
// Ensemble means and variances in a fixed summation order, so that results are bitwise the same on any
// number of threads: each block of `block_size` consecutive members is reduced sequentially (Welford) by one
// thread, and the host merges the blocks in order (Chan et al.). A Kokkos parallel_reduce would combine
// partial sums in an order that depends on the thread count. Members with a non-finite entry (a path that
// escaped to infinity) are left out and counted. A run split over MPI ranks splits at block boundaries
// (engine/member_share.hpp): the blocks of every rank are gathered and merged in the same order, so the moments
// are the same bits for any number of ranks as well.
#include "core/collectives.hpp"
#include "core/errors.hpp"
#include "core/math.hpp"
#include "kernels/bank.hpp"

#include <Kokkos_Core.hpp>

#include <cstdint>
#include <limits>
#include <vector>

namespace kushner {

constexpr int moment_block_size = 256;

/// blocks(b, 0) = finite members of block b; blocks(b, 1 + c) = mean of column c; blocks(b, 1 + K + c) = sum
/// of squared deviations of column c, over the finite members of block b (K = columns).
template <class MemSpace>
struct BlockMoments {
  Kokkos::View<const double**, Kokkos::LayoutLeft, MemSpace> x;
  Kokkos::View<double**, Kokkos::LayoutLeft, MemSpace> blocks;

  KOKKOS_INLINE_FUNCTION void operator()(const int b) const {
    const int columns = static_cast<int>(x.extent(1));
    const int begin = b * moment_block_size;
    const int end = begin + moment_block_size < static_cast<int>(x.extent(0)) ? begin + moment_block_size
                                                                              : static_cast<int>(x.extent(0));
    for (int c = 0; c < columns; ++c) blocks(b, 1 + c) = blocks(b, 1 + columns + c) = 0.0;
    int count = 0;
    for (int m = begin; m < end; ++m) {
      bool finite = true;
      for (int c = 0; c < columns; ++c) finite = finite && math::is_finite(x(m, c));
      if (!finite) continue;
      ++count;
      for (int c = 0; c < columns; ++c) {
        const double delta = x(m, c) - blocks(b, 1 + c);
        blocks(b, 1 + c) += delta / count;
        blocks(b, 1 + columns + c) += delta * (x(m, c) - blocks(b, 1 + c));
      }
    }
    blocks(b, 0) = count;
  }
};

/// The moments of several columns in one pass, each column on its own (a member non-finite in one column is left
/// out of that column only): blocks(b, 3 c) = finite members of column c in block b, blocks(b, 3 c + 1) their
/// mean, blocks(b, 3 c + 2) their sum of squared deviations, by the same Welford recurrence as BlockMoments of
/// that column alone, so the same bits. A column's recurrence is a chain of dependent divisions; four columns
/// side by side overlap theirs.
template <class MemSpace>
struct BlockColumnMoments {
  Kokkos::View<const std::uintptr_t*, MemSpace> columns;  // column c's values at (const double*) columns(c)
  int members;
  Kokkos::View<double**, Kokkos::LayoutLeft, MemSpace> blocks;

  KOKKOS_INLINE_FUNCTION void operator()(const int b) const {
    constexpr int G = 4;
    const int num_columns = static_cast<int>(columns.extent(0));
    const int begin = b * moment_block_size;
    const int end = begin + moment_block_size < members ? begin + moment_block_size : members;
    for (int c0 = 0; c0 < num_columns; c0 += G) {
      const int g = num_columns - c0 < G ? num_columns - c0 : G;
      const double* x[G];
      int count[G];
      double mean[G], m2[G];
      for (int k = 0; k < G; ++k) {
        x[k] = k < g ? reinterpret_cast<const double*>(columns(c0 + k)) : nullptr;
        count[k] = 0;
        mean[k] = m2[k] = 0.0;
      }
      for (int m = begin; m < end; ++m)
        for (int k = 0; k < g; ++k) {
          const double v = x[k][m];
          if (!math::is_finite(v)) continue;
          ++count[k];
          const double delta = v - mean[k];
          mean[k] += delta / count[k];
          m2[k] += delta * (v - mean[k]);
        }
      for (int k = 0; k < g; ++k) {
        blocks(b, 3 * (c0 + k)) = count[k];
        blocks(b, 3 * (c0 + k) + 1) = mean[k];
        blocks(b, 3 * (c0 + k) + 2) = m2[k];
      }
    }
  }
};

struct EnsembleMoments {
  std::vector<double> mean;      // per column, over finite members
  std::vector<double> variance;  // per column, sample variance (divisor finite members - 1)
  long non_finite = 0;           // members left out
  long members = 0;              // members of every rank, finite or not
};

/// Mean and sample variance of every column of x(member, column) over members.
template <class ExecSpace, class View>
EnsembleMoments ensemble_moments(const ExecSpace& space, const View& x) {
  using MemSpace = typename View::memory_space;
  const int members = static_cast<int>(x.extent(0));
  const int columns = static_cast<int>(x.extent(1));
  const int num_blocks = (members + moment_block_size - 1) / moment_block_size;
  // Zero-filled on `space`, not on the default execution space: with a few members on Serial, an OpenMP
  // fork and join per call cost more than the moments (kushner reproduce's one-member runs).
  Kokkos::View<double**, Kokkos::LayoutLeft, MemSpace> blocks(Kokkos::view_alloc(space, "kushner::moment_blocks"),
                                                              num_blocks, 1 + 2 * columns);
  Kokkos::parallel_for("kushner::block_moments", Kokkos::RangePolicy<ExecSpace>(space, 0, num_blocks),
                       BlockMoments<MemSpace>{x, blocks});
  space.fence();
  const auto host = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), blocks);
  // Every rank's blocks, row after row, in rank order: the blocks of the whole ensemble in member order.
  const int width = 1 + 2 * columns;
  std::vector<double> local(static_cast<std::size_t>(num_blocks) * width);
  for (int b = 0; b < num_blocks; ++b)
    for (int j = 0; j < width; ++j) local[static_cast<std::size_t>(b) * width + j] = host(b, j);
  const std::vector<double> all = collective::gather(local);
  const long all_blocks = static_cast<long>(all.size()) / width;
  const long all_members = collective::sum(members);

  EnsembleMoments result{std::vector<double>(columns, 0.0), std::vector<double>(columns, 0.0), all_members,
                         all_members};
  for (int c = 0; c < columns; ++c) {
    double count = 0.0, mean = 0.0, m2 = 0.0;
    for (long b = 0; b < all_blocks; ++b) {
      const double* row = all.data() + b * width;
      const double nb = row[0], mean_b = row[1 + c], m2_b = row[1 + columns + c];
      if (nb == 0) continue;
      const double total = count + nb;
      const double delta = mean_b - mean;
      mean += delta * nb / total;
      m2 += m2_b + delta * delta * count * nb / total;
      count = total;
    }
    result.mean[c] = count > 0 ? mean : std::numeric_limits<double>::quiet_NaN();
    result.variance[c] = count > 1 ? m2 / (count - 1) : std::numeric_limits<double>::quiet_NaN();
    result.non_finite = all_members - static_cast<long>(count);
  }
  return result;
}

}  // namespace kushner

namespace kushner {

/// ensemble_moments of each of `columns` (contiguous member-indexed columns of equal length, e.g. subviews
/// (ALL, c) of LayoutLeft banks), bit for bit, in one pass over the blocks and one gather over the ranks.
template <class ExecSpace, class MemSpace>
std::vector<EnsembleMoments> column_moments(const ExecSpace& space,
                                            const std::vector<Kokkos::View<const double*, MemSpace>>& columns) {
  const int num_columns = static_cast<int>(columns.size());
  if (num_columns == 0) return {};
  const int members = static_cast<int>(columns.front().extent(0));
  const int num_blocks = (members + moment_block_size - 1) / moment_block_size;
  Kokkos::View<std::uintptr_t*, MemSpace> pointers(Kokkos::view_alloc(space, "kushner::moment_columns"), num_columns);
  const auto host_pointers = Kokkos::create_mirror_view(pointers);
  for (int c = 0; c < num_columns; ++c) {
    KUSHNER_REQUIRE(static_cast<int>(columns[c].extent(0)) == members && columns[c].span_is_contiguous(),
                    "column_moments: column " << c << " is not a contiguous column of " << members << " members");
    host_pointers(c) = reinterpret_cast<std::uintptr_t>(columns[c].data());
  }
  Kokkos::deep_copy(space, pointers, host_pointers);
  const int width = 3 * num_columns;
  Kokkos::View<double**, Kokkos::LayoutLeft, MemSpace> blocks(Kokkos::view_alloc(space, "kushner::moment_blocks"),
                                                              num_blocks, width);
  Kokkos::parallel_for("kushner::block_column_moments", Kokkos::RangePolicy<ExecSpace>(space, 0, num_blocks),
                       BlockColumnMoments<MemSpace>{pointers, members, blocks});
  space.fence();
  const auto host = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), blocks);
  std::vector<double> local(static_cast<std::size_t>(num_blocks) * width);
  for (int b = 0; b < num_blocks; ++b)
    for (int j = 0; j < width; ++j) local[static_cast<std::size_t>(b) * width + j] = host(b, j);
  const std::vector<double> all = collective::gather(local);
  const long all_blocks = static_cast<long>(all.size()) / width;
  const long all_members = collective::sum(members);
  std::vector<EnsembleMoments> result;
  for (int c = 0; c < num_columns; ++c) {
    // ensemble_moments' merge of one column's blocks, in block order.
    double count = 0.0, mean = 0.0, m2 = 0.0;
    for (long b = 0; b < all_blocks; ++b) {
      const double* row = all.data() + b * width + 3 * c;
      const double nb = row[0], mean_b = row[1], m2_b = row[2];
      if (nb == 0) continue;
      const double total = count + nb;
      const double delta = mean_b - mean;
      mean += delta * nb / total;
      m2 += m2_b + delta * delta * count * nb / total;
      count = total;
    }
    EnsembleMoments mo{{count > 0 ? mean : std::numeric_limits<double>::quiet_NaN()},
                       {count > 1 ? m2 / (count - 1) : std::numeric_limits<double>::quiet_NaN()},
                       all_members - static_cast<long>(count),
                       all_members};
    result.push_back(mo);
  }
  return result;
}

}  // namespace kushner
