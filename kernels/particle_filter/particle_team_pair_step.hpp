#pragma once
// Two particle steps (k and k + 1) fused into one pass of the GPU's team kernel: the particles stay in
// registers between the steps, so a particle-step moves half the bytes (the step is bound by the GPU's power
// limit, of which memory traffic is a large part). The pass reads d.x and d.log_weight and writes next.x and
// next.log_weight, so its first step can be redone from untouched inputs. Step k + 1's log-weights are left
// normalized by step k - 1's normalizer (step k's is not known yet): its shift is the sum of both steps'
// bounds, and both steps' moments are taken relative to the same reference point.
// ParticleFilterBank::step_pair redoes the members that step k resamples.
#include "kernels/particle_filter/particle_team_chunk.hpp"

#include <Kokkos_Core.hpp>

#include <type_traits>

namespace kushner {

/// Mixed: the `mixed` precision's kernel for a model with float increments (has_float_increments): its normals,
/// Euler-Maruyama increments and weights' exps in float, compiled apart so that fp64's kernel carries none of it.
template <class Model, class ExecSpace, class Real = double, bool Mixed = false>
struct ParticleTeamPairStep {
  using MemSpace = typename ExecSpace::memory_space;
  using Team = typename Kokkos::TeamPolicy<ExecSpace>::member_type;
  using Scratch = Kokkos::View<double*, typename ExecSpace::scratch_memory_space, Kokkos::MemoryUnmanaged>;
  static constexpr int n = Model::state_dim, p = Model::obs_dim;
  static_assert(!Mixed || has_mixed_increments<Model, Real>, "mixed's own kernel");
  static constexpr bool float_exp = std::is_same_v<Real, float> || Mixed;  // add_shifted_particle
  static constexpr bool fp32_steps = fp32_step_draws<Real, false>;
  ParticleStepData<Model, MemSpace, Real> d;       // step k: its inputs, increments and partials
  ParticleSecondStep<Model, MemSpace, Real> next;  // step k + 1: its outputs, increments and partials
  // No control: a closed loop's second control depends on the first step's posterior (step_pair refuses one).
  KOKKOS_INLINE_FUNCTION static typename Model::Control uncontrolled() { return Model::Control::zero(); }

  static std::size_t scratch_bytes(int team_size) { return team_sum_scratch_bytes<n>(team_size); }

  /// Known at compile time in fp32's and mixed's own kernels; a run-time flag in fp64's, which also run mixed for a
  /// model without float increments (its normals alone in float).
  KOKKOS_INLINE_FUNCTION bool float_normals() const { return Mixed || d.float_normals(); }

  KOKKOS_INLINE_FUNCTION void step_chunk(const Team& team, int member, int chunk) const {
    const ParticleChunk c = particle_chunk(team, chunk, d.block_size, d.num_particles);
    const Scratch buffer(team.team_scratch(0), WeightedMoments<n>::size * (c.threads + 1));
    WeightedMoments<n> w[2] = {WeightedMoments<n>::empty(), WeightedMoments<n>::empty()};
    double shift[2] = {0.0, 0.0};
    Vec<p> vinv_dy[2] = {Vec<p>::zero(), Vec<p>::zero()};
    Vec<n> ref = Vec<n>::zero();
    if (d.status(member) == Status::ok) {
      ref = load<n>(d.reference, member);
      double bound = 0.0;
      KUSHNER_DEVICE_UNROLL
      for (int s = 0; s < 2; ++s) {
        const Vec<p> dy = load<p>(s == 0 ? d.dy : next.dy, member);
        vinv_dy[s] = precision<double>(s) * dy;
        bound += log_weight_bound(d.model, dy, vinv_dy[s], d.dt);
        shift[s] = team_shift<S>(bound);
      }
      step_particles(member, c, ref, vinv_dy, shift, w);
    }
    // Step k's resum recomputes it from the pass's inputs; step k + 1's reads the values just stored.
    team_moments_at_shift<float_exp>(team, buffer, shift[0], w[0], [&](double s, WeightedMoments<n>& v) {
      resum_first_step(member, c, ref, vinv_dy[0], s, v);
    });
    if (c.rank == 0) w[0].store(d.partials, chunk, member);
    team_moments_at_shift<float_exp>(team, buffer, shift[1], w[1], [&](double s, WeightedMoments<n>& v) {
      for (int j = c.begin + c.rank; j < c.end; j += c.threads)
        add_shifted_particle<float_exp>(next.log_weight(j, member) - s, load_particle<n>(next.x, j, member) - ref, v);
    });
    if (c.rank == 0) w[1].store(next.partials, chunk, member);
  }

 private:
  // V^-1 and V^-1 dy are rounded to it once, not for every particle; fp32's float steps hold their particles in it.
  using S = particle_step_scalar<Model, Real>;

  /// Step s of the pass: its start time and V^{-1} there.
  KOKKOS_INLINE_FUNCTION double step_time(int s) const { return s == 0 ? d.t : next.t; }
  template <class T>
  KOKKOS_INLINE_FUNCTION const Mat<p, p, T>& precision(int s) const {
    return (s == 0 ? d.observation_precision : next.observation_precision).template as<T>();
  }

  /// As ParticleTeamStep::step_particles, for both steps: a batch is loaded once, stepped twice, stored once.
  KOKKOS_INLINE_FUNCTION void step_particles(int member, const ParticleChunk& c, const Vec<n>& ref,
                                             const Vec<p>* vinv_dy, const double* shift, WeightedMoments<n>* w) const {
    constexpr int B = 2 * device_pairs_per_batch;
    constexpr int K = particle_draw_dim<Model, false>;
    const double log_normalizer = d.log_normalizer(member);
    S top[2] = {static_cast<S>(-math::infinity()), static_cast<S>(-math::infinity())};
    const Real* const xm = held_in_registers(&d.x(0, member, 0));
    const Real* const lwm = held_in_registers(&d.log_weight(0, member));
    Real* const xo = held_in_registers(&next.x(0, member, 0));
    Real* const lwo = held_in_registers(&next.log_weight(0, member));
    const std::size_t stride = d.x.stride_2();  // the same for next.x
    const RngKey key = particle_draw_key<false>(d);
    const Vec<p, S> vinv_dy_s[2] = {convert<S>(vinv_dy[0]), convert<S>(vinv_dy[1])};
    const S shift_s[2] = {static_cast<S>(shift[0]), static_cast<S>(shift[1])};  // team_shift<S>: exact
    const bool paired = moves_whole_pairs(d.num_particles, stride, xm, lwm, xo, lwo);
    for_each_particle_batch<n, false, S>(c, xm, lwm, stride, paired, [&](int base, Vec<n, S>* x, S* lw) {
      // x and lw in S: fp32's float steps hold their particles in float
      Vec<K> z[2][B];  // fp32 draws both steps' at once (one block for both where d.step is even), others a step's
      double u[2][B];
      KUSHNER_DEVICE_UNROLL
      for (int s = 0; s < 2; ++s) {
        if constexpr (fp32_steps) {
          if (s == 0) draw_fp32_batch_two_steps<Model>(key, member, base, c.threads, d.step, z, u);
        } else {
          draw_particle_batch<Model, false>(key, member, base, c.threads, d.step + s, float_normals(), z[s], u[s]);
        }
        KUSHNER_DEVICE_UNROLL
        for (int k = 0; k < B; ++k) {
          const int j = batch_particle(base, k, c.threads);
          const bool live = j < c.end;  // else stepped from zeros and dropped (for_each_particle_batch)
          S l = update_particle<false, Mixed>(d, step_time(s), precision<S>(s), z[s][k], u[s][k], lw[k],
                                              s == 0 ? log_normalizer : 0.0, vinv_dy_s[s], uncontrolled(), x[k]);
          if (!live) l = static_cast<S>(-math::infinity());
          lw[k] = l;
          top[s] = l > top[s] ? l : top[s];
          add_shifted_particle<float_exp>(l - shift_s[s], convert<double>(x[k]) - ref, w[s]);
        }
        if (s == 1) store_particle_batch<n>(xo, lwo, stride, base, c.threads, c.end, paired, x, lw);
      }
    });
    w[0].max_log_weight = top[0];
    w[1].max_log_weight = top[1];
  }

  /// Step k again for the thread's particles, from the pass's inputs, summed relative to `shift`.
  KOKKOS_INLINE_FUNCTION void resum_first_step(int member, const ParticleChunk& c, const Vec<n>& ref,
                                               const Vec<p>& vinv_dy, double shift, WeightedMoments<n>& w) const {
    constexpr int K = particle_draw_dim<Model, false>;
    const double log_normalizer = d.log_normalizer(member);
    const RngKey key = particle_draw_key<false>(d);
    const Vec<p, S> vinv_dy_s = convert<S>(vinv_dy);
    for (int pair = c.begin / 2 + c.rank; pair < (c.end + 1) / 2; pair += c.threads) {
      Vec<K> z[2];
      double u[2];
      draw_particle_pair<Model, false, fp32_steps>(key, member, pair, d.step, float_normals(), z[0], z[1], u[0], u[1]);
      for (int k = 0; k < 2; ++k) {
        const int j = 2 * pair + k;
        if (j >= c.end) continue;
        Vec<n> x = load_particle<n>(d.x, j, member);
        const double l = update_particle<false, Mixed>(d, d.t, precision<S>(0), z[k], u[k], d.log_weight(j, member),
                                                       log_normalizer, vinv_dy_s, uncontrolled(), x);
        add_shifted_particle<float_exp>(l - shift, x - ref, w);
      }
    }
  }
};

}  // namespace kushner
