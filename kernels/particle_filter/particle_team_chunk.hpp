#pragma once
// What the GPU's team kernels (particle_team_step.hpp: one step; particle_team_pair_step.hpp: two steps fused) share: a
// team takes one chunk of one member's particles; each thread takes pairs of particles (which share their Philox
// blocks) in batches, loading a whole batch before it computes (fp32: while it computes the batch before,
// for_each_particle_batch); the team's moments are summed as e = exp(l - s) with one shift s per member and step (no
// running maximum: one exp per particle, and the threads' sums add without rescaling), checked afterwards against the
// team's largest l. Which members and chunks the league covers is the launcher's choice: every (member, chunk), or the
// listed members only.
#include "kernels/particle_filter/particle_update.hpp"
#include "kernels/particle_filter/team_reduction.hpp"
#include "kernels/particle_filter/tuning.hpp"

#include <Kokkos_Core.hpp>

#include <cstdint>
#include <type_traits>

namespace kushner {

/// Where the team's sums are too far from their shift (particles far from the observation, an extreme dy)
/// they could under- or overflow. Within 200 of the shift a square is at most e^400 ~ 5e173, so sums of
/// squares of any int-counted number of particles stay finite. Where the exp is taken in float (FloatExp: fp32's and
/// mixed's kernels, add_shifted_particle), whose normal numbers span e^-87 .. e^88: within 60 of the shift, every
/// particle within e^-27 of the largest weight is a normal float.
template <bool FloatExp>
constexpr double team_max_shift_gap = FloatExp ? 60.0 : 200.0;

/// Particle pairs per batch of a thread.
constexpr int device_pairs_per_batch = (device_particle_batch + 1) / 2;

/// The particles [begin, end) of a team's chunk, and the thread's place in the team.
struct ParticleChunk {
  int begin, end, rank, threads;
};
template <class Team>
KOKKOS_INLINE_FUNCTION ParticleChunk particle_chunk(const Team& team, int chunk, int block_size, int num_particles) {
  const int begin = chunk * block_size;
  const int end = begin + block_size < num_particles ? begin + block_size : num_particles;
  return {begin, end, team.team_rank(), team.team_size()};
}

/// Slot k of the batch that starts at pair `base` holds particle 2 (base + (k / 2) threads) + k % 2: a thread's
/// pairs are strided by the team size, so a warp's loads are contiguous.
KOKKOS_INLINE_FUNCTION int batch_particle(int base, int k, int threads) {
  return 2 * (base + (k / 2) * threads) + k % 2;
}

/// Whether a kernel moves each pair of particles 2p, 2p + 1 of a member as one 8-byte access (load_particle_batch,
/// store_particle_batch): fp32 on a GPU, where the member's columns hold an even number of particles and start at
/// 8-byte boundaries (p0 .. p3: the columns a kernel reads and writes). Chunks start at even particles (whole pairs),
/// so a pair's second particle then exists wherever its first does. A warp's access takes each 32-byte sector once,
/// where the accesses of its even and of its odd particles took each sector twice: the L2 had become the limit of
/// fp32's fused pass (95% of its throughput), at 68% of the DRAM's.
template <class Real>
KOKKOS_INLINE_FUNCTION bool moves_whole_pairs(int num_particles, std::size_t stride, const Real* p0, const Real* p1,
                                              const Real* p2, const Real* p3) {
#if KUSHNER_CUDA_DEVICE_PASS
  const auto address = [](const Real* p) { return reinterpret_cast<std::uintptr_t>(p); };
  return std::is_same_v<Real, float> && num_particles % 2 == 0 && stride % 2 == 0 &&
         ((address(p0) | address(p1) | address(p2) | address(p3)) & 7) == 0;
#else
  (void)num_particles, (void)stride, (void)p0, (void)p1, (void)p2, (void)p3;
  return false;
#endif
}

/// Loads the batch's particles (and log-weights, unless initializing) from one member's columns: xm[j + i * stride]
/// and lwm[j], as H: the scalar a step computes in (float for fp32's float steps, which hold their particles in float
/// from load to store; else double); each pair in one access where `paired` (moves_whole_pairs). Slots past `end` get
/// zeros (for_each_particle_batch).
template <int N, bool Initialize, class Real, class H>
KOKKOS_INLINE_FUNCTION void load_particle_batch(const Real* xm, const Real* lwm, std::size_t stride, int base,
                                                int threads, int end, bool paired, Vec<N, H>* x, H* lw) {
#if KUSHNER_CUDA_DEVICE_PASS
  if constexpr (std::is_same_v<Real, float>) {
    if (paired) {
      KUSHNER_DEVICE_UNROLL
      for (int b = 0; b < device_pairs_per_batch; ++b) {
        const int j = batch_particle(base, 2 * b, threads);
        x[2 * b] = x[2 * b + 1] = Vec<N, H>::zero();
        lw[2 * b] = lw[2 * b + 1] = H(0);
        if (j < end) {
          KUSHNER_DEVICE_UNROLL
          for (int i = 0; i < N; ++i) {
            const float2 v = *reinterpret_cast<const float2*>(xm + j + i * stride);
            x[2 * b][i] = v.x;
            x[2 * b + 1][i] = v.y;
          }
          if (!Initialize) {
            const float2 v = *reinterpret_cast<const float2*>(lwm + j);
            lw[2 * b] = v.x;
            lw[2 * b + 1] = v.y;
          }
        }
      }
      return;
    }
  }
#endif
  (void)paired;
  KUSHNER_DEVICE_UNROLL
  for (int k = 0; k < 2 * device_pairs_per_batch; ++k) {
    const int j = batch_particle(base, k, threads);
    if (j < end) {
      KUSHNER_DEVICE_UNROLL
      for (int i = 0; i < N; ++i) x[k][i] = xm[j + i * stride];
      lw[k] = Initialize ? H(0) : lwm[j];
    } else {
      x[k] = Vec<N, H>::zero();
      lw[k] = H(0);
    }
  }
}

/// Stores the batch's stepped particles x and log-weights l into one member's columns, as load_particle_batch loaded
/// them: the slots below `end` only.
template <int N, class Real, class H>
KOKKOS_INLINE_FUNCTION void store_particle_batch(Real* xm, Real* lwm, std::size_t stride, int base, int threads,
                                                 int end, bool paired, const Vec<N, H>* x, const H* l) {
#if KUSHNER_CUDA_DEVICE_PASS
  if constexpr (std::is_same_v<Real, float>) {
    if (paired) {
      KUSHNER_DEVICE_UNROLL
      for (int b = 0; b < device_pairs_per_batch; ++b) {
        const int j = batch_particle(base, 2 * b, threads);
        if (j >= end) continue;
        KUSHNER_DEVICE_UNROLL
        for (int i = 0; i < N; ++i)
          *reinterpret_cast<float2*>(xm + j + i * stride) =
              float2{static_cast<float>(x[2 * b][i]), static_cast<float>(x[2 * b + 1][i])};
        *reinterpret_cast<float2*>(lwm + j) = float2{static_cast<float>(l[2 * b]), static_cast<float>(l[2 * b + 1])};
      }
      return;
    }
  }
#endif
  (void)paired;
  KUSHNER_DEVICE_UNROLL
  for (int k = 0; k < 2 * device_pairs_per_batch; ++k) {
    const int j = batch_particle(base, k, threads);
    if (j >= end) continue;
    KUSHNER_DEVICE_UNROLL
    for (int i = 0; i < N; ++i) xm[j + i * stride] = static_cast<Real>(x[k][i]);
    lwm[j] = static_cast<Real>(l[k]);
  }
}

/// body(base, x, lw) for each batch of the thread's pairs of the chunk, its particles and log-weights loaded into x
/// and lw (load_particle_batch). A batch's slots past the chunk's end hold zeros: the kernels step them too and keep
/// neither their values nor their weights (without a branch around each particle's step: fp32's fused pass x1.065,
/// mixed's x1.05 on an H100). Where the kernel holds its particles in float (H float; not while initializing), the
/// next batch is loaded while this one is stepped: nvcc issued the loads of a pair's first particle after its Philox
/// rounds, and a third of fp32's stall samples waited at their first use (fp32's fused pass x1.02 on top). In double
/// the loads ahead take 8 more registers of the launch bound's 64 (fp64 x0.986, mixed x0.933).
template <int N, bool Initialize, class H, class Real, class Body>
KOKKOS_INLINE_FUNCTION void for_each_particle_batch(const ParticleChunk& c, const Real* xm, const Real* lwm,
                                                    std::size_t stride, bool paired, const Body& body) {
  constexpr int B = 2 * device_pairs_per_batch;
  constexpr bool load_ahead = std::is_same_v<H, float> && !Initialize;
  const int first = c.begin / 2 + c.rank, last = (c.end + 1) / 2, step = device_pairs_per_batch * c.threads;
  Vec<N, H> x[B], ahead_x[B];
  H lw[B], ahead_lw[B];
  if (load_ahead && first < last)
    load_particle_batch<N, Initialize>(xm, lwm, stride, first, c.threads, c.end, paired, ahead_x, ahead_lw);
  for (int base = first; base < last; base += step) {
    if constexpr (load_ahead) {
      KUSHNER_DEVICE_UNROLL
      for (int k = 0; k < B; ++k) {
        x[k] = ahead_x[k];
        lw[k] = ahead_lw[k];
      }
      if (base + step < last)
        load_particle_batch<N, Initialize>(xm, lwm, stride, base + step, c.threads, c.end, paired, ahead_x, ahead_lw);
    } else {
      load_particle_batch<N, Initialize>(xm, lwm, stride, base, c.threads, c.end, paired, x, lw);
    }
    body(base, x, lw);
  }
}

/// p, as a value the GPU's compiler cannot recompute: it keeps the pointer in registers. Without this nvcc recomputed a
/// member's column pointers from the views' data pointers and strides (kernel parameters) at every load and store of
/// fp32's fused pair loop: 369 SASS instructions, 325 with it, and fp32's `step_pair` x1.044 on an H100, though the
/// loads and stores become generic ones (LD, ST) where they were global (perf/particle_filter.md).
template <class T>
KOKKOS_FORCEINLINE_FUNCTION T* held_in_registers(T* p) {
#if KUSHNER_CUDA_DEVICE_PASS
  asm("" : "+l"(p));
#endif
  return p;
}

/// The batch's draws at `step`.
template <class Model, bool Initialize, bool Fp32Steps = false>
KOKKOS_INLINE_FUNCTION void draw_particle_batch(const RngKey& key, int member, int base, int threads,
                                                std::uint32_t step, bool fp32,
                                                Vec<particle_draw_dim<Model, Initialize>>* z, double* u) {
  KUSHNER_DEVICE_UNROLL
  for (int b = 0; b < device_pairs_per_batch; ++b)
    draw_particle_pair<Model, Initialize, Fp32Steps>(key, member, base + b * threads, step, fp32, z[2 * b],
                                                     z[2 * b + 1], u[2 * b], u[2 * b + 1]);
}

/// The `fp32` precision's draws of the batch at `step` (z[0], u[0]) and step + 1 (z[1], u[1]): draw_particle_batch's
/// numbers, with the normals of both steps from one block where `step` is even (fp32_pair_normals_two_steps).
template <class Model>
KOKKOS_INLINE_FUNCTION void draw_fp32_batch_two_steps(
    const RngKey& key, int member, int base, int threads, std::uint32_t step,
    Vec<particle_draw_dim<Model, false>> (*z)[2 * device_pairs_per_batch], double (*u)[2 * device_pairs_per_batch]) {
  constexpr int K = particle_draw_dim<Model, false>;
  KUSHNER_DEVICE_UNROLL
  for (int b = 0; b < device_pairs_per_batch; ++b) {
    const int pair = base + b * threads;
    KUSHNER_DEVICE_UNROLL
    for (int i = 0; i < K; ++i) {
      NormalPair first, second;
      fp32_pair_normals_two_steps(key, member, pair, step, i, first, second);
      z[0][2 * b][i] = first.z0;
      z[0][2 * b + 1][i] = first.z1;
      z[1][2 * b][i] = second.z0;
      z[1][2 * b + 1][i] = second.z1;
    }
    KUSHNER_DEVICE_UNROLL
    for (int s = 0; s < 2; ++s) {
      u[s][2 * b] = u[s][2 * b + 1] = 0.0;
      if constexpr (draws_uniform<Model, false>)
        pair_uniforms(key, member, pair, step + s, K, u[s][2 * b], u[s][2 * b + 1]);
    }
  }
}

/// Adds a particle of log-weight l - shift (`shifted`, a float where the kernel holds its particles in float); weight
/// zero adds nothing (its x may not be finite). Its weight's exp is taken in float with FloatExp (the fp32 and mixed
/// kernels: a GPU's fp64 exp costs several times the energy of its float one; math::weight_exp), the sums in double.
template <bool FloatExp, int N, class T>
KOKKOS_INLINE_FUNCTION void add_shifted_particle(T shifted, const Vec<N>& dx, WeightedMoments<N>& w) {
  static_assert(FloatExp || std::is_same_v<T, double>, "an fp64 weight's l - shift in double");
  double e;
  if constexpr (FloatExp)
    e = math::weight_exp(static_cast<float>(shifted));
  else
    e = math::exp(shifted);
  if (e > 0.0) w.add_weight(e, dx);
}

/// A member's shift as a team kernel whose particles are held in H takes it: rounded to a float where H is float
/// (fp32's float steps), so that a particle's l - shift is one float subtraction, the double difference's rounding to
/// float (past float's range, shift becomes infinite and the team sums again relative to its largest l).
template <class H>
KOKKOS_INLINE_FUNCTION double team_shift(double shift) {
  return std::is_same_v<H, float> ? static_cast<double>(static_cast<float>(shift)) : shift;
}

/// The team's moments of one step: w holds the thread's sums relative to `shift` and (in max_log_weight) its
/// largest l. Afterwards every thread holds the team's sums relative to the returned shift in w. Where the
/// team's largest l is more than team_max_shift_gap from `shift` (rare, and the same for the whole team), the
/// team sums again relative to its largest l: resum(shift, w) adds the thread's particles to an empty w.
template <bool FloatExp, int N, class Team, class Scratch, class Resum>
KOKKOS_INLINE_FUNCTION void team_moments_at_shift(const Team& team, const Scratch& buffer, double shift,
                                                  WeightedMoments<N>& w, const Resum& resum) {
  team_sum(team, buffer, w);
  if (!(w.max_log_weight > -math::infinity())) return;  // every particle of the chunk has weight zero
  const double gap = w.max_log_weight - shift;
  constexpr double max_gap = team_max_shift_gap<FloatExp>;
  if (!(gap >= -max_gap && gap <= max_gap)) {
    shift = w.max_log_weight;
    w = WeightedMoments<N>::empty();
    resum(shift, w);
    team_sum(team, buffer, w);
  }
  w.max_log_weight = shift;
}

/// Launches a team kernel's step_chunk(team, member, chunk) over every (member, chunk): a team each.
template <class Kernel>
struct EveryMemberChunk {
  Kernel kernel;
  int chunks_per_member;
  KOKKOS_INLINE_FUNCTION void operator()(const typename Kernel::Team& team) const {
    kernel.step_chunk(team, team.league_rank() / chunks_per_member, team.league_rank() % chunks_per_member);
  }
};

/// ... over the chunks of members(0 .. member_count() - 1) only: a fixed league loops over them (how many
/// members are listed stays on the device). A separate instantiation: the loop costs registers.
template <class Kernel>
struct ListedMemberChunks {
  Kernel kernel;
  Kokkos::View<const int*, typename Kernel::MemSpace> members;
  Kokkos::View<const int, typename Kernel::MemSpace> member_count;
  int chunks_per_member;
  KOKKOS_INLINE_FUNCTION void operator()(const typename Kernel::Team& team) const {
    const int items = member_count() * chunks_per_member;
    for (int item = team.league_rank(); item < items; item += team.league_size())
      kernel.step_chunk(team, members(item / chunks_per_member), item % chunks_per_member);
  }
};

}  // namespace kushner
