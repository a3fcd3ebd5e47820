#pragma once
// The team kernels' reduction of WeightedMoments (the largest log-weight, then sums): every thread gets the
// team's total, in an order fixed by the team size, so a seed gives the same bits on every run.
//
// On a CUDA device the default is hand-written: shuffles within each warp, then the warps' partials in
// order by thread 0 through team scratch. Kokkos' own team primitive, team.team_reduce with a reducer (also
// shuffles, then the warps joined four at a time in shared memory), does the same job in fewer lines; build
// with -DKUSHNER_TEAM_SUM_KOKKOS to use it. Measured side by side on an H100 (perf/particle_filter.md, "Team
// reduction"): equal on the one-step kernel, 3.4% slower on the fused two-step one, so the shuffles stay the
// default. Elsewhere (the team kernel on host spaces, for tests) a
// pairwise tree in team scratch.
#include "core/portability.hpp"
#include "kernels/particle_filter/weighted_moments.hpp"

#include <Kokkos_Core.hpp>

#include <cstddef>

namespace kushner {

/// Team scratch the reduction needs: one row of values per thread and one for the total.
template <int N>
constexpr std::size_t team_sum_scratch_bytes(int team_size) {
  return sizeof(double) * WeightedMoments<N>::size * (team_size + 1);
}

/// WeightedMoments as plain doubles, for Kokkos' reducer interface: entry 0 combines by max, the rest by sum.
template <int Values>
struct MomentValues {
  double v[Values];
};

/// Kokkos reducer over MomentValues (Kokkos 3.4 asks for the volatile joins as well).
template <int Values>
struct MomentValuesReducer {
  using reducer = MomentValuesReducer;
  using value_type = MomentValues<Values>;
  using result_view_type = Kokkos::View<value_type, Kokkos::AnonymousSpace, Kokkos::MemoryUnmanaged>;
  value_type* value;

  KOKKOS_INLINE_FUNCTION explicit MomentValuesReducer(value_type& v) : value(&v) {}
  KOKKOS_INLINE_FUNCTION static void combine(double& a, double b, int k) { a = k == 0 ? (b > a ? b : a) : a + b; }
  KOKKOS_INLINE_FUNCTION void join(value_type& dst, const value_type& src) const {
    for (int k = 0; k < Values; ++k) combine(dst.v[k], src.v[k], k);
  }
  KOKKOS_INLINE_FUNCTION void join(volatile value_type& dst, const volatile value_type& src) const {
    for (int k = 0; k < Values; ++k) {
      double a = dst.v[k];
      combine(a, src.v[k], k);
      dst.v[k] = a;
    }
  }
  KOKKOS_INLINE_FUNCTION void init(value_type& x) const {
    x.v[0] = -math::infinity();
    for (int k = 1; k < Values; ++k) x.v[k] = 0.0;
  }
  KOKKOS_INLINE_FUNCTION value_type& reference() const { return *value; }
  KOKKOS_INLINE_FUNCTION result_view_type view() const { return result_view_type(value); }
  KOKKOS_INLINE_FUNCTION bool references_scalar() const { return true; }
};

/// w <- the team's total on every thread. `buffer` holds team_sum_scratch_bytes<N>(team size) of team scratch.
template <int N, class Team, class Scratch>
KOKKOS_INLINE_FUNCTION void team_sum(const Team& team, const Scratch& buffer, WeightedMoments<N>& w) {
  constexpr int values = WeightedMoments<N>::size;
  const int threads = team.team_size(), rank = team.team_rank();
  MomentValues<values> v;
  w.store(v.v);
  const double* total = &buffer(threads * values);
#if KUSHNER_CUDA_DEVICE_PASS
#if defined(KUSHNER_TEAM_SUM_KOKKOS)
  (void)total;
  team.team_reduce(MomentValuesReducer<values>(v));
  w = WeightedMoments<N>::load(v.v);
  return;
#else
  if (threads % 32 == 0) {  // Kokkos' CUDA teams: team rank = thread index in the block (vector length 1)
    KUSHNER_DEVICE_UNROLL
    for (int offset = 16; offset > 0; offset /= 2) {
      KUSHNER_DEVICE_UNROLL
      for (int k = 0; k < values; ++k) {
        const double o = __shfl_down_sync(0xffffffffu, v.v[k], offset);
        MomentValuesReducer<values>::combine(v.v[k], o, k);
      }
    }
    if (rank % 32 == 0)
      for (int k = 0; k < values; ++k) buffer((rank / 32) * values + k) = v.v[k];
    team.team_barrier();
    if (rank == 0) {
      for (int warp = 1; warp < threads / 32; ++warp)
        for (int k = 0; k < values; ++k) MomentValuesReducer<values>::combine(v.v[k], buffer(warp * values + k), k);
      for (int k = 0; k < values; ++k) buffer(threads * values + k) = v.v[k];
    }
    team.team_barrier();
    w = WeightedMoments<N>::load(total);
    return;
  }
#endif
#endif
  for (int k = 0; k < values; ++k) buffer(rank * values + k) = v.v[k];
  team.team_barrier();
  for (int active = threads; active > 1;) {
    const int half = (active + 1) / 2;
    if (rank < active - half)
      for (int k = 0; k < values; ++k) {
        double a = buffer(rank * values + k);
        MomentValuesReducer<values>::combine(a, buffer((rank + half) * values + k), k);
        buffer(rank * values + k) = a;
      }
    team.team_barrier();
    active = half;
  }
  if (rank == 0)
    for (int k = 0; k < values; ++k) buffer(threads * values + k) = buffer(k);
  team.team_barrier();
  w = WeightedMoments<N>::load(total);
}

}  // namespace kushner
