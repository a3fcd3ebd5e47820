// The particle-filter bank: one step against a hand computation, resampling bookkeeping, a diverged member
// staying isolated, and the GPU's team kernel (run here on the host) against the host's SIMD block kernel.
#include "drivers/simulate_ensemble.hpp"
#include "kernels/particle_filter/particle_filter_bank.hpp"
#include "models/cubic_oscillator_model.hpp"
#include "models/sine_model.hpp"
#include "tests/test_spaces.hpp"

#include <cmath>
#include <vector>

namespace kushner {
namespace {

constexpr std::uint32_t seed = 20261122;
using Host = Kokkos::DefaultHostExecutionSpace;

template <class View>
auto to_host(const View& v) {
  auto h = Kokkos::create_mirror(v);  // a copy even for host views: later steps must not change it
  Kokkos::deep_copy(h, v);
  return h;
}

/// Particle j's normal: the cosine (j even) or sine (j odd) normal of block {member, j / 2, step, 0}.
double normal_draw(Stream stream, int member, int particle, std::uint32_t step) {
  double z0, z1;
  normal_pair(RngKey{seed, stream}, Counter{std::uint32_t(member), std::uint32_t(particle / 2), step, 0}, z0, z1);
  return particle % 2 == 0 ? z0 : z1;
}

class ParticleKernels : public ::testing::TestWithParam<ParticleKernel> {};

TEST_P(ParticleKernels, FirstStepMatchesHandComputation) {
  SineModel model;
  model.prior_mean[0] = 0.3;
  model.prior_cov(0, 0) = 0.5;
  const int members = 3, particles = 301;  // more than one host block; odd: the last particle has no pair
  ParticleFilterOptions options;
  options.kernel = GetParam();
  options.ess_threshold = 0.0;  // no resampling: the weights must be exactly the likelihoods
  ParticleFilterBank<Host, SineModel> pf(Host(), model, members, particles, seed, options);
  BankVector<Kokkos::HostSpace> dy("dy", members, 1);
  for (int m = 0; m < members; ++m) dy(m, 0) = 0.01 * (m - 1);
  const double dt = 0.01;
  pf.step(4, dt, dy);
  Host().fence();
  const auto x = pf.particles();
  const auto lw = pf.log_weights();
  const auto mean = pf.posterior_mean();
  const auto cov = pf.posterior_covariance();
  const auto ess = pf.effective_sample_size();
  // libmvec's sin/cos/log in the block kernel are within a few ulp of libm's: compare to 1e-13.
  const double tol = 1e-13;
  for (int m = 0; m < members; ++m) {
    double sw = 0.0, swx = 0.0, swxx = 0.0, sww = 0.0;
    for (int j = 0; j < particles; ++j) {
      const double x0 = 0.3 + std::sqrt(0.5) * normal_draw(Stream::particle_initial, m, j, 0);
      const double x1 = x0 - std::sin(x0) * dt + model.q * std::sqrt(dt) * normal_draw(Stream::particle_noise, m, j, 4);
      const double l = (x1 * dy(m, 0) - 0.5 * dt * x1 * x1) / (model.r * model.r) - std::log(double(particles));
      ASSERT_NEAR(x(j, m, 0), x1, tol * (1 + std::abs(x1))) << "member " << m << " particle " << j;
      ASSERT_NEAR(lw(j, m), l, tol * (1 + std::abs(l)));
      const double w = std::exp(l);
      sw += w, swx += w * x1, swxx += w * x1 * x1, sww += w * w;
    }
    const double mu = swx / sw;
    EXPECT_NEAR(mean(m, 0), mu, 1e-12);
    EXPECT_NEAR(cov(m, 0), swxx / sw - mu * mu, 1e-12);
    EXPECT_NEAR(ess(m), sw * sw / sww, 1e-9 * particles);
    EXPECT_NEAR(pf.log_normalizer()(m), std::log(sw), 1e-12);
    EXPECT_DOUBLE_EQ(pf.monte_carlo_standard_error()(m, 0), std::sqrt(cov(m, 0) / ess(m)));
  }
}

TEST_P(ParticleKernels, ResamplesWhenEssFallsAndResetsTheWeights) {
  SineModel model;
  const int members = 4, particles = 512;
  ParticleFilterOptions options;
  options.kernel = GetParam();
  options.ess_threshold = 1.0;  // ESS < N after any informative step: resample every step
  ParticleFilterBank<Host, SineModel> pf(Host(), model, members, particles, seed, options);
  BankVector<Kokkos::HostSpace> dy("dy", members, 1);
  Kokkos::deep_copy(dy, 0.05);
  const auto before = to_host(pf.particles());
  pf.step(0, 0.01, dy);
  Host().fence();
  for (int m = 0; m < members; ++m) {
    EXPECT_EQ(pf.resample_count()(m), 1);
    EXPECT_LT(pf.effective_sample_size()(m), particles);
    EXPECT_DOUBLE_EQ(pf.log_normalizer()(m), std::log(double(particles)));
    for (int j = 0; j < particles; ++j) EXPECT_EQ(pf.log_weights()(j, m), 0.0);
  }
  options.ess_threshold = 0.0;
  ParticleFilterBank<Host, SineModel> never(Host(), model, members, particles, seed, options);
  never.step(0, 0.01, dy);
  Host().fence();
  // Resampled particles are copies of propagated ones: every value appears in the unresampled bank.
  for (int m = 0; m < members; ++m) {
    EXPECT_EQ(never.resample_count()(m), 0);
    std::vector<double> propagated(particles);
    for (int j = 0; j < particles; ++j) propagated[j] = never.particles()(j, m, 0);
    std::sort(propagated.begin(), propagated.end());
    for (int j = 0; j < particles; ++j)
      EXPECT_TRUE(std::binary_search(propagated.begin(), propagated.end(), pf.particles()(j, m, 0)));
  }
  (void)before;
}

TEST_P(ParticleKernels, NonFiniteObservationKillsOnlyThatMember) {
  CubicOscillatorModel model;
  model.prior_mean = Vec<2>{{1.0, 0.5}};
  model.prior_cov = Mat<2, 2>::diagonal(0.1);
  const int members = 3, particles = 700;
  ParticleFilterOptions options;
  options.kernel = GetParam();
  ParticleFilterBank<Host, CubicOscillatorModel> pf(Host(), model, members, particles, seed, options);
  BankVector<Kokkos::HostSpace> dy("dy", members, 2);
  Kokkos::deep_copy(dy, 0.01);
  for (int k = 0; k < 20; ++k) {
    dy(1, 0) = k == 5 ? std::nan("") : 0.01;
    pf.step(k, 0.01, dy);
  }
  Host().fence();
  EXPECT_EQ(pf.status()(0), Status::ok);
  EXPECT_EQ(pf.status()(1), Status::non_finite);
  EXPECT_EQ(pf.status()(2), Status::ok);
  EXPECT_TRUE(std::isfinite(pf.posterior_mean()(0, 0)) && std::isfinite(pf.posterior_mean()(2, 1)));
  EXPECT_EQ(pf.effective_sample_size()(1), 0.0);
}

INSTANTIATE_TEST_SUITE_P(HostAndTeam, ParticleKernels,
                         ::testing::Values(ParticleKernel::host_block, ParticleKernel::team),
                         [](const auto& info) { return info.param == ParticleKernel::team ? "team" : "host_block"; });

/// Runs a sine bank for `steps` steps with truths from seed 7 and returns the posterior means (member-major).
template <class Space>
std::vector<double> run_sine(int members, int particles, int steps, ParticleFilterOptions options,
                             std::vector<double>* covariance = nullptr, std::vector<double>* ess = nullptr) {
  SineModel model;
  TruthBank<Space, SineModel> truth(Space(), model, members, 7);
  ParticleFilterBank<Space, SineModel> pf(Space(), model, members, particles, seed, options);
  for (int k = 0; k < steps; ++k) {
    truth.step(k, 1e-2);
    pf.step(k, 1e-2, truth.observations());
  }
  Space().fence();
  const auto mean = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), pf.posterior_mean());
  const auto cov = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), pf.posterior_covariance());
  const auto e = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), pf.effective_sample_size());
  std::vector<double> out;
  for (int m = 0; m < members; ++m) {
    out.push_back(mean(m, 0));
    if (covariance) covariance->push_back(cov(m, 0));
    if (ess) ess->push_back(e(m));
  }
  return out;
}

TEST(ParticleFilterBank, TeamKernelAgreesWithHostBlockKernel) {
  // The GPU's kernel, run on the host, against the host kernel: the same particles up to libmvec's last bits,
  // through 200 steps with resampling (the rare index flip at a cumulative-weight boundary would show here).
  ParticleFilterOptions block, team;
  block.kernel = ParticleKernel::host_block;
  team.kernel = ParticleKernel::team;
  team.team_size = std::min(2, Host::concurrency());
  std::vector<double> cb, ct, eb, et;
  const auto mb = run_sine<Host>(16, 2000, 200, block, &cb, &eb);
  const auto mt = run_sine<Host>(16, 2000, 200, team, &ct, &et);
  for (int m = 0; m < 16; ++m) {
    EXPECT_NEAR(mt[m], mb[m], 1e-12 * (1 + std::abs(mb[m]))) << m;
    EXPECT_NEAR(ct[m], cb[m], 1e-12 * cb[m]) << m;
    EXPECT_NEAR(et[m], eb[m], 1e-10 * eb[m]) << m;
  }
}

TEST(ParticleFilterBank, TeamKernelResumsWhenTheWeightBoundIsFarOff) {
  // The team kernel sums exp(l - s) with s = dy^T V^-1 dy / (2 dt), the largest log-weight any particle could
  // get. A large dy puts s hundreds of nats above every particle's l: the kernel must notice and sum again
  // relative to the largest l (member 1), and give what the host kernel (exact block maxima) gives.
  SineModel model;
  const int members = 3, particles = 3000;
  ParticleFilterOptions block, team;
  block.kernel = ParticleKernel::host_block;
  block.ess_threshold = team.ess_threshold = 0.0;  // keep the weights: the next steps start from them
  team.kernel = ParticleKernel::team;
  ParticleFilterBank<Host, SineModel> pb(Host(), model, members, particles, seed, block);
  ParticleFilterBank<Host, SineModel> pt(Host(), model, members, particles, seed, team);
  BankVector<Kokkos::HostSpace> dy("dy", members, 1);
  for (int k = 0; k < 3; ++k) {
    dy(0, 0) = 0.01;
    dy(1, 0) = k == 1 ? 30.0 : 0.01;  // s - max l ~ 0.5 * 30^2 / 0.01 at step 1
    dy(2, 0) = -0.02;
    pb.step(k, 0.01, dy);
    pt.step(k, 0.01, dy);
  }
  Host().fence();
  for (int m = 0; m < members; ++m) {
    ASSERT_EQ(pt.status()(m), Status::ok) << m;
    EXPECT_NEAR(pt.posterior_mean()(m, 0), pb.posterior_mean()(m, 0), 1e-12 * (1 + std::abs(pb.posterior_mean()(m, 0)))) << m;
    EXPECT_NEAR(pt.posterior_covariance()(m, 0), pb.posterior_covariance()(m, 0), 1e-12 * pb.posterior_covariance()(m, 0)) << m;
    EXPECT_NEAR(pt.effective_sample_size()(m), pb.effective_sample_size()(m), 1e-10 * pb.effective_sample_size()(m)) << m;
    EXPECT_NEAR(pt.log_normalizer()(m), pb.log_normalizer()(m), 1e-12 * (1 + std::abs(pb.log_normalizer()(m)))) << m;
  }
  EXPECT_LT(pt.effective_sample_size()(1), 0.1 * particles);  // the outlying dy did concentrate the weights
}

TEST(ParticleFilterBank, RejectsBadSizesAndThresholds) {
  SineModel model;
  EXPECT_THROW((ParticleFilterBank<Host, SineModel>(Host(), model, 2, 0, seed)), InputError);
  try {
    ParticleFilterBank<Host, SineModel>(Host(), model, 2, 16, seed, ResamplingScheme::systematic, 1.5);
    FAIL() << "threshold 1.5 accepted";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "--ess-threshold: must be in [0, 1] (got 1.5)");
  }
  EXPECT_THROW(parse_resampling_scheme("systemic"), InputError);
  EXPECT_EQ(parse_resampling_scheme("residual"), ResamplingScheme::residual);
}

#if defined(KOKKOS_ENABLE_CUDA)
TEST(ParticleFilterBank, DeviceMatchesHostToTwelveDigits) {
  // Same counters, same fixed-order sums; only the math libraries differ (CUDA's vs glibc's, each within
  // an ulp or two), through 150 steps with resampling and every resampling scheme.
  for (auto scheme : {ResamplingScheme::systematic, ResamplingScheme::stratified, ResamplingScheme::multinomial,
                      ResamplingScheme::residual}) {
    ParticleFilterOptions options;
    options.scheme = scheme;
    std::vector<double> ch, cd, eh, ed;
    const auto mh = run_sine<Kokkos::DefaultHostExecutionSpace>(12, 5000, 150, options, &ch, &eh);
    const auto md = run_sine<Kokkos::Cuda>(12, 5000, 150, options, &cd, &ed);
    for (int m = 0; m < 12; ++m) {
      EXPECT_NEAR(md[m], mh[m], 1e-12 * std::abs(mh[m]) + 1e-14) << to_string(scheme) << " member " << m;
      EXPECT_NEAR(cd[m], ch[m], 1e-12 * ch[m]) << to_string(scheme) << " member " << m;
      EXPECT_NEAR(ed[m], eh[m], 1e-12 * eh[m]) << to_string(scheme) << " member " << m;
    }
  }
}
#endif

#if defined(KOKKOS_ENABLE_SERIAL) && defined(KOKKOS_ENABLE_OPENMP)
TEST(ParticleFilterBank, SerialAndOpenMPGiveTheSameBits) {
  for (auto scheme : {ResamplingScheme::systematic, ResamplingScheme::residual}) {
    ParticleFilterOptions options;
    options.scheme = scheme;
    std::vector<double> cs, co, es, eo;
    const auto ms = run_sine<Kokkos::Serial>(12, 1000, 150, options, &cs, &es);
    const auto mo = run_sine<Kokkos::OpenMP>(12, 1000, 150, options, &co, &eo);
    EXPECT_EQ(ms, mo) << to_string(scheme);
    EXPECT_EQ(cs, co);
    EXPECT_EQ(es, eo);
  }
}
#endif

}  // namespace
}  // namespace kushner
