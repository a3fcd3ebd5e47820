#pragma once
// The particle filter's random draws. Particles 2k and 2k + 1 of a member share Philox blocks: block
// {member, k, step, i} gives component i of both particles' normals by Box-Muller (the cosine normal to the
// even particle, the sine normal to the odd one), and a model with an exact transition sampler takes block
// i = K (after the K normals) for one uniform each. So one Philox block, one log and one square root serve two
// particles: the GPU step is bound by instruction issue, and Box-Muller with one normal per block was a
// quarter of it (perf/particle_filter.md). A GPU thread draws its pair's blocks with rng.hpp's Philox
// (pair_normals); the host draws a block's or a chunk's lanes at once with the host's Philox
// (simd::uniform_pair_lanes, the same uniforms bit for bit: tests/test_particle_random.cpp) and then runs
// Box-Muller over them in SIMD loops (draw_block_lanes, draw_pair_lanes). With `Fp32` (the `mixed` precision) the
// normals come from the same blocks by the float Box-Muller (kernels/rng.hpp); the uniforms of exact transition
// samplers stay fp64. The `fp32` precision's steps take a block's four words as four float uniforms, so that two
// steps share a block (fp32_pair_normals). The truths' and the EnKBF's host draws are here too.
#include "kernels/particle_filter/simd_random.hpp"
#include "kernels/rng.hpp"
#include "kernels/vector_math.hpp"

#include <cstdint>
#include <type_traits>

namespace kushner {

/// The pieces in which the host's draw loops take their lanes' uniforms: their buffers stay on the stack.
constexpr int host_draw_piece = 64;

/// Host: the normal pair of each of `lanes` lanes' blocks (lane j's block counters(j), simd::LaneCounters): the
/// uniforms of all of them first (simd::uniform_pair_lanes, into z0s and z1s), then Box-Muller in a SIMD loop of its
/// own, with no model code in it, so that it vectorizes whatever the caller's step does: the draws are the same bits
/// for every model, whether or not its step vectorizes (a model file's polynomial and the built-in model it equals
/// give the same numbers). Lane j's z0 at z0s[j], its z1 at z1s[j]. The truths' draws
/// (EulerMaruyamaTruthStep::draw_lanes) and draw_normal_lanes use it.
KUSHNER_FLATTEN inline void draw_block_lanes(const RngKey& key, const simd::LaneCounters& counters, const int lanes,
                                             double* const z0s, double* const z1s) {
  simd::uniform_pair_lanes(key, counters, lanes, z0s, z1s);
  KUSHNER_SIMD
  for (int j = 0; j < lanes; ++j) {
    const NormalPair pair = box_muller(z0s[j], z1s[j]);
    z0s[j] = pair.z0;
    z1s[j] = pair.z1;
  }
}

/// Host: N normals for each of `lanes` lanes, normal i of lane j at z[i * stride + j] from block i / 2 of lane j,
/// whose counter is counters(j) with i / 2 added to its draw (so normal_vector's numbers where counters(j) is lane j's
/// {member, particle, step, 0}; the EnKBF's ensemble members draw so), by draw_block_lanes. With N odd the last block's
/// second normal is not wanted, and its sine is not computed.
template <int N>
KUSHNER_FLATTEN void draw_normal_lanes(const RngKey& key, const simd::LaneCounters& counters, const int lanes,
                                       double* const z, const int stride) {
  for (int i = 0; i + 1 < N; i += 2) {
    simd::LaneCounters block = counters;
    block.first.draw += static_cast<std::uint32_t>(i / 2);
    draw_block_lanes(key, block, lanes, z + i * stride, z + (i + 1) * stride);
  }
  if constexpr (N % 2 == 1) {
    simd::LaneCounters block = counters;
    block.first.draw += static_cast<std::uint32_t>(N / 2);
    double* const last = z + (N - 1) * stride;
    for (int first = 0; first < lanes; first += host_draw_piece) {
      const int count = lanes - first < host_draw_piece ? lanes - first : host_draw_piece;
      double u1[host_draw_piece];
      simd::uniform_pair_lanes(key, block.from(first), count, last + first, u1);
      KUSHNER_SIMD
      for (int j = 0; j < count; ++j) last[first + j] = box_muller_cosine_host(last[first + j], u1[j]);
    }
  }
}

/// Component i of the normals of particles 2 pair (z0) and 2 pair + 1 (z1) of `member` at `step`; in float
/// with Fp32.
template <bool Fp32 = false>
KOKKOS_INLINE_FUNCTION NormalPair pair_normals(const RngKey& key, int member, int pair, std::uint32_t step, int i) {
  const Counter c{std::uint32_t(member), std::uint32_t(pair), step, std::uint32_t(i)};
  if constexpr (Fp32) {
    float u0, u1;
    uniform_pair_fp32(key, c, u0, u1);
    return box_muller_fp32(u0, u1);
  } else {
    double u0, u1;
    uniform_pair(key, c, u0, u1);
    return box_muller(u0, u1);
  }
}

/// The `fp32` precision's step normals, component i of particles 2 pair (z0) and 2 pair + 1 (z1) at `step`: steps 2m
/// and 2m + 1 share block {member, pair, 2m, i}, whose four words are four float uniforms (uniform_open_fp32 takes 23
/// bits of a word). Step 2m takes words 0 and 2 (mixed's normals of that block), step 2m + 1 words 1 and 3. Half of
/// mixed's Philox blocks per particle-step: on a GPU a block's rounds were 43 of the 368 SASS instructions of fp32's
/// fused pair loop (two particles, two steps), x1.08 on an H100 (perf/particle_filter.md). fp32's initial particles
/// are mixed's (pair_normals<true>).
KOKKOS_INLINE_FUNCTION Counter step_pair_block(int member, int pair, std::uint32_t step, int i) {
  return {std::uint32_t(member), std::uint32_t(pair), step & ~1u, std::uint32_t(i)};
}
KOKKOS_INLINE_FUNCTION NormalPair fp32_pair_normals(const RngKey& key, int member, int pair, std::uint32_t step,
                                                    int i) {
  float u0, u1;
  uniform_pair_fp32(key, step_pair_block(member, pair, step, i), u0, u1, (step & 1u) != 0);
  return box_muller_fp32(u0, u1);
}

/// fp32_pair_normals at `step` (first) and step + 1 (second): one block where `step` is even, two where it is odd.
KOKKOS_INLINE_FUNCTION void fp32_pair_normals_two_steps(const RngKey& key, int member, int pair, std::uint32_t step,
                                                        int i, NormalPair& first, NormalPair& second) {
  const r123array4x32 a = philox_block(key, step_pair_block(member, pair, step, i));
  std::uint32_t w0 = a.v[0], w1 = a.v[2], w2 = a.v[1], w3 = a.v[3];
  if ((step & 1u) != 0) {  // the same for every particle of a pass: no divergence
    const r123array4x32 b = philox_block(key, step_pair_block(member, pair, step + 1, i));
    w0 = a.v[1], w1 = a.v[3], w2 = b.v[0], w3 = b.v[2];
  }
  first = box_muller_fp32(uniform_open_fp32(w0), uniform_open_fp32(w1));
  second = box_muller_fp32(uniform_open_fp32(w2), uniform_open_fp32(w3));
}

/// The uniforms of particles 2 pair (u0) and 2 pair + 1 (u1) whose draws also hold K normals each.
KOKKOS_INLINE_FUNCTION void pair_uniforms(const RngKey& key, int member, int pair, std::uint32_t step, int K,
                                          double& u0, double& u1) {
  uniform_pair(key, Counter{std::uint32_t(member), std::uint32_t(pair), step, std::uint32_t(K)}, u0, u1);
}

/// Host: the counters of `member`'s particle pairs from first_pair on at `step`, block i (pair_normals' and, with i =
/// K, pair_uniforms' blocks) as lanes.
inline simd::LaneCounters particle_pair_lanes(int member, int first_pair, std::uint32_t step, int i) {
  return {Counter{std::uint32_t(member), std::uint32_t(first_pair), step, std::uint32_t(i)}, Counter{0, 1, 0, 0}};
}

/// box_muller, or box_muller_fp32 of float uniforms.
KOKKOS_INLINE_FUNCTION NormalPair box_muller_of(const double u0, const double u1) { return box_muller(u0, u1); }
KOKKOS_INLINE_FUNCTION NormalPair box_muller_of(const float u0, const float u1) { return box_muller_fp32(u0, u1); }

/// Host: the normals of `pairs` particle pairs from lanes' blocks (particle_pair_lanes), z0 of pair k to z[2 k] and
/// z1 to z[2 k + 1]; in float with Fp32 (pair_normals' numbers, in pieces of host_draw_piece pairs), from the blocks'
/// low words with LowWords.
template <bool Fp32, bool LowWords = false>
KUSHNER_FLATTEN void draw_pair_lanes(const RngKey& key, const simd::LaneCounters& pairs_at, const int pairs,
                                     double* const z) {
  static_assert(Fp32 || !LowWords, "fp64's uniforms take all four words");
  using Uniform = std::conditional_t<Fp32, float, double>;
  for (int first = 0; first < pairs; first += host_draw_piece) {
    const int count = pairs - first < host_draw_piece ? pairs - first : host_draw_piece;
    Uniform u0[host_draw_piece], u1[host_draw_piece];
    if constexpr (Fp32)
      simd::uniform_pair_fp32_lanes<LowWords>(key, pairs_at.from(first), count, u0, u1);
    else
      simd::uniform_pair_lanes(key, pairs_at.from(first), count, u0, u1);
    double* const out = z + 2 * first;
    KUSHNER_SIMD
    for (int k = 0; k < count; ++k) {
      const NormalPair pair = box_muller_of(u0[k], u1[k]);
      out[2 * k] = pair.z0;
      out[2 * k + 1] = pair.z1;
    }
  }
}

/// Host: fp32_pair_normals of `pairs` particle pairs of `member` from first_pair on, component i, into z as
/// draw_pair_lanes.
inline void draw_fp32_pair_lanes(const RngKey& key, int member, int first_pair, int pairs, std::uint32_t step, int i,
                                 double* const z) {
  const simd::LaneCounters lanes = particle_pair_lanes(member, first_pair, step & ~1u, i);
  if ((step & 1u) != 0)
    draw_pair_lanes<true, true>(key, lanes, pairs, z);
  else
    draw_pair_lanes<true>(key, lanes, pairs, z);
}

/// Host: member_pair_normal(key, lane, step, draw) for each lane (local member) of [begin, end) into z[lane - begin]:
/// one normal pair per member pair (draw_pair_lanes over the pairs' blocks). Where end - begin is odd the last pair's
/// z1 goes to z[end - begin], which z must hold. A host chunk starts at a multiple of host_member_chunk and an MPI
/// share at a multiple of moment_block_size (engine/member_share.hpp), so begin's global member is even and the pairs
/// are whole; were it odd, its normal would be drawn alone first (the same number, possibly not the same last bit
/// where the host's log is glibc's: its scalar one against its vector one).
KUSHNER_FLATTEN inline void draw_member_pair_normal_lanes(int begin, const int end, const RngKey& key,
                                                          const std::uint32_t step, const std::uint32_t draw,
                                                          double* z) {
  if (begin < end && ((static_cast<std::uint32_t>(begin) + key.seed.first_member) & 1u) != 0) {
    *z++ = member_pair_normal(key, static_cast<std::uint32_t>(begin), step, draw);
    ++begin;
  }
  const Counter first_pair{static_cast<std::uint32_t>(begin), 0, step, draw};
  draw_pair_lanes<false>(key, {first_pair, Counter{2, 0, 0, 0}}, (end - begin + 1) / 2, z);
}

}  // namespace kushner
