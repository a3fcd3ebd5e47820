#pragma once
// Systematic resampling of the members that need it, spread over many teams per member: the particle
// filter's resampling path on GPUs. A member resampled by one team (one multiprocessor) leaves the rest of the
// GPU idle (perf/particle_filter.md, "Resampling"); here every chunk of particles of every listed member is
// a work item, in four kernels:
//   1. block sums:  w_j = exp(l_j - log_normalizer) summed sequentially over each scan block
//   2. cumulative:  each block's cumulative weights C_j, from the prefix of the block sums, over the
//                   log-weights (which resampling resets anyway)
//   3. scatter:     particle j is copied into the slots s with g(C_{j-1}) <= s < g(C_j),
//                   g(C) = ceil(N C / C_{N-1} - u)
//   4. copy back:   the resampled particles return to the bank, with equal weights
// Every thread's sequential chain is at most one scan block long (or the block sums before it, read from team
// scratch), so no thread recomputes whole blocks of exp() alone.
// The kernels are latency-bound (a step resamples one or two members of a thousand), so each thread issues
// the loads of its share of a chunk together: one memory latency per chunk, not one per particle.
// The sums are the ones blocked_inclusive_scan and resample_member compute (same blocks, same sequential
// order, same expressions), so the indices are the same as the one-team path's on every backend; the test
// ChunkedSystematic.MatchesTheTeamPathAndMovesTheParticles (tests/test_resampling.cpp) checks it.
#include "core/errors.hpp"
#include "core/math.hpp"
#include "kernels/bank.hpp"
#include "kernels/particle_filter/blocked_scan.hpp"
#include "kernels/particle_filter/resampling.hpp"
#include "kernels/particle_filter/tuning.hpp"

#include <Kokkos_Core.hpp>

#include <cstdint>

namespace kushner {

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

/// What the four kernels read and write. Views are (particle, member[, i]) or (member), LayoutLeft; the particles
/// and log-weights (then cumulative weights) stored as Real.
template <class MemSpace, class Real = double>
struct ChunkedResampleData {
  using Stored = Real;
  ParticleBank<MemSpace, Real> x, x_scratch;
  ParticleColumn<MemSpace, Real> log_weight;
  Kokkos::View<int**, Kokkos::LayoutLeft, MemSpace> ancestors;      // a_s, kept for inspection and tests
  Kokkos::View<double**, Kokkos::LayoutLeft, MemSpace> block_sums;  // (scan block, member)
  BankScalar<double, MemSpace> log_normalizer;
  Kokkos::View<int*, MemSpace> members;  // the members to resample: entries [0, member_count())
  Kokkos::View<int, MemSpace> member_count;
  int num_particles = 0;
  Seed seed;
  std::uint32_t step = 0;
};

namespace detail {

/// Loops the team over work items (listed member, chunk), so a fixed league covers any number of members:
/// body(member, begin, end) with the chunk's particles [begin, end), resample_chunk_blocks(n) whole scan blocks.
template <class Team, class Data, class Body>
KOKKOS_INLINE_FUNCTION void for_each_chunk(const Team& team, const Data& d, const Body& body) {
  const int n = d.num_particles, chunks = resample_chunks(n), size = resample_chunk_blocks(n) * scan_block_size(n);
  const int items = d.member_count() * chunks;
  for (int item = team.league_rank(); item < items; item += team.league_size()) {
    const int begin = (item % chunks) * size;
    body(d.members(item / chunks), begin, begin + size < n ? begin + size : n);
    team.team_barrier();  // the next item reuses the team's scratch
  }
}

/// body(j0, stride) for each batch of the team's particles [begin, end): the thread's particles
/// j0 + k stride, k < resample_batch (those below `end`), whose loads the body issues before it uses them.
template <class Team, class Body>
KOKKOS_INLINE_FUNCTION void for_each_batch(const Team& team, int begin, int end, const Body& body) {
  const int threads = team.team_size();
  for (int j0 = begin + team.team_rank(); j0 < end; j0 += resample_batch * threads) body(j0, threads);
}

/// The weights exp(l - log_normalizer) of particles [begin, end) into team scratch, loaded by the whole team, as
/// the one-team path stores them (rounded to the bank's Real).
template <class Team, class Data, class Scratch>
KOKKOS_INLINE_FUNCTION void load_weights(const Team& team, const Data& d, int member, int begin, int end,
                                         const Scratch& w) {
  using Real = typename Data::Stored;
  const double log_total = d.log_normalizer(member);
  for_each_batch(team, begin, end, [&](int j0, int stride) {
    double l[resample_batch];
    for (int k = 0; k < resample_batch; ++k) l[k] = j0 + k * stride < end ? d.log_weight(j0 + k * stride, member) : 0.0;
    for (int k = 0; k < resample_batch; ++k)
      if (j0 + k * stride < end) w(j0 + k * stride - begin) = stored_value<Real>(math::exp(l[k] - log_total));
  });
  team.team_barrier();
}

/// offsets(k) = the sum of block_sums(0 .. first_block + k - 1, member) in index order (blocked_inclusive_scan's
/// exclusive prefix), k < blocks. The block sums come into team scratch `sums` first, in one parallel load.
template <class Team, class Data, class Scratch>
KOKKOS_INLINE_FUNCTION void block_offsets(const Team& team, const Data& d, int member, int first_block, int blocks,
                                          const Scratch& sums, const Scratch& offsets) {
  Kokkos::parallel_for(Kokkos::TeamThreadRange(team, first_block + blocks),
                       [&](const int b) { sums(b) = d.block_sums(b, member); });
  team.team_barrier();
  Kokkos::parallel_for(Kokkos::TeamThreadRange(team, blocks), [&](const int k) {
    double offset = 0.0;
    for (int b = 0; b < first_block + k; ++b) offset += sums(b);
    offsets(k) = offset;
  });
  team.team_barrier();
}

/// For each work item: the chunk's weights into team scratch `w`, then, on one thread per scan block of the
/// chunk, body(member, b, begin, lo, hi, offset): block b, the chunk's first particle, the block's entries
/// [lo, hi) of w and (WithOffsets) the sum of the member's block sums before b, else 0. `w` has
/// scan_num_blocks(n) entries at least; `offsets` resample_chunk_blocks(n).
template <bool WithOffsets, class Team, class Data, class Scratch, class Body>
KOKKOS_INLINE_FUNCTION void for_each_weight_block(const Team& team, const Data& d, const Scratch& w,
                                                  const Scratch& offsets, const Body& body) {
  for_each_chunk(team, d, [&](int member, int begin, int end) {
    const int block = scan_block_size(d.num_particles);
    const int first_block = begin / block, blocks = (end - begin + block - 1) / block;
    if (WithOffsets) block_offsets(team, d, member, first_block, blocks, w, offsets);  // before w holds weights
    load_weights(team, d, member, begin, end, w);
    Kokkos::parallel_for(Kokkos::TeamThreadRange(team, blocks), [&](const int k) {
      const int lo = k * block, hi = lo + block < end - begin ? lo + block : end - begin;
      body(member, first_block + k, begin, lo, hi, WithOffsets ? offsets(k) : 0.0);
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
template <class ExecSpace, bool Cumulative, class Real = double>
struct ChunkedScanPass {
  using MemSpace = typename ExecSpace::memory_space;
  using Team = typename Kokkos::TeamPolicy<ExecSpace>::member_type;
  using Scratch = Kokkos::View<double*, typename ExecSpace::scratch_memory_space, Kokkos::MemoryUnmanaged>;
  ChunkedResampleData<MemSpace, Real> d;

  /// Team scratch: the chunk's weights (or, before them, the member's block sums), then the blocks' offsets.
  KOKKOS_INLINE_FUNCTION static int weights_size(int n) {
    return scan_num_blocks(n) > resample_chunk_particles ? scan_num_blocks(n) : resample_chunk_particles;
  }
  static std::size_t scratch_bytes(int n) {
    return Scratch::shmem_size(weights_size(n)) + Scratch::shmem_size(resample_chunk_blocks(n));
  }

  KOKKOS_INLINE_FUNCTION void operator()(const Team& team) const {
    const int n = d.num_particles;
    const Scratch w(team.team_scratch(0), weights_size(n)), offsets(team.team_scratch(0), resample_chunk_blocks(n));
    detail::for_each_weight_block<Cumulative>(
        team, d, w, offsets, [&](int member, int b, int begin, int lo, int hi, double offset) {
          if constexpr (Cumulative)
            detail::add_in_order(w, lo, hi, offset,
                                 [&](int j, double c) { d.log_weight(begin + j, member) = static_cast<Real>(c); });
          else
            d.block_sums(b, member) = detail::add_in_order(w, lo, hi, 0.0, [](int, double) {});
        });
  }
};

/// Kernel 3: each particle copied into its slots of x_scratch (resample_member's systematic rule, on the
/// same cumulative weights).
template <class ExecSpace, int N, class Real = double>
struct ChunkedSystematicScatter {
  using MemSpace = typename ExecSpace::memory_space;
  using Team = typename Kokkos::TeamPolicy<ExecSpace>::member_type;
  ChunkedResampleData<MemSpace, Real> d;

  KOKKOS_INLINE_FUNCTION void operator()(const Team& team) const {
    detail::for_each_chunk(team, d, [&](int member, int begin, int end) {
      const int n = d.num_particles;
      const auto& c = d.log_weight;  // now the cumulative weights
      const double total = c(n - 1, member);
      const double u = detail::resampling_uniform(d.seed, member, 0, d.step);
      detail::for_each_batch(team, begin, end, [&](int j0, int stride) {
        constexpr int B = resample_batch;
        double lo[B], hi[B], v[B][N];
        for (int k = 0; k < B; ++k) {
          const int j = j0 + k * stride;
          if (j >= end) continue;
          lo[k] = j > 0 ? c(j - 1, member) : 0.0;
          hi[k] = c(j, member);
          for (int i = 0; i < N; ++i) v[k][i] = d.x(j, member, i);
        }
        for (int k = 0; k < B; ++k) {
          const int j = j0 + k * stride;
          if (j >= end) continue;
          const int first = j == 0 ? 0 : detail::ceil_clamped((lo[k] * n) / total - u, n);
          const int last = j == n - 1 ? n : detail::ceil_clamped((hi[k] * n) / total - u, n);
          for (int s = first; s < last; ++s) {
            d.ancestors(s, member) = j;
            for (int i = 0; i < N; ++i) d.x_scratch(s, member, i) = static_cast<Real>(v[k][i]);
          }
        }
      });
    });
  }
};

/// Kernel 4: the resampled particles back into the bank, log-weights 0 and log-normalizer log N.
template <class ExecSpace, int N, class Real = double>
struct ChunkedCopyBack {
  using MemSpace = typename ExecSpace::memory_space;
  using Team = typename Kokkos::TeamPolicy<ExecSpace>::member_type;
  ChunkedResampleData<MemSpace, Real> d;

  KOKKOS_INLINE_FUNCTION void operator()(const Team& team) const {
    detail::for_each_chunk(team, d, [&](int member, int begin, int end) {
      detail::for_each_batch(team, begin, end, [&](int s0, int stride) {
        double v[resample_batch][N];
        for (int k = 0; k < resample_batch; ++k)
          if (s0 + k * stride < end)
            for (int i = 0; i < N; ++i) v[k][i] = d.x_scratch(s0 + k * stride, member, i);
        for (int k = 0; k < resample_batch; ++k)
          if (s0 + k * stride < end) {
            for (int i = 0; i < N; ++i) d.x(s0 + k * stride, member, i) = static_cast<Real>(v[k][i]);
            d.log_weight(s0 + k * stride, member) = 0.0;
          }
      });
      if (begin == 0)
        Kokkos::single(Kokkos::PerTeam(team),
                       [&]() { d.log_normalizer(member) = math::log(static_cast<double>(d.num_particles)); });
    });
  }
};

/// Resamples the listed members systematically (d.members, d.member_count on the device). `team_size`:
/// threads per team; `league`: teams, each looping over the work items. No fence.
template <int N, class ExecSpace, class Real>
void chunked_systematic_resample(const ExecSpace& space,
                                 const ChunkedResampleData<typename ExecSpace::memory_space, Real>& d, int team_size,
                                 int league) {
  KUSHNER_REQUIRE(chunked_resample_supports(d.num_particles),
                  "chunked resampling: " << d.num_particles << " particles per member is more than it supports");
  using Policy = Kokkos::TeamPolicy<ExecSpace>;
  const std::size_t scratch = ChunkedScanPass<ExecSpace, false, Real>::scratch_bytes(d.num_particles);
  Kokkos::parallel_for("kushner::resample_block_sums",
                       Policy(space, league, team_size).set_scratch_size(0, Kokkos::PerTeam(scratch)),
                       ChunkedScanPass<ExecSpace, false, Real>{d});
  Kokkos::parallel_for("kushner::resample_cumulative",
                       Policy(space, league, team_size).set_scratch_size(0, Kokkos::PerTeam(scratch)),
                       ChunkedScanPass<ExecSpace, true, Real>{d});
  Kokkos::parallel_for("kushner::resample_scatter", Policy(space, league, team_size),
                       ChunkedSystematicScatter<ExecSpace, N, Real>{d});
  Kokkos::parallel_for("kushner::resample_copy_back", Policy(space, league, team_size),
                       ChunkedCopyBack<ExecSpace, N, Real>{d});
}

}  // namespace kushner
