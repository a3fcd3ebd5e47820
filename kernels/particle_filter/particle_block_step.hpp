#pragma once
// The host's particle step: propagate + weight + moments for a block of host_particle_block particles of one
// member, with `#pragma omp simd` loops over particle-contiguous arrays (GCC does not vectorize a Kokkos range
// loop). Each (block, member) is a work item of a range loop; the block's WeightedMoments go to d.partials.
#include "kernels/for_each_member.hpp"
#include "kernels/particle_filter/particle_update.hpp"
#include "kernels/particle_filter/tuning.hpp"
#include "kernels/vector_math.hpp"

#include <Kokkos_Core.hpp>

#include <cstdint>
#include <type_traits>

namespace kushner {

/// The normals of `pairs` particle pairs from first_pair on, component i in z[i][particle]; in float with Fp32, and
/// fp32_pair_normals with Fp32Steps.
template <bool Fp32, bool Fp32Steps, int K>
inline void draw_block_normals(const RngKey& key, int member, int first_pair, int pairs, std::uint32_t step,
                               double (&z)[K][host_particle_block]) {
  for (int i = 0; i < K; ++i) {
    if constexpr (Fp32Steps)
      draw_fp32_pair_lanes(key, member, first_pair, pairs, step, i, z[i]);
    else
      draw_pair_lanes<Fp32>(key, particle_pair_lanes(member, first_pair, step, i), pairs, z[i]);
  }
}

/// The host kernel's work for one block: a function of the model and the data only (not of the execution
/// space), so Serial and OpenMP run the same machine code and give the same bits (kernels/for_each_member.hpp).
template <bool Initialize, bool FloatIncrements, class Model, class Real>
KUSHNER_SAME_CODE_FOR_ALL_CALLERS void particle_block_host(const ParticleStepData<Model, Kokkos::HostSpace, Real>& d,
                                                           int member, int block) {
  constexpr int n = Model::state_dim;
  constexpr int B = host_particle_block;
  const int begin = block * B;
  const int count = d.num_particles - begin < B ? d.num_particles - begin : B;
  // The particle loop runs on doubles: float storage (fp32) is widened into block buffers first and narrowed back
  // after it, in loops of their own. Mixing the widths in one SIMD loop made GCC pick 16 float lanes, for which
  // libmvec has no double sin or exp, so it called the scalar ones (4x slower).
  constexpr bool widen = !std::is_same_v<Real, double>;
  double widened_x[widen ? n : 1][widen ? B : 1], widened_lw[widen ? B : 1];
  double* xs[n];
  double* lw;
  if constexpr (widen) {
    for (int i = 0; i < n; ++i) {
      const Real* column = &d.x(begin, member, i);
      KUSHNER_SIMD
      for (int j = 0; j < count; ++j) widened_x[i][j] = column[j];
      xs[i] = widened_x[i];
    }
    const Real* column = &d.log_weight(begin, member);
    KUSHNER_SIMD
    for (int j = 0; j < count; ++j) widened_lw[j] = column[j];
    lw = widened_lw;
  } else {
    for (int i = 0; i < n; ++i) xs[i] = &d.x(begin, member, i);
    lw = &d.log_weight(begin, member);
  }
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
  if constexpr (fp32_step_draws<Real, Initialize>)
    draw_block_normals<true, true, K>(key, member, first_pair, pairs, step, z);
  else if (d.float_normals())
    draw_block_normals<true, false, K>(key, member, first_pair, pairs, step, z);
  else
    draw_block_normals<false, false, K>(key, member, first_pair, pairs, step, z);
  if constexpr (draws_uniform<Model, Initialize>) {
    double u0[B / 2], u1[B / 2];
    simd::uniform_pair_lanes(key, particle_pair_lanes(member, first_pair, step, K), pairs, u0, u1);
    KUSHNER_SIMD
    for (int k = 0; k < pairs; ++k) {
      u[2 * k] = u0[k];
      u[2 * k + 1] = u1[k];
    }
  }
  const typename Model::Control control = particle_control(d, member);
  KUSHNER_SIMD
  for (int j = 0; j < count; ++j) {
    Vec<n> xj;
    Vec<K> zj;
    KUSHNER_UNROLL_FULLY
    for (int i = 0; i < n; ++i) xj[i] = xs[i][j];
    KUSHNER_UNROLL_FULLY
    for (int i = 0; i < K; ++i) zj[i] = z[i][j];
    const double uj = draws_uniform<Model, Initialize> ? u[j] : 0.0;
    const double lj = detail::update_particle_unrounded<Initialize, FloatIncrements>(
        d, d.t, d.observation_precision.value, zj, uj, lw[j], log_normalizer, vinv_dy, control, xj);
    KUSHNER_UNROLL_FULLY
    for (int i = 0; i < n; ++i) xs[i][j] = xj[i];
    lw[j] = lj;
    l[j] = lj;
  }
  if constexpr (widen) {   // rounded as stored (round_to_storage's rule), in simple loops of their own (vectorized)
    double not_finite[B];  // NaN where a rounded coordinate is not finite (r - r), else 0
    KUSHNER_SIMD
    for (int j = 0; j < count; ++j) not_finite[j] = 0.0;
    for (int i = 0; i < n; ++i) {
      KUSHNER_SIMD
      for (int j = 0; j < count; ++j) {
        const double r = stored_value<Real>(xs[i][j]);
        xs[i][j] = r;
        not_finite[j] += r - r;
      }
    }
    KUSHNER_SIMD
    for (int j = 0; j < count; ++j) {
      // -inf added where a coordinate is not finite: a select of constants, which GCC vectorizes (l is finite or
      // -inf, so the sum is l or -inf)
      const double dead = not_finite[j] == 0.0 ? 0.0 : -math::infinity();
      l[j] = lw[j] = stored_value<Real>(l[j]) + dead;
    }
  }
  double m = -math::infinity();
  KUSHNER_SIMD_REDUCTION(max : m)
  for (int j = 0; j < count; ++j) m = l[j] > m ? l[j] : m;

  WeightedMoments<n> w = WeightedMoments<n>::empty();
  if (m > -math::infinity()) {
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
  if constexpr (widen) {  // the values are already rounded to float (above): exact
    for (int i = 0; i < n; ++i) {
      Real* column = &d.x(begin, member, i);
      KUSHNER_SIMD
      for (int j = 0; j < count; ++j) column[j] = static_cast<Real>(xs[i][j]);
    }
    Real* column = &d.log_weight(begin, member);
    KUSHNER_SIMD
    for (int j = 0; j < count; ++j) column[j] = static_cast<Real>(lw[j]);
  }
}

/// Host kernel: one work item per (block, member).
template <class Model, class Real = double>
struct ParticleBlockStep {
  ParticleStepData<Model, Kokkos::HostSpace, Real> d;
  int blocks_per_member;
  void operator()(const int item) const {
    const int member = item / blocks_per_member, block = item % blocks_per_member;
    if (d.status(member) != Status::ok) {
      WeightedMoments<Model::state_dim>::empty().store(d.partials, block, member);
      return;
    }
    if (d.initialize) {
      particle_block_host<true, false>(d, member, block);
      return;
    }
    if constexpr (has_mixed_increments<Model, Real>) {  // `mixed`: a loop of its own
      if (d.float_increments()) {
        particle_block_host<false, true>(d, member, block);
        return;
      }
    }
    particle_block_host<false, false>(d, member, block);
  }
};

}  // namespace kushner
