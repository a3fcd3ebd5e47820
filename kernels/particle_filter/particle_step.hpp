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
#include "core/linear_algebra.hpp"
#include "core/math.hpp"
#include "kernels/particle_filter/particle_draws.hpp"
#include "kernels/particle_filter/particle_model_traits.hpp"
#include "kernels/vector_math.hpp"
#include "kernels/particle_filter/weighted_moments.hpp"
#include "kernels/rng.hpp"
#include "core/status.hpp"

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
/// GPU teams: 256 threads, each taking 16 particles of the team's chunk one pair (one Philox block) at a time,
/// the pair's loads in flight while its draws are computed. Measured on an H100 at M = 1000, N = 65536, fp64,
/// with resampling (perf/particle_filter.md): batches of 2 particles 6.38e10 particle-steps/s, of 4 4.68e10
/// (more registers under the 64-register bound); the next batch's loads issued ahead: 6.13e10; a pair's
/// values moved as one 16-byte load/store: +0.5%, within the noise, not kept.
constexpr int device_particle_team = 256;
constexpr int device_particles_per_thread = 16;
constexpr int device_particle_batch = 2;
/// Launch bound of the team kernel: teams resident per multiprocessor (4 caps it at 64 registers; on an H100,
/// 4 teams of 64 registers ran 18% faster than 2 of 106, bench_particle_filter, M = 1000, N = 65536; batches of
/// 4 with 3 teams (85 registers) ran 4% slower than batches of 2 with 4).
constexpr int device_particle_teams_per_sm = 4;
/// GPU teams of the one-team-per-member resampling kernel (schemes other than systematic): a resampled
/// member's loops are latency-bound, so more threads help (1024 instead of 256: 0.4 -> 0.16 ms per step at
/// M = 1000, N = 65536, on an H100).
constexpr int device_resample_team = 1024;
/// The chunked systematic resampling (chunked_systematic_resample.hpp): teams of 256 threads, at most 1024
/// teams looping over the (member, chunk) items.
constexpr int device_chunked_resample_team = 256;
constexpr int chunked_resample_league = 1024;

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
  double sqrt_dt = 0.0;             // computed once: nvcc re-evaluated sqrt(dt) for every particle
  std::uint32_t seed = 0, step = 0;
  int num_particles = 0, block_size = 0;
  bool initialize = false;          // sample the initial law instead of propagating; no observation
  // Team kernel only. If `members` is allocated, only members(0 .. member_count() - 1) take the step.
  Kokkos::View<const int*, MemSpace> members;
  Kokkos::View<const int, MemSpace> member_count;
  // The second step of a fused pair (ParticleTeamStep<..., 2>), step + 1 over [t_next, t_next + dt]. A pair reads
  // x and log_weight and writes x_out and log_weight_out (same layout), so its first step can be recomputed.
  ParticleBank<MemSpace> x_out;
  Kokkos::View<double**, Kokkos::LayoutLeft, MemSpace> log_weight_out;
  BankVector<MemSpace> dy_next;
  Kokkos::View<double***, Kokkos::LayoutLeft, MemSpace> partials_next;
  Mat<p, p> observation_precision_next;
  double t_next = 0.0;
};

/// Draws per particle and step: the normals of the initial state, or of the Euler-Maruyama step.
template <class Model, bool Initialize>
constexpr int particle_draw_dim = Initialize ? Model::state_dim : Model::noise_dim;

/// The key and step of the particles' draws: their initial states, or step d.step.
template <bool Initialize, class Model, class MemSpace>
KOKKOS_INLINE_FUNCTION RngKey particle_draw_key(const ParticleStepData<Model, MemSpace>& d) {
  return RngKey{d.seed, Initialize ? Stream::particle_initial : Stream::particle_noise};
}
template <bool Initialize, class Model, class MemSpace>
KOKKOS_INLINE_FUNCTION std::uint32_t particle_draw_step(const ParticleStepData<Model, MemSpace>& d) {
  return Initialize ? 0 : d.step;
}
template <class Model, bool Initialize>
constexpr bool draws_uniform = !Initialize && has_exact_transition<Model>::value;

/// V^{-1} dy of one member: the only observation term the likelihood needs besides h(x).
template <class Model, class MemSpace>
KOKKOS_INLINE_FUNCTION Vec<Model::obs_dim> precision_times_dy(const ParticleStepData<Model, MemSpace>& d, int member) {
  return d.observation_precision * load<Model::obs_dim>(d.dy, member);
}

/// Moves one particle (x in, x out) over [t, t + dt] with its draws (normals z, uniform u) and returns its new
/// log-weight, normalized by the member's previous log-normalizer; -inf for a particle that left the finite
/// numbers. `precision` is V^{-1} at t.
template <bool Initialize, class Model, class MemSpace>
KOKKOS_INLINE_FUNCTION double update_particle(const ParticleStepData<Model, MemSpace>& d, double t,
                                              const Mat<Model::obs_dim, Model::obs_dim>& precision,
                                              const Vec<particle_draw_dim<Model, Initialize>>& z, double u,
                                              double log_weight, double log_normalizer,
                                              const Vec<Model::obs_dim>& vinv_dy, Vec<Model::state_dim>& x) {
  constexpr int n = Model::state_dim, p = Model::obs_dim;
  if constexpr (Initialize) {
    x = d.initial_mean + d.initial_root * z;
    return 0.0;
  } else {
    if constexpr (has_exact_transition<Model>::value) {
      x = d.model.sample_exact_transition(t, x, d.dt, z, u);
    } else {
      const typename Model::Control control = Model::Control::zero();
      x = x + d.model.drift(t, x, control) * d.dt + d.model.diffusion(t, x) * (z * d.sqrt_dt);
    }
    const Vec<p> h = d.model.observation(t + d.dt, x);
    const double increment = dot(h, vinv_dy) - 0.5 * d.dt * dot(h, precision * h);
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
  // The block's draws first, pair by pair, into particle-contiguous arrays that the particle loop reads.
  constexpr int K = particle_draw_dim<Model, Initialize>;
  double z[K][B], u[B];
  const RngKey key = particle_draw_key<Initialize>(d);
  const std::uint32_t step = particle_draw_step<Initialize>(d);
  const int first_pair = begin / 2;   // blocks start at even particles
  const int pairs = (count + 1) / 2;  // an odd count's last particle is the even half of its pair
  for (int i = 0; i < K; ++i) {
    KUSHNER_SIMD
    for (int k = 0; k < pairs; ++k) {
      const NormalPair zk = pair_normals<SimdDraws>(key, member, first_pair + k, step, i);
      z[i][2 * k] = zk.z0;
      z[i][2 * k + 1] = zk.z1;
    }
  }
  if constexpr (draws_uniform<Model, Initialize>) {
    KUSHNER_SIMD
    for (int k = 0; k < pairs; ++k) {
      double u0, u1;
      pair_uniforms<SimdDraws>(key, member, first_pair + k, step, K, u0, u1);
      u[2 * k] = u0;
      u[2 * k + 1] = u1;
    }
  }
KUSHNER_SIMD
  for (int j = 0; j < count; ++j) {
    Vec<n> xj;
    Vec<K> zj;
    KUSHNER_UNROLL_FULLY
    for (int i = 0; i < n; ++i) xj[i] = xs[i][j];
    KUSHNER_UNROLL_FULLY
    for (int i = 0; i < K; ++i) zj[i] = z[i][j];
    const double uj = draws_uniform<Model, Initialize> ? u[j] : 0.0;
    const double lj =
        update_particle<Initialize>(d, d.t, d.observation_precision, zj, uj, lw[j], log_normalizer, vinv_dy, xj);
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

/// The largest log-likelihood increment any particle can get from an increment dy: h.a - (dt/2) h^T V^-1 h
/// with a = V^-1 dy is largest at h = V a / dt, where it is dy^T V^-1 dy / (2 dt). The previous log-weights
/// are normalized (each <= 0), so this bounds every new log-weight from above; 0 where it is not finite.
template <int P>
KOKKOS_INLINE_FUNCTION double log_weight_bound(const Vec<P>& dy, const Vec<P>& vinv_dy, double dt) {
  const double bound = 0.5 * dot(dy, vinv_dy) / dt;
  return math::is_finite(bound) ? bound : 0.0;
}

/// GPU kernel: a team per (chunk, member). Each thread takes its particles in batches of P: all loads of a
/// batch are issued before the first use, so a warp keeps 2 P loads in flight. The weights are summed as
/// e = exp(l - s) with one shift s per member and step, s = log_weight_bound (the largest l any particle can
/// get): no running maximum, one exp per particle, and the team's sums add without rescaling (warp shuffles,
/// then the warps in order). Where the team's largest l is more than `max_shift_gap` from s (particles far
/// from the observation, an extreme dy), the sums could under- or overflow: the team then sums its particles
/// again with s = its largest l. Every sum has an order fixed by the team size, so a seed gives the same bits
/// on every run.
///
/// Steps = 2 fuses two steps (k and k + 1) into one pass: the particles stay in registers between them, so a
/// particle-step moves half the bytes (on an H100 the step runs at its power limit, and memory traffic is a
/// large part of that power). The log-weights of step k + 1 are left normalized by step k - 1's normalizer
/// (step k's is not known yet), its shift is the sum of both steps' bounds, and both steps' moments are taken
/// relative to the same reference point. ParticleFilterBank::step_pair redoes the members that step k
/// resamples.
///
/// Listed: a fixed league loops over the (listed member, chunk) items of d.members instead (a separate
/// instantiation: the loop costs the 64-register kernel registers).
template <class Model, class ExecSpace, int P = device_particle_batch, int Steps = 1, bool Listed = false>
struct ParticleTeamStep {
  static_assert(Steps == 1 || Steps == 2, "ParticleTeamStep: one step or a fused pair");
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
    if constexpr (Listed) {
      const int items = d.member_count() * chunks_per_member;
      for (int item = team.league_rank(); item < items; item += team.league_size())
        step_chunk(team, d.members(item / chunks_per_member), item % chunks_per_member);
    } else {
      step_chunk(team, team.league_rank() / chunks_per_member, team.league_rank() % chunks_per_member);
    }
  }

 private:
  KOKKOS_INLINE_FUNCTION void step_chunk(const Team& team, int member, int chunk) const {
    const int threads = team.team_size(), rank = team.team_rank();
    const Scratch buffer(team.team_scratch(0), values * (threads + 1));
    const int begin = chunk * d.block_size;
    const int end = begin + d.block_size < d.num_particles ? begin + d.block_size : d.num_particles;
    WeightedMoments<n> w[Steps];  // sums relative to `shift`; max_log_weight: largest l
    double shift[Steps];
    Vec<p> vinv_dy[Steps];
    KUSHNER_DEVICE_UNROLL
    for (int s = 0; s < Steps; ++s) {
      w[s] = WeightedMoments<n>::empty();
      shift[s] = 0.0;
      vinv_dy[s] = Vec<p>::zero();
    }
    Vec<n> ref = Vec<n>::zero();
    if (d.status(member) == Status::ok) {
      ref = load<n>(d.reference, member);
      if (Steps == 1 && d.initialize) {
        if constexpr (Steps == 1) step_particles<true>(member, begin, end, rank, threads, ref, vinv_dy, shift, w);
      } else {
        double bound = 0.0;
        KUSHNER_DEVICE_UNROLL
        for (int s = 0; s < Steps; ++s) {
          const Vec<p> dy = load<p>(s == 0 ? d.dy : d.dy_next, member);
          vinv_dy[s] = precision(s) * dy;
          bound += log_weight_bound(dy, vinv_dy[s], d.dt);
          shift[s] = bound;
        }
        step_particles<false>(member, begin, end, rank, threads, ref, vinv_dy, shift, w);
      }
    }
    KUSHNER_DEVICE_UNROLL
    for (int s = 0; s < Steps; ++s) {
      team_sum(team, buffer, w[s]);
      if (w[s].max_log_weight > -positive_infinity()) {
        const double gap = w[s].max_log_weight - shift[s];
        if (!(gap >= -max_shift_gap && gap <= max_shift_gap)) {  // rare: the same for the whole team
          shift[s] = w[s].max_log_weight;
          w[s] = WeightedMoments<n>::empty();
          if (s == Steps - 1) {  // from the values just stored
            const auto& x = Steps == 1 ? d.x : d.x_out;
            const auto& lw = Steps == 1 ? d.log_weight : d.log_weight_out;
            for (int j = begin + rank; j < end; j += threads)
              add_particle(lw(j, member) - shift[s], load_particle<n>(x, j, member) - ref, w[s]);
          } else {  // the first step of a pair, recomputed from its inputs
            resum_first_step(member, begin, end, rank, threads, ref, vinv_dy[0], shift[0], w[0]);
          }
          team_sum(team, buffer, w[s]);
        }
        w[s].max_log_weight = shift[s];
      }  // else every particle of the chunk has weight zero: w is empty
      if (rank == 0) w[s].store(s == 0 ? d.partials : d.partials_next, chunk, member);
    }
  }

  /// Step s of the pass: its start time and V^{-1} there.
  KOKKOS_INLINE_FUNCTION double step_time(int s) const { return s == 0 ? d.t : d.t_next; }
  KOKKOS_INLINE_FUNCTION const Mat<p, p>& precision(int s) const {
    return s == 0 ? d.observation_precision : d.observation_precision_next;
  }

  /// Adds a particle of log-weight l - shift (the largest l goes to max_log_weight); weight zero adds nothing
  /// (its x may not be finite).
  KOKKOS_INLINE_FUNCTION static void add_particle(double shifted, const Vec<n>& dx, WeightedMoments<n>& w) {
    const double e = math::exp(shifted);
    if (e > 0.0) w.add_weight(e, dx);
  }

  /// The draws of particles 2 pair (z0, u0) and 2 pair + 1 (z1, u1) at `step`.
  template <bool Initialize>
  KOKKOS_INLINE_FUNCTION static void draw_pair(const RngKey& key, int member, int pair, std::uint32_t step,
                                               Vec<particle_draw_dim<Model, Initialize>>& z0,
                                               Vec<particle_draw_dim<Model, Initialize>>& z1, double& u0, double& u1) {
    constexpr int K = particle_draw_dim<Model, Initialize>;
    KUSHNER_DEVICE_UNROLL
    for (int i = 0; i < K; ++i) {
      const NormalPair zi = pair_normals<Random123Draws>(key, member, pair, step, i);
      z0[i] = zi.z0;
      z1[i] = zi.z1;
    }
    u0 = u1 = 0.0;
    if constexpr (draws_uniform<Model, Initialize>) pair_uniforms<Random123Draws>(key, member, pair, step, K, u0, u1);
  }

  /// The particles [begin, end) of `member`, pairs (2 k, 2 k + 1) sharing their draws: thread `rank` takes
  /// pairs begin / 2 + rank, + threads, ..., B at a time. A batch's loads are issued first and its draws
  /// computed next (they need no memory), so the draws run while the loads are in flight.
  template <bool Initialize>
  KOKKOS_INLINE_FUNCTION void step_particles(int member, int begin, int end, int rank, int threads, const Vec<n>& ref,
                                             const Vec<p>* vinv_dy, const double* shift,
                                             WeightedMoments<n>* w) const {
    constexpr int B = (P + 1) / 2;  // pairs per batch
    constexpr int K = particle_draw_dim<Model, Initialize>;
    const double log_normalizer = Initialize ? 0.0 : d.log_normalizer(member);
    double top[Steps];
    KUSHNER_DEVICE_UNROLL
    for (int s = 0; s < Steps; ++s) top[s] = -positive_infinity();
    // The member's columns as pointers: one 64-bit address computation per thread, not per access.
    double* const xm = &d.x(0, member, 0);
    double* const lwm = &d.log_weight(0, member);
    double* const xo = Steps == 1 ? xm : &d.x_out(0, member, 0);
    double* const lwo = Steps == 1 ? lwm : &d.log_weight_out(0, member);
    const std::size_t x_stride = d.x.stride_2();  // LayoutLeft: x(j, member, i) = xm[j + i * x_stride]
    const int end_pair = (end + 1) / 2;
    const RngKey key = particle_draw_key<Initialize>(d);
    const std::uint32_t step = particle_draw_step<Initialize>(d);
    for (int base = begin / 2 + rank; base < end_pair; base += B * threads) {
      Vec<n> x[2 * B];
      double lw[2 * B];
      KUSHNER_DEVICE_UNROLL
      for (int k = 0; k < 2 * B; ++k) {
        const int j = 2 * (base + (k / 2) * threads) + k % 2;
        if (j < end) {
          KUSHNER_DEVICE_UNROLL
          for (int i = 0; i < n; ++i) x[k][i] = xm[j + i * x_stride];
          lw[k] = Initialize ? 0.0 : lwm[j];
        }
      }
      KUSHNER_DEVICE_UNROLL
      for (int s = 0; s < Steps; ++s) {
        Vec<K> z[2 * B];
        double u[2 * B];
        KUSHNER_DEVICE_UNROLL
        for (int b = 0; b < B; ++b)
          draw_pair<Initialize>(key, member, base + b * threads, step + s, z[2 * b], z[2 * b + 1], u[2 * b],
                                u[2 * b + 1]);
        KUSHNER_DEVICE_UNROLL
        for (int k = 0; k < 2 * B; ++k) {
          const int j = 2 * (base + (k / 2) * threads) + k % 2;
          if (j >= end) continue;
          const double l = update_particle<Initialize>(d, step_time(s), precision(s), z[k], u[k], lw[k],
                                                       s == 0 ? log_normalizer : 0.0, vinv_dy[s], x[k]);
          if (s == Steps - 1) {
            KUSHNER_DEVICE_UNROLL
            for (int i = 0; i < n; ++i) xo[j + i * x_stride] = x[k][i];
            lwo[j] = l;
          }
          lw[k] = l;
          top[s] = l > top[s] ? l : top[s];
          add_particle(l - shift[s], x[k] - ref, w[s]);
        }
      }
    }
    KUSHNER_DEVICE_UNROLL
    for (int s = 0; s < Steps; ++s) w[s].max_log_weight = top[s];
  }

  /// The first step of a pair again, from the pass's inputs (which it did not overwrite), summed with `shift`.
  KOKKOS_INLINE_FUNCTION void resum_first_step(int member, int begin, int end, int rank, int threads,
                                               const Vec<n>& ref, const Vec<p>& vinv_dy, double shift,
                                               WeightedMoments<n>& w) const {
    constexpr int K = particle_draw_dim<Model, false>;
    const double log_normalizer = d.log_normalizer(member);
    const RngKey key = particle_draw_key<false>(d);
    for (int pair = begin / 2 + rank; pair < (end + 1) / 2; pair += threads) {
      Vec<K> z[2];
      double u[2];
      draw_pair<false>(key, member, pair, d.step, z[0], z[1], u[0], u[1]);
      for (int k = 0; k < 2; ++k) {
        const int j = 2 * pair + k;
        if (j >= end) continue;
        Vec<n> x = load_particle<n>(d.x, j, member);
        const double l = update_particle<false>(d, d.t, d.observation_precision, z[k], u[k], d.log_weight(j, member),
                                                log_normalizer, vinv_dy, x);
        add_particle(l - shift, x - ref, w);
      }
    }
  }

  /// w <- the team's total (max for max_log_weight, sums for the rest) on every thread, in an order fixed by
  /// the team size: on a GPU, shuffles within each warp and then the warps in order; elsewhere a pairwise
  /// tree in scratch memory.
  KOKKOS_INLINE_FUNCTION static void team_sum(const Team& team, const Scratch& buffer, WeightedMoments<n>& w) {
    const int threads = team.team_size(), rank = team.team_rank();
    double v[values];
    w.store(v);
    const double* total = &buffer(threads * values);
#if KUSHNER_CUDA_DEVICE_PASS
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
