#pragma once
// One step of the bootstrap particle filter for every particle of every member (Gordon, Salmond & Smith
// 1993; continuous-time observations as in Bain & Crisan 2009, ch. 9): propagate with the model's
// Euler-Maruyama step (or its exact transition), multiply the weight by the likelihood of the member's
// observation increment,
//   log g(dy | x) = h(x)^T V^{-1} dy - (dt / 2) h(x)^T V^{-1} h(x) + const,   V = R R^T,
// which is -|dy - h dt|^2_{(V dt)^{-1}} / 2 up to a constant of the member, and reduce each block of
// particles to WeightedMoments. Two kernels do this: a host kernel that handles a block of particles with
// `#pragma omp simd` loops (GCC does not vectorize a Kokkos range loop), and a team kernel for GPUs where a
// team reduces its chunk in shared memory. Both call the same per-particle physics below.
#include "kernels/bank.hpp"
#include "kernels/linear_algebra.hpp"
#include "kernels/math.hpp"
#include "kernels/particle_filter/particle_model_traits.hpp"
#include "kernels/particle_filter/simd_random.hpp"
#include "kernels/particle_filter/vector_math.hpp"
#include "kernels/particle_filter/weighted_moments.hpp"
#include "kernels/rng.hpp"
#include "kernels/status.hpp"

#include <Kokkos_Core.hpp>

#include <cstdint>

// `#pragma omp simd` where GCC honours it (-fopenmp or -fopenmp-simd); nothing elsewhere (nvcc's host pass).
#define KUSHNER_PRAGMA(x) _Pragma(#x)
#if defined(_OPENMP) || defined(KUSHNER_VECTOR_MATH)
#define KUSHNER_SIMD KUSHNER_PRAGMA(omp simd)
#define KUSHNER_SIMD_REDUCTION(...) KUSHNER_PRAGMA(omp simd reduction(__VA_ARGS__))
#else
#define KUSHNER_SIMD
#define KUSHNER_SIMD_REDUCTION(...)
#endif

namespace kushner {

/// Particles per block of the host kernel: its arrays stay in L1, and the blocks of all members are the
/// units of parallel work.
constexpr int host_particle_block = 256;
/// GPU teams: 256 threads, each streaming 4 particles of the team's chunk (benchmarked against 8 and 16 by
/// perf/bench_particle_filter.cpp's BM_ParticleFilterStepPerThread).
constexpr int device_particle_team = 256;
constexpr int device_particles_per_thread = 4;

/// Everything one step reads and writes. Views are (particle, member[, i]) or (member[, i]), LayoutLeft.
template <class Model, class MemSpace>
struct ParticleStepData {
  static constexpr int n = Model::state_dim, p = Model::obs_dim, q = Model::noise_dim;
  Model model;
  ParticleBank<MemSpace> x;                                            // (particle, member, i)
  Kokkos::View<double**, Kokkos::LayoutLeft, MemSpace> log_weight;     // (particle, member)
  BankScalar<double, MemSpace> log_normalizer;                         // log sum_j exp(log_weight_j)
  BankVector<MemSpace> reference;                                      // (member, i): previous posterior mean
  BankVector<MemSpace> dy;                                             // (member, j): this step's increments
  BankScalar<Status, MemSpace> status;
  Kokkos::View<double***, Kokkos::LayoutLeft, MemSpace> partials;      // (block, member, k)
  Mat<p, p> observation_precision;  // (R R^T)^{-1} at t
  Vec<n> initial_mean;
  Mat<n, n> initial_root;           // any square root of the initial covariance
  double t = 0.0, dt = 0.0;
  std::uint32_t seed = 0, step = 0;
  int num_particles = 0, block_size = 0;
  bool initialize = false;          // sample the initial law instead of propagating; no observation
};

/// Normals from Random123 (GPU, and the reference for the host's vectorizable copy).
struct Random123Draws {
  template <int N>
  KOKKOS_INLINE_FUNCTION static Vec<N> normals(const RngKey& key, int member, int particle, std::uint32_t step) {
    return normal_vector<N>(key, static_cast<std::uint32_t>(member), static_cast<std::uint32_t>(particle), step);
  }
  KOKKOS_INLINE_FUNCTION static double uniform(const RngKey& key, const Counter& c) {
    double u0, u1;
    uniform_pair(key, c, u0, u1);
    return u0;
  }
};

/// The same draws from the vectorizable Philox (host block kernel).
struct SimdDraws {
  template <int N>
  KOKKOS_INLINE_FUNCTION static Vec<N> normals(const RngKey& key, int member, int particle, std::uint32_t step) {
    return simd::normal_vector<N>(key, static_cast<std::uint32_t>(member), static_cast<std::uint32_t>(particle), step);
  }
  KOKKOS_INLINE_FUNCTION static double uniform(const RngKey& key, const Counter& c) {
    double u0, u1;
    simd::uniform_pair(key, c, u0, u1);
    return u0;
  }
};

/// V^{-1} dy of one member: the only observation term the likelihood needs besides h(x).
template <class Model, class MemSpace>
KOKKOS_INLINE_FUNCTION Vec<Model::obs_dim> precision_times_dy(const ParticleStepData<Model, MemSpace>& d, int member) {
  return d.observation_precision * load<Model::obs_dim>(d.dy, member);
}

/// Moves particle `particle` of `member` (x in, x out) and returns its new log-weight, normalized by the
/// member's previous log-normalizer; -inf for a particle that left the finite numbers (weight zero).
template <class Draws, bool Initialize, class Model, class MemSpace>
KOKKOS_INLINE_FUNCTION double update_particle(const ParticleStepData<Model, MemSpace>& d, int member, int particle,
                                              double log_weight, double log_normalizer,
                                              const Vec<Model::obs_dim>& vinv_dy, Vec<Model::state_dim>& x) {
  constexpr int n = Model::state_dim, p = Model::obs_dim, q = Model::noise_dim;
  if constexpr (Initialize) {
    const Vec<n> z = Draws::template normals<n>(RngKey{d.seed, Stream::particle_initial}, member, particle, 0);
    x = d.initial_mean + d.initial_root * z;
    return 0.0;
  } else {
  const RngKey key{d.seed, Stream::particle_noise};
  const Vec<q> z = Draws::template normals<q>(key, member, particle, d.step);
  if constexpr (has_exact_transition<Model>::value) {
    const double u = Draws::uniform(key, Counter{static_cast<std::uint32_t>(member), static_cast<std::uint32_t>(particle),
                                                 d.step, static_cast<std::uint32_t>((q + 1) / 2)});
    x = d.model.sample_exact_transition(d.t, x, d.dt, z, u);
  } else {
    const typename Model::Control u = Model::Control::zero();
    x = x + d.model.drift(d.t, x, u) * d.dt + d.model.diffusion(d.t, x) * (z * math::sqrt(d.dt));
  }
  const Vec<p> h = d.model.observation(d.t + d.dt, x);
  const double increment = dot(h, vinv_dy) - 0.5 * d.dt * dot(h, d.observation_precision * h);
  const double l = log_weight - log_normalizer + increment;
  bool finite = math::is_finite(l);
  KUSHNER_UNROLL_FULLY
  for (int i = 0; i < n; ++i) finite = finite & math::is_finite(x[i]);  // `&`: no branch, so GCC can vectorize
  return finite ? l : -positive_infinity();
  }
}

/// The host kernel's work for one block: a function of the model and the data only (not of the execution
/// space), so Serial and OpenMP run the same machine code and give the same bits. noinline keeps it so.
template <bool Initialize, class Model>
#if defined(__GNUC__)
__attribute__((noinline))
#endif
void particle_block_host(const ParticleStepData<Model, Kokkos::HostSpace>& d, int member, int block) {
  constexpr int n = Model::state_dim;
  constexpr int B = host_particle_block;
  const int begin = block * B;
  const int count = d.num_particles - begin < B ? d.num_particles - begin : B;
  double* xs[n];
  for (int i = 0; i < n; ++i) xs[i] = &d.x(begin, member, i);
  double* lw = &d.log_weight(begin, member);
  const double log_normalizer = d.initialize ? 0.0 : d.log_normalizer(member);
  const Vec<Model::obs_dim> vinv_dy = d.initialize ? Vec<Model::obs_dim>::zero() : precision_times_dy(d, member);
  double l[B], e[B], dx[n][B];

KUSHNER_SIMD
  for (int j = 0; j < count; ++j) {
    Vec<n> xj;
    KUSHNER_UNROLL_FULLY
    for (int i = 0; i < n; ++i) xj[i] = xs[i][j];
    const double lj = update_particle<SimdDraws, Initialize>(d, member, begin + j, lw[j], log_normalizer, vinv_dy, xj);
    KUSHNER_UNROLL_FULLY
    for (int i = 0; i < n; ++i) xs[i][j] = xj[i];
    lw[j] = lj;
    l[j] = lj;
  }
  double m = -positive_infinity();
KUSHNER_SIMD_REDUCTION(max : m)
  for (int j = 0; j < count; ++j) m = l[j] > m ? l[j] : m;

  WeightedMoments<n> w = WeightedMoments<n>::empty();
  if (m > -positive_infinity()) {
    const Vec<n> ref = load<n>(d.reference, member);
    w.max_log_weight = m;
KUSHNER_SIMD
    for (int j = 0; j < count; ++j) {
      e[j] = math::exp(l[j] - m);
      KUSHNER_UNROLL_FULLY
      for (int i = 0; i < n; ++i) dx[i][j] = e[j] > 0.0 ? xs[i][j] - ref[i] : 0.0;
    }
    double s = 0.0, s2 = 0.0;
KUSHNER_SIMD_REDUCTION(+ : s, s2)
    for (int j = 0; j < count; ++j) {
      s += e[j];
      s2 += e[j] * e[j];
    }
    w.sum_weight = s;
    w.sum_weight_sq = s2;
    for (int i = 0; i < n; ++i) {
      double sx = 0.0;
KUSHNER_SIMD_REDUCTION(+ : sx)
      for (int j = 0; j < count; ++j) sx += e[j] * dx[i][j];
      w.sum_dx[i] = sx;
      for (int k = i; k < n; ++k) {
        double sxx = 0.0;
KUSHNER_SIMD_REDUCTION(+ : sxx)
        for (int j = 0; j < count; ++j) sxx += e[j] * dx[i][j] * dx[k][j];
        w.sum_dxdx[packed_index(n, i, k)] = sxx;
      }
    }
  }
  w.store(d.partials, block, member);
}

/// Host kernel: one work item per (block, member).
template <class Model>
struct ParticleBlockStep {
  ParticleStepData<Model, Kokkos::HostSpace> d;
  int blocks_per_member;
  void operator()(const int item) const {
    const int member = item / blocks_per_member, block = item % blocks_per_member;
    if (d.status(member) != Status::ok) {
      WeightedMoments<Model::state_dim>::empty().store(d.partials, block, member);
      return;
    }
    if (d.initialize) particle_block_host<true>(d, member, block);
    else particle_block_host<false>(d, member, block);
  }
};

/// GPU kernel: a team per (chunk, member); each thread streams its particles into WeightedMoments, then the
/// team merges them pairwise in shared memory in an order fixed by the team size.
template <class Model, class ExecSpace>
struct ParticleTeamStep {
  using MemSpace = typename ExecSpace::memory_space;
  using Team = typename Kokkos::TeamPolicy<ExecSpace>::member_type;
  using Scratch = Kokkos::View<double*, typename ExecSpace::scratch_memory_space, Kokkos::MemoryUnmanaged>;
  static constexpr int n = Model::state_dim, size = WeightedMoments<n>::size;
  ParticleStepData<Model, MemSpace> d;
  int chunks_per_member;

  static std::size_t scratch_bytes(int team_size) { return sizeof(double) * size * team_size; }

  KOKKOS_INLINE_FUNCTION void operator()(const Team& team) const {
    const int member = team.league_rank() / chunks_per_member, chunk = team.league_rank() % chunks_per_member;
    const int threads = team.team_size(), rank = team.team_rank();
    const Scratch buffer(team.team_scratch(0), size * threads);
    WeightedMoments<n> w = WeightedMoments<n>::empty();
    if (d.status(member) == Status::ok) {
      const int begin = chunk * d.block_size;
      const int end = begin + d.block_size < d.num_particles ? begin + d.block_size : d.num_particles;
      const double log_normalizer = d.initialize ? 0.0 : d.log_normalizer(member);
      const Vec<Model::obs_dim> vinv_dy = d.initialize ? Vec<Model::obs_dim>::zero() : precision_times_dy(d, member);
      const Vec<n> ref = load<n>(d.reference, member);
      for (int j = begin + rank; j < end; j += threads) {
        Vec<n> x = load_particle<n>(d.x, j, member);
        const double l =
            d.initialize
                ? update_particle<Random123Draws, true>(d, member, j, 0.0, 0.0, vinv_dy, x)
                : update_particle<Random123Draws, false>(d, member, j, d.log_weight(j, member), log_normalizer, vinv_dy, x);
        store_particle<n>(d.x, j, member, x);
        d.log_weight(j, member) = l;
        w.add(l, x - ref);
      }
    }
    w.store(&buffer(rank * size));
    team.team_barrier();
    for (int active = threads; active > 1;) {
      const int half = (active + 1) / 2;
      if (rank < active - half) {
        WeightedMoments<n> a = WeightedMoments<n>::load(&buffer(rank * size));
        a.merge(WeightedMoments<n>::load(&buffer((rank + half) * size)));
        a.store(&buffer(rank * size));
      }
      team.team_barrier();
      active = half;
    }
    if (rank == 0) WeightedMoments<n>::load(&buffer(0)).store(d.partials, chunk, member);
  }
};

}  // namespace kushner
