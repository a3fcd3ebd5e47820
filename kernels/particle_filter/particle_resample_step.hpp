#pragma once
// Resampling inside the particle filter: a team per member, working only on the members whose ESS fell
// below the threshold this step. The member's log-weights become weights exp(l - log_normalizer) in place,
// then cumulative weights (resample_member), then the particles are gathered by ancestor into a scratch
// bank and copied back, and the weights reset to equal.
#include "core/math.hpp"
#include "kernels/bank.hpp"
#include "kernels/particle_filter/resampling.hpp"
#include "kernels/particle_filter/tuning.hpp"

#include <Kokkos_Core.hpp>

#include <cstdint>

namespace kushner {

template <int N, class ExecSpace, class Real = double>
struct ParticleResampleStep {
  using MemSpace = typename ExecSpace::memory_space;
  using Team = typename Kokkos::TeamPolicy<ExecSpace>::member_type;
  using Scratch = Kokkos::View<double*, typename ExecSpace::scratch_memory_space, Kokkos::MemoryUnmanaged>;
  ParticleBank<MemSpace, Real> x, x_scratch;  // (particle, member, i)
  ResamplingWorkspace<MemSpace, Real> ws;     // ws.cumulative is the log-weight bank
  BankScalar<double, MemSpace> log_normalizer;
  BankScalar<int, MemSpace> resample;
  int num_particles;
  ResamplingScheme scheme;
  Seed seed;
  std::uint32_t step;

  KOKKOS_INLINE_FUNCTION void operator()(const Team& team) const {
    const int member = team.league_rank();
    if (resample(member) == 0) return;
    const int n = num_particles;
    const double log_total = log_normalizer(member);
    // Each thread handles `batch` particles at a time, strided by the team size, with every load of a batch
    // issued before its stores: these loops are latency-bound on a GPU (one team per resampled member).
    constexpr int batch = resample_step_batch;
    const int threads = team.team_size(), rank = team.team_rank();
    for (int j0 = rank; j0 < n; j0 += batch * threads) {
      double l[batch];
      for (int k = 0; k < batch; ++k) l[k] = j0 + k * threads < n ? ws.cumulative(j0 + k * threads, member) : 0.0;
      for (int k = 0; k < batch; ++k)  // exp(-inf) = 0: dead particles
        if (j0 + k * threads < n)
          ws.cumulative(j0 + k * threads, member) = static_cast<Real>(math::exp(l[k] - log_total));
    }
    team.team_barrier();
    const Scratch block_sums(team.team_scratch(0), scan_num_blocks(n));
    resample_member(team, ws, member, n, scheme, seed, step, block_sums);
    for (int s0 = rank; s0 < n; s0 += batch * threads) {
      int a[batch];
      double v[batch][N];
      for (int k = 0; k < batch; ++k) a[k] = s0 + k * threads < n ? ws.ancestors(s0 + k * threads, member) : 0;
      for (int k = 0; k < batch; ++k)
        for (int i = 0; i < N; ++i) v[k][i] = s0 + k * threads < n ? x(a[k], member, i) : 0.0;
      for (int k = 0; k < batch; ++k)
        if (s0 + k * threads < n)
          for (int i = 0; i < N; ++i) x_scratch(s0 + k * threads, member, i) = static_cast<Real>(v[k][i]);
    }
    team.team_barrier();
    for (int s0 = rank; s0 < n; s0 += batch * threads) {
      double v[batch][N];
      for (int k = 0; k < batch; ++k)
        for (int i = 0; i < N; ++i) v[k][i] = s0 + k * threads < n ? x_scratch(s0 + k * threads, member, i) : 0.0;
      for (int k = 0; k < batch; ++k)
        if (s0 + k * threads < n) {
          for (int i = 0; i < N; ++i) x(s0 + k * threads, member, i) = static_cast<Real>(v[k][i]);
          ws.cumulative(s0 + k * threads, member) = 0.0;
        }
    }
    Kokkos::single(Kokkos::PerTeam(team), [&]() { log_normalizer(member) = math::log(static_cast<double>(n)); });
  }
};

}  // namespace kushner
