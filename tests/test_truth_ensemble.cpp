// The bank of truths against exact moments: scalar OU, a 2-D linear model, and Clark's discrete-time model.
// Statistical tests: fixed seed, M = 1e5 members, tolerance 4 standard errors, and a perturbed model that
// the same test must reject (so the test can fail). And the host's truth steps by blocks, with an output step's
// moments in the same pass, against the chunks of one member kernel and ensemble_moments, bit for bit; and its
// segments (several steps per block) against steps one at a time, bit for bit.
#include "core/eigen_dense.hpp"
#include "engine/truth_bank.hpp"
#include "models/clark_linear_model.hpp"
#include "models/cubic_oscillator_model.hpp"
#include "models/linear_model.hpp"
#include "models/ou_model.hpp"
#include "models/sine_model.hpp"
#include "tests/filter_test_helpers.hpp"
#include "tests/test_spaces.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace kushner {
namespace {

constexpr std::uint32_t seed = 20261122;
constexpr long num_members = 100000;

struct OuExact {
  double mean, variance;
};
OuExact ou_exact(const OuModel& m, double t) {
  const double decay = std::exp(-m.theta * t);
  return {m.mu + (m.x0_mean[0] - m.mu) * decay,
          m.x0_cov(0, 0) * decay * decay + m.sigma * m.sigma * (1.0 - decay * decay) / (2.0 * m.theta)};
}

TEST(OuEnsemble, MeanAndVarianceAtOneWithinFourStandardErrors) {
  OuModel model;
  model.x0_cov(0, 0) = 0.2;
  const TimeGrid grid = make_time_grid(1.0, 1e-3, 1);
  const auto series = simulate_ensemble(Kokkos::DefaultExecutionSpace(), model, num_members, seed, grid);
  const double mean = series.moments.back().mean[0], variance = series.moments.back().variance[0];
  const OuExact exact = ou_exact(model, 1.0);
  const double se_mean = std::sqrt(exact.variance / num_members);
  const double se_variance = exact.variance * std::sqrt(2.0 / (num_members - 1));
  EXPECT_LT(std::abs(mean - exact.mean), 4.0 * se_mean) << "mean " << mean << " exact " << exact.mean;
  EXPECT_LT(std::abs(variance - exact.variance), 4.0 * se_variance)
      << "variance " << variance << " exact " << exact.variance;

  OuModel off = model;  // power: a 10% error in theta must show
  off.theta = 1.1;
  const OuExact wrong = ou_exact(off, 1.0);
  EXPECT_GT(std::abs(mean - wrong.mean), 4.0 * se_mean);
}

/// Exact mean and covariance of dx = (a0 + A x) dt + b dw by RK4 on dm/dt = a0 + A m, dP/dt = AP + PA' + bb'.
template <int N>
std::pair<Eigen::Matrix<double, N, 1>, Eigen::Matrix<double, N, N>> linear_exact(const LinearModel<N>& m, double T) {
  const Eigen::Matrix<double, N, N> A = to_eigen(m.A);
  const Eigen::Matrix<double, N, N> Q = to_eigen(m.b) * to_eigen(m.b).transpose();
  Eigen::Matrix<double, N, 1> a0, mean;
  for (int i = 0; i < N; ++i) a0(i) = m.a0[i], mean(i) = m.x0_mean[i];
  Eigen::Matrix<double, N, N> P = to_eigen(m.x0_cov);
  const int steps = 10000;
  const double h = T / steps;
  auto dm = [&](const Eigen::Matrix<double, N, 1>& x) { return (a0 + A * x).eval(); };
  auto dP = [&](const Eigen::Matrix<double, N, N>& p) { return (A * p + p * A.transpose() + Q).eval(); };
  for (int k = 0; k < steps; ++k) {
    const auto k1 = dm(mean), k2 = dm(mean + 0.5 * h * k1), k3 = dm(mean + 0.5 * h * k2), k4 = dm(mean + h * k3);
    mean += h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4);
    const auto l1 = dP(P), l2 = dP(P + 0.5 * h * l1), l3 = dP(P + 0.5 * h * l2), l4 = dP(P + h * l3);
    P += h / 6.0 * (l1 + 2 * l2 + 2 * l3 + l4);
  }
  return {mean, P};
}

/// Sample mean and covariance of the bank's final states (host, in member order).
template <int N, class View>
std::pair<Eigen::Matrix<double, N, 1>, Eigen::Matrix<double, N, N>> sample_moments(const View& x) {
  const auto h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), x);
  const long n = static_cast<long>(h.extent(0));
  Eigen::Matrix<double, N, 1> mean = Eigen::Matrix<double, N, 1>::Zero();
  for (long m = 0; m < n; ++m)
    for (int i = 0; i < N; ++i) mean(i) += h(m, i);
  mean /= n;
  Eigen::Matrix<double, N, N> cov = Eigen::Matrix<double, N, N>::Zero();
  for (long m = 0; m < n; ++m) {
    Eigen::Matrix<double, N, 1> d;
    for (int i = 0; i < N; ++i) d(i) = h(m, i) - mean(i);
    cov += d * d.transpose();
  }
  return {mean, cov / (n - 1)};
}

template <int N>
std::pair<Eigen::Matrix<double, N, 1>, Eigen::Matrix<double, N, N>> simulate_linear(const LinearModel<N>& model,
                                                                                    double T, double dt) {
  using Space = Kokkos::DefaultExecutionSpace;
  TruthBank<Space, LinearModel<N>> bank(Space(), model, num_members, seed);
  const long steps = std::lround(T / dt);
  for (long k = 0; k < steps; ++k) bank.step(k, dt);
  Space().fence();
  return sample_moments<N>(bank.state());
}

TEST(LinearEnsemble, TwoDimensionalMeanAndCovarianceWithinFourStandardErrors) {
  LinearModel<2> model;
  model.a0 = Vec<2>{{0.3, -0.2}};
  const auto [mean, cov] = simulate_linear(model, 1.0, 1e-3);
  const auto [exact_mean, exact_cov] = linear_exact(model, 1.0);
  for (int i = 0; i < 2; ++i) {
    const double se = std::sqrt(exact_cov(i, i) / num_members);
    EXPECT_LT(std::abs(mean(i) - exact_mean(i)), 4.0 * se)
        << "mean " << i << ": " << mean(i) << " exact " << exact_mean(i);
    for (int j = 0; j <= i; ++j) {  // Var of a sample covariance entry of a Gaussian: (P_ii P_jj + P_ij^2) / M
      const double se_cov =
          std::sqrt((exact_cov(i, i) * exact_cov(j, j) + exact_cov(i, j) * exact_cov(i, j)) / num_members);
      EXPECT_LT(std::abs(cov(i, j) - exact_cov(i, j)), 4.0 * se_cov)
          << "cov(" << i << "," << j << "): " << cov(i, j) << " exact " << exact_cov(i, j);
    }
  }
  LinearModel<2> off = model;  // power: a 10% error in the damping must show in the covariance or mean
  off.A(0, 0) *= 1.1;
  off.A(1, 1) *= 1.1;
  const auto [wrong_mean, wrong_cov] = linear_exact(off, 1.0);
  double worst = 0.0;
  for (int i = 0; i < 2; ++i)
    worst = std::max(worst, std::abs(mean(i) - wrong_mean(i)) / std::sqrt(exact_cov(i, i) / num_members));
  EXPECT_GT(worst, 4.0);
}

TEST(ClarkLinearEnsemble, DiscreteStepVarianceMatchesBoundedNoiseMoments) {
  ClarkLinearModel model;
  using Space = Kokkos::DefaultExecutionSpace;
  TruthBank<Space, ClarkLinearModel> bank(Space(), model, num_members, seed);
  const int steps = 20;
  for (int k = 0; k < steps; ++k) bank.step(k, 1.0);
  Space().fence();
  // x[K] = sum_j a^j w[K-1-j]: Var = Var(w) (1 - a^{2K}) / (1 - a^2); z = x + v, Var(v) = 1/3.
  const double var_w = model.w.moment(2);
  EXPECT_DOUBLE_EQ(var_w, 11.0 / 13.0);
  const double var_x = var_w * (1.0 - std::pow(model.a, 2 * steps)) / (1.0 - model.a * model.a);
  const auto [mx, cx] = sample_moments<1>(bank.state());
  const auto [mz, cz] = sample_moments<1>(bank.observations());
  // Var of a sample variance: (mu4 - sigma^4) / M; mu4 of x is bounded by that of w (kurtosis < 3 here), use 2 sigma^4.
  EXPECT_LT(std::abs(mx(0)), 4.0 * std::sqrt(var_x / num_members));
  EXPECT_LT(std::abs(cx(0, 0) - var_x), 4.0 * var_x * std::sqrt(2.0 / num_members)) << cx(0, 0) << " vs " << var_x;
  const double var_z = var_x + model.v.moment(2);
  EXPECT_LT(std::abs(cz(0, 0) - var_z), 4.0 * var_z * std::sqrt(2.0 / num_members)) << cz(0, 0) << " vs " << var_z;
}

TEST(EulerMaruyamaStep, SineStepMatchesHandComputation) {
  SineModel model;
  model.q = 0.7;
  model.r = 0.3;
  using Space = Kokkos::DefaultExecutionSpace;
  TruthBank<Space, SineModel> bank(Space(), model, 3, seed);
  const auto x0 = Kokkos::create_mirror(bank.state());  // a copy even when the bank lives in host memory
  Kokkos::deep_copy(x0, bank.state());
  const double dt = 0.01;
  bank.step(5, dt);
  Space().fence();
  const auto x1 = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), bank.state());
  const auto dy = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), bank.observations());
  for (int m = 0; m < 3; ++m) {
    // One block of the process-noise stream: dv its first normal, dw its second (p = q = 1).
    double dv, dw;
    normal_pair(RngKey{seed, Stream::process_noise}, Counter{std::uint32_t(m), 0, 5, 0}, dv, dw);
    const double x = x0(m, 0);
    // Equal to rounding: a GPU contracts a*b+c into one FMA and has its own sin, so allow 1e-13 of the
    // terms' magnitude (a wrong draw or step would be off by the noise term itself, ~1e-2).
    const double dx_noise = 0.7 * dw * std::sqrt(dt), dy_noise = 0.3 * dv * std::sqrt(dt);
    EXPECT_NEAR(x1(m, 0), x - std::sin(x) * dt + dx_noise, 1e-13 * (std::abs(x) + std::abs(dx_noise)));
    EXPECT_NEAR(dy(m, 0), x * dt + dy_noise, 1e-13 * (std::abs(x * dt) + std::abs(dy_noise)));
  }
}

/// TruthBank's steps (by blocks from truth_block_min_members on the host) and step_and_moments (in one pass there)
/// against a twin bank stepped by parallel_for_members' chunks, with ensemble_moments after each step: the same states
/// and the same moments, bit for bit, over whole blocks and a short one, with a member that escaped (left out of every
/// column by both).
template <class Space, class Model>
void expect_truth_steps_to_be_chunks_then_moments(const Model& model, const long members) {
  using MemSpace = typename Space::memory_space;
  TruthBank<Space, Model> bank(Space(), model, members, seed), chunks(Space(), model, members, seed);
  for (auto* b : {&bank, &chunks}) {
    auto x = b->state();
    const auto host = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), x);
    host(300, Model::state_dim - 1) = std::numeric_limits<double>::infinity();
    Kokkos::deep_copy(x, host);
  }
  const double dt = 1e-2;
  for (long k = 0; k < 4; ++k) {
    parallel_for_members("chunks", Space(), members,
                         TruthStep<Model, MemSpace>{model, chunks.state(), chunks.observations(), k * dt, dt,
                                                    Seed{seed}, static_cast<std::uint32_t>(k)});
    const EnsembleMoments expected = ensemble_moments(Space(), chunks.state());
    if (k % 2 == 1) {
      bank.step(k, dt);
      continue;
    }
    const EnsembleMoments a = bank.step_and_moments(k, dt);
    EXPECT_EQ(a.mean, expected.mean) << Model::name << ", " << members << " members, step " << k;
    EXPECT_EQ(a.variance, expected.variance) << Model::name << ", " << members << " members, step " << k;
    EXPECT_EQ(a.non_finite, 1) << Model::name << ", " << members << " members, step " << k;
    EXPECT_EQ(expected.non_finite, 1) << Model::name << ", " << members << " members, step " << k;
    EXPECT_EQ(a.members, members);
  }
  EXPECT_EQ(test::entries_not_the_same_bits(bank.state(), chunks.state()), 0) << Model::name << ", " << members;
  EXPECT_EQ(test::entries_not_the_same_bits(bank.observations(), chunks.observations()), 0)
      << Model::name << ", " << members;
}

template <class Space>
class StepAndMoments : public ::testing::Test {};
TYPED_TEST_SUITE(StepAndMoments, test::ExecutionSpaces);

TYPED_TEST(StepAndMoments, AreChunkStepsThenEnsembleMomentsBitForBit) {
  for (const long members : {3L * moment_block_size + 37, truth_block_min_members + 37}) {  // chunks; blocks
    expect_truth_steps_to_be_chunks_then_moments<TypeParam>(SineModel{}, members);
    expect_truth_steps_to_be_chunks_then_moments<TypeParam>(CubicOscillatorModel{}, members);
    expect_truth_steps_to_be_chunks_then_moments<TypeParam>(ClarkLinearModel{}, members);
  }
}

/// TruthBank::step_segment against a twin bank stepped one step at a time (step, step_and_moments): the same states,
/// observations and moments, bit for bit, over segments of 1, 3, 5 and truth_segment_steps steps with outputs
/// anywhere or none, whole blocks and a short one, with a member that escaped (left out of every column by both).
template <class Model>
void expect_segments_to_be_steps_one_at_a_time(const Model& model, const long members) {
  using Host = Kokkos::DefaultHostExecutionSpace;
  TruthBank<Host, Model> segments(Host(), model, members, seed), steps(Host(), model, members, seed);
  ASSERT_TRUE(segments.steps_in_segments()) << members << " members";
  for (auto* b : {&segments, &steps}) b->state()(300, Model::state_dim - 1) = std::numeric_limits<double>::infinity();
  std::vector<char> last_only(truth_segment_steps, 0);
  last_only.back() = 1;
  const double dt = 1e-2;
  long k = 0;
  for (const std::vector<char>& outputs :
       {std::vector<char>{1}, std::vector<char>{0, 1, 1, 0, 1}, last_only, std::vector<char>{0, 0, 0}}) {
    const std::vector<EnsembleMoments> got = segments.step_segment(k, dt, outputs);
    std::vector<EnsembleMoments> expected;
    for (const char output : outputs) {
      if (output != 0)
        expected.push_back(steps.step_and_moments(k, dt));
      else
        steps.step(k, dt);
      ++k;
    }
    ASSERT_EQ(got.size(), expected.size()) << Model::name << ", to step " << k;
    for (std::size_t o = 0; o < got.size(); ++o) {
      EXPECT_EQ(got[o].mean, expected[o].mean) << Model::name << ", to step " << k << ", output " << o;
      EXPECT_EQ(got[o].variance, expected[o].variance) << Model::name << ", to step " << k << ", output " << o;
      EXPECT_EQ(got[o].non_finite, 1) << Model::name << ", to step " << k << ", output " << o;
      EXPECT_EQ(got[o].members, members);
    }
  }
  EXPECT_EQ(test::entries_not_the_same_bits(segments.state(), steps.state()), 0) << Model::name;
  EXPECT_EQ(test::entries_not_the_same_bits(segments.observations(), steps.observations()), 0) << Model::name;
}

TEST(TruthSegments, AreStepsOneAtATimeBitForBit) {
  const long members = truth_block_min_members + 37;
  expect_segments_to_be_steps_one_at_a_time(SineModel{}, members);
  expect_segments_to_be_steps_one_at_a_time(CubicOscillatorModel{}, members);
  expect_segments_to_be_steps_one_at_a_time(ClarkLinearModel{}, members);
  using Host = Kokkos::DefaultHostExecutionSpace;
  EXPECT_FALSE(
      (TruthBank<Host, SineModel>(Host(), SineModel{}, truth_block_min_members - 1, seed).steps_in_segments()));
  TruthBank<Host, SineModel> bank(Host(), SineModel{}, members, seed);
  EXPECT_THROW(bank.step_segment(0, 1e-2, std::vector<char>(truth_segment_steps + 1, 0)), std::logic_error);
  EXPECT_THROW(bank.step_segment(0, 1e-2, {}), std::logic_error);
}

}  // namespace
}  // namespace kushner
