#pragma once
// The host's Philox4x32-10: the uniforms of a run of SIMD lanes' blocks (uniform_pair_lanes), the same counters and
// the same 52-bit uniforms as kernels/rng.hpp, bit for bit (tests/test_particle_random.cpp); a GPU takes rng.hpp's
// rounds (philox4x32_10), one 32 x 32 -> 64-bit multiply per product.
//
// On an x86-64 host with AVX2 but not AVX-512DQ, four lanes per 256-bit vector, written with AVX2's intrinsics: each
// round's two 32 x 32 -> 64-bit products are one vpmuludq each. GCC's vectorization of the scalar rounds below
// (philox4x32_10) cannot see that a round's words fit in 32 bits, so after the first round it multiplied full 64-bit
// lanes by the constants, which AVX2 cannot do in one instruction: chains of 12 shifts, adds and subtractions per
// product, 12-18 ns per block and lane against 4 here on the development machine (AMD EPYC, znver3), most of a truth
// step's time. With AVX-512DQ GCC multiplies 64-bit lanes in one instruction (vpmullq, 8 lanes), and the scalar rounds
// serve, as everywhere else and for a run's last lanes.
#include "core/math.hpp"
#include "core/small_matrix.hpp"
#include "kernels/rng.hpp"
#include "kernels/vector_math.hpp"

#include <cstdint>
#include <cstring>

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__CUDACC__) && defined(__AVX2__) && !defined(__AVX512DQ__)
#include <immintrin.h>
#define KUSHNER_PHILOX_AVX2 1
#else
#define KUSHNER_PHILOX_AVX2 0
#endif

// GCC vectorizes a loop only if every loop inside it has been unrolled away: say so for the Philox rounds.
#if defined(__GNUC__) && !defined(__clang__) && !defined(__CUDACC__)
#define KUSHNER_UNROLL_FULLY _Pragma("GCC unroll 16")
#else
#define KUSHNER_UNROLL_FULLY
#endif

namespace kushner::simd {

/// Philox4x32 with 10 rounds (Salmon et al. 2011, SC'11; constants from Random123's philox.h), in a form GCC vectorizes
/// inside `#pragma omp simd` loops: 32-bit words held in 64-bit lanes (Random123's array structs do not vectorize).
KOKKOS_INLINE_FUNCTION void philox4x32_10(std::uint64_t c0, std::uint64_t c1, std::uint64_t c2, std::uint64_t c3,
                                          std::uint64_t k0, std::uint64_t k1, std::uint64_t out[4]) {
  constexpr std::uint64_t mask = 0xffffffffull;
  KUSHNER_UNROLL_FULLY
  for (int round = 0; round < 10; ++round) {
    const std::uint64_t p0 = 0xD2511F53ull * c0, p1 = 0xCD9E8D57ull * c2;
    const std::uint64_t n0 = (p1 >> 32) ^ c1 ^ k0, n2 = (p0 >> 32) ^ c3 ^ k1;
    c1 = p1 & mask;
    c3 = p0 & mask;
    c0 = n0;
    c2 = n2;
    k0 = (k0 + 0x9E3779B9ull) & mask;
    k1 = (k1 + 0xBB67AE85ull) & mask;
  }
  out[0] = c0;
  out[1] = c1;
  out[2] = c2;
  out[3] = c3;
}

/// (k + 1/2) 2^-52 with k the top 52 bits of (hi, lo), as kushner::uniform_open: 1 + k 2^-52 is built from
/// its bit pattern (uint64 -> double conversion has no AVX2 instruction) and 1 - 2^-53 subtracted, which is exact
/// (Sterbenz).
KOKKOS_INLINE_FUNCTION double uniform_open(std::uint64_t hi, std::uint64_t lo) {
  const std::uint64_t bits = ((((hi << 32) | lo) >> 12)) | 0x3FF0000000000000ull;
  double one_plus;
  std::memcpy(&one_plus, &bits, sizeof one_plus);
  return one_plus - (1.0 - 0x1.0p-53);
}

/// kushner::uniform_pair, the same bits. The counter by value: GCC does not vectorize a loop that stores a counter it
/// computes to pass a reference.
KOKKOS_INLINE_FUNCTION void uniform_pair(const RngKey& key, const Counter c, double& u0, double& u1) {
  std::uint64_t r[4];
  philox4x32_10(c.member + key.seed.first_member, c.particle, c.step, c.draw, key.seed.value,
                static_cast<std::uint32_t>(key.stream), r);
  u0 = uniform_open(r[0], r[1]);
  u1 = uniform_open(r[2], r[3]);
}

/// kushner::uniform_pair_fp32, the same floats (uniform_open_fp32 of the block's high words, or with LowWords its low
/// ones). The words chosen at compile time: with a run-time choice GCC's vectorized loops over lanes ran fp32's host
/// particle step at 0.67x (AVX-512 host).
template <bool LowWords = false>
KOKKOS_INLINE_FUNCTION void uniform_pair_fp32(const RngKey& key, const Counter c, float& u0, float& u1) {
  std::uint64_t r[4];
  philox4x32_10(c.member + key.seed.first_member, c.particle, c.step, c.draw, key.seed.value,
                static_cast<std::uint32_t>(key.stream), r);
  u0 = kushner::uniform_open_fp32(static_cast<std::uint32_t>(r[LowWords ? 1 : 0]));
  u1 = kushner::uniform_open_fp32(static_cast<std::uint32_t>(r[LowWords ? 3 : 2]));
}

/// The counters of a run of lanes: lane j's block is first + j stride, field by field, modulo 2^32 (a member's
/// particle pairs one after another, or a chunk's members).
struct LaneCounters {
  Counter first, stride;
  KOKKOS_INLINE_FUNCTION Counter operator()(const int j) const {
    const auto u = static_cast<std::uint32_t>(j);
    return {first.member + u * stride.member, first.particle + u * stride.particle, first.step + u * stride.step,
            first.draw + u * stride.draw};
  }
  /// The lanes from lane j on.
  KOKKOS_INLINE_FUNCTION LaneCounters from(const int j) const { return {(*this)(j), stride}; }
};

#if KUSHNER_PHILOX_AVX2
namespace avx2 {

/// Four lanes' words: word i of lane l in the low half of 64-bit element l of w[i]. The high halves may hold
/// anything: a product takes the low halves only, a sum or xor keeps each half apart, and the results are masked.
struct Words {
  __m256i w[4];
};

/// Philox4x32-10 of four lanes with key (k0, k1): philox4x32_10's operations, in the same order.
__attribute__((always_inline)) inline Words philox4x32_10(Words c, std::uint32_t k0, std::uint32_t k1) {
  const __m256i m0 = _mm256_set1_epi64x(0xD2511F53ll), m1 = _mm256_set1_epi64x(0xCD9E8D57ll);
  KUSHNER_UNROLL_FULLY
  for (int round = 0; round < 10; ++round) {
    const __m256i p0 = _mm256_mul_epu32(c.w[0], m0), p1 = _mm256_mul_epu32(c.w[2], m1);
    const __m256i key0 = _mm256_set1_epi64x(k0), key1 = _mm256_set1_epi64x(k1);
    c.w[0] = _mm256_xor_si256(_mm256_xor_si256(_mm256_srli_epi64(p1, 32), c.w[1]), key0);
    c.w[2] = _mm256_xor_si256(_mm256_xor_si256(_mm256_srli_epi64(p0, 32), c.w[3]), key1);
    c.w[1] = p1;
    c.w[3] = p0;
    k0 += 0x9E3779B9u;
    k1 += 0xBB67AE85u;
  }
  const __m256i low = _mm256_set1_epi64x(0xffffffffll);
  for (__m256i& w : c.w) w = _mm256_and_si256(w, low);
  return c;
}

/// uniform_open of four lanes' (hi, lo), the same bits.
__attribute__((always_inline)) inline __m256d uniform_open(const __m256i hi, const __m256i lo) {
  const __m256i bits = _mm256_or_si256(_mm256_srli_epi64(_mm256_or_si256(_mm256_slli_epi64(hi, 32), lo), 12),
                                       _mm256_set1_epi64x(0x3FF0000000000000ll));
  return _mm256_sub_pd(_mm256_castsi256_pd(bits), _mm256_set1_pd(1.0 - 0x1.0p-53));
}

/// uniform_open_fp32 of four lanes' words, the same floats.
__attribute__((always_inline)) inline __m128 uniform_open_fp32(const __m256i words) {
  const __m128i packed =
      _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(words, _mm256_setr_epi32(0, 2, 4, 6, 0, 2, 4, 6)));
  const __m128i bits = _mm_or_si128(_mm_srli_epi32(packed, 9), _mm_set1_epi32(0x3F800000));
  return _mm_sub_ps(_mm_castsi128_ps(bits), _mm_set1_ps(1.0f - 0x1.0p-24f));
}

/// The words of lanes j .. j + 3 of `c` (member offset by the key's first member).
__attribute__((always_inline)) inline Words lane_counters(const RngKey& key, const LaneCounters& c, const int j) {
  const Counter at = c(j);
  const std::uint32_t first[4] = {at.member + key.seed.first_member, at.particle, at.step, at.draw};
  const std::uint32_t stride[4] = {c.stride.member, c.stride.particle, c.stride.step, c.stride.draw};
  const __m256i lane = _mm256_setr_epi64x(0, 1, 2, 3);
  Words w;
  for (int i = 0; i < 4; ++i)
    w.w[i] = _mm256_add_epi64(_mm256_set1_epi64x(first[i]), _mm256_mul_epu32(lane, _mm256_set1_epi64x(stride[i])));
  return w;
}

/// f(j, words) for lanes j .. j + 3 of [0, lanes), j a multiple of 4, while four are left; returns the first lane
/// not taken. Eight lanes at a time where eight are left: two independent chains of rounds keep the multipliers busy
/// (~10% faster than one).
template <class Store>
__attribute__((always_inline)) inline int for_lane_quads(const RngKey& key, const LaneCounters& c, const int lanes,
                                                         const Store& store) {
  const std::uint32_t k0 = key.seed.value, k1 = static_cast<std::uint32_t>(key.stream);
  int j = 0;
  for (; j + 8 <= lanes; j += 8) {
    const Words a = philox4x32_10(lane_counters(key, c, j), k0, k1);
    const Words b = philox4x32_10(lane_counters(key, c, j + 4), k0, k1);
    store(j, a);
    store(j + 4, b);
  }
  for (; j + 4 <= lanes; j += 4) store(j, philox4x32_10(lane_counters(key, c, j), k0, k1));
  return j;
}

}  // namespace avx2
#endif

/// uniform_pair of lane j's block c(j) into u0[j], u1[j], for j in [0, lanes).
inline void uniform_pair_lanes(const RngKey& key, const LaneCounters& c, const int lanes, double* const u0,
                               double* const u1) {
  int j = 0;
#if KUSHNER_PHILOX_AVX2
  j = avx2::for_lane_quads(key, c, lanes, [u0, u1](const int at, const avx2::Words& r) {
    _mm256_storeu_pd(u0 + at, avx2::uniform_open(r.w[0], r.w[1]));
    _mm256_storeu_pd(u1 + at, avx2::uniform_open(r.w[2], r.w[3]));
  });
#endif
  KUSHNER_SIMD
  for (int i = j; i < lanes; ++i) simd::uniform_pair(key, c(i), u0[i], u1[i]);
}

/// uniform_pair_fp32<LowWords> of lane j's block c(j) into u0[j], u1[j], for j in [0, lanes).
template <bool LowWords = false>
inline void uniform_pair_fp32_lanes(const RngKey& key, const LaneCounters& c, const int lanes, float* const u0,
                                    float* const u1) {
  int j = 0;
#if KUSHNER_PHILOX_AVX2
  j = avx2::for_lane_quads(key, c, lanes, [u0, u1](const int at, const avx2::Words& r) {
    _mm_storeu_ps(u0 + at, avx2::uniform_open_fp32(r.w[LowWords ? 1 : 0]));
    _mm_storeu_ps(u1 + at, avx2::uniform_open_fp32(r.w[LowWords ? 3 : 2]));
  });
#endif
  KUSHNER_SIMD
  for (int i = j; i < lanes; ++i) simd::uniform_pair_fp32<LowWords>(key, c(i), u0[i], u1[i]);
}

}  // namespace kushner::simd
