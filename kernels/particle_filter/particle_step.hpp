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
#include "kernels/for_each_member.hpp"
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
/// GPU teams: 256 threads, each taking 16 particles of the team's chunk in batches of 4 (the loads of a batch
/// in flight together). Measured on an H100 at M = 1000, N = 65536 (perf/bench_particle_filter.cpp's
/// per_thread argument): 4.44e10 particle-steps/s with 4 per thread, 4.71e10 with 8, 4.84e10 with 16; batches
/// of 8 or 16 need more registers and ran slower.
constexpr int device_particle_team = 256;
constexpr int device_particles_per_thread = 16;
constexpr int device_particle_batch = 4;
/// Launch bound of the team kernel: teams resident per multiprocessor (4 caps it at 64 registers; on an H100,
/// 4 teams of 64 registers ran 18% faster than 2 of 106, bench_particle_filter, M = 1000, N = 65536).
constexpr int device_particle_teams_per_sm = 4;
/// GPU teams of the resampling kernel: a resampled member's loops are latency-bound, so more threads help
/// (1024 instead of 256: resampling went from 0.4 to 0.16 ms per step at M = 1000, N = 65536, on an H100).
constexpr int device_resample_team = 1024;

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
/// space), so Serial and OpenMP run the same machine code and give the same bits (kernels/for_each_member.hpp).
template <bool Initialize, class Model>
KUSHNER_SAME_CODE_FOR_ALL_CALLERS void particle_block_host(const ParticleStepData<Model, Kokkos::HostSpace>& d,
                                                           int member, int block) {
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

/// The largest log-likelihood increment any particle of `member` can get this step: h.a - (dt/2) h^T V^-1 h
/// with a = V^-1 dy is largest at h = V a / dt, where it is dy^T V^-1 dy / (2 dt). The previous log-weights
/// are normalized (each <= 0), so this bounds every new log-weight from above; 0 where it is not finite.
template <class Model, class MemSpace>
KOKKOS_INLINE_FUNCTION double log_weight_bound(const ParticleStepData<Model, MemSpace>& d, int member,
                                               const Vec<Model::obs_dim>& vinv_dy) {
  const double bound = 0.5 * dot(load<Model::obs_dim>(d.dy, member), vinv_dy) / d.dt;
  return math::is_finite(bound) ? bound : 0.0;
}

// Full unrolling of the GPU kernel's fixed-size particle loops (nvcc's device pass; GCC would warn).
#if defined(__CUDA_ARCH__)
#define KUSHNER_DEVICE_UNROLL _Pragma("unroll")
#else
#define KUSHNER_DEVICE_UNROLL
#endif

/// GPU kernel: a team per (chunk, member). Each thread takes its particles in batches of P: all loads of a
/// batch are issued before the first use, so a warp keeps 2 P loads in flight. The weights are summed as
/// e = exp(l - s) with one shift s per member and step, s = log_weight_bound (the largest l any particle can
/// get): no running maximum, one exp per particle, and the team's sums add without rescaling (warp shuffles,
/// then the warps in order). Where the team's largest l is more than `max_shift_gap` from s (particles far
/// from the observation, an extreme dy), the sums could under- or overflow: the team then sums its particles
/// again, from the values it just stored, with s = its largest l. Every sum has an order fixed by the team
/// size, so a seed gives the same bits on every run.
template <class Model, class ExecSpace, int P = device_particle_batch>
struct ParticleTeamStep {
  using MemSpace = typename ExecSpace::memory_space;
  using Team = typename Kokkos::TeamPolicy<ExecSpace>::member_type;
  using Scratch = Kokkos::View<double*, typename ExecSpace::scratch_memory_space, Kokkos::MemoryUnmanaged>;
  static constexpr int n = Model::state_dim, p = Model::obs_dim;
  static constexpr int values = WeightedMoments<n>::size;  // the largest l, then the sums
  static constexpr double max_shift_gap = 200.0;           // e^200 ~ 7e86: sums of squares stay finite
  ParticleStepData<Model, MemSpace> d;
  int chunks_per_member;

  static std::size_t scratch_bytes(int team_size) { return sizeof(double) * values * (team_size + 1); }

  KOKKOS_INLINE_FUNCTION void operator()(const Team& team) const {
    const int member = team.league_rank() / chunks_per_member, chunk = team.league_rank() % chunks_per_member;
    const int threads = team.team_size(), rank = team.team_rank();
    const Scratch buffer(team.team_scratch(0), values * (threads + 1));
    const int begin = chunk * d.block_size;
    const int end = begin + d.block_size < d.num_particles ? begin + d.block_size : d.num_particles;
    WeightedMoments<n> w = WeightedMoments<n>::empty();  // sums relative to `shift`; max_log_weight: largest l
    double shift = 0.0;
    Vec<n> ref = Vec<n>::zero();
    if (d.status(member) == Status::ok) {
      ref = load<n>(d.reference, member);
      if (d.initialize) {
        step_particles<true>(member, begin + rank, end, threads, ref, shift, w);
      } else {
        const Vec<p> vinv_dy = precision_times_dy(d, member);
        shift = log_weight_bound(d, member, vinv_dy);
        step_particles<false>(member, begin + rank, end, threads, ref, shift, w);
      }
    }
    team_sum(team, buffer, w);
    if (w.max_log_weight > -positive_infinity()) {
      const double gap = w.max_log_weight - shift;
      if (!(gap >= -max_shift_gap && gap <= max_shift_gap)) {  // rare: the same for the whole team
        shift = w.max_log_weight;
        w = WeightedMoments<n>::empty();
        for (int j = begin + rank; j < end; j += threads) add_particle(d.log_weight(j, member) - shift,
                                                                       load_particle<n>(d.x, j, member) - ref, w);
        team_sum(team, buffer, w);
      }
      w.max_log_weight = shift;
    }  // else every particle of the chunk has weight zero: w is empty
    if (rank == 0) w.store(d.partials, chunk, member);
  }

 private:
  /// Adds a particle of log-weight l - shift (the largest l goes to max_log_weight); weight zero adds nothing
  /// (its x may not be finite).
  KOKKOS_INLINE_FUNCTION static void add_particle(double shifted, const Vec<n>& dx, WeightedMoments<n>& w) {
    const double e = math::exp(shifted);
    if (e > 0.0) w.add_weight(e, dx);
  }

  template <bool Initialize>
  KOKKOS_INLINE_FUNCTION void step_particles(int member, int first, int end, int threads, const Vec<n>& ref,
                                             double shift, WeightedMoments<n>& w) const {
    const double log_normalizer = Initialize ? 0.0 : d.log_normalizer(member);
    const Vec<p> vinv_dy = Initialize ? Vec<p>::zero() : precision_times_dy(d, member);
    double top = -positive_infinity();
    // The member's columns as pointers: one 64-bit address computation per thread, not per access.
    double* const xm = &d.x(0, member, 0);
    double* const lwm = &d.log_weight(0, member);
    const std::size_t x_stride = d.x.stride_2();  // LayoutLeft: x(j, member, i) = xm[j + i * x_stride]
    for (int base = first; base < end; base += P * threads) {
      Vec<n> x[P];
      double lw[P];
      KUSHNER_DEVICE_UNROLL
      for (int k = 0; k < P; ++k) {
        const int j = base + k * threads;
        if (j < end) {
          KUSHNER_DEVICE_UNROLL
          for (int i = 0; i < n; ++i) x[k][i] = xm[j + i * x_stride];
          lw[k] = Initialize ? 0.0 : lwm[j];
        }
      }
      KUSHNER_DEVICE_UNROLL
      for (int k = 0; k < P; ++k) {
        const int j = base + k * threads;
        if (j < end) {
          const double l =
              update_particle<Random123Draws, Initialize>(d, member, j, lw[k], log_normalizer, vinv_dy, x[k]);
          KUSHNER_DEVICE_UNROLL
          for (int i = 0; i < n; ++i) xm[j + i * x_stride] = x[k][i];
          lwm[j] = l;
          top = l > top ? l : top;
          add_particle(l - shift, x[k] - ref, w);
        }
      }
    }
    w.max_log_weight = top;
  }

  /// w <- the team's total (max for max_log_weight, sums for the rest) on every thread, in an order fixed by
  /// the team size: on a GPU, shuffles within each warp and then the warps in order; elsewhere a pairwise
  /// tree in scratch memory.
  KOKKOS_INLINE_FUNCTION static void team_sum(const Team& team, const Scratch& buffer, WeightedMoments<n>& w) {
    const int threads = team.team_size(), rank = team.team_rank();
    double v[values];
    w.store(v);
    const double* total = &buffer(threads * values);
#if defined(__CUDA_ARCH__)
    if (threads % 32 == 0) {  // Kokkos' CUDA teams: team rank = thread index in the block (vector length 1)
      KUSHNER_DEVICE_UNROLL
      for (int offset = 16; offset > 0; offset /= 2) {
        KUSHNER_DEVICE_UNROLL
        for (int k = 0; k < values; ++k) {
          const double o = __shfl_down_sync(0xffffffffu, v[k], offset);
          v[k] = k == 0 ? (o > v[k] ? o : v[k]) : v[k] + o;
        }
      }
      if (rank % 32 == 0)
        for (int k = 0; k < values; ++k) buffer((rank / 32) * values + k) = v[k];
      team.team_barrier();
      if (rank == 0) {
        for (int warp = 1; warp < threads / 32; ++warp)
          for (int k = 0; k < values; ++k) {
            const double o = buffer(warp * values + k);
            v[k] = k == 0 ? (o > v[k] ? o : v[k]) : v[k] + o;
          }
        for (int k = 0; k < values; ++k) buffer(threads * values + k) = v[k];
      }
      team.team_barrier();
      w = WeightedMoments<n>::load(total);
      return;
    }
#endif
    for (int k = 0; k < values; ++k) buffer(rank * values + k) = v[k];
    team.team_barrier();
    for (int active = threads; active > 1;) {
      const int half = (active + 1) / 2;
      if (rank < active - half)
        for (int k = 0; k < values; ++k) {
          const double o = buffer((rank + half) * values + k);
          const double a = buffer(rank * values + k);
          buffer(rank * values + k) = k == 0 ? (o > a ? o : a) : a + o;
        }
      team.team_barrier();
      active = half;
    }
    if (rank == 0)
      for (int k = 0; k < values; ++k) buffer(threads * values + k) = buffer(k);
    team.team_barrier();
    w = WeightedMoments<n>::load(total);
  }
};

}  // namespace kushner
