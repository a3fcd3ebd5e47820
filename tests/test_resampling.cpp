// Resampling schemes on fixed weight vectors: unbiased offspring counts (statistical, with a power check),
// the residual scheme's deterministic part, and systematic indices identical on every backend and team size.
#include "kernels/particle_filter/resampling.hpp"
#include "tests/test_spaces.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace kushner {
namespace {

constexpr std::uint32_t seed = 20261122;

/// A fixed, uneven weight vector: a few heavy particles, many light ones, some exactly zero.
std::vector<double> fixed_weights(int n) {
  std::vector<double> w(n);
  for (int j = 0; j < n; ++j) w[j] = (j % 7 == 3) ? 0.0 : 0.05 + std::pow(std::sin(0.37 * j + 0.2), 4) + (j % 11 == 0 ? 3.0 : 0.0);
  return w;
}

/// Ancestors of `members` copies of weight vector w: the copies differ by their member index in the
/// resampling counter, so they are independent replicates.
template <class Space>
std::vector<std::vector<int>> resample_copies(const std::vector<double>& w, int members, ResamplingScheme scheme,
                                              std::uint32_t step0, int team_size = 0) {
  using Mem = typename Space::memory_space;
  const int n = static_cast<int>(w.size());
  ResamplingWorkspace<Mem> ws;
  ws.cumulative = decltype(ws.cumulative)("w", n, members);
  ws.ancestors = decltype(ws.ancestors)("a", n, members);
  ws.copies = decltype(ws.copies)("k", n, members);
  auto h = Kokkos::create_mirror_view(ws.cumulative);
  for (int m = 0; m < members; ++m)
    for (int j = 0; j < n; ++j) h(j, m) = w[j];
  Kokkos::deep_copy(ws.cumulative, h);
  resample_members(Space(), ws, scheme, seed, step0, team_size);
  Space().fence();
  const auto a = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), ws.ancestors);
  std::vector<std::vector<int>> out(members, std::vector<int>(n));
  for (int m = 0; m < members; ++m)
    for (int s = 0; s < n; ++s) out[m][s] = a(s, m);
  return out;
}

struct OffspringStatistics {
  std::vector<double> mean, standard_error;
};

OffspringStatistics offspring_statistics(const std::vector<std::vector<int>>& ancestors, int n) {
  const int r = static_cast<int>(ancestors.size());
  std::vector<double> sum(n, 0.0), sum_sq(n, 0.0);
  for (const auto& a : ancestors) {
    std::vector<int> count(n, 0);
    for (int s : a) {
      EXPECT_GE(s, 0);
      EXPECT_LT(s, n);
      ++count[s];
    }
    for (int j = 0; j < n; ++j) sum[j] += count[j], sum_sq[j] += double(count[j]) * count[j];
  }
  OffspringStatistics st{std::vector<double>(n), std::vector<double>(n)};
  for (int j = 0; j < n; ++j) {
    st.mean[j] = sum[j] / r;
    const double var = (sum_sq[j] - r * st.mean[j] * st.mean[j]) / (r - 1);
    st.standard_error[j] = std::sqrt(std::max(var, 0.0) / r);
  }
  return st;
}

/// Largest |mean - N w_j| / SE over particles; particles whose count never varies must match N w_j to
/// rounding (systematic and residual give exactly floor or ceil of N w_j).
double worst_z(const OffspringStatistics& st, const std::vector<double>& w) {
  const int n = static_cast<int>(w.size());
  double total = 0.0;
  for (double v : w) total += v;
  double worst = 0.0;
  for (int j = 0; j < n; ++j) {
    const double expected = n * w[j] / total;
    const double diff = std::abs(st.mean[j] - expected);
    if (st.standard_error[j] > 0.0) worst = std::max(worst, diff / st.standard_error[j]);
    else if (diff > 1e-9) worst = std::max(worst, 1e9);
  }
  return worst;
}

class ResamplingUnbiased : public ::testing::TestWithParam<ResamplingScheme> {};

TEST_P(ResamplingUnbiased, OffspringCountsWithinFourStandardErrorsOfNw) {
  const int n = 50, replicates = 20000;  // 50 particles x 4 schemes: P(any false alarm) ~ 1e-2 per run; fixed seed
  const auto w = fixed_weights(n);
  const auto ancestors = resample_copies<Kokkos::DefaultExecutionSpace>(w, replicates, GetParam(), 7);
  const auto st = offspring_statistics(ancestors, n);
  EXPECT_LT(worst_z(st, w), 4.0) << to_string(GetParam());
  // Power: the same counts must reject weights 10% off on the heavy particles.
  auto off = w;
  for (int j = 0; j < n; j += 11) off[j] *= 1.1;
  EXPECT_GT(worst_z(st, off), 4.0) << to_string(GetParam());
}

INSTANTIATE_TEST_SUITE_P(AllSchemes, ResamplingUnbiased,
                         ::testing::Values(ResamplingScheme::systematic, ResamplingScheme::stratified,
                                           ResamplingScheme::multinomial, ResamplingScheme::residual),
                         [](const auto& info) { return std::string(to_string(info.param)); });

TEST(ResidualResampling, EveryParticleGetsAtLeastTheFloorOfNw) {
  const int n = 64;
  const auto w = fixed_weights(n);
  double total = 0.0;
  for (double v : w) total += v;
  const auto ancestors = resample_copies<Kokkos::DefaultExecutionSpace>(w, 200, ResamplingScheme::residual, 3);
  for (const auto& a : ancestors) {
    std::vector<int> count(n, 0);
    for (int s : a) ++count[s];
    for (int j = 0; j < n; ++j) EXPECT_GE(count[j], static_cast<int>(std::floor(n * w[j] / total))) << j;
  }
}

TEST(SystematicResampling, MatchesTextbookAlgorithmOnExactlySummableWeights) {
  // Weights k / 64 sum without rounding, so the scan order cannot matter; Kitagawa's loop must agree exactly.
  const int n = 32;
  std::vector<double> w(n);
  for (int j = 0; j < n; ++j) w[j] = ((j * 5) % 9) / 64.0;
  const auto ancestors = resample_copies<Kokkos::DefaultExecutionSpace>(w, 5, ResamplingScheme::systematic, 11);
  double total = 0.0;
  for (double v : w) total += v;
  for (int m = 0; m < 5; ++m) {
    double u0, u1;
    uniform_pair(RngKey{seed, Stream::resampling}, Counter{std::uint32_t(m), 0, 11, 0}, u0, u1);
    int j = 0;
    double c = w[0];
    for (int s = 0; s < n; ++s) {
      const double point = (s + u0) / n * total;
      while (c <= point) c += w[++j];
      EXPECT_EQ(ancestors[m][s], j) << "member " << m << " slot " << s;
    }
  }
}

template <class Space>
class SystematicOnEveryBackend : public ::testing::Test {};
TYPED_TEST_SUITE(SystematicOnEveryBackend, test::ExecutionSpaces);

TYPED_TEST(SystematicOnEveryBackend, IndicesIdenticalToHostSerialAndAcrossTeamSizes) {
  // Weights with rounding in every partial sum, and more than one scan block.
  const int n = 3000;
  std::vector<double> w(n);
  for (int j = 0; j < n; ++j) w[j] = std::exp(-0.5 * std::pow((j - 1200.0) / 300.0, 2)) * (1.0 + 0.1 * std::sin(j));
  const auto here = resample_copies<TypeParam>(w, 16, ResamplingScheme::systematic, 5);
  const auto host = resample_copies<Kokkos::DefaultHostExecutionSpace>(w, 16, ResamplingScheme::systematic, 5);
  EXPECT_EQ(here, host);
  const int wide = std::is_same<typename TypeParam::memory_space, Kokkos::HostSpace>::value
                       ? std::min(2, TypeParam::concurrency())
                       : 128;
  EXPECT_EQ(resample_copies<TypeParam>(w, 16, ResamplingScheme::systematic, 5, wide), host);
  // And they are a valid systematic draw: sorted, and particle j has floor or ceil of N w_j copies.
  double total = 0.0;
  for (double v : w) total += v;
  for (const auto& a : here) {
    EXPECT_TRUE(std::is_sorted(a.begin(), a.end()));
    std::vector<int> count(n, 0);
    for (int s : a) ++count[s];
    for (int j = 0; j < n; ++j) EXPECT_LE(std::abs(count[j] - n * w[j] / total), 1.0) << j;
  }
}

}  // namespace
}  // namespace kushner
