#pragma once
// Resampling inside the particle filter: a team per member, working only on the members whose ESS fell
// below the threshold this step. The member's log-weights become weights exp(l - log_normalizer) in place,
// then cumulative weights (resample_member), then the particles are gathered by ancestor into a scratch
// bank and copied back, and the weights reset to equal.
#include "kernels/bank.hpp"
#include "kernels/math.hpp"
#include "kernels/particle_filter/resampling.hpp"

#include <Kokkos_Core.hpp>

#include <cstdint>

namespace kushner {

template <int N, class ExecSpace>
struct ParticleResampleStep {
  using MemSpace = typename ExecSpace::memory_space;
  using Team = typename Kokkos::TeamPolicy<ExecSpace>::member_type;
  using Scratch = Kokkos::View<double*, typename ExecSpace::scratch_memory_space, Kokkos::MemoryUnmanaged>;
  ParticleBank<MemSpace> x, x_scratch;              // (particle, member, i)
  ResamplingWorkspace<MemSpace> ws;                 // ws.cumulative is the log-weight bank
  BankScalar<double, MemSpace> log_normalizer;
  BankScalar<int, MemSpace> resample;
  int num_particles;
  ResamplingScheme scheme;
  std::uint32_t seed, step;

  KOKKOS_INLINE_FUNCTION void operator()(const Team& team) const {
    const int member = team.league_rank();
    if (resample(member) == 0) return;
    const int n = num_particles;
    const double log_total = log_normalizer(member);
    Kokkos::parallel_for(Kokkos::TeamThreadRange(team, n), [&](const int j) {
      ws.cumulative(j, member) = math::exp(ws.cumulative(j, member) - log_total);  // exp(-inf) = 0: dead particles
    });
    team.team_barrier();
    const Scratch block_sums(team.team_scratch(0), scan_num_blocks(n));
    resample_member(team, ws, member, n, scheme, seed, step, block_sums);
    Kokkos::parallel_for(Kokkos::TeamThreadRange(team, n), [&](const int s) {
      const int a = ws.ancestors(s, member);
      for (int i = 0; i < N; ++i) x_scratch(s, member, i) = x(a, member, i);
    });
    team.team_barrier();
    Kokkos::parallel_for(Kokkos::TeamThreadRange(team, n), [&](const int s) {
      for (int i = 0; i < N; ++i) x(s, member, i) = x_scratch(s, member, i);
      ws.cumulative(s, member) = 0.0;
    });
    Kokkos::single(Kokkos::PerTeam(team), [&]() { log_normalizer(member) = math::log(static_cast<double>(n)); });
  }
};

}  // namespace kushner
