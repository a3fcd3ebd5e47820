#pragma once
// The particle filter's random draws. Particles 2k and 2k + 1 of a member share Philox blocks: block
// {member, k, step, i} gives component i of both particles' normals by Box-Muller (the cosine normal to the
// even particle, the sine normal to the odd one), and a model with an exact transition sampler takes block
// i = K (after the K normals) for one uniform each. So one Philox block, one log and one square root serve two
// particles: the GPU step is bound by instruction issue, and Box-Muller with one normal per block was a
// quarter of it (perf/particle_filter.md). Random123Draws (GPU) and SimdDraws (the host's SIMD kernel) give
// the same uniforms bit for bit (tests/test_particle_random.cpp). With `Fp32` (the `mixed` precision) the normals
// come from the same blocks by the float Box-Muller (kernels/rng.hpp); the uniforms of exact transition
// samplers stay fp64.
#include "kernels/particle_filter/simd_random.hpp"
#include "kernels/rng.hpp"
#include "kernels/vector_math.hpp"

#include <cstdint>

namespace kushner {

/// Uniforms from Random123's Philox (GPU).
struct Random123Draws {
  KOKKOS_INLINE_FUNCTION static void uniforms(const RngKey& key, const Counter& c, double& u0, double& u1) {
    uniform_pair(key, c, u0, u1);
  }
  KOKKOS_INLINE_FUNCTION static void uniforms_fp32(const RngKey& key, const Counter& c, float& u0, float& u1) {
    uniform_pair_fp32(key, c, u0, u1);
  }
};

/// The same uniforms from the vectorizable Philox (host block kernel).
struct SimdDraws {
  KOKKOS_INLINE_FUNCTION static void uniforms(const RngKey& key, const Counter& c, double& u0, double& u1) {
    simd::uniform_pair(key, c, u0, u1);
  }
  KOKKOS_INLINE_FUNCTION static void uniforms_fp32(const RngKey& key, const Counter& c, float& u0, float& u1) {
    simd::uniform_pair_fp32(key, c, u0, u1);
  }
};

/// Two normals from block c by the vectorizable Philox (SimdDraws) and box_muller: normal_pair's numbers.
KOKKOS_INLINE_FUNCTION NormalPair simd_normal_pair(const RngKey key, const Counter c) {
  double u0, u1;
  SimdDraws::uniforms(key, c, u0, u1);
  return box_muller(u0, u1);
}

/// Host: simd_normal_pair's z0 alone, the same bits, without the sine (box_muller_cosine_host). The counter by value,
/// as there: GCC does not vectorize a loop that stores it to pass a reference.
inline double simd_normal_cosine(const RngKey key, const Counter c) {
  double u0, u1;
  SimdDraws::uniforms(key, c, u0, u1);
  return box_muller_cosine_host(u0, u1);
}

/// Host: block `draw` of counter_of(lane, draw) for each lane of a SIMD loop over [begin, end), by simd_normal_pair
/// (glibc's vector log, sqrt, sin and cos): its z0 at z0s[lane - begin] and its z1 at z1s[lane - begin]. A loop of its
/// own, with no model code in it, so that it vectorizes whatever the caller's step does: the draws are the same bits
/// for every model, whether or not its step vectorizes (a model file's polynomial and the built-in model it equals
/// give the same numbers). The truths' draws (EulerMaruyamaTruthStep::draw_lanes) and draw_normal_lanes use it.
template <class CounterOf>
KUSHNER_FLATTEN void draw_block_lanes(const int begin, const int end, const RngKey& key, const CounterOf& counter_of,
                                      const int draw, double* const z0s, double* const z1s) {
  KUSHNER_SIMD
  for (int lane = begin; lane < end; ++lane) {
    const NormalPair pair = simd_normal_pair(key, counter_of(lane, draw));
    z0s[lane - begin] = pair.z0;
    z1s[lane - begin] = pair.z1;
  }
}

/// Host: N normals for each lane of a SIMD loop over [begin, end), normal i of lane l at z[i * stride + l - begin]
/// from block i / 2 of counter_of(l, i / 2) (so normal_vector's numbers where counter_of gives its counters; the
/// EnKBF's ensemble members draw so), in draw_block_lanes' loops. With N odd the last block's second normal is not
/// wanted, and its sine is not computed.
template <int N, class CounterOf>
KUSHNER_FLATTEN void draw_normal_lanes(const int begin, const int end, const RngKey& key, const CounterOf& counter_of,
                                       double* const z, const int stride) {
  for (int i = 0; i + 1 < N; i += 2)
    draw_block_lanes(begin, end, key, counter_of, i / 2, z + i * stride, z + (i + 1) * stride);
  if constexpr (N % 2 == 1) {
    KUSHNER_SIMD
    for (int lane = begin; lane < end; ++lane)
      z[(N - 1) * stride + lane - begin] = simd_normal_cosine(key, counter_of(lane, N / 2));
  }
}

/// Host: member_pair_normal(key, lane, step, draw) for each lane (local member) of [begin, end) into z[lane - begin]:
/// one simd_normal_pair per member pair, in a SIMD loop over the pairs. Where end - begin is odd the last pair's z1
/// goes to z[end - begin], which z must hold. A host chunk starts at a multiple of host_member_chunk and an MPI share
/// at a multiple of moment_block_size (engine/member_share.hpp), so begin's global member is even and the pairs are
/// whole; were it odd, its normal would be drawn alone first (the same number, possibly not the same last bit:
/// glibc's scalar log against its vector one).
KUSHNER_FLATTEN inline void draw_member_pair_normal_lanes(int begin, const int end, const RngKey& key,
                                                          const std::uint32_t step, const std::uint32_t draw,
                                                          double* z) {
  if (begin < end && ((static_cast<std::uint32_t>(begin) + key.seed.first_member) & 1u) != 0) {
    *z++ = member_pair_normal(key, static_cast<std::uint32_t>(begin), step, draw);
    ++begin;
  }
  const int pairs = (end - begin + 1) / 2;
  KUSHNER_SIMD
  for (int j = 0; j < pairs; ++j) {
    const NormalPair pair = simd_normal_pair(key, Counter{static_cast<std::uint32_t>(begin + 2 * j), 0, step, draw});
    z[2 * j] = pair.z0;
    z[2 * j + 1] = pair.z1;
  }
}

/// Component i of the normals of particles 2 pair (z0) and 2 pair + 1 (z1) of `member` at `step`; in float
/// with Fp32.
template <class Draws, bool Fp32 = false>
KOKKOS_INLINE_FUNCTION NormalPair pair_normals(const RngKey& key, int member, int pair, std::uint32_t step, int i) {
  const Counter c{std::uint32_t(member), std::uint32_t(pair), step, std::uint32_t(i)};
  if constexpr (Fp32) {
    float u0, u1;
    Draws::uniforms_fp32(key, c, u0, u1);
    return box_muller_fp32(u0, u1);
  } else {
    double u0, u1;
    Draws::uniforms(key, c, u0, u1);
    return box_muller(u0, u1);
  }
}

/// The uniforms of particles 2 pair (u0) and 2 pair + 1 (u1) whose draws also hold K normals each.
template <class Draws>
KOKKOS_INLINE_FUNCTION void pair_uniforms(const RngKey& key, int member, int pair, std::uint32_t step, int K,
                                          double& u0, double& u1) {
  Draws::uniforms(key, Counter{std::uint32_t(member), std::uint32_t(pair), step, std::uint32_t(K)}, u0, u1);
}

}  // namespace kushner
