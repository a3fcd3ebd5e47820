#pragma once
// The GPU's particle step: a team per (chunk, member) propagates and weights its particles (update_particle)
// and reduces them to the chunk's WeightedMoments in d.partials (particle_team_chunk.hpp has the batches and
// the shifted sums). Also runs on host spaces, where the tests compare it with the host's block kernel.
#include "kernels/particle_filter/particle_team_chunk.hpp"

#include <Kokkos_Core.hpp>

#include <type_traits>

namespace kushner {

/// Mixed: the `mixed` precision's kernel for a model with float increments (has_float_increments): its normals,
/// Euler-Maruyama increments and weights' exps in float, compiled apart so that fp64's kernel carries none of it.
template <class Model, class ExecSpace, class Real = double, bool Mixed = false>
struct ParticleTeamStep {
  using MemSpace = typename ExecSpace::memory_space;
  using Team = typename Kokkos::TeamPolicy<ExecSpace>::member_type;
  using Scratch = Kokkos::View<double*, typename ExecSpace::scratch_memory_space, Kokkos::MemoryUnmanaged>;
  static constexpr int n = Model::state_dim, p = Model::obs_dim;
  static_assert(!Mixed || has_mixed_increments<Model, Real>, "mixed's own kernel");
  static constexpr bool float_exp = std::is_same_v<Real, float> || Mixed;  // add_shifted_particle
  // V^-1 and V^-1 dy are rounded to it once, not for every particle; fp32's float steps hold their particles in it.
  using S = particle_step_scalar<Model, Real>;
  ParticleStepData<Model, MemSpace, Real> d;

  static std::size_t scratch_bytes(int team_size) { return team_sum_scratch_bytes<n>(team_size); }

  /// Known at compile time in fp32's and mixed's own kernels; a run-time flag in fp64's, which also run mixed for a
  /// model without float increments (its normals alone in float).
  KOKKOS_INLINE_FUNCTION bool float_normals() const { return Mixed || d.float_normals(); }

  KOKKOS_INLINE_FUNCTION void step_chunk(const Team& team, int member, int chunk) const {
    const ParticleChunk c = particle_chunk(team, chunk, d.block_size, d.num_particles);
    const Scratch buffer(team.team_scratch(0), WeightedMoments<n>::size * (c.threads + 1));
    WeightedMoments<n> w = WeightedMoments<n>::empty();  // sums relative to `shift`; max_log_weight: largest l
    double shift = 0.0;
    Vec<n> ref = Vec<n>::zero();
    if (d.status(member) == Status::ok) {
      ref = load<n>(d.reference, member);
      if (d.initialize) {
        step_particles<true>(member, c, ref, Vec<p>::zero(), shift, w);
      } else {
        const Vec<p> dy = load<p>(d.dy, member);
        const Vec<p> vinv_dy = d.observation_precision.value * dy;
        shift = team_shift<S>(log_weight_bound(d.model, dy, vinv_dy, d.dt));
        step_particles<false>(member, c, ref, vinv_dy, shift, w);
      }
    }
    team_moments_at_shift<float_exp>(team, buffer, shift, w, [&](double s, WeightedMoments<n>& v) {
      for (int j = c.begin + c.rank; j < c.end; j += c.threads)
        add_shifted_particle<float_exp>(d.log_weight(j, member) - s, load_particle<n>(d.x, j, member) - ref, v);
    });
    if (c.rank == 0) w.store(d.partials, chunk, member);
  }

 private:
  /// The thread's pairs of the chunk, device_pairs_per_batch at a time: a batch's loads are issued first and
  /// its draws computed next (they need no memory), so the draws run while the loads are in flight.
  template <bool Initialize>
  KOKKOS_INLINE_FUNCTION void step_particles(int member, const ParticleChunk& c, const Vec<n>& ref,
                                             const Vec<p>& vinv_dy, double shift, WeightedMoments<n>& w) const {
    constexpr int B = 2 * device_pairs_per_batch;  // particles per batch
    constexpr int K = particle_draw_dim<Model, Initialize>;
    const double log_normalizer = Initialize ? 0.0 : d.log_normalizer(member);
    S top = static_cast<S>(-math::infinity());
    // The member's columns as pointers: one 64-bit address computation per thread, not per access.
    Real* const xm = &d.x(0, member, 0);
    Real* const lwm = &d.log_weight(0, member);
    const std::size_t stride = d.x.stride_2();  // LayoutLeft: x(j, member, i) = xm[j + i * stride]
    const RngKey key = particle_draw_key<Initialize>(d);
    const std::uint32_t step = particle_draw_step<Initialize>(d);
    const typename Model::Control control = particle_control(d, member);
    const Mat<p, p, S>& precision = d.observation_precision.template as<S>();
    const Vec<p, S> vinv_dy_s = convert<S>(vinv_dy);
    const S shift_s = static_cast<S>(shift);  // team_shift<S>: exact
    const bool paired = moves_whole_pairs(d.num_particles, stride, xm, lwm, xm, lwm);
    for_each_particle_batch<n, Initialize, S>(c, xm, lwm, stride, paired, [&](int base, Vec<n, S>* x, S* lw) {
      // x and lw in S: fp32's float steps hold their particles in float
      Vec<K> z[B];
      double u[B];
      draw_particle_batch<Model, Initialize, fp32_step_draws<Real, Initialize>>(key, member, base, c.threads, step,
                                                                                float_normals(), z, u);
      KUSHNER_DEVICE_UNROLL
      for (int k = 0; k < B; ++k) {
        const int j = batch_particle(base, k, c.threads);
        const bool live = j < c.end;  // else stepped from zeros and dropped (for_each_particle_batch)
        S l = update_particle<Initialize, Mixed>(d, d.t, precision, z[k], u[k], lw[k], log_normalizer, vinv_dy_s,
                                                 control, x[k]);
        if (!live) l = static_cast<S>(-math::infinity());
        lw[k] = l;
        top = l > top ? l : top;
        add_shifted_particle<float_exp>(l - shift_s, convert<double>(x[k]) - ref, w);
      }
      store_particle_batch<n>(xm, lwm, stride, base, c.threads, c.end, paired, x, lw);
    });
    w.max_log_weight = top;
  }
};

}  // namespace kushner
