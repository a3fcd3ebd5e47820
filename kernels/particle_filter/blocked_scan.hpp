#pragma once
// Prefix sums of one member's column, computed by a team in a fixed order that does not depend on the team
// size or the backend: the column is cut into blocks of scan_block_size(n) entries, each block is summed
// sequentially, the block sums are prefixed sequentially, then each block is prefixed sequentially from its
// offset. So the cumulative weights -- and the resampled indices -- are the same bits on CPU and GPU.
// (A tree-ordered parallel_scan would round differently on each backend.)
#include "kernels/particle_filter/tuning.hpp"

#include <Kokkos_Core.hpp>

#include <type_traits>

namespace kushner {

/// At most this many blocks per column: their sums live in team scratch memory (32 KiB of doubles).
constexpr int max_scan_blocks = 4096;

/// Entries per block: 256, or more when the column has more than 256 * max_scan_blocks entries.
KOKKOS_INLINE_FUNCTION constexpr int scan_block_size(int n) {
  const int needed = (n + max_scan_blocks - 1) / max_scan_blocks;
  return needed > 256 ? needed : 256;
}
KOKKOS_INLINE_FUNCTION constexpr int scan_num_blocks(int n) {
  return (n + scan_block_size(n) - 1) / scan_block_size(n);
}

/// values(0 .. n-1, member) <- inclusive prefix sums, in place; returns the total (as stored) on every thread of
/// the team. `block_sums` is team scratch with at least scan_num_blocks(n) entries. Integer columns are exact; a
/// float column is summed in double and each prefix rounded once, where it is stored.
template <class Team, class View, class Scratch>
KOKKOS_INLINE_FUNCTION typename View::non_const_value_type blocked_inclusive_scan(const Team& team, const View& values,
                                                                                  int member, int n,
                                                                                  const Scratch& block_sums) {
  using Value = typename View::non_const_value_type;
  using Sum = std::conditional_t<std::is_floating_point_v<Value>, double, Value>;
  const int block = scan_block_size(n), num_blocks = scan_num_blocks(n);
  // Both passes read `scan_batch` entries before using them: the same sequential sums, but a GPU thread
  // waits for memory once per batch instead of once per entry (the second pass stores into the column it
  // reads, so the compiler cannot move loads ahead by itself).
  Kokkos::parallel_for(Kokkos::TeamThreadRange(team, num_blocks), [&](const int b) {
    const int end = (b + 1) * block < n ? (b + 1) * block : n;
    Sum sum = 0;
    for (int j0 = b * block; j0 < end; j0 += scan_batch) {
      Sum v[scan_batch];
      for (int k = 0; k < scan_batch; ++k) v[k] = j0 + k < end ? values(j0 + k, member) : Value(0);
      for (int k = 0; k < scan_batch; ++k)
        if (j0 + k < end) sum += v[k];
    }
    block_sums(b) = static_cast<double>(sum);
  });
  team.team_barrier();
  Kokkos::single(Kokkos::PerTeam(team), [&]() {
    double offset = 0.0;
    for (int b = 0; b < num_blocks; ++b) {
      const double sum = block_sums(b);
      block_sums(b) = offset;  // exclusive prefix
      offset += sum;
    }
  });
  team.team_barrier();
  Kokkos::parallel_for(Kokkos::TeamThreadRange(team, num_blocks), [&](const int b) {
    const int end = (b + 1) * block < n ? (b + 1) * block : n;
    Sum running = static_cast<Sum>(block_sums(b));
    for (int j0 = b * block; j0 < end; j0 += scan_batch) {
      Sum v[scan_batch];
      for (int k = 0; k < scan_batch; ++k) v[k] = j0 + k < end ? values(j0 + k, member) : Value(0);
      for (int k = 0; k < scan_batch; ++k)
        if (j0 + k < end) {
          running += v[k];
          values(j0 + k, member) = static_cast<Value>(running);
        }
    }
  });
  team.team_barrier();
  return values(n - 1, member);
}

}  // namespace kushner
