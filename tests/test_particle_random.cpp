// The host particle kernel's vectorizable Philox (kernels/particle_filter/simd_random.hpp) against Random123's
// (kernels/rng.hpp, used on the GPU): the same uniforms bit for bit, the same normals to the last bits of the
// math library.
#include "kernels/particle_filter/simd_random.hpp"

#include <gtest/gtest.h>

#include <cmath>

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

TEST(SimdPhilox, NormalsMatchRandom123) {
  const RngKey key{7, Stream::particle_initial};
  for (std::uint32_t particle = 0; particle < 2000; ++particle) {
    const Vec<3> a = normal_vector<3>(key, 5, particle, 11), b = simd::normal_vector<3>(key, 5, particle, 11);
    for (int i = 0; i < 3; ++i) ASSERT_NEAR(a[i], b[i], 1e-15 * (1.0 + std::abs(a[i]))) << particle << " " << i;
  }
}

TEST(SimdPhilox, ExtremeWordsGiveTheOpenIntervalEnds) {
  // k = 0 and k = 2^52 - 1: (k + 1/2) 2^-52, computed exactly by the bit-pattern construction.
  EXPECT_EQ(simd::uniform_open(0, 0), 0x1.0p-53);
  EXPECT_EQ(simd::uniform_open(0xffffffffu, 0xffffffffu), 1.0 - 0x1.0p-53);
  EXPECT_EQ(simd::uniform_open(0xffffffffu, 0xffffffffu), uniform_open(0xffffffffu, 0xffffffffu));
}

}  // namespace
}  // namespace kushner
