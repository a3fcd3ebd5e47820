// Philox normals and uniforms: moments, Kolmogorov-Smirnov against the exact laws, and independence of streams.
#include "kernels/particle_filter/particle_draws.hpp"
#include "kernels/rng.hpp"
#include "tests/test_spaces.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <set>
#include <utility>
#include <vector>

namespace kushner {
namespace {

constexpr std::uint32_t seed = 20261122;
constexpr int num_draws = 1 << 20;  // ~1e6

/// Draws normal_vector<2> for members 0 .. n/2-1 at one step, flattened.
template <class ExecSpace>
std::vector<double> draw_normals(Stream stream, int n, double scale = 1.0) {
  Kokkos::View<double*, typename ExecSpace::memory_space> out("normals", n);
  Kokkos::parallel_for(
      "test::draw_normals", Kokkos::RangePolicy<ExecSpace>(0, n / 2), KOKKOS_LAMBDA(const int member) {
        const Vec<2> z = normal_vector<2>(RngKey{seed, stream}, member, 3, 7);
        out(2 * member) = scale * z[0];
        out(2 * member + 1) = scale * z[1];
      });
  const auto host = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), out);
  return std::vector<double>(host.data(), host.data() + n);
}

/// A process that runs members [first, first + count) of a split ensemble (MPI ranks) draws, for its local member
/// i, exactly the numbers of global member first + i: the counter's member is offset by Seed::first_member.
TEST(Rng, SeedFirstMemberOffsetsTheMemberCounter) {
  for (std::uint32_t first : {0u, 256u, 512u, 4096u})
    for (std::uint32_t local : {0u, 1u, 255u}) {
      const Counter c{local, 3, 7, 1};
      const r123array4x32 split = philox_block(RngKey{Seed(seed, first), Stream::process_noise}, c);
      const r123array4x32 whole =
          philox_block(RngKey{seed, Stream::process_noise}, Counter{first + local, c.particle, c.step, c.draw});
      for (int w = 0; w < 4; ++w) EXPECT_EQ(split.v[w], whole.v[w]) << "first " << first << ", local " << local;
    }
  // and the offset matters: member 0 of the second share is not member 0 of the first
  const r123array4x32 a = philox_block(RngKey{Seed(seed, 256), Stream::process_noise}, Counter{0, 0, 0, 0});
  const r123array4x32 b = philox_block(RngKey{seed, Stream::process_noise}, Counter{0, 0, 0, 0});
  EXPECT_NE(a.v[0], b.v[0]);
}

/// The key and counter of block i of PhiloxBlocks: every field varies, the seed's first member too.
KOKKOS_INLINE_FUNCTION RngKey philox_test_key(const std::uint32_t i) {
  return RngKey{Seed(seed + i % 7, i * 2654435761u), static_cast<Stream>(i % 9 + 1)};
}
KOKKOS_INLINE_FUNCTION Counter philox_test_counter(const std::uint32_t i) { return {i, i * 40503u, ~i, i >> 3}; }

/// philox_block of blocks 0 .. n - 1 (philox_test_key, philox_test_counter), computed on ExecSpace.
template <class ExecSpace>
Kokkos::View<std::uint32_t* [4], Kokkos::LayoutRight, Kokkos::HostSpace> philox_blocks(int n) {
  Kokkos::View<std::uint32_t* [4], Kokkos::LayoutRight, typename ExecSpace::memory_space> out("blocks", n);
  Kokkos::parallel_for(
      "test::philox_blocks", Kokkos::RangePolicy<ExecSpace>(0, n), KOKKOS_LAMBDA(const int i) {
        const auto u = static_cast<std::uint32_t>(i);
        const r123array4x32 r = philox_block(philox_test_key(u), philox_test_counter(u));
        for (int w = 0; w < 4; ++w) out(i, w) = r.v[w];
      });
  return Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), out);
}

template <class ExecSpace>
class PhiloxBlocks : public ::testing::Test {};
TYPED_TEST_SUITE(PhiloxBlocks, test::ExecutionSpaces);

/// Every backend's blocks are Random123's philox4x32 on the host, bit for bit (a GPU takes rng.hpp's own rounds,
/// philox4x32_10, which the host's are checked against here too).
TYPED_TEST(PhiloxBlocks, AreRandom123sPhiloxBitForBit) {
  constexpr int n = 1 << 18;
  const auto blocks = philox_blocks<TypeParam>(n);
  long differ = 0, own_differ = 0;
  for (int i = 0; i < n; ++i) {
    const auto u = static_cast<std::uint32_t>(i);
    const RngKey key = philox_test_key(u);
    const Counter c = philox_test_counter(u);
    const r123array2x32 k = {{key.seed.value, static_cast<std::uint32_t>(key.stream)}};
    const r123array4x32 ctr = {{c.member + key.seed.first_member, c.particle, c.step, c.draw}};
    const r123array4x32 expected = philox4x32(ctr, k), own = philox4x32_10(ctr, k);
    for (int w = 0; w < 4; ++w) {
      differ += blocks(i, w) != expected.v[w];
      own_differ += own.v[w] != expected.v[w];
    }
  }
  EXPECT_EQ(differ, 0) << "words of " << n << " blocks";
  EXPECT_EQ(own_differ, 0) << "words of " << n << " blocks";
}

double standard_normal_cdf(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

/// Kolmogorov-Smirnov statistic of the sample against the standard normal.
double ks_statistic(std::vector<double> x) {
  std::sort(x.begin(), x.end());
  const double n = static_cast<double>(x.size());
  double d = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double f = standard_normal_cdf(x[i]);
    d = std::max({d, f - i / n, (i + 1) / n - f});
  }
  return d;
}

template <class ExecSpace>
class PhiloxNormals : public ::testing::Test {};
TYPED_TEST_SUITE(PhiloxNormals, test::ExecutionSpaces);

/// The sample's mean within four standard errors of 0 and its variance within four of 1.
void expect_standard_normal_moments(const std::vector<double>& z) {
  double mean = 0.0, m2 = 0.0;
  for (double v : z) mean += v;
  mean /= z.size();
  for (double v : z) m2 += (v - mean) * (v - mean);
  const double variance = m2 / (z.size() - 1);
  const double n = static_cast<double>(z.size());
  EXPECT_LT(std::abs(mean), 4.0 / std::sqrt(n)) << "mean " << mean;
  EXPECT_LT(std::abs(variance - 1.0), 4.0 * std::sqrt(2.0 / n)) << "variance " << variance;
}

TYPED_TEST(PhiloxNormals, MeanAndVarianceWithinFourStandardErrors) {
  expect_standard_normal_moments(draw_normals<TypeParam>(Stream::particle_noise, num_draws));
}

TYPED_TEST(PhiloxNormals, KolmogorovSmirnovAcceptsNormalAndRejectsScaledNormal) {
  const double n = num_draws;
  const double critical = 1.95 / std::sqrt(n);  // alpha = 0.001
  const double d = ks_statistic(draw_normals<TypeParam>(Stream::process_noise, num_draws));
  EXPECT_LT(d, critical) << "KS statistic " << d;
  // Power: a 2% error in the standard deviation must be detected on the same draws.
  const double d_scaled = ks_statistic(draw_normals<TypeParam>(Stream::process_noise, num_draws, 1.02));
  EXPECT_GT(d_scaled, critical) << "KS statistic of scaled draws " << d_scaled;
}

/// Block i's float uniforms u(i, 0..1) and box_muller_fp32's normals of them z(i, 0..1), computed on ExecSpace.
template <class ExecSpace>
void draw_float_box_muller(int blocks, Kokkos::View<float* [2], Kokkos::LayoutRight, Kokkos::HostSpace>& u,
                           Kokkos::View<double* [2], Kokkos::LayoutRight, Kokkos::HostSpace>& z) {
  using Memory = typename ExecSpace::memory_space;
  Kokkos::View<float* [2], Kokkos::LayoutRight, Memory> uniforms("uniforms", blocks);
  Kokkos::View<double* [2], Kokkos::LayoutRight, Memory> normals("normals", blocks);
  Kokkos::parallel_for(
      "test::float_box_muller", Kokkos::RangePolicy<ExecSpace>(0, blocks), KOKKOS_LAMBDA(const int i) {
        float u0, u1;
        uniform_pair_fp32(RngKey{seed, Stream::particle_noise}, Counter{std::uint32_t(i), 1, 2, 0}, u0, u1);
        const NormalPair pair = box_muller_fp32(u0, u1);
        uniforms(i, 0) = u0;
        uniforms(i, 1) = u1;
        normals(i, 0) = pair.z0;
        normals(i, 1) = pair.z1;
      });
  u = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), uniforms);
  z = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), normals);
}

/// The float Box-Muller (mixed and fp32 particles) against the double one on the same float uniforms, each normal
/// within twice its bound (kernels/rng.hpp: the GPU's special-function unit; libm's on the host, within a sixth of
/// it: its float angle's rounding), and the float normals' mean and variance within four standard errors.
TYPED_TEST(PhiloxNormals, FloatBoxMullerIsWithinItsBoundOfTheDoubleOne) {
  constexpr int blocks = num_draws / 2;
  Kokkos::View<float* [2], Kokkos::LayoutRight, Kokkos::HostSpace> u;
  Kokkos::View<double* [2], Kokkos::LayoutRight, Kokkos::HostSpace> z;
  draw_float_box_muller<TypeParam>(blocks, u, z);
  int outside = 0;
  double worst = 0.0;
  std::vector<double> fast_normals;
  for (int i = 0; i < blocks; ++i) {
    const NormalPair exact = box_muller(u(i, 0), u(i, 1));
    const double r = std::hypot(exact.z0, exact.z1);
    const double bound = 2.0 * (std::min(std::sqrt(3.3e-7), 1.65e-7 / r) + 1.2e-6 * r) + 1e-7;
    for (const auto& [fast, accurate] : {std::pair{z(i, 0), exact.z0}, std::pair{z(i, 1), exact.z1}}) {
      outside += !(std::abs(fast - accurate) <= bound);
      worst = std::max(worst, std::abs(fast - accurate) / bound);
      fast_normals.push_back(fast);
    }
  }
  EXPECT_EQ(outside, 0) << "largest error over its bound " << worst;
  expect_standard_normal_moments(fast_normals);
  std::cout << "largest error over its bound " << worst << "\n";
}

/// The `fp32` precision's step draws of particle pairs [0, pairs) on ExecSpace, as its fused pass takes them
/// (fp32_pair_normals_two_steps): z(pair, t, 0..3) the normals of steps first_step + t and first_step + t + 1 (member
/// 3, component 1); the count of pairs whose one-step form (fp32_pair_normals, the fused pass's redo) differs.
template <class ExecSpace>
int draw_fp32_step_pairs(int pairs, std::uint32_t first_step,
                         Kokkos::View<double* [2][4], Kokkos::LayoutRight, Kokkos::HostSpace>& z) {
  using Memory = typename ExecSpace::memory_space;
  const RngKey key{seed, Stream::particle_noise};
  Kokkos::View<double* [2][4], Kokkos::LayoutRight, Memory> normals("normals", pairs);
  Kokkos::View<int*, Memory> one_step_differs("one_step_differs", 1);
  Kokkos::parallel_for(
      "test::fp32_step_draws", Kokkos::RangePolicy<ExecSpace>(0, pairs), KOKKOS_LAMBDA(const int pair) {
        for (int t = 0; t < 2; ++t) {
          NormalPair first, second;
          fp32_pair_normals_two_steps(key, 3, pair, first_step + t, 1, first, second);
          const NormalPair a = fp32_pair_normals(key, 3, pair, first_step + t, 1);
          const NormalPair b = fp32_pair_normals(key, 3, pair, first_step + t + 1, 1);
          if (a.z0 != first.z0 || a.z1 != first.z1 || b.z0 != second.z0 || b.z1 != second.z1)
            Kokkos::atomic_add(&one_step_differs(0), 1);
          normals(pair, t, 0) = first.z0;
          normals(pair, t, 1) = first.z1;
          normals(pair, t, 2) = second.z0;
          normals(pair, t, 3) = second.z1;
        }
      });
  z = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), normals);
  return Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), one_step_differs)(0);
}

/// The fp32 step draws on the backend from an even step (one block) and an odd one (two) against the words the host
/// reads from Random123's blocks: steps 2m and 2m + 1 from block {member, pair, 2m, i}, words 0, 2 and 1, 3. Each
/// normal within FloatBoxMuller's bound of the double Box-Muller of its float uniforms (a wrong word would be off by
/// about 1); the one-step form gives the same bits on the backend.
TYPED_TEST(PhiloxNormals, Fp32StepsTakeTheirBlocksWords) {
  constexpr int pairs = 1 << 16;
  constexpr std::uint32_t first_step = 6;
  Kokkos::View<double* [2][4], Kokkos::LayoutRight, Kokkos::HostSpace> z;
  EXPECT_EQ(draw_fp32_step_pairs<TypeParam>(pairs, first_step, z), 0);
  int outside = 0;
  double worst = 0.0;
  for (int pair = 0; pair < pairs; ++pair)
    for (int t = 0; t < 2; ++t)
      for (int s = 0; s < 2; ++s) {
        const std::uint32_t step = first_step + t + s;
        const r123array4x32 block = {{3, std::uint32_t(pair), step & ~1u, 1}};
        const r123array2x32 k = {{seed, std::uint32_t(Stream::particle_noise)}};
        const r123array4x32 r = philox4x32(block, k);
        const int w = step & 1u;
        const NormalPair exact = box_muller(uniform_open_fp32(r.v[w]), uniform_open_fp32(r.v[w + 2]));
        const double radius = std::hypot(exact.z0, exact.z1);
        const double bound = 2.0 * (std::min(std::sqrt(3.3e-7), 1.65e-7 / radius) + 1.2e-6 * radius) + 1e-7;
        for (const auto& [got, want] :
             {std::pair{z(pair, t, 2 * s), exact.z0}, std::pair{z(pair, t, 2 * s + 1), exact.z1}}) {
          outside += !(std::abs(got - want) <= bound);
          worst = std::max(worst, std::abs(got - want) / bound);
        }
      }
  EXPECT_EQ(outside, 0) << "largest error over its bound " << worst;
  std::cout << "fp32 steps: largest error over its bound " << worst << "\n";
}

TEST(PhiloxStreams, DistinctStreamsShareNoBlockAndAreUncorrelated) {
  const std::vector<Stream> streams = {Stream::truth_initial,    Stream::process_noise,  Stream::observation_noise,
                                       Stream::particle_initial, Stream::particle_noise, Stream::resampling};
  constexpr int blocks = 1 << 16;
  std::set<std::uint64_t> seen;
  for (Stream s : streams)
    for (std::uint32_t m = 0; m < blocks; ++m) {
      const r123array4x32 r = philox_block(RngKey{seed, s}, Counter{m, 0, 0, 0});
      const std::uint64_t word = (static_cast<std::uint64_t>(r.v[0]) << 32) | r.v[1];
      EXPECT_TRUE(seen.insert(word).second) << "block repeated in stream " << static_cast<int>(s) << " member " << m;
    }
  const auto a = draw_normals<Kokkos::DefaultHostExecutionSpace>(Stream::process_noise, num_draws);
  const auto b = draw_normals<Kokkos::DefaultHostExecutionSpace>(Stream::observation_noise, num_draws);
  double correlation = 0.0;
  for (int i = 0; i < num_draws; ++i) correlation += a[i] * b[i];
  correlation /= num_draws;
  EXPECT_LT(std::abs(correlation), 4.0 / std::sqrt(static_cast<double>(num_draws))) << "correlation " << correlation;
}

TEST(PhiloxStreams, SameKeyAndCounterGiveSameNumbersOnEveryCall) {
  double a0, a1, b0, b1;
  normal_pair(RngKey{seed, Stream::process_noise}, Counter{5, 6, 7, 0}, a0, a1);
  normal_pair(RngKey{seed, Stream::process_noise}, Counter{5, 6, 7, 0}, b0, b1);
  EXPECT_EQ(a0, b0);
  EXPECT_EQ(a1, b1);
  normal_pair(RngKey{seed + 1, Stream::process_noise}, Counter{5, 6, 7, 0}, b0, b1);
  EXPECT_NE(a0, b0);
}

TEST(UniformOpen, StaysInsideOpenInterval) {
  EXPECT_GT(uniform_open(0, 0), 0.0);
  EXPECT_LT(uniform_open(0xffffffffu, 0xffffffffu), 1.0);
}

}  // namespace
}  // namespace kushner
