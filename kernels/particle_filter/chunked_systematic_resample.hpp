#pragma once
// Systematic resampling of the members that need it, spread over many teams per member: the particle
// filter's resampling path on GPUs. A member of 65536 particles resampled by one team (one multiprocessor)
// kept the rest of the GPU idle for ~0.2 ms per step; here every chunk of particles of every listed member is
// a work item, in four kernels:
//   1. block sums:  w_j = exp(l_j - log_normalizer) summed sequentially over each scan block
//   2. cumulative:  each block's cumulative weights C_j, from the prefix of the block sums, over the
//                   log-weights (which resampling resets anyway)
//   3. scatter:     particle j is copied into the slots s with g(C_{j-1}) <= s < g(C_j),
//                   g(C) = ceil(N C / C_{N-1} - u)
//   4. copy back:   the resampled particles return to the bank, with equal weights
// Every thread's sequential chain is at most one scan block long (or the block sums before it): a first
// version recomputed whole blocks of exp() in one thread and spent 0.1 ms per step there.
// The sums are the ones blocked_inclusive_scan and resample_member compute (same blocks, same sequential
// order, same expressions), so the indices are the same as the one-team path's on every backend; the test
// ChunkedSystematic.MatchesTheTeamPathAndMovesTheParticles (tests/test_resampling.cpp) checks it.
#include "kernels/bank.hpp"
#include "kernels/errors.hpp"
#include "kernels/math.hpp"
#include "kernels/particle_filter/blocked_scan.hpp"
#include "kernels/particle_filter/resampling.hpp"

#include <Kokkos_Core.hpp>

#include <cstdint>

namespace kushner {

/// Particles of a work item: whole scan blocks, at most this many (their weights live in team scratch).
constexpr int resample_chunk_particles = 2048;

/// Whether the chunked path handles members of n particles: its chunks hold whole scan blocks.
KOKKOS_INLINE_FUNCTION constexpr bool chunked_resample_supports(int n) {
  return scan_block_size(n) <= resample_chunk_particles;
}
KOKKOS_INLINE_FUNCTION constexpr int resample_chunk_blocks(int n) {
  return resample_chunk_particles / scan_block_size(n);
}
KOKKOS_INLINE_FUNCTION constexpr int resample_chunks(int n) {
  return (scan_num_blocks(n) + resample_chunk_blocks(n) - 1) / resample_chunk_blocks(n);
}

/// What the four kernels read and write. Views are (particle, member[, i]) or (member), LayoutLeft.
template <class MemSpace>
struct ChunkedResampleData {
  ParticleBank<MemSpace> x, x_scratch;
  Kokkos::View<double**, Kokkos::LayoutLeft, MemSpace> log_weight;
  Kokkos::View<int**, Kokkos::LayoutLeft, MemSpace> ancestors;    // a_s, kept for inspection and tests
  Kokkos::View<double**, Kokkos::LayoutLeft, MemSpace> block_sums;  // (scan block, member)
  BankScalar<double, MemSpace> log_normalizer;
  Kokkos::View<int*, MemSpace> members;  // the members to resample: entries [0, member_count())
  Kokkos::View<int, MemSpace> member_count;
  int num_particles = 0;
  std::uint32_t seed = 0, step = 0;
};

namespace detail {

/// Loops the team over work items (listed member, chunk), so a fixed league covers any number of members:
/// body(member, begin, end) with the chunk's particles [begin, end), resample_chunk_blocks(n) whole scan blocks.
template <class Team, class MemSpace, class Body>
KOKKOS_INLINE_FUNCTION void for_each_chunk(const Team& team, const ChunkedResampleData<MemSpace>& d, const Body& body) {
  const int n = d.num_particles, chunks = resample_chunks(n), size = resample_chunk_blocks(n) * scan_block_size(n);
  const int items = d.member_count() * chunks;
  for (int item = team.league_rank(); item < items; item += team.league_size()) {
    const int begin = (item % chunks) * size;
    body(d.members(item / chunks), begin, begin + size < n ? begin + size : n);
    team.team_barrier();  // the next item reuses the team's scratch
  }
}

/// The weights exp(l - log_normalizer) of particles [begin, end) into team scratch, loaded by the whole team.
template <class Team, class MemSpace, class Scratch>
KOKKOS_INLINE_FUNCTION void load_weights(const Team& team, const ChunkedResampleData<MemSpace>& d, int member,
                                         int begin, int end, const Scratch& w) {
  const double log_total = d.log_normalizer(member);
  Kokkos::parallel_for(Kokkos::TeamThreadRange(team, begin, end),
                       [&](const int j) { w(j - begin) = math::exp(d.log_weight(j, member) - log_total); });
  team.team_barrier();
}

/// Sum of block_sums(0 .. b-1, member) in index order: blocked_inclusive_scan's exclusive prefix.
template <class MemSpace>
KOKKOS_INLINE_FUNCTION double block_offset(const ChunkedResampleData<MemSpace>& d, int member, int b) {
  double offset = 0.0;
  for (int b0 = 0; b0 < b; b0 += scan_batch) {
    double v[scan_batch];
    for (int k = 0; k < scan_batch; ++k) v[k] = b0 + k < b ? d.block_sums(b0 + k, member) : 0.0;
    for (int k = 0; k < scan_batch; ++k)
      if (b0 + k < b) offset += v[k];
  }
  return offset;
}

/// For each work item: the chunk's weights into team scratch `w`, then, on one thread per scan block of the
/// chunk, body(member, b, begin, lo, hi): block b, the chunk's first particle, the block's entries [lo, hi) of w.
template <class Team, class MemSpace, class Scratch, class Body>
KOKKOS_INLINE_FUNCTION void for_each_weight_block(const Team& team, const ChunkedResampleData<MemSpace>& d,
                                                  const Scratch& w, const Body& body) {
  for_each_chunk(team, d, [&](int member, int begin, int end) {
    load_weights(team, d, member, begin, end, w);
    const int block = scan_block_size(d.num_particles);
    const int first_block = begin / block, blocks = (end - begin + block - 1) / block;
    Kokkos::parallel_for(Kokkos::TeamThreadRange(team, blocks), [&](const int k) {
      const int lo = k * block, hi = lo + block < end - begin ? lo + block : end - begin;
      body(member, first_block + k, begin, lo, hi);
    });
  });
}

/// running + w(lo) + w(lo + 1) + ... + w(hi - 1), added in that order (blocked_inclusive_scan's), each
/// partial sum handed to partial(j, sum); the loads of a batch are issued together.
template <class Scratch, class Partial>
KOKKOS_INLINE_FUNCTION double add_in_order(const Scratch& w, int lo, int hi, double running, const Partial& partial) {
  for (int j0 = lo; j0 < hi; j0 += scan_batch) {
    double v[scan_batch];
    for (int i = 0; i < scan_batch; ++i) v[i] = j0 + i < hi ? w(j0 + i) : 0.0;
    for (int i = 0; i < scan_batch; ++i)
      if (j0 + i < hi) {
        running += v[i];
        partial(j0 + i, running);
      }
  }
  return running;
}

}  // namespace detail

/// Kernels 1 and 2, blocked_inclusive_scan's two passes over each chunk. Pass 1 (Cumulative false):
/// block_sums(b, member) = the sum of scan block b's weights in particle order. Pass 2: the cumulative weights
/// C_j, from each block's offset, written over the log-weights.
template <class ExecSpace, bool Cumulative>
struct ChunkedScanPass {
  using MemSpace = typename ExecSpace::memory_space;
  using Team = typename Kokkos::TeamPolicy<ExecSpace>::member_type;
  using Scratch = Kokkos::View<double*, typename ExecSpace::scratch_memory_space, Kokkos::MemoryUnmanaged>;
  ChunkedResampleData<MemSpace> d;

  KOKKOS_INLINE_FUNCTION void operator()(const Team& team) const {
    const Scratch w(team.team_scratch(0), resample_chunk_particles);
    detail::for_each_weight_block(team, d, w, [&](int member, int b, int begin, int lo, int hi) {
      if constexpr (Cumulative)
        detail::add_in_order(w, lo, hi, detail::block_offset(d, member, b),
                             [&](int j, double c) { d.log_weight(begin + j, member) = c; });
      else
        d.block_sums(b, member) = detail::add_in_order(w, lo, hi, 0.0, [](int, double) {});
    });
  }
};

/// Kernel 3: each particle copied into its slots of x_scratch (resample_member's systematic rule, on the
/// same cumulative weights).
template <class ExecSpace, int N>
struct ChunkedSystematicScatter {
  using MemSpace = typename ExecSpace::memory_space;
  using Team = typename Kokkos::TeamPolicy<ExecSpace>::member_type;
  ChunkedResampleData<MemSpace> d;

  KOKKOS_INLINE_FUNCTION void operator()(const Team& team) const {
    detail::for_each_chunk(team, d, [&](int member, int begin, int end) {
      const int n = d.num_particles;
      const auto& c = d.log_weight;  // now the cumulative weights
      const double total = c(n - 1, member);
      const double u = detail::resampling_uniform(d.seed, member, 0, d.step);
      Kokkos::parallel_for(Kokkos::TeamThreadRange(team, begin, end), [&](const int j) {
        const double lo = j > 0 ? c(j - 1, member) : 0.0, hi = c(j, member);
        const int first = j == 0 ? 0 : detail::ceil_clamped((lo * n) / total - u, n);
        const int last = j == n - 1 ? n : detail::ceil_clamped((hi * n) / total - u, n);
        if (first >= last) return;
        double v[N];
        for (int i = 0; i < N; ++i) v[i] = d.x(j, member, i);
        for (int s = first; s < last; ++s) {
          d.ancestors(s, member) = j;
          for (int i = 0; i < N; ++i) d.x_scratch(s, member, i) = v[i];
        }
      });
    });
  }
};

/// Kernel 4: the resampled particles back into the bank, log-weights 0 and log-normalizer log N.
template <class ExecSpace, int N>
struct ChunkedCopyBack {
  using MemSpace = typename ExecSpace::memory_space;
  using Team = typename Kokkos::TeamPolicy<ExecSpace>::member_type;
  ChunkedResampleData<MemSpace> d;

  KOKKOS_INLINE_FUNCTION void operator()(const Team& team) const {
    detail::for_each_chunk(team, d, [&](int member, int begin, int end) {
      Kokkos::parallel_for(Kokkos::TeamThreadRange(team, begin, end), [&](const int s) {
        for (int i = 0; i < N; ++i) d.x(s, member, i) = d.x_scratch(s, member, i);
        d.log_weight(s, member) = 0.0;
      });
      if (begin == 0)
        Kokkos::single(Kokkos::PerTeam(team),
                       [&]() { d.log_normalizer(member) = math::log(static_cast<double>(d.num_particles)); });
    });
  }
};

/// Resamples the listed members systematically (d.members, d.member_count on the device). `team_size`:
/// threads per team; `league`: teams, each looping over the work items. No fence.
template <int N, class ExecSpace>
void chunked_systematic_resample(const ExecSpace& space, const ChunkedResampleData<typename ExecSpace::memory_space>& d,
                                 int team_size, int league) {
  KUSHNER_REQUIRE(chunked_resample_supports(d.num_particles),
                  "chunked resampling: " << d.num_particles << " particles per member is more than it supports");
  using Policy = Kokkos::TeamPolicy<ExecSpace>;
  const std::size_t scratch = sizeof(double) * resample_chunk_particles;
  Kokkos::parallel_for("kushner::resample_block_sums",
                       Policy(space, league, team_size).set_scratch_size(0, Kokkos::PerTeam(scratch)),
                       ChunkedScanPass<ExecSpace, false>{d});
  Kokkos::parallel_for("kushner::resample_cumulative",
                       Policy(space, league, team_size).set_scratch_size(0, Kokkos::PerTeam(scratch)),
                       ChunkedScanPass<ExecSpace, true>{d});
  Kokkos::parallel_for("kushner::resample_scatter", Policy(space, league, team_size),
                       ChunkedSystematicScatter<ExecSpace, N>{d});
  Kokkos::parallel_for("kushner::resample_copy_back", Policy(space, league, team_size),
                       ChunkedCopyBack<ExecSpace, N>{d});
}

}  // namespace kushner
