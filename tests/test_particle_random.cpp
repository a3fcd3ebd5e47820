// The host's Philox (kernels/particle_filter/simd_random.hpp: the scalar rounds GCC vectorizes, and the runs of lanes
// that an AVX2 host draws four at a time) against Random123's (kernels/rng.hpp's host blocks; a GPU's are
// tests/test_rng.cpp's): the same uniforms bit for bit, the same normals to the last bits of the math library; the
// particle pairs' draws (kernels/particle_filter/particle_draws.hpp), in fp64, in the `mixed` precision's fp32 and in
// the `fp32` precision's steps (two steps from one block); and the truths' member pairs (an odd count's last normal:
// truth_normals).
#include "kernels/for_each_member.hpp"
#include "kernels/particle_filter/particle_draws.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace kushner {
namespace {

TEST(SimdPhilox, UniformsBitIdenticalToRandom123) {
  for (std::uint32_t seed : {0u, 1u, 20261122u, 0xffffffffu})
    for (std::uint32_t member = 0; member < 40; member += 7)
      for (std::uint32_t particle : {0u, 1u, 255u, 65535u, 0xfffffffeu})
        for (std::uint32_t step : {0u, 3u, 999999u})
          for (std::uint32_t draw = 0; draw < 3; ++draw) {
            const RngKey key{seed, Stream::particle_noise};
            const Counter c{member, particle, step, draw};
            double a0, a1, b0, b1;
            uniform_pair(key, c, a0, a1);
            simd::uniform_pair(key, c, b0, b1);
            ASSERT_EQ(a0, b0) << seed << " " << member << " " << particle << " " << step << " " << draw;
            ASSERT_EQ(a1, b1);
            ASSERT_GT(b0, 0.0);
            ASSERT_LT(b0, 1.0);
          }
}

/// Lane counts that fill eight-lane and four-lane bodies and leave each remainder, up to two draw pieces.
constexpr int lane_counts[] = {1, 2, 3, 4, 5, 7, 8, 9, 11, 12, 13, 16, 31, 64, 65, 100, 128};

TEST(SimdPhilox, LaneRunsBitIdenticalToRandom123) {
  // uniform_pair_lanes and uniform_pair_fp32_lanes (high words and low words) against Random123 lane by lane: each
  // field as the lanes' stride (members, particles, member pairs, steps), counters that wrap past 2^32 within a run, a
  // process's first member.
  const Counter strides[] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {2, 0, 0, 0}, {0, 0, 3, 0}, {0, 0, 0, 1}};
  const Counter firsts[] = {{0, 0, 0, 0}, {5, 255, 999999, 2}, {0xfffffff0u, 0xffffffc0u, 7, 0xfffffffeu}};
  for (const std::uint32_t first_member : {0u, 1u, 0xfffffff9u})
    for (const Counter& first : firsts)
      for (const Counter& stride : strides)
        for (const int lanes : lane_counts) {
          const RngKey key{Seed(20261205, first_member), Stream::particle_noise};
          const simd::LaneCounters c{first, stride};
          double u0[128], u1[128];
          float f0[128], f1[128], h0[128], h1[128];
          simd::uniform_pair_lanes(key, c, lanes, u0, u1);
          simd::uniform_pair_fp32_lanes(key, c, lanes, f0, f1);
          simd::uniform_pair_fp32_lanes<true>(key, c, lanes, h0, h1);
          for (int j = 0; j < lanes; ++j) {
            double a0, a1;
            float g0, g1, l0, l1;
            uniform_pair(key, c(j), a0, a1);
            uniform_pair_fp32(key, c(j), g0, g1);
            uniform_pair_fp32(key, c(j), l0, l1, true);
            ASSERT_EQ(u0[j], a0) << lanes << " lanes, lane " << j << ", stride " << stride.member << stride.particle
                                 << stride.step << stride.draw << ", first member " << first_member;
            ASSERT_EQ(u1[j], a1) << lanes << " lanes, lane " << j;
            ASSERT_EQ(f0[j], g0) << lanes << " lanes, lane " << j;
            ASSERT_EQ(f1[j], g1) << lanes << " lanes, lane " << j;
            ASSERT_EQ(h0[j], l0) << lanes << " lanes, lane " << j;
            ASSERT_EQ(h1[j], l1) << lanes << " lanes, lane " << j;
          }
        }
}

/// draw_pair_lanes<Fp32> of `pairs` pairs of (member, first_pair.., step, block i) into z, compiled once for every
/// count (draw_lane_normals_apart's reason, below).
template <bool Fp32>
KUSHNER_SAME_CODE_FOR_ALL_CALLERS void draw_pairs_apart(const RngKey& key, const int member, const int first_pair,
                                                        const int pairs, const std::uint32_t step, const int i,
                                                        double* const z) {
  draw_pair_lanes<Fp32>(key, particle_pair_lanes(member, first_pair, step, i), pairs, z);
}

/// The host's normals of `pairs` particle pairs from first_pair on (draw_pair_lanes), as NormalPairs.
template <bool Fp32 = false>
std::vector<NormalPair> host_pair_normals(const RngKey& key, const int member, const int first_pair, const int pairs,
                                          const std::uint32_t step, const int i) {
  std::vector<double> z(2 * static_cast<std::size_t>(pairs));
  draw_pairs_apart<Fp32>(key, member, first_pair, pairs, step, i, z.data());
  std::vector<NormalPair> out(pairs);
  for (int k = 0; k < pairs; ++k) out[k] = {z[2 * k], z[2 * k + 1]};
  return out;
}

TEST(SimdPhilox, ParticlePairDrawsMatchRandom123) {
  const RngKey key{7, Stream::particle_initial};
  for (int i = 0; i < 3; ++i) {
    const std::vector<NormalPair> host = host_pair_normals(key, 5, 0, 2000, 11, i);
    for (int pair = 0; pair < 2000; ++pair) {
      const NormalPair a = pair_normals(key, 5, pair, 11, i);
      ASSERT_NEAR(a.z0, host[pair].z0, 1e-15 * (1.0 + std::abs(a.z0))) << pair << " " << i;
      ASSERT_NEAR(a.z1, host[pair].z1, 1e-15 * (1.0 + std::abs(a.z1))) << pair << " " << i;
    }
  }
}

TEST(ParticleDraws, PairFollowsTheDocumentedBlocks) {
  // Component i of particles 2k, 2k + 1: the two Box-Muller normals of block {member, k, step, i}; their
  // uniforms (after K normals each): block {member, k, step, K}.
  const RngKey key{20261122, Stream::particle_noise};
  for (std::uint32_t i = 0; i < 2; ++i) {
    double z0, z1;
    normal_pair(key, Counter{3, 17, 9, i}, z0, z1);
    const NormalPair z = pair_normals(key, 3, 17, 9, static_cast<int>(i));
    EXPECT_EQ(z.z0, z0);
    EXPECT_EQ(z.z1, z1);
  }
  double u0, u1, v0[1], v1[1], w0, w1;
  uniform_pair(key, Counter{3, 17, 9, 2}, u0, u1);
  simd::uniform_pair_lanes(key, particle_pair_lanes(3, 17, 9, 2), 1, v0, v1);
  pair_uniforms(key, 3, 17, 9, 2, w0, w1);
  EXPECT_EQ(v0[0], u0);
  EXPECT_EQ(v1[0], u1);
  EXPECT_EQ(w0, u0);
  EXPECT_EQ(w1, u1);
}

constexpr int lane_stride = 128;

/// draw_normal_lanes<N> over lanes [0, lanes) into z (normal k at z[k lane_stride]), in a function compiled once for
/// every lane count, as the chunk functions that draw in production are (kernels/for_each_member.hpp): inlined into a
/// test body whose lane counts it can see, GCC chose scalar code at some call sites and vector code at others, whose
/// last bits differ.
template <int N>
KUSHNER_SAME_CODE_FOR_ALL_CALLERS void draw_lane_normals_apart(const RngKey& key, const int lanes, double* const z) {
  draw_normal_lanes<N>(key, {Counter{0, 0, 7, 0}, Counter{1, 0, 0, 0}}, lanes, z, lane_stride);
}

TEST(ParticleDraws, OddCountOfLaneNormalsTakesTheLastBlocksCosineNormalBitForBit) {
  // draw_normal_lanes with N odd computes its last normal without the block's sine: the same bits as normal N - 1 of
  // N + 1 normals (both of that block's), for lane counts that fill vector bodies and leave remainders.
  const RngKey key{20261129, Stream::process_noise};
  constexpr int stride = lane_stride;
  for (const int lanes : lane_counts) {
    double one[stride], two[2 * stride], three[3 * stride], four[4 * stride];
    draw_lane_normals_apart<1>(key, lanes, one);
    draw_lane_normals_apart<2>(key, lanes, two);
    draw_lane_normals_apart<3>(key, lanes, three);
    draw_lane_normals_apart<4>(key, lanes, four);
    for (int lane = 0; lane < lanes; ++lane) {
      ASSERT_EQ(one[lane], two[lane]) << lanes << " lanes, lane " << lane;
      for (int k = 0; k < 3; ++k)
        ASSERT_EQ(three[k * stride + lane], four[k * stride + lane])
            << lanes << " lanes, normal " << k << ", lane " << lane;
    }
  }
}

TEST(TruthNormals, AnOddCountsLastNormalIsSharedByAPairOfGlobalMembers) {
  // truth_normals<2, 1> (the cubic oscillator's v, w): v from the member's block 0; w from block 1 of the pair's even
  // global member, its z0 to the even member and its z1 to the odd one. A process whose first member is odd draws
  // the numbers of the same global members; a padded layout (<2, 2>, a model file's) told that 3 are drawn, the same
  // numbers and a zero for the fourth.
  for (const std::uint32_t first : {0u, 1u, 256u, 0xffffffffu}) {
    const RngKey key{Seed(20261130, first), Stream::process_noise};
    for (std::uint32_t member = 0; member < 9; ++member) {
      const std::uint32_t global = member + first;
      const RngKey whole{Seed(20261130), Stream::process_noise};
      Vec<2> v, v_padded;
      Vec<1> w;
      Vec<2> w_padded;
      truth_normals<2, 1>(key, member, 7, 3, v, w);
      truth_normals<2, 2>(key, member, 7, 3, v_padded, w_padded);
      double a0, a1, b0, b1;
      normal_pair(whole, Counter{global, 0, 7, 0}, a0, a1);
      normal_pair(whole, Counter{global & ~1u, 0, 7, 1}, b0, b1);
      EXPECT_EQ(v[0], a0) << first << " " << member;
      EXPECT_EQ(v[1], a1);
      EXPECT_EQ(w[0], (global & 1u) ? b1 : b0) << first << " " << member;
      EXPECT_EQ(v_padded[0], v[0]);
      EXPECT_EQ(v_padded[1], v[1]);
      EXPECT_EQ(w_padded[0], w[0]);
      EXPECT_EQ(w_padded[1], 0.0);
    }
  }
  // An even count: every normal from the member's own blocks, as observation_and_process_normals draws them.
  const RngKey key{3, Stream::process_noise};
  Vec<1> v, v_own, w, w_own;
  truth_normals<1, 1>(key, 5, 2, 2, v, w);
  observation_and_process_normals<1, 1>(key, 5, 0, 2, v_own, w_own);
  EXPECT_EQ(v[0], v_own[0]);
  EXPECT_EQ(w[0], w_own[0]);
}

/// draw_member_pair_normal_lanes over lanes [begin, end) into z, compiled once (draw_lane_normals_apart's reason).
KUSHNER_SAME_CODE_FOR_ALL_CALLERS void draw_pair_lanes_apart(const RngKey& key, const int begin, const int end,
                                                             double* const z) {
  draw_member_pair_normal_lanes(begin, end, key, 7, 1, z);
}

TEST(TruthNormals, MemberPairLanesDrawTheScalarNumbers) {
  // The host's SIMD loop over member pairs against member_pair_normal, for chunks of either parity of length and of
  // first global member (odd: its first normal drawn alone); the slot after an odd chunk is the only one written
  // beyond it.
  for (const std::uint32_t first : {0u, 1u}) {
    const RngKey key{Seed(99, first), Stream::process_noise};
    for (const int begin : {0, 1, 32, 33})
      for (const int lanes : {1, 2, 7, 8, 31, 95, 96}) {
        double z[lane_stride + 2];
        std::fill(z, z + lane_stride + 2, -1.0);
        draw_pair_lanes_apart(key, begin, begin + lanes, z);
        for (int lane = 0; lane < lanes; ++lane) {
          const double scalar = member_pair_normal(key, static_cast<std::uint32_t>(begin + lane), 7, 1);
          ASSERT_NEAR(z[lane], scalar, 1e-15 * (1.0 + std::abs(scalar)))
              << "first " << first << ", begin " << begin << ", " << lanes << " lanes, lane " << lane;
        }
        EXPECT_EQ(z[lanes + 1], -1.0) << "first " << first << ", begin " << begin << ", " << lanes << " lanes";
      }
  }
}

TEST(ParticleDraws, PairedNormalsAreUncorrelatedUnitNormals) {
  // 2^20 pairs: the even and odd particles' normals each have variance 1 and correlation 0, within 5 standard
  // errors (SE of a sample variance of normals sqrt(2 / n), of a correlation 1 / sqrt(n)); P(false alarm) ~ 1e-6.
  const int pairs = 1 << 20;
  const RngKey key{11, Stream::particle_noise};
  double see = 0.0, soo = 0.0, seo = 0.0;
  for (const NormalPair& z : host_pair_normals(key, 2, 0, pairs, 4, 0)) {
    see += z.z0 * z.z0;
    soo += z.z1 * z.z1;
    seo += z.z0 * z.z1;
  }
  const double n = pairs;
  EXPECT_LT(std::abs(see / n - 1.0), 5.0 * std::sqrt(2.0 / n));
  EXPECT_LT(std::abs(soo / n - 1.0), 5.0 * std::sqrt(2.0 / n));
  EXPECT_LT(std::abs(seo / n), 5.0 / std::sqrt(n));  // a pairing that reused one normal would give 1
}

TEST(SimdPhilox, ExtremeWordsGiveTheOpenIntervalEnds) {
  // k = 0 and k = 2^52 - 1: (k + 1/2) 2^-52, computed exactly by the bit-pattern construction.
  EXPECT_EQ(simd::uniform_open(0, 0), 0x1.0p-53);
  EXPECT_EQ(simd::uniform_open(0xffffffffu, 0xffffffffu), 1.0 - 0x1.0p-53);
  EXPECT_EQ(simd::uniform_open(0xffffffffu, 0xffffffffu), uniform_open(0xffffffffu, 0xffffffffu));
}

TEST(MixedPrecisionDraws, Fp32UniformsAreTheTopBitsOfTheFp64OnesOnBothPhiloxes) {
  // The same blocks' high words: within half a 2^-23 step (plus the fp64 offset) of the fp64 uniforms, the same
  // floats from the scalar rounds as from Random123 (LaneRunsBitIdenticalToRandom123: from the host's runs of lanes),
  // and the interval's ends (k + 1/2) 2^-23 exactly.
  for (std::uint32_t member = 0; member < 40; member += 3)
    for (std::uint32_t particle : {0u, 1u, 255u, 65535u, 0xfffffffeu})
      for (std::uint32_t step : {0u, 3u, 999999u}) {
        const RngKey key{20261126, Stream::particle_noise};
        const Counter c{member, particle, step, 1};
        double a0, a1;
        float f0, f1, g0, g1;
        uniform_pair(key, c, a0, a1);
        uniform_pair_fp32(key, c, f0, f1);
        simd::uniform_pair_fp32(key, c, g0, g1);
        ASSERT_EQ(f0, g0);
        ASSERT_EQ(f1, g1);
        ASSERT_LE(std::abs(f0 - a0), 0x1.0p-24);
        ASSERT_LE(std::abs(f1 - a1), 0x1.0p-24);
      }
  EXPECT_EQ(uniform_open_fp32(0), 0x1.0p-24f);
  EXPECT_EQ(uniform_open_fp32(0xffffffffu), 1.0f - 0x1.0p-24f);
  EXPECT_EQ(uniform_open_fp32(0x80000000u), 0.5f + 0x1.0p-24f);
}

TEST(MixedPrecisionDraws, Fp32NormalsAgreeWithTheFp64OnesToFloatRounding) {
  // Box-Muller in float against the double one on the same float uniforms: float rounding only (log, sqrt,
  // cos, sin: a few 6e-8 relative steps, times a radius of at most 5.77), a GPU thread's and the host's. Against the
  // fp64 normals (52-bit uniforms of the same blocks) the uniforms' rounding (at most 2^-24) moves the radius r by up
  // to 2^-24 / (u0 r) and the point across it by 2 pi 2^-24 r: each pair within that plus float rounding.
  const RngKey key{5, Stream::particle_noise};
  double worst = 0.0;
  const int pairs = 100000;
  const std::vector<NormalPair> host = host_pair_normals<true>(key, 9, 0, pairs, 2, 0);
  for (int pair = 0; pair < pairs; ++pair) {
    const Counter c{9, std::uint32_t(pair), 2, 0};
    double u0, u1;
    float f0, f1;
    uniform_pair(key, c, u0, u1);
    uniform_pair_fp32(key, c, f0, f1);
    const NormalPair exact = box_muller(f0, f1);
    const double r = std::hypot(exact.z0, exact.z1);
    for (const NormalPair z : {pair_normals<true>(key, 9, pair, 2, 0), host[pair]}) {
      ASSERT_NEAR(z.z0, exact.z0, 1e-6 * (1.0 + r)) << pair;
      ASSERT_NEAR(z.z1, exact.z1, 1e-6 * (1.0 + r)) << pair;
    }
    const NormalPair a = pair_normals(key, 9, pair, 2, 0);
    const NormalPair b = pair_normals<true>(key, 9, pair, 2, 0);
    const double ra = std::hypot(a.z0, a.z1);
    if (ra < 1e-3) continue;  // the radius' bound grows without limit as u0 -> 1
    const double bound = 0x1.0p-24 / (u0 * ra) + 2.0 * math::pi * 0x1.0p-24 * ra + 1e-6 * (1.0 + ra);
    ASSERT_LE(std::hypot(a.z0 - b.z0, a.z1 - b.z1), bound) << pair << " u0 " << u0 << " r " << ra;
    worst = std::max(worst, std::hypot(a.z0 - b.z0, a.z1 - b.z1));
  }
  EXPECT_GT(worst, 0.0);  // they are float normals
}

TEST(MixedPrecisionDraws, Fp32NormalsAreUnitNormals) {
  // As PairedNormalsAreUncorrelatedUnitNormals, plus the fourth moment (3, SE sqrt(96 / n)): the radius cut at
  // 5.77 sd removes a probability of 2^-24, far below what 2^20 pairs resolve.
  const int pairs = 1 << 20;
  const RngKey key{13, Stream::particle_noise};
  double s1 = 0.0, see = 0.0, soo = 0.0, seo = 0.0, s4 = 0.0;
  for (const NormalPair& z : host_pair_normals<true>(key, 2, 0, pairs, 4, 0)) {
    s1 += z.z0 + z.z1;
    see += z.z0 * z.z0;
    soo += z.z1 * z.z1;
    seo += z.z0 * z.z1;
    s4 += z.z0 * z.z0 * z.z0 * z.z0;
  }
  const double n = pairs;
  EXPECT_LT(std::abs(s1 / (2 * n)), 5.0 / std::sqrt(2 * n));
  EXPECT_LT(std::abs(see / n - 1.0), 5.0 * std::sqrt(2.0 / n));
  EXPECT_LT(std::abs(soo / n - 1.0), 5.0 * std::sqrt(2.0 / n));
  EXPECT_LT(std::abs(seo / n), 5.0 / std::sqrt(n));
  EXPECT_LT(std::abs(s4 / n - 3.0), 5.0 * std::sqrt(96.0 / n));
}

/// The host's fp32 step normals (draw_fp32_pair_lanes) of `pairs` particle pairs of `member` at `step`, component 0,
/// as NormalPairs, compiled once for every count.
KUSHNER_SAME_CODE_FOR_ALL_CALLERS void draw_fp32_pairs_apart(const RngKey& key, const int member, const int pairs,
                                                             const std::uint32_t step, double* const z) {
  draw_fp32_pair_lanes(key, member, 0, pairs, step, 0, z);
}
std::vector<NormalPair> host_fp32_step_normals(const RngKey& key, const int member, const int pairs,
                                               const std::uint32_t step) {
  std::vector<double> z(2 * static_cast<std::size_t>(pairs));
  draw_fp32_pairs_apart(key, member, pairs, step, z.data());
  std::vector<NormalPair> out(pairs);
  for (int k = 0; k < pairs; ++k) out[k] = {z[2 * k], z[2 * k + 1]};
  return out;
}

TEST(Fp32StepDraws, TwoStepsShareABlockAsDocumented) {
  // Steps 2m and 2m + 1 from block {member, pair, 2m, i}: the even step mixed's normals of it (bit for bit), the odd
  // step the float Box-Muller of its words 1 and 3 (Random123's block, read here word by word). The two-step form (the
  // GPU's fused pass) gives the one-step form's numbers from an even step and from an odd one, and the host's runs of
  // lanes give them to the last bits of the float math library (libmvec's against libm's).
  const RngKey key{20261206, Stream::particle_noise};
  const int pairs = 300;
  for (const std::uint32_t step : {0u, 1u, 6u, 7u, 0xfffffffeu}) {
    const std::vector<NormalPair> lanes = host_fp32_step_normals(key, 4, pairs, step);
    for (int pair = 0; pair < pairs; ++pair) {
      const NormalPair z = fp32_pair_normals(key, 4, pair, step, 0);
      const r123array4x32 block = {{4, std::uint32_t(pair), step & ~1u, 0}};
      const r123array2x32 k = {{key.seed.value, static_cast<std::uint32_t>(key.stream)}};
      const r123array4x32 r = philox4x32(block, k);  // Random123's block
      const bool odd = (step & 1u) != 0;
      const NormalPair want = box_muller_fp32(uniform_open_fp32(r.v[odd ? 1 : 0]), uniform_open_fp32(r.v[odd ? 3 : 2]));
      ASSERT_EQ(z.z0, want.z0) << "step " << step << " pair " << pair;
      ASSERT_EQ(z.z1, want.z1) << "step " << step << " pair " << pair;
      if (!odd) {
        const NormalPair mixed = pair_normals<true>(key, 4, pair, step, 0);
        ASSERT_EQ(z.z0, mixed.z0);
        ASSERT_EQ(z.z1, mixed.z1);
      }
      const double r_z = std::hypot(z.z0, z.z1);
      ASSERT_NEAR(lanes[pair].z0, z.z0, 1e-6 * (1.0 + r_z)) << "step " << step << " pair " << pair;
      ASSERT_NEAR(lanes[pair].z1, z.z1, 1e-6 * (1.0 + r_z)) << "step " << step << " pair " << pair;
      if (step == 0xfffffffeu) continue;  // its next step is past the counter
      NormalPair first, second;
      fp32_pair_normals_two_steps(key, 4, pair, step, 0, first, second);
      const NormalPair next = fp32_pair_normals(key, 4, pair, step + 1, 0);
      ASSERT_EQ(first.z0, z.z0);
      ASSERT_EQ(first.z1, z.z1);
      ASSERT_EQ(second.z0, next.z0);
      ASSERT_EQ(second.z1, next.z1);
    }
  }
}

TEST(Fp32StepDraws, TheTwoStepsOfABlockAreIndependentUnitNormals) {
  // 2^20 pairs at steps 4 and 5 (one block each): each step's normals have mean 0, variance 1 and fourth moment 3,
  // and every correlation between them (within a step, and across the two steps: the block's high words against its
  // low words) is 0, within 5 standard errors (a sample variance's sqrt(2 / n), a correlation's 1 / sqrt(n), the
  // fourth moment's sqrt(96 / n)); P(false alarm) ~ 1e-5 over the ten checks.
  const int pairs = 1 << 20;
  const RngKey key{17, Stream::particle_noise};
  const std::vector<NormalPair> even = host_fp32_step_normals(key, 2, pairs, 4);
  const std::vector<NormalPair> odd = host_fp32_step_normals(key, 2, pairs, 5);
  const double n = pairs;
  for (const auto* step : {&even, &odd}) {
    double s1 = 0.0, see = 0.0, soo = 0.0, seo = 0.0, s4 = 0.0;
    for (const NormalPair& z : *step) {
      s1 += z.z0 + z.z1;
      see += z.z0 * z.z0;
      soo += z.z1 * z.z1;
      seo += z.z0 * z.z1;
      s4 += z.z1 * z.z1 * z.z1 * z.z1;
    }
    EXPECT_LT(std::abs(s1 / (2 * n)), 5.0 / std::sqrt(2 * n));
    EXPECT_LT(std::abs(see / n - 1.0), 5.0 * std::sqrt(2.0 / n));
    EXPECT_LT(std::abs(soo / n - 1.0), 5.0 * std::sqrt(2.0 / n));
    EXPECT_LT(std::abs(seo / n), 5.0 / std::sqrt(n));
    EXPECT_LT(std::abs(s4 / n - 3.0), 5.0 * std::sqrt(96.0 / n));
  }
  double c00 = 0.0, c11 = 0.0, c01 = 0.0, c10 = 0.0;
  for (int k = 0; k < pairs; ++k) {
    c00 += even[k].z0 * odd[k].z0;
    c11 += even[k].z1 * odd[k].z1;
    c01 += even[k].z0 * odd[k].z1;
    c10 += even[k].z1 * odd[k].z0;
  }
  for (const double c : {c00, c11, c01, c10}) EXPECT_LT(std::abs(c / n), 5.0 / std::sqrt(n));
}

}  // namespace
}  // namespace kushner
