// The whole particle-filter step (propagate, weight, block moments, posterior and ESS, amortized
// resampling) in particle-steps per second, sine model, fp64, mixed or fp32 precision, next to BM_StreamCopy of the
// bytes an fp64 step must move (the memory floor) in the same binary. Observation increments come from a bank of truths
// that is stepped outside the timed region. With steps = 2 each timed call is ParticleFilterBank::step_pair (two steps,
// one pass over the particles on a GPU: half the bytes per particle-step).
#include "engine/particle_filter_bank.hpp"
#include "engine/truth_bank.hpp"
#include "models/sine_model.hpp"
#include "perf/bench_timing.hpp"

#include <benchmark/benchmark.h>

#include <cmath>
#include <type_traits>

namespace kushner {
namespace {

/// Bytes a step must move per particle: read and write the state (state_dim numbers) and the log-weight, each
/// `stored` bytes (8 in fp64 and mixed, 4 in fp32).
template <class Model>
constexpr double bytes_per_particle_step(double stored = 8.0) {
  return stored * 2 * (Model::state_dim + 1);
}

constexpr double dt = 1e-3;
constexpr int warmup_steps = 200;  // past the first resamplings, which the prior's spread makes frequent

template <class Model, class Real>
void particle_filter_steps(benchmark::State& state, const ParticleFilterOptions& options) {
  using Space = Kokkos::DefaultExecutionSpace;
  const int members = static_cast<int>(state.range(0)), particles = static_cast<int>(state.range(1));
  const Space space;
  const Model model;
  TruthBank<Space, Model> truth(space, model, members, 42);
  ParticleFilterBank<Space, Model, Real> pf(space, model, members, particles, 43, options);
  const bool pairs = state.range(4) == 2;
  BankVector<typename Space::memory_space> first_dy("first_dy", members, Model::obs_dim);
  long k = 0;
  for (; k < warmup_steps; ++k) {
    truth.step(k, dt);
    pf.step(k, dt, truth.observations());
  }
  for (auto _ : state) {
    truth.step(k, dt);
    if (pairs) {
      Kokkos::deep_copy(space, first_dy, truth.observations());
      truth.step(k + 1, dt);
    }
    space.fence();
    Kokkos::Timer timer;
    if (pairs)
      pf.step_pair(k, dt, first_dy, truth.observations());
    else
      pf.step(k, dt, truth.observations());
    space.fence();
    state.SetIterationTime(timer.seconds());
    k += pairs ? 2 : 1;
  }
  using C = benchmark::Counter;
  const double particle_steps = static_cast<double>(members) * particles * (pairs ? 2 : 1);
  state.counters["particle_steps_per_s"] = C(particle_steps, C::kIsIterationInvariantRate);
  // A fused pair reads and writes the particles once for two steps.
  const double bytes = bytes_per_particle_step<Model>(sizeof(Real)) / (pairs && pf.fuses_step_pairs() ? 2 : 1);
  state.counters["GB_per_s"] = C(1e-9 * bytes * particle_steps, C::kIsIterationInvariantRate);
  state.counters["bytes_per_particle_step"] = bytes;
  const auto counts = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), pf.resample_count());
  const auto status = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), pf.status());
  const auto mean = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), pf.posterior_mean());
  double resamples = 0.0;
  for (int m = 0; m < members; ++m) {
    resamples += counts(m);
    if (status(m) != Status::ok || !std::isfinite(mean(m, 0))) {
      state.SkipWithError("non-finite posterior");
      return;
    }
  }
  state.counters["resamples_per_member_step"] = resamples / (static_cast<double>(members) * k);
}

template <class Model>
void BM_ParticleFilterStep(benchmark::State& state) {
  ParticleFilterOptions options;
  if (state.range(3) == 0) options.ess_threshold = 0.0;  // never resample: the cost of the other kernels
  if (state.range(2) > 0) options.particles_per_thread = static_cast<int>(state.range(2));
  if (state.range(5) == 1) options.precision = ParticlePrecision::mixed;
  if (state.range(5) == 2) options.precision = ParticlePrecision::fp32;
  with_particle_storage(options.precision, [&](auto* stored) {
    particle_filter_steps<Model, std::remove_pointer_t<decltype(stored)>>(state, options);
  });
}

/// The physical floor: a deep_copy of the bytes one step moves (half read, half written).
template <class Model>
void BM_StreamCopy(benchmark::State& state) {
  const long particle_count = state.range(0) * state.range(1);
  time_stream_copy(state, particle_count * static_cast<long>(bytes_per_particle_step<Model>() / 16.0));
  using C = benchmark::Counter;
  state.counters["particle_steps_per_s"] = C(static_cast<double>(particle_count), C::kIsIterationInvariantRate);
}

// M x N: the CPU target (100 x 4096), then M.N = 1e6 .. 1e9; sizes past 1e7 only where a GPU runs them.
// The third argument (GPU team kernel only) is particles per thread, 0 = the default; the fourth, 0, turns
// resampling off (ESS threshold 0), which shows what resampling costs; the fifth is steps per timed call
// (2: step_pair, which fuses them where the team kernel runs); the sixth is the precision: 0 fp64, 1 mixed (normals
// drawn in fp32), 2 fp32 (also particles and log-weights stored in float).
BENCHMARK_TEMPLATE(BM_ParticleFilterStep, SineModel)
    ->Apply([](benchmark::internal::Benchmark* b) {
      b->ArgNames({"members", "particles", "per_thread", "resample", "steps", "precision"});
      b->Args({100, 4096, 0, 1, 1, 0})->Args({1000, 1024, 0, 1, 1, 0})->Args({1000, 16384, 0, 1, 1, 0});
      b->Args({100, 4096, 0, 1, 1, 1})->Args({1000, 16384, 0, 1, 1, 1});
      b->Args({100, 4096, 0, 1, 1, 2})->Args({1000, 16384, 0, 1, 1, 2});
#if defined(KOKKOS_ENABLE_CUDA)
      b->Args({1000, 65536, 0, 1, 1, 0})->Args({10000, 65536, 0, 1, 1, 0})->Args({15259, 65536, 0, 1, 1, 0});
      b->Args({1000, 65536, 8, 1, 1, 0})->Args({1000, 65536, 32, 1, 1, 0})->Args({1000, 65536, 0, 0, 1, 0});
      b->Args({1000, 65536, 0, 1, 2, 0})->Args({1000, 65536, 0, 0, 2, 0})->Args({1000, 1024, 0, 1, 2, 0});
      b->Args({1000, 16384, 0, 1, 2, 0})->Args({10000, 65536, 0, 1, 2, 0});
      b->Args({1000, 65536, 0, 1, 1, 1})->Args({1000, 65536, 0, 1, 2, 1})->Args({10000, 65536, 0, 1, 2, 1});
      b->Args({1000, 65536, 0, 1, 1, 2})->Args({1000, 65536, 0, 1, 2, 2})->Args({10000, 65536, 0, 1, 2, 2});
#endif
    })
    ->UseManualTime();
BENCHMARK_TEMPLATE(BM_StreamCopy, SineModel)
    ->Apply([](benchmark::internal::Benchmark* b) {
      b->ArgNames({"members", "particles"})->Args({100, 4096})->Args({1000, 1024})->Args({1000, 16384});
#if defined(KOKKOS_ENABLE_CUDA)
      b->Args({1000, 65536})->Args({15259, 65536});
#endif
    })
    ->UseManualTime();

}  // namespace
}  // namespace kushner
