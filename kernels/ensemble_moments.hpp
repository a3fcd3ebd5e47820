#pragma once
// Ensemble means and variances in a fixed summation order, so that results are bitwise the same on any
// number of threads: each block of `block_size` consecutive members is reduced sequentially (Welford) by one
// thread, and the host merges the blocks in order (Chan et al.). A Kokkos parallel_reduce would combine
// partial sums in an order that depends on the thread count. Members with a non-finite entry (a path that
// escaped to infinity) are left out and counted. A run split over MPI ranks splits at block boundaries
// (engine/member_share.hpp): the blocks of every rank are gathered and merged in the same order, so the moments
// are the same bits for any number of ranks as well.
#include "core/collectives.hpp"
#include "core/math.hpp"
#include "kernels/bank.hpp"

#include <Kokkos_Core.hpp>

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
