// Resampling every member at once (the worst case; in a filter run a member resamples every few hundred
// steps): the Kokkos team kernel (fixed-order blocked scan + per-particle systematic intervals) against a
// Thrust version (segmented inclusive_scan_by_key + vectorized upper_bound) where CUDA and Thrust are
// built in. The particle filter keeps the Kokkos kernel unless this measurement says otherwise.
#include "engine/backend.hpp"
#include "kernels/particle_filter/resampling.hpp"

#include <benchmark/benchmark.h>

#if defined(KOKKOS_ENABLE_CUDA) && defined(KUSHNER_THRUST)
#include <thrust/binary_search.h>
#include <thrust/device_ptr.h>
#include <thrust/execution_policy.h>
#include <thrust/iterator/counting_iterator.h>
#include <thrust/iterator/transform_iterator.h>
#include <thrust/scan.h>
#endif

#include <cmath>

namespace kushner {
namespace {

using Space = Kokkos::DefaultExecutionSpace;
using Mem = Space::memory_space;

ResamplingWorkspace<Mem> make_workspace(int n, int members) {
  ResamplingWorkspace<Mem> ws;
  ws.cumulative = decltype(ws.cumulative)("w", n, members);
  ws.ancestors = decltype(ws.ancestors)("a", n, members);
  return ws;
}

/// Smooth, uneven weights (a Gaussian bump per member): like a filter's weights before resampling.
Kokkos::View<double**, Kokkos::LayoutLeft, Mem> make_weights(int n, int members) {
  Kokkos::View<double**, Kokkos::LayoutLeft, Mem> w("weights", n, members);
  Kokkos::parallel_for(
      "fill", Kokkos::MDRangePolicy<Space, Kokkos::Rank<2>>({0, 0}, {n, members}), KOKKOS_LAMBDA(int j, int m) {
        const double z = (j - 0.4 * n - m % 17) / (0.15 * n);
        w(j, m) = math::exp(-0.5 * z * z);
      });
  return w;
}

void BM_ResampleMembersKokkos(benchmark::State& state) {
  const int members = static_cast<int>(state.range(0)), n = static_cast<int>(state.range(1));
  const auto ws = make_workspace(n, members);
  const auto weights = make_weights(n, members);
  const Space space;
  std::uint32_t step = 0;
  for (auto _ : state) {
    Kokkos::deep_copy(space, ws.cumulative, weights);
    space.fence();
    Kokkos::Timer timer;
    resample_members(space, ws, ResamplingScheme::systematic, 7, step++);
    space.fence();
    state.SetIterationTime(timer.seconds());
  }
  state.counters["particles_per_s"] =
      benchmark::Counter(static_cast<double>(members) * n, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_ResampleMembersKokkos)
    ->ArgNames({"members", "particles"})
    ->Args({100, 4096})
    ->Args({1000, 65536})
    ->UseManualTime();

#if defined(KOKKOS_ENABLE_CUDA) && defined(KUSHNER_THRUST)
struct MemberOf {
  int n;
  __host__ __device__ int operator()(long i) const { return static_cast<int>(i / n); }
};

void BM_ResampleMembersThrust(benchmark::State& state) {
  const int members = static_cast<int>(state.range(0)), n = static_cast<int>(state.range(1));
  const auto ws = make_workspace(n, members);
  const auto weights = make_weights(n, members);
  Kokkos::View<double*, Mem> points("points", static_cast<long>(n) * members);
  const Space space;
  const long total = static_cast<long>(n) * members;
  std::uint32_t step = 0;
  for (auto _ : state) {
    Kokkos::deep_copy(space, ws.cumulative, weights);
    space.fence();
    Kokkos::Timer timer;
    double* c = ws.cumulative.data();
    const auto keys = thrust::make_transform_iterator(thrust::counting_iterator<long>(0), MemberOf{n});
    thrust::inclusive_scan_by_key(thrust::device, keys, keys + total, thrust::device_ptr<double>(c),
                                  thrust::device_ptr<double>(c));
    // Make the cumulative weights globally sorted: member m's normalized cumulative lies in (m, m + 1].
    const auto cw = ws.cumulative;
    const auto p = points;
    const std::uint32_t s = step++;
    Kokkos::parallel_for(
        "normalize", Kokkos::RangePolicy<Space>(space, 0, total), KOKKOS_LAMBDA(long i) {
          const int m = static_cast<int>(i / n), j = static_cast<int>(i % n);
          p(i) = m + (j + detail::resampling_uniform(7, m, 0, s)) / n;
          cw(j, m) = m + cw(j, m) / cw(n - 1, m);
        });
    space.fence();
    Kokkos::parallel_for(
        "fix_totals", Kokkos::RangePolicy<Space>(space, 0, members), KOKKOS_LAMBDA(int m) { cw(n - 1, m) = m + 1.0; });
    space.fence();
    thrust::upper_bound(thrust::device, thrust::device_ptr<double>(c), thrust::device_ptr<double>(c) + total,
                        thrust::device_ptr<double>(points.data()), thrust::device_ptr<double>(points.data()) + total,
                        thrust::device_ptr<int>(ws.ancestors.data()));
    space.fence();
    state.SetIterationTime(timer.seconds());
  }
  state.counters["particles_per_s"] =
      benchmark::Counter(static_cast<double>(members) * n, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_ResampleMembersThrust)
    ->ArgNames({"members", "particles"})
    ->Args({100, 4096})
    ->Args({1000, 65536})
    ->UseManualTime();
#endif

}  // namespace
}  // namespace kushner
