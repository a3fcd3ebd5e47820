#pragma once
// Resampling of one member by a team: from non-negative weights w_j (particle j of the member's column) to
// ancestor indices a_s (slot s), with E[#{s : a_s = j}] = N w_j / sum(w) for every scheme.
//   systematic   one uniform u per member and step; slot s takes the particle whose cumulative interval
//                holds (s + u) / N (Kitagawa 1996; Carpenter, Clifford & Fearnhead 1999)
//   stratified   one uniform per slot: (s + u_s) / N (Kitagawa 1996)
//   multinomial  one uniform per slot: u_s, inverse-CDF (Gordon, Salmond & Smith 1993)
//   residual     floor(N w_j) copies of j, then the remaining slots multinomially from the residual
//                weights N w_j - floor(N w_j) (Liu & Chen 1998)
// Uniforms come from Stream::resampling with counter {member, slot, step, 0} (systematic: slot 0), so the
// indices depend only on the weights, the seed, the member and the step. Cumulative weights come from
// blocked_inclusive_scan, whose order is fixed: the same weights give the same indices on every backend.
#include "kernels/bank.hpp"
#include "kernels/particle_filter/blocked_scan.hpp"
#include "kernels/particle_filter/resampling_scheme.hpp"
#include "kernels/rng.hpp"

#include <Kokkos_Core.hpp>

#include <cstdint>
#include <type_traits>

namespace kushner {

/// Views a team needs to resample member columns: (particle, member), particle index contiguous. The weights and
/// their cumulative sums are stored as Real (summed in double: blocked_inclusive_scan).
template <class MemSpace, class Real = double>
struct ResamplingWorkspace {
  ParticleColumn<MemSpace, Real> cumulative;                    // weights in, cumulative weights out
  Kokkos::View<int**, Kokkos::LayoutLeft, MemSpace> ancestors;  // a_s
  Kokkos::View<int**, Kokkos::LayoutLeft, MemSpace> copies;     // residual: floor(N w_j), then their prefix
};

namespace detail {

/// ceil(v) clamped to [0, n], for the systematic offspring boundaries.
KOKKOS_INLINE_FUNCTION int ceil_clamped(double v, int n) {
  if (!(v > 0.0)) return 0;
  if (v >= static_cast<double>(n)) return n;
  const int k = static_cast<int>(v);
  return static_cast<double>(k) < v ? k + 1 : k;
}

/// First j in [0, n) with cumulative(j) > target; when rounding puts target at or above the total, the
/// first j whose cumulative weight reaches the total (a particle with positive weight).
template <class View>
KOKKOS_INLINE_FUNCTION int upper_bound_particle(const View& cumulative, int member, int n, double target) {
  const double total = cumulative(n - 1, member);
  const bool inside = target < total;
  int lo = 0, hi = n;
  while (lo < hi) {
    const int mid = lo + (hi - lo) / 2;
    const double c = cumulative(mid, member);
    if (inside ? c > target : c >= total)
      hi = mid;
    else
      lo = mid + 1;
  }
  return lo < n ? lo : n - 1;
}

KOKKOS_INLINE_FUNCTION double resampling_uniform(Seed seed, int member, int slot, std::uint32_t step) {
  double u0, u1;
  uniform_pair(RngKey{seed, Stream::resampling},
               Counter{static_cast<std::uint32_t>(member), static_cast<std::uint32_t>(slot), step, 0}, u0, u1);
  return u0;
}

}  // namespace detail

/// Team-level resampling of member `member`: ws.cumulative(., member) holds n non-negative weights with a
/// positive sum on entry (cumulative sums on exit); ws.ancestors(., member) receives the n ancestors.
/// `block_sums`: team scratch with scan_num_blocks(n) doubles.
template <class Team, class MemSpace, class Real, class Scratch>
KOKKOS_INLINE_FUNCTION void resample_member(const Team& team, const ResamplingWorkspace<MemSpace, Real>& ws, int member,
                                            int n, ResamplingScheme scheme, Seed seed, std::uint32_t step,
                                            const Scratch& block_sums) {
  const auto& c = ws.cumulative;
  const auto& a = ws.ancestors;
  if (scheme == ResamplingScheme::residual) {
    // Total first (same fixed block order as the scan), then integer copies and residual weights in place.
    const int block = scan_block_size(n), num_blocks = scan_num_blocks(n);
    Kokkos::parallel_for(Kokkos::TeamThreadRange(team, num_blocks), [&](const int b) {
      const int end = (b + 1) * block < n ? (b + 1) * block : n;
      double sum = 0.0;
      for (int j = b * block; j < end; ++j) sum += c(j, member);
      block_sums(b) = sum;
    });
    team.team_barrier();
    double total = 0.0;
    for (int b = 0; b < num_blocks; ++b) total += block_sums(b);
    team.team_barrier();
    Kokkos::parallel_for(Kokkos::TeamThreadRange(team, n), [&](const int j) {
      const double expected = (c(j, member) * n) / total;
      int k = static_cast<int>(expected);  // floor: expected >= 0
      if (k > n) k = n;
      ws.copies(j, member) = k;
      c(j, member) = expected - k;
    });
    team.team_barrier();
    blocked_inclusive_scan(team, ws.copies, member, n, block_sums);
    const double residual_total = blocked_inclusive_scan(team, c, member, n, block_sums);
    Kokkos::parallel_for(Kokkos::TeamThreadRange(team, n), [&](const int j) {
      const int begin = j == 0 ? 0 : ws.copies(j - 1, member);
      const int end = ws.copies(j, member) < n ? ws.copies(j, member) : n;
      for (int s = begin; s < end; ++s) a(s, member) = j;
    });
    const int deterministic = ws.copies(n - 1, member) < n ? ws.copies(n - 1, member) : n;
    team.team_barrier();
    Kokkos::parallel_for(Kokkos::TeamThreadRange(team, deterministic, n), [&](const int s) {
      // residual_total is N - sum floor(N w_j) > 0 up to rounding; if rounding left a slot with no residual
      // weight, it repeats a deterministic copy (a particle of positive weight).
      a(s, member) = residual_total > 0.0
                         ? detail::upper_bound_particle(
                               c, member, n, detail::resampling_uniform(seed, member, s, step) * residual_total)
                         : a((s - deterministic) % deterministic, member);
    });
    team.team_barrier();
    return;
  }
  const double total = blocked_inclusive_scan(team, c, member, n, block_sums);
  if (scheme == ResamplingScheme::systematic) {
    // Particle j owns the slots s with C_{j-1} <= (s + u) total / N < C_j, i.e. s in [g(C_{j-1}), g(C_j)) with
    // g(C) = ceil(N C / total - u): the same function of the same stored C at both ends of neighbouring
    // intervals, so the slots are partitioned exactly whatever the rounding.
    const double u = detail::resampling_uniform(seed, member, 0, step);
    // Batches of 8 particles per thread, loads first (latency-bound on a GPU); the same slots either way.
    constexpr int batch = 8;
    const int threads = team.team_size(), rank = team.team_rank();
    for (int j0 = rank; j0 < n; j0 += batch * threads) {
      double lo[batch], hi[batch];
      for (int k = 0; k < batch; ++k) {
        const int j = j0 + k * threads;
        lo[k] = j > 0 && j < n ? c(j - 1, member) : 0.0;
        hi[k] = j < n ? c(j, member) : 0.0;
      }
      for (int k = 0; k < batch; ++k) {
        const int j = j0 + k * threads;
        if (j >= n) break;
        const int begin = j == 0 ? 0 : detail::ceil_clamped((lo[k] * n) / total - u, n);
        const int end = j == n - 1 ? n : detail::ceil_clamped((hi[k] * n) / total - u, n);
        for (int s = begin; s < end; ++s) a(s, member) = j;
      }
    }
  } else {
    const bool stratified = scheme == ResamplingScheme::stratified;
    Kokkos::parallel_for(Kokkos::TeamThreadRange(team, n), [&](const int s) {
      const double u = detail::resampling_uniform(seed, member, s, step);
      const double point = stratified ? (s + u) / n : u;
      a(s, member) = detail::upper_bound_particle(c, member, n, point * total);
    });
  }
  team.team_barrier();
}

/// Team size for resampling kernels: one thread per member on the host (members are the parallelism
/// there), a block of threads per member on a GPU.
template <class ExecSpace>
constexpr int resampling_team_size() {
  return std::is_same<typename ExecSpace::memory_space, Kokkos::HostSpace>::value ? 1 : 256;
}

template <class ExecSpace, class Real = double>
struct ResampleMembers {
  using MemSpace = typename ExecSpace::memory_space;
  using Scratch = Kokkos::View<double*, typename ExecSpace::scratch_memory_space, Kokkos::MemoryUnmanaged>;
  ResamplingWorkspace<MemSpace, Real> ws;
  int num_particles;
  ResamplingScheme scheme;
  Seed seed;
  std::uint32_t step;

  KOKKOS_INLINE_FUNCTION void operator()(const typename Kokkos::TeamPolicy<ExecSpace>::member_type& team) const {
    const Scratch block_sums(team.team_scratch(0), scan_num_blocks(num_particles));
    resample_member(team, ws, team.league_rank(), num_particles, scheme, seed, step, block_sums);
  }
};

/// Resamples every member: ws.cumulative (particle, member) holds each member's non-negative weights (any
/// positive sum; overwritten), ws.ancestors receives the indices. ws.copies is needed for `residual` only.
/// `team_size` 0 means resampling_team_size<ExecSpace>(). No fence.
template <class ExecSpace, class MemSpace, class Real>
void resample_members(const ExecSpace& space, const ResamplingWorkspace<MemSpace, Real>& ws, ResamplingScheme scheme,
                      Seed seed, std::uint32_t step, int team_size = 0) {
  const int n = ws.cumulative.extent_int(0), members = ws.cumulative.extent_int(1);
  KUSHNER_REQUIRE(n > 0 && ws.ancestors.extent_int(0) == n && ws.ancestors.extent_int(1) == members,
                  "ancestors have shape (" << ws.ancestors.extent(0) << ", " << ws.ancestors.extent(1) << "), weights ("
                                           << n << ", " << members << ")");
  KUSHNER_REQUIRE(
      scheme != ResamplingScheme::residual || (ws.copies.extent_int(0) == n && ws.copies.extent_int(1) == members),
      "residual resampling needs a copies workspace of the weights' shape");
  Kokkos::TeamPolicy<ExecSpace> policy(space, members, team_size > 0 ? team_size : resampling_team_size<ExecSpace>());
  policy.set_scratch_size(0, Kokkos::PerTeam(sizeof(double) * scan_num_blocks(n)));
  Kokkos::parallel_for("kushner::resample_members", policy,
                       ResampleMembers<ExecSpace, Real>{ws, n, scheme, seed, step});
}

}  // namespace kushner
