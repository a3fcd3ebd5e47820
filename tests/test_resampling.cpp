// Resampling schemes on fixed weight vectors: unbiased offspring counts (statistical, with a power check),
// the residual scheme's deterministic part, systematic indices identical on every backend and team size, and
// the particle filter's chunked systematic path identical to the one-team path.
#include "kernels/particle_filter/chunked_systematic_resample.hpp"
#include "kernels/particle_filter/resampling.hpp"
#include "tests/test_spaces.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace kushner {
namespace {

constexpr std::uint32_t seed = 20261122;

/// A fixed, uneven weight vector: a few heavy particles, many light ones, some exactly zero.
std::vector<double> fixed_weights(int n) {
  std::vector<double> w(n);
  for (int j = 0; j < n; ++j)
    w[j] = (j % 7 == 3) ? 0.0 : 0.05 + std::pow(std::sin(0.37 * j + 0.2), 4) + (j % 11 == 0 ? 3.0 : 0.0);
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
    if (st.standard_error[j] > 0.0)
      worst = std::max(worst, diff / st.standard_error[j]);
    else if (diff > 1e-9)
      worst = std::max(worst, 1e9);
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

/// w(j, m) = exp(l(j, m) - log_normalizer(m)): the weights the one-team path starts from.
template <class Mem, class Real = double>
struct ExponentiatedWeights {
  ParticleColumn<Mem, Real> l, w;
  BankScalar<double, Mem> log_normalizer;
  KOKKOS_INLINE_FUNCTION void operator()(const int j, const int m) const {
    w(j, m) = math::exp(l(j, m) - log_normalizer(m));
  }
};

template <class Space>
class ChunkedSystematic : public ::testing::Test {};
TYPED_TEST_SUITE(ChunkedSystematic, test::ExecutionSpaces);

/// Resamples the `listed` members of a bank of n particles by the chunked path and by the one-team path on
/// the same backend: the same ancestors, the particles moved accordingly, and only the listed members changed.
/// Log-weights with rounding everywhere and dead particles; stored as Real (float: the fp32 precision). `into`: the
/// chunked path writes into another bank (ChunkedResampleData::x_into), and leaves its input as it was.
template <class Space, class Real = double>
void check_chunked_against_team_path(int n, int members, const std::vector<int>& listed, bool into = false) {
  using Mem = typename Space::memory_space;
  const std::uint32_t step = 17;
  ChunkedResampleData<Mem, Real> d;
  d.x = ParticleBank<Mem, Real>("x", n, members, 2);
  d.x_scratch = ParticleBank<Mem, Real>("x_scratch", n, members, 2);
  d.log_weight = decltype(d.log_weight)("l", n, members);
  d.ancestors = decltype(d.ancestors)("a", n, members);
  d.block_sums = decltype(d.block_sums)("block_sums", scan_num_blocks(n), members);
  d.log_normalizer = BankScalar<double, Mem>("log_normalizer", members);
  d.members = Kokkos::View<int*, Mem>("members", members);
  d.member_count = Kokkos::View<int, Mem>("member_count");
  d.num_particles = n;
  d.seed = seed;
  d.step = step;
  auto x = Kokkos::create_mirror(d.x);  // copies even on the host: the bank changes, these must not
  auto l = Kokkos::create_mirror(d.log_weight);
  auto log_normalizer = Kokkos::create_mirror(d.log_normalizer);
  for (int m = 0; m < members; ++m) {
    log_normalizer(m) = 3.0 + 0.1 * m;  // any value: the weights need not sum to one
    for (int j = 0; j < n; ++j) {
      l(j, m) = j % 13 == 5 ? -std::numeric_limits<double>::infinity()
                            : -0.5 * std::pow((j - 0.34 * n - 300.0 * m) / (0.14 * n), 2) + 0.3 * std::sin(0.1 * j);
      x(j, m, 0) = j + 1e7 * m;
      x(j, m, 1) = -0.5 * j;
    }
  }
  Kokkos::deep_copy(d.x, x);
  Kokkos::deep_copy(d.log_weight, l);
  Kokkos::deep_copy(d.log_normalizer, log_normalizer);
  auto list = Kokkos::create_mirror_view(d.members);
  for (std::size_t k = 0; k < listed.size(); ++k) list(k) = listed[k];
  Kokkos::deep_copy(d.members, list);
  Kokkos::deep_copy(d.member_count, static_cast<int>(listed.size()));
  const double untouched = -7.0;  // what the other bank holds where nothing is resampled into it
  if (into) {
    d.x_into = ParticleBank<Mem, Real>("x_into", n, members, 2);
    d.log_weight_into = decltype(d.log_weight_into)("l_into", n, members);
    d.log_normalizer_into = BankScalar<double, Mem>("log_normalizer_into", members);
    Kokkos::deep_copy(d.x_into, untouched);
    Kokkos::deep_copy(d.log_weight_into, untouched);
    Kokkos::deep_copy(d.log_normalizer_into, untouched);
  }

  // The one-team path on the same backend: weights exp(l - log_normalizer), then resample_members.
  ResamplingWorkspace<Mem, Real> ws;
  ws.cumulative = decltype(ws.cumulative)("w", n, members);
  ws.ancestors = decltype(ws.ancestors)("a_team", n, members);
  Kokkos::parallel_for(Kokkos::MDRangePolicy<Space, Kokkos::Rank<2>>({0, 0}, {n, members}),
                       ExponentiatedWeights<Mem, Real>{d.log_weight, ws.cumulative, d.log_normalizer});
  resample_members(Space(), ws, ResamplingScheme::systematic, seed, step);

  const bool host = std::is_same<Mem, Kokkos::HostSpace>::value;
  chunked_systematic_resample<2>(Space(), d, host ? 1 : 256, host ? 3 : 64);
  Space().fence();
  const auto expected = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), ws.ancestors);
  const auto ancestors = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), d.ancestors);
  const auto x_after = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), into ? d.x_into : d.x);
  const auto l_after =
      Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), into ? d.log_weight_into : d.log_weight);
  const auto n_after =
      Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), into ? d.log_normalizer_into : d.log_normalizer);
  const auto x_input = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), d.x);
  const auto l_input = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), d.log_weight);
  const auto n_input = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), d.log_normalizer);
  for (int m = 0; m < members; ++m) {
    const bool resampled = std::find(listed.begin(), listed.end(), m) != listed.end();
    const bool kept = into && !resampled;  // the other bank as it was
    EXPECT_EQ(n_after(m), resampled ? std::log(double(n)) : (kept ? untouched : log_normalizer(m))) << m;
    if (into) {
      EXPECT_EQ(n_input(m), log_normalizer(m)) << m;
    }
    int mismatches = 0;
    for (int s = 0; s < n; ++s) {
      const int a = resampled ? expected(s, m) : s;
      if (resampled && ancestors(s, m) != a) ++mismatches;
      if (resampled) {
        EXPECT_NE(l(a, m), -std::numeric_limits<double>::infinity()) << "dead particle drawn, member " << m;
      }
      EXPECT_EQ(x_after(s, m, 0), kept ? untouched : x(a, m, 0));
      EXPECT_EQ(x_after(s, m, 1), kept ? untouched : x(a, m, 1));
      EXPECT_EQ(l_after(s, m), resampled ? 0.0 : (kept ? untouched : l(s, m)));
      if (into) {
        EXPECT_EQ(x_input(s, m, 0), x(s, m, 0));
        EXPECT_EQ(l_input(s, m), l(s, m));
      }
    }
    EXPECT_EQ(mismatches, 0) << "member " << m;
  }
}

TYPED_TEST(ChunkedSystematic, MatchesTheTeamPathAndMovesTheParticles) {
  // Several chunks and a partial last one, members listed in a scrambled order.
  check_chunked_against_team_path<TypeParam>(5003, 6, {3, 0, 5, 2});
  // Over 2^20 particles: scan blocks of 269, which do not divide the chunk size.
  ASSERT_EQ(scan_block_size(1100003), 269);
  check_chunked_against_team_path<TypeParam>(1100003, 2, {1});
}

TYPED_TEST(ChunkedSystematic, MatchesTheTeamPathInFloatStorage) {
  // The fp32 precision: weights and cumulative weights stored in float, summed in double by both paths.
  check_chunked_against_team_path<TypeParam, float>(5003, 6, {3, 0, 5, 2});
}

TYPED_TEST(ChunkedSystematic, IntoAnotherBankLeavesTheInput) {
  // ParticleFilterBank::step_pair resamples the members its first step resamples from the second bank into the
  // first: no copy back.
  check_chunked_against_team_path<TypeParam>(5003, 6, {3, 0, 5, 2}, true);
  check_chunked_against_team_path<TypeParam, float>(5003, 6, {4, 1}, true);
}

}  // namespace
}  // namespace kushner
