#pragma once
// Philox4x32-10 in a form GCC vectorizes inside `#pragma omp simd` loops: 32-bit words held in 64-bit lanes
// (Random123's array structs do not vectorize) and the uniform built from its bit pattern (uint64 -> double
// conversion has no AVX2 instruction). Same counters, same 52-bit uniforms as kernels/rng.hpp, bit for bit
// (tests/test_particle_random.cpp); only the host particle kernel uses it, the GPU keeps Random123's version,
// which uses the hardware's 32-bit multiply-high.
#include "core/math.hpp"
#include "core/small_matrix.hpp"
#include "kernels/rng.hpp"

#include <cstdint>
#include <cstring>

// GCC vectorizes a loop only if every loop inside it has been unrolled away: say so for the Philox rounds.
#if defined(__GNUC__) && !defined(__clang__) && !defined(__CUDACC__)
#define KUSHNER_UNROLL_FULLY _Pragma("GCC unroll 16")
#else
#define KUSHNER_UNROLL_FULLY
#endif

namespace kushner::simd {

/// Philox4x32 with 10 rounds (Salmon et al. 2011, SC'11; constants from Random123's philox.h).
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
/// its bit pattern and 1 - 2^-53 subtracted, which is exact (Sterbenz).
KOKKOS_INLINE_FUNCTION double uniform_open(std::uint64_t hi, std::uint64_t lo) {
  const std::uint64_t bits = ((((hi << 32) | lo) >> 12)) | 0x3FF0000000000000ull;
  double one_plus;
  std::memcpy(&one_plus, &bits, sizeof one_plus);
  return one_plus - (1.0 - 0x1.0p-53);
}

KOKKOS_INLINE_FUNCTION void uniform_pair(const RngKey& key, const Counter& c, double& u0, double& u1) {
  std::uint64_t r[4];
  philox4x32_10(c.member + key.seed.first_member, c.particle, c.step, c.draw, key.seed.value,
                static_cast<std::uint32_t>(key.stream), r);
  u0 = uniform_open(r[0], r[1]);
  u1 = uniform_open(r[2], r[3]);
}

/// kushner::uniform_pair_fp32, the same floats (uniform_open_fp32 of the block's high words).
KOKKOS_INLINE_FUNCTION void uniform_pair_fp32(const RngKey& key, const Counter& c, float& u0, float& u1) {
  std::uint64_t r[4];
  philox4x32_10(c.member + key.seed.first_member, c.particle, c.step, c.draw, key.seed.value,
                static_cast<std::uint32_t>(key.stream), r);
  u0 = kushner::uniform_open_fp32(static_cast<std::uint32_t>(r[0]));
  u1 = kushner::uniform_open_fp32(static_cast<std::uint32_t>(r[2]));
}

}  // namespace kushner::simd
