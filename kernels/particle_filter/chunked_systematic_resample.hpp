#pragma once
// Systematic resampling of the members that need it, spread over many teams per member: the particle
// filter's resampling path on GPUs. A member resampled by one team (one multiprocessor) leaves the rest of the
// GPU idle (perf/particle_filter.md, "Resampling"); here every chunk of particles of every listed member is
// a work item, in three kernels:
//   1. block sums:  w_j = exp(l_j - log_normalizer) summed sequentially over each scan block
//   2. scatter:     the chunk's cumulative weights C_j in team scratch, each block's from the prefix of the block
//                   sums; then particle j is copied into the slots s with g(C_{j-1}) <= s < g(C_j),
//                   g(C) = ceil(N C / C_{N-1} - u). C_{begin-1} and the total C_{N-1} come from two more chains:
//                   the block before the chunk and the member's last block.
//   3. copy back:   the resampled particles return to the bank, with equal weights (none where the scatter wrote
//                   them into another bank: ChunkedResampleData::x_into)
// Every thread's sequential chain is at most one scan block long (or the block sums before it, read from team
// scratch), so no thread recomputes whole blocks of exp() alone. The cumulative weights never go to memory: the
// scatter takes them from the team that computed them (one kernel launch and one pass over the weights fewer than
// a kernel of their own).
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

/// What the three kernels read and write. Views are (particle, member[, i]) or (member), LayoutLeft; the particles
/// and log-weights stored as Real.
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
  // Where allocated: the resampled particles go into this other bank, with log-weights 0 and log-normalizer log N,
  // and x, log_weight and log_normalizer stay as they were (no copy back; x_scratch unused).
  ParticleBank<MemSpace, Real> x_into;
  ParticleColumn<MemSpace, Real> log_weight_into;
  BankScalar<double, MemSpace> log_normalizer_into;
};

/// The log-normalizer of n particles of log-weight 0, as resampling leaves them.
KOKKOS_INLINE_FUNCTION double equal_log_normalizer(int n) { return math::log(static_cast<double>(n)); }

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

/// The weights exp(l - log_normalizer) of particles [begin, end) into team scratch w(at + j - begin), as the
/// one-team path stores them (rounded to the bank's Real). No barrier.
template <class Team, class Data, class Scratch>
KOKKOS_INLINE_FUNCTION void load_weights(const Team& team, const Data& d, int member, int begin, int end,
                                         const Scratch& w, int at) {
  using Real = typename Data::Stored;
  const double log_total = d.log_normalizer(member);
  for_each_batch(team, begin, end, [&](int j0, int stride) {
    double l[resample_batch];
    for (int k = 0; k < resample_batch; ++k) l[k] = j0 + k * stride < end ? d.log_weight(j0 + k * stride, member) : 0.0;
    for (int k = 0; k < resample_batch; ++k)
      if (j0 + k * stride < end) w(at + j0 + k * stride - begin) = stored_value<Real>(math::exp(l[k] - log_total));
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

/// The scan blocks whose cumulative weights the scatter of a chunk needs, a chain each: the chunk's own blocks
/// (chains 0 .. blocks - 1, each C_j kept), then the block before the chunk (for C_{begin-1}) and the member's last
/// block (for the total C_{N-1}) where the chunk holds neither (their last C alone kept: ends(0) and ends(1)). Kernel
/// 1 sums the chunk's own blocks, chains 0 .. blocks - 1.
struct ScatterChains {
  int n, block, first_block, blocks, previous, last;  // previous, last: block indices, or -1
  int count;                                          // chains
  KOKKOS_INLINE_FUNCTION ScatterChains(int num_particles, int begin, int end) {
    n = num_particles;
    block = scan_block_size(n);
    first_block = begin / block;
    blocks = (end - begin + block - 1) / block;
    previous = first_block > 0 ? first_block - 1 : -1;
    last = scan_num_blocks(n) - 1 >= first_block + blocks ? scan_num_blocks(n) - 1 : -1;
    count = blocks + (previous >= 0) + (last >= 0);
  }
  /// Chain k's scan block.
  KOKKOS_INLINE_FUNCTION int block_of(int k) const {
    return k < blocks ? first_block + k : (k == blocks && previous >= 0 ? previous : last);
  }
  /// Chain k's first particle and its number of particles (the member's last block may be short).
  KOKKOS_INLINE_FUNCTION int first_particle(int k) const { return block_of(k) * block; }
  KOKKOS_INLINE_FUNCTION int length(int k) const {
    return first_particle(k) + block < n ? block : n - first_particle(k);
  }
  /// Where chain k's weights sit in team scratch: the chunk's at 0, then the previous block's, then the last one's.
  KOKKOS_INLINE_FUNCTION int scratch_at(int k, int chunk_size) const {
    return k < blocks ? k * block : chunk_size + (k - blocks) * block;
  }
};

}  // namespace detail

/// Kernel 1, blocked_inclusive_scan's first pass over each chunk: block_sums(b, member) = the sum of scan block b's
/// weights in particle order.
template <class ExecSpace, class Real = double>
struct ChunkedBlockSums {
  using MemSpace = typename ExecSpace::memory_space;
  using Team = typename Kokkos::TeamPolicy<ExecSpace>::member_type;
  using Scratch = Kokkos::View<double*, typename ExecSpace::scratch_memory_space, Kokkos::MemoryUnmanaged>;
  ChunkedResampleData<MemSpace, Real> d;

  static std::size_t scratch_bytes(int) { return Scratch::shmem_size(resample_chunk_particles); }

  KOKKOS_INLINE_FUNCTION void operator()(const Team& team) const {
    const Scratch w(team.team_scratch(0), resample_chunk_particles);
    detail::for_each_chunk(team, d, [&](int member, int begin, int end) {
      const detail::ScatterChains chains(d.num_particles, begin, end);  // the chunk's own blocks: chains < blocks
      detail::load_weights(team, d, member, begin, end, w, 0);
      team.team_barrier();
      Kokkos::parallel_for(Kokkos::TeamThreadRange(team, chains.blocks), [&](const int k) {
        const int lo = k * chains.block, hi = lo + chains.length(k);
        d.block_sums(chains.block_of(k), member) = detail::add_in_order(w, lo, hi, 0.0, [](int, double) {});
      });
    });
  }
};

/// Kernel 2: each chunk's cumulative weights (blocked_inclusive_scan's second pass, rounded to Real as the one-team
/// path stores them) in team scratch, then each particle copied into its slots of x_scratch, or of x_into
/// (resample_member's systematic rule).
template <class ExecSpace, int N, class Real = double>
struct ChunkedSystematicScatter {
  using MemSpace = typename ExecSpace::memory_space;
  using Team = typename Kokkos::TeamPolicy<ExecSpace>::member_type;
  using Scratch = Kokkos::View<double*, typename ExecSpace::scratch_memory_space, Kokkos::MemoryUnmanaged>;
  ChunkedResampleData<MemSpace, Real> d;

  /// Team scratch: the chunk's weights and those of the two other chains (before them, the member's block sums, in
  /// the same place), the chains' offsets, and the two other chains' last cumulative weights.
  KOKKOS_INLINE_FUNCTION static int chunk_size(int n) { return resample_chunk_blocks(n) * scan_block_size(n); }
  KOKKOS_INLINE_FUNCTION static int weights_size(int n) {
    const int weights = chunk_size(n) + 2 * scan_block_size(n);
    return scan_num_blocks(n) > weights ? scan_num_blocks(n) : weights;
  }
  static std::size_t scratch_bytes(int n) {
    return Scratch::shmem_size(weights_size(n)) + Scratch::shmem_size(resample_chunk_blocks(n) + 2) +
           Scratch::shmem_size(2);
  }

  KOKKOS_INLINE_FUNCTION void operator()(const Team& team) const {
    const int n = d.num_particles, size = chunk_size(n);
    const Scratch w(team.team_scratch(0), weights_size(n)), offsets(team.team_scratch(0), resample_chunk_blocks(n) + 2),
        ends(team.team_scratch(0), 2);
    detail::for_each_chunk(team, d, [&](int member, int begin, int end) {
      const detail::ScatterChains chains(n, begin, end);
      // Each chain's offset: the member's block sums before its block, added in index order.
      Kokkos::parallel_for(Kokkos::TeamThreadRange(team, scan_num_blocks(n)),
                           [&](const int b) { w(b) = d.block_sums(b, member); });
      team.team_barrier();
      Kokkos::parallel_for(Kokkos::TeamThreadRange(team, chains.count), [&](const int k) {
        double offset = 0.0;
        for (int b = 0; b < chains.block_of(k); ++b) offset += w(b);
        offsets(k) = offset;
      });
      team.team_barrier();
      detail::load_weights(team, d, member, begin, end, w, 0);
      for (int k = chains.blocks; k < chains.count; ++k) {
        const int first = chains.first_particle(k);
        detail::load_weights(team, d, member, first, first + chains.length(k), w, chains.scratch_at(k, size));
      }
      team.team_barrier();
      Kokkos::parallel_for(Kokkos::TeamThreadRange(team, chains.count), [&](const int k) {
        const int lo = chains.scratch_at(k, size), hi = lo + chains.length(k);
        if (k < chains.blocks) {
          detail::add_in_order(w, lo, hi, offsets(k), [&](int j, double c) { w(j) = stored_value<Real>(c); });
        } else {
          const int slot = chains.block_of(k) == chains.previous ? 0 : 1;
          ends(slot) = stored_value<Real>(detail::add_in_order(w, lo, hi, offsets(k), [](int, double) {}));
        }
      });
      team.team_barrier();
      const double before = chains.previous >= 0 ? ends(0) : 0.0;  // C_{begin-1}; no particle before the first
      const double total = chains.last >= 0 ? ends(1) : w(n - 1 - begin);
      const double u = detail::resampling_uniform(d.seed, member, 0, d.step);
      const bool into = d.x_into.data() != nullptr;
      const auto& to = into ? d.x_into : d.x_scratch;
      detail::for_each_batch(team, begin, end, [&](int j0, int stride) {
        constexpr int B = resample_batch;
        double v[B][N];
        for (int k = 0; k < B; ++k)
          if (j0 + k * stride < end)
            for (int i = 0; i < N; ++i) v[k][i] = d.x(j0 + k * stride, member, i);
        for (int k = 0; k < B; ++k) {
          const int j = j0 + k * stride;
          if (j >= end) continue;
          const double lo = j > begin ? w(j - 1 - begin) : before, hi = w(j - begin);
          const int first = j == 0 ? 0 : detail::ceil_clamped((lo * n) / total - u, n);
          const int last = j == n - 1 ? n : detail::ceil_clamped((hi * n) / total - u, n);
          for (int s = first; s < last; ++s) {
            d.ancestors(s, member) = j;
            for (int i = 0; i < N; ++i) to(s, member, i) = static_cast<Real>(v[k][i]);
            if (into) d.log_weight_into(s, member) = 0.0;
          }
        }
      });
      if (into && begin == 0)
        Kokkos::single(Kokkos::PerTeam(team), [&]() { d.log_normalizer_into(member) = equal_log_normalizer(n); });
    });
  }
};

/// Kernel 3: the resampled particles back into the bank, log-weights 0 and log-normalizer log N.
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
                       [&]() { d.log_normalizer(member) = equal_log_normalizer(d.num_particles); });
    });
  }
};

/// Resamples the listed members systematically (d.members, d.member_count on the device): in place, or into
/// d.x_into where allocated. `team_size`: threads per team; `league`: teams, each looping over the work items. No
/// fence.
template <int N, class ExecSpace, class Real>
void chunked_systematic_resample(const ExecSpace& space,
                                 const ChunkedResampleData<typename ExecSpace::memory_space, Real>& d, int team_size,
                                 int league) {
  KUSHNER_REQUIRE(chunked_resample_supports(d.num_particles),
                  "chunked resampling: " << d.num_particles << " particles per member is more than it supports");
  // The functors go to the device as the launches' parameters, however large the data grows (above 512 bytes Kokkos
  // copies them to constant memory first, and waits for the launch before).
  using Policy = Kokkos::TeamPolicy<ExecSpace, Kokkos::Experimental::WorkItemProperty::HintLightWeight_t>;
  const int n = d.num_particles;
  Kokkos::parallel_for("kushner::resample_block_sums",
                       Policy(space, league, team_size)
                           .set_scratch_size(0, Kokkos::PerTeam(ChunkedBlockSums<ExecSpace, Real>::scratch_bytes(n))),
                       ChunkedBlockSums<ExecSpace, Real>{d});
  Kokkos::parallel_for(
      "kushner::resample_scatter",
      Policy(space, league, team_size)
          .set_scratch_size(0, Kokkos::PerTeam(ChunkedSystematicScatter<ExecSpace, N, Real>::scratch_bytes(n))),
      ChunkedSystematicScatter<ExecSpace, N, Real>{d});
  if (d.x_into.data() != nullptr) return;
  Kokkos::parallel_for("kushner::resample_copy_back", Policy(space, league, team_size),
                       ChunkedCopyBack<ExecSpace, N, Real>{d});
}

}  // namespace kushner
