#pragma once
// Counter-based random numbers: Philox4x32-10 (Random123). Every draw is a pure function of
// (seed, stream, member, particle, step, draw), so a run gives the same numbers on any number of threads,
// on CPU or GPU, and in any order of evaluation.
//
//   key     = {seed, stream}                    -- distinct streams are distinct Philox keys: never overlap
//   counter = {member, particle, step, draw}    -- draw counts Philox blocks within one (member, particle, step);
//                                                  member is the global index (Seed::first_member + local)
//
// Normals: each Philox block (4 x 32 bits) gives two 52-bit uniforms u1, u2 in (0, 1), and Box-Muller
// turns them into two independent standard normals sqrt(-2 ln u1) (cos 2 pi u2, sin 2 pi u2). Box-Muller,
// not a rejection method, so every member uses the same number of blocks per step and counters stay aligned.
// The fp32 variant (the particle filter's `mixed` and `fp32` precisions) takes 23-bit uniforms from the same blocks'
// high words (the top bits of the 52-bit ones) and runs Box-Muller in float (on a GPU by its special-function unit):
// the same normals to about 1e-7 on a host and about 1e-6 on a GPU, with the radius cut at sqrt(48 ln 2) = 5.77
// (probability 2^-24 beyond it). The `fp32` precision's steps take the low words too: two steps' normals from one
// block (fp32_pair_normals, kernels/particle_filter/particle_draws.hpp).
// The truths take component i of their N normals from block i / 2 (normal_vector; a continuous-time truth's
// observation and process normals are one vector of the process-noise stream, and where their count is odd two
// neighbouring members share the last one's block: truth_normals);
// the particle filter gives both normals of a block to two particles (kernels/particle_filter/particle_draws.hpp).
#include "core/math.hpp"
#include "core/small_matrix.hpp"

#include <Random123/philox.h>

#include <cstdint>
#include <cstring>

namespace kushner {

/// Streams of random numbers; one Philox key each. Values are part of the file format of results
/// (changing one changes every number a seed gives), so they never change.
enum class Stream : std::uint32_t {
  truth_initial = 1,       // initial states of the truths
  process_noise = 2,       // dw of the truths (and before it a continuous-time truth's dv)
  observation_noise = 3,   // dv of the discrete-time truths' observations
  particle_initial = 4,    // initial particles
  particle_noise = 5,      // dw of the particles
  resampling = 6,          // uniforms of the resampling schemes
  filter_initial = 7,      // randomized filter initial conditions (the EnKBF's initial ensemble)
  filter_noise = 8,        // dw of a randomized filter's members (EnKBF), and before it the stochastic EnKBF's
                           // perturbed observations (observation_and_process_normals)
  filter_observation = 9,  // unused since the stochastic EnKBF's perturbations share filter_noise's blocks
};

/// The run's seed and the global index of this process's first member: a process running members
/// [first_member, first_member + count) of an ensemble split over MPI ranks draws, for its local member i, the
/// numbers of global member first_member + i, so a member's numbers do not depend on how members are split.
struct Seed {
  std::uint32_t value = 0;
  std::uint32_t first_member = 0;
  constexpr Seed() = default;
  // Implicit: a bare seed is a whole ensemble in one process.
  KOKKOS_INLINE_FUNCTION constexpr Seed(std::uint32_t seed) : value(seed) {}  // NOLINT(google-explicit-constructor)
  KOKKOS_INLINE_FUNCTION constexpr Seed(std::uint32_t seed, std::uint32_t first) : value(seed), first_member(first) {}
};

struct RngKey {
  Seed seed;
  Stream stream;
};

struct Counter {
  std::uint32_t member, particle, step, draw;
};

/// The low and high words of the 64-bit product a * M: on a GPU one mul.wide.u32, which ptxas makes one IMAD.WIDE.U32.
template <std::uint32_t M>
KOKKOS_FORCEINLINE_FUNCTION void multiply_wide(const std::uint32_t a, std::uint32_t& lo, std::uint32_t& hi) {
#if KUSHNER_CUDA_DEVICE_PASS
  asm("{\n .reg .u64 t;\n mul.wide.u32 t, %2, %3;\n mov.b64 {%0, %1}, t;\n}" : "=r"(lo), "=r"(hi) : "r"(a), "n"(M));
#else
  const std::uint64_t product = std::uint64_t{M} * a;
  lo = static_cast<std::uint32_t>(product);
  hi = static_cast<std::uint32_t>(product >> 32);
#endif
}

/// Philox4x32-10 (Salmon et al. 2011) as a GPU takes it (philox_block), Random123's philox4x32 bit for bit
/// (tests/test_rng.cpp, every backend; a host runs it in that test alone). Each round's two products are one
/// multiply_wide each. From Random123's uint64 products (its R123_USE_64BIT path, which nvcc takes) LLVM carried the
/// next round's xor and product into 64 bits (xor.b64, mul.lo.s64 of words whose high halves are zero), and ptxas
/// took those in 32-bit pieces; from `__umulhi` and `a * b` it made an IMAD.HI.U32 and an IMAD of half the products.
/// SASS for sm_90 of fp32's fused pair loop (two particles, two steps: two blocks): 403 instructions, 387 by
/// `__umulhi`, 368 now (perf/particle_filter.md).
KOKKOS_INLINE_FUNCTION r123array4x32 philox4x32_10(r123array4x32 c, r123array2x32 k) {
  constexpr std::uint32_t m0 = 0xD2511F53u, m1 = 0xCD9E8D57u;  // Random123's PHILOX_M4x32_0, _1
  constexpr std::uint32_t w0 = 0x9E3779B9u, w1 = 0xBB67AE85u;  // PHILOX_W32_0, _1: the key's bump per round
  KUSHNER_DEVICE_UNROLL
  for (int round = 0; round < 10; ++round) {
    std::uint32_t lo0, hi0, lo1, hi1;
    multiply_wide<m0>(c.v[0], lo0, hi0);
    multiply_wide<m1>(c.v[2], lo1, hi1);
    c = {{hi1 ^ c.v[1] ^ k.v[0], lo1, hi0 ^ c.v[3] ^ k.v[1], lo0}};
    k.v[0] += w0;
    k.v[1] += w1;
  }
  return c;
}

KOKKOS_INLINE_FUNCTION r123array4x32 philox_block(const RngKey& key, const Counter& c) {
  const r123array2x32 k = {{key.seed.value, static_cast<std::uint32_t>(key.stream)}};
  const r123array4x32 ctr = {{c.member + key.seed.first_member, c.particle, c.step, c.draw}};
#if KUSHNER_CUDA_DEVICE_PASS
  return philox4x32_10(ctr, k);
#else
  return philox4x32(ctr, k);  // the host code as before (simd_random.hpp has the vectorized rounds)
#endif
}

/// Uniform in the open interval (0, 1) from two 32-bit words: the top 52 bits, offset by half a step, so
/// that neither 0 (log in Box-Muller) nor 1 can occur: (k + 1/2) 2^-52, k = 0 .. 2^52 - 1.
KOKKOS_INLINE_FUNCTION double uniform_open(std::uint32_t hi, std::uint32_t lo) {
#if KUSHNER_CUDA_DEVICE_PASS
  // The same value from its bit pattern, as simd::uniform_open: 1 + k 2^-52 minus 1 - 2^-53, both exact
  // (Sterbenz). A GPU converts 64-bit integers to double at a quarter of its fp64 rate; this costs 32-bit
  // integer operations and one subtraction.
  return __hiloint2double(static_cast<int>((hi >> 12) | 0x3FF00000u), static_cast<int>((hi << 20) | (lo >> 12))) -
         (1.0 - 0x1.0p-53);
#else
  const std::uint64_t bits = ((static_cast<std::uint64_t>(hi) << 32) | lo) >> 12;
  return (static_cast<double>(bits) + 0.5) * 0x1.0p-52;
#endif
}

/// Uniform in (0, 1) from the top 23 bits of a 32-bit word: (k + 1/2) 2^-23, built as 1 + k 2^-23 from its bit
/// pattern minus 1 - 2^-24, which is exact (Sterbenz), so every backend gets the same float and no integer
/// conversion runs. Its top bits are those of uniform_open(word, any).
KOKKOS_INLINE_FUNCTION float uniform_open_fp32(std::uint32_t word) {
  const std::uint32_t bits = (word >> 9) | 0x3F800000u;
  float one_plus;
  std::memcpy(&one_plus, &bits, sizeof one_plus);
  return one_plus - (1.0f - 0x1.0p-24f);
}

/// Two independent uniforms in (0, 1) from one Philox block.
KOKKOS_INLINE_FUNCTION void uniform_pair(const RngKey& key, const Counter& c, double& u0, double& u1) {
  const r123array4x32 r = philox_block(key, c);
  u0 = uniform_open(r.v[0], r.v[1]);
  u1 = uniform_open(r.v[2], r.v[3]);
}

/// Two independent fp32 uniforms in (0, 1) from one Philox block: uniform_open_fp32 of its high words, words 0 and 2
/// (the `mixed` precision's), or of its low words 1 and 3 with `low_words` (the `fp32` precision's odd steps:
/// fp32_pair_normals); simd::uniform_pair_fp32 gives the same floats.
KOKKOS_INLINE_FUNCTION void uniform_pair_fp32(const RngKey& key, const Counter& c, float& u0, float& u1,
                                              const bool low_words = false) {
  const r123array4x32 r = philox_block(key, c);
  u0 = uniform_open_fp32(low_words ? r.v[1] : r.v[0]);
  u1 = uniform_open_fp32(low_words ? r.v[3] : r.v[2]);
}

struct NormalPair {
  double z0, z1;
};

/// Box-Muller's radius sqrt(-2 ln u0), which both of a pair's normals (and a lone cosine normal) take.
KOKKOS_INLINE_FUNCTION double box_muller_radius(double u0) { return math::sqrt(-2.0 * math::log_of_normal(u0)); }

/// Box-Muller: two independent standard normals sqrt(-2 ln u0) (cos 2 pi u1, sin 2 pi u1) from two uniforms.
/// Returned by value: GCC does not vectorize the host particle kernel when they are written through references.
KOKKOS_INLINE_FUNCTION NormalPair box_muller(double u0, double u1) {
  const double radius = box_muller_radius(u0);
  double c, s;
  math::cos_sin_two_pi(u1, c, s);
  return {radius * c, radius * s};
}

/// Host: box_muller's z0 alone (the same bits), for a draw that needs one normal of its last block: the sine that
/// z1 would take is not computed.
inline double box_muller_cosine_host(double u0, double u1) { return box_muller_radius(u0) * math::cos_two_pi_host(u1); }

/// box_muller in float (the particle filter's `mixed` and `fp32` precisions); the normals are returned as doubles
/// for mixed's fp64 state. On a GPU from the special-function unit: log2, reciprocal square root, sine and cosine
/// (MUFU) in place of CUDA's logf, sqrtf and sincospif, in a particle step bound by instruction issue (fp32's fused
/// pair: 162 -> 138 thread instructions per particle-step, perf/particle_filter.md). By CUDA's bounds (log2: 2^-22
/// absolute on [0.5, 2], 2 ulp elsewhere; rsqrt 2 ulp; sine and cosine 2^-21.41 absolute on [-pi, pi]) a normal of
/// radius r is within about 1.7e-7 / r + 1.2e-6 r of the accurate one (tests/test_rng.cpp checks each draw against
/// twice that): about 1e-6 in the bulk, up to 6e-4 for the radii below 1e-3 that one draw in 2e6 has. Elsewhere
/// libm's (libmvec's in the host's SIMD lanes), to a float's last bits.
KOKKOS_INLINE_FUNCTION NormalPair box_muller_fp32(float u0, float u1) {
#if KUSHNER_CUDA_DEVICE_PASS
  // -2 ln u0 = -2 ln 2 log2 u0. Near u0 = 1 the log2's absolute error can give 0 or a tiny negative value: the floor
  // at the smallest normal float keeps the reciprocal square root finite (and the radius about 0). Both as PTX in
  // their .ftz forms: neither input is ever subnormal (u0 >= 2^-24, the floor), and the forms that __log2f and rsqrtf
  // emit take 7 more instructions for subnormal inputs.
  float log2_u0, inverse_radius;
  asm("lg2.approx.ftz.f32 %0, %1;" : "=f"(log2_u0) : "f"(u0));
  const float r2 = fmaxf(-1.38629436f * log2_u0, 0x1.0p-126f);
  asm("rsqrt.approx.ftz.f32 %0, %1;" : "=f"(inverse_radius) : "f"(r2));
  const float radius = r2 * inverse_radius;
  // The angle 2 pi u1 - pi in (-pi, pi), where the sine and cosine units hold their bound: cos 2 pi u1 = -cos of it.
  float s, c;
  __sincosf(fmaf(u1, 6.28318548f, -3.14159274f), &s, &c);
  return {static_cast<double>(-radius * c), static_cast<double>(-radius * s)};
#else
  const float radius = math::sqrt(-2.0f * math::log(u0));
  constexpr float pi_f = static_cast<float>(math::pi);
  // Two expressions of one angle: GCC does not fuse them into sincosf, which has no vector version.
  const float c = math::cos(2.0f * pi_f * u1);
  const float s = math::sin(pi_f * (2.0f * u1));
  return {static_cast<double>(radius * c), static_cast<double>(radius * s)};
#endif
}

/// Two independent standard normals from one Philox block (Box-Muller).
KOKKOS_INLINE_FUNCTION void normal_pair(const RngKey& key, const Counter& c, double& z0, double& z1) {
  double u0, u1;
  uniform_pair(key, c, u0, u1);
  const NormalPair z = box_muller(u0, u1);
  z0 = z.z0;
  z1 = z.z1;
}

/// N standard normals for one (member, particle, step): blocks draw = 0 .. ceil(N/2)-1.
template <int N>
KOKKOS_INLINE_FUNCTION Vec<N> normal_vector(const RngKey& key, std::uint32_t member, std::uint32_t particle,
                                            std::uint32_t step) {
  Vec<N> z;
  for (int i = 0; i < N; i += 2) {
    double z0, z1;
    normal_pair(key, Counter{member, particle, step, static_cast<std::uint32_t>(i / 2)}, z0, z1);
    z[i] = z0;
    if (i + 1 < N) z[i + 1] = z1;
  }
  return z;
}

/// Where P observation normals v and Q process normals w lie among the `normals` = P + Q normals of one draw
/// (normal_vector<P + Q>, or a lane's rows of draw_normal_lanes<P + Q>): v first, v_i at v + i and w_i at w + i.
/// With P = 0, w alone. v first, so that a model whose noise is padded with columns of zeros (a model file's Q is
/// its state dimension) draws the numbers of the model without them.
template <int P, int Q>
struct ObservationAndProcessLayout {
  static constexpr int normals = P + Q;
  static constexpr int v = 0;
  static constexpr int w = P;
};

/// The P observation normals v and the Q process normals w of one (member, particle, step) as one vector of `key`'s
/// blocks (ObservationAndProcessLayout): where P and Q are both odd, one block and one Box-Muller pair serve the
/// last of v and the first of w. The stochastic EnKBF's ensemble members draw so (the truths: truth_normals).
template <int P, int Q>
KOKKOS_INLINE_FUNCTION void observation_and_process_normals(const RngKey& key, std::uint32_t member,
                                                            std::uint32_t particle, std::uint32_t step, Vec<P>& v,
                                                            Vec<Q>& w) {
  using Layout = ObservationAndProcessLayout<P, Q>;
  const Vec<Layout::normals> z = normal_vector<Layout::normals>(key, member, particle, step);
  for (int i = 0; i < P; ++i) v[i] = z[Layout::v + i];
  for (int i = 0; i < Q; ++i) w[i] = z[Layout::w + i];
}

/// The member-pair normal of block `draw` of (member, 0, step): the block of the even global member of the pair that
/// `member` is in (global index, Seed::first_member added) gives its z0 to the even member and its z1 to the odd one.
/// A truth whose step takes an odd count of normals draws the last one so: one Philox block, one logarithm and one
/// square root per two members instead of per member (the cubic oscillator's truth step 1.1-1.3x faster here).
KOKKOS_INLINE_FUNCTION double member_pair_normal(const RngKey& key, std::uint32_t member, std::uint32_t step,
                                                 std::uint32_t draw) {
  const std::uint32_t odd = (member + key.seed.first_member) & 1u;
  double z0, z1;
  normal_pair(key, Counter{member - odd, 0, step, draw}, z0, z1);  // wraps where the pair's even member is on
  return odd ? z1 : z0;                                            // the rank before: philox_block wraps it back
}

/// A continuous-time truth's observation and process normals v, w of (member, step) (ObservationAndProcessLayout<P,
/// Q>), of which the model uses the first `drawn` (P + Q, or fewer where a model file's noise is padded with columns
/// of zeros: truth_normal_count): normals 2i and 2i + 1 from the member's block i, where `drawn` is odd the last one
/// from the member pair's block (member_pair_normal), and the unused ones zero. observation_and_process_normals'
/// numbers but for that last one.
template <int P, int Q>
KOKKOS_INLINE_FUNCTION void truth_normals(const RngKey& key, std::uint32_t member, std::uint32_t step, const int drawn,
                                          Vec<P>& v, Vec<Q>& w) {
  using Layout = ObservationAndProcessLayout<P, Q>;
  Vec<Layout::normals> z = Vec<Layout::normals>::zero();
  for (int i = 0; i + 1 < Layout::normals; i += 2)
    if (i + 1 < drawn) normal_pair(key, Counter{member, 0, step, static_cast<std::uint32_t>(i / 2)}, z[i], z[i + 1]);
  if (drawn % 2 == 1) {
    const double lone = member_pair_normal(key, member, step, static_cast<std::uint32_t>(drawn / 2));
    for (int i = 0; i < Layout::normals; ++i)  // a constant index: z stays in registers on a GPU
      if (i == drawn - 1) z[i] = lone;
  }
  for (int i = 0; i < P; ++i) v[i] = z[Layout::v + i];
  for (int i = 0; i < Q; ++i) w[i] = z[Layout::w + i];
}

/// N uniforms in (0, 1) for one (member, particle, step): blocks draw = 0 .. ceil(N/2)-1.
template <int N>
KOKKOS_INLINE_FUNCTION Vec<N> uniform_vector(const RngKey& key, std::uint32_t member, std::uint32_t particle,
                                             std::uint32_t step) {
  Vec<N> u;
  for (int i = 0; i < N; i += 2) {
    double u0, u1;
    uniform_pair(key, Counter{member, particle, step, static_cast<std::uint32_t>(i / 2)}, u0, u1);
    u[i] = u0;
    if (i + 1 < N) u[i + 1] = u1;
  }
  return u;
}

}  // namespace kushner
