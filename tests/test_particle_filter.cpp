// The particle-filter bank: one step against a hand computation, resampling bookkeeping, a diverged member
// staying isolated, and the GPU's team kernel (run here on the host) against the host's SIMD block kernel.
#include "engine/particle_filter_bank.hpp"
#include "engine/truth_bank.hpp"
#include "models/benes_model.hpp"
#include "models/cubic_oscillator_model.hpp"
#include "models/sine_model.hpp"
#include "tests/test_spaces.hpp"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <memory>
#include <string>
#include <type_traits>
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

/// A bank of `members` members of 700 particles of the cubic oscillator near (1, 0.5), for the tests that kill a
/// member with a non-finite observation.
std::unique_ptr<ParticleFilterBank<Host, CubicOscillatorModel>> oscillator_bank(int members, ParticleKernel kernel) {
  CubicOscillatorModel model;
  model.prior_mean = Vec<2>{{1.0, 0.5}};
  model.prior_cov = Mat<2, 2>::diagonal(0.1);
  ParticleFilterOptions options;
  options.kernel = kernel;
  return std::make_unique<ParticleFilterBank<Host, CubicOscillatorModel>>(Host(), model, members, 700, seed, options);
}

TEST(ParticleFilterBank, StepPairsFirstStepHasTheStatusAfterIt) {
  // A member killed by a non-finite observation at the first step of a fused pair: first_step() says so (the
  // reference's first scores read it), the other members stay ok.
  const int members = 3;
  auto pf = oscillator_bank(members, ParticleKernel::team);
  ASSERT_TRUE(pf->fuses_step_pairs());
  BankVector<Kokkos::HostSpace> dy("dy", members, 2), dy_next("dy_next", members, 2);
  Kokkos::deep_copy(dy, 0.01);
  Kokkos::deep_copy(dy_next, 0.01);
  for (int k = 0; k < 8; k += 2) {
    dy(1, 0) = k == 4 ? std::nan("") : 0.01;
    pf->step_pair(k, 0.01, dy, dy_next);
    Host().fence();
    EXPECT_EQ(pf->first_step().status(0), Status::ok) << k;
    EXPECT_EQ(pf->first_step().status(1), k < 4 ? Status::ok : Status::non_finite) << k;
    EXPECT_EQ(pf->first_step().status(2), Status::ok) << k;
  }
  EXPECT_EQ(pf->status()(1), Status::non_finite);
}

TEST_P(ParticleKernels, NonFiniteObservationKillsOnlyThatMember) {
  const int members = 3;
  auto owned = oscillator_bank(members, GetParam());
  auto& pf = *owned;
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

/// Runs a sine bank for `steps` steps with truths from seed 7 and returns the posterior means (member-major);
/// with `pairs`, two steps per step_pair call (steps even). Particles stored in float for the fp32 precision.
template <class Space, class Real = double>
std::vector<double> run_sine_stored(int members, int particles, int steps, ParticleFilterOptions options,
                                    std::vector<double>* covariance, std::vector<double>* ess, bool pairs) {
  SineModel model;
  TruthBank<Space, SineModel> truth(Space(), model, members, 7);
  ParticleFilterBank<Space, SineModel, Real> pf(Space(), model, members, particles, seed, options);
  BankVector<typename Space::memory_space> first_dy("first_dy", members, 1);
  for (int k = 0; k < steps; k += pairs ? 2 : 1) {
    truth.step(k, 1e-2);
    if (!pairs) {
      pf.step(k, 1e-2, truth.observations());
      continue;
    }
    Kokkos::deep_copy(first_dy, truth.observations());
    truth.step(k + 1, 1e-2);
    pf.step_pair(k, 1e-2, first_dy, truth.observations());
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
template <class Space>
std::vector<double> run_sine(int members, int particles, int steps, ParticleFilterOptions options,
                             std::vector<double>* covariance = nullptr, std::vector<double>* ess = nullptr,
                             bool pairs = false) {
  return with_particle_storage(options.precision, [&](auto* stored) {
    using Real = std::remove_pointer_t<decltype(stored)>;
    return run_sine_stored<Space, Real>(members, particles, steps, options, covariance, ess, pairs);
  });
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

/// The runs of the two re-sum tests: 5 steps of dt = 0.01, member 1's increment `outlier` at steps 1 and 4 (the
/// other members' small), taken by the host kernel (`host`), the team kernel a step at a time (`team`) and in pairs
/// (`pairs`: steps (1, 2) and (3, 4), so the outlier is once in a pair's first step and once in its second).
/// after(k) checks the banks after step k.
template <class Bank, class After>
void step_through_outliers(Bank& host, Bank& team, Bank& pairs, double outlier, const After& after) {
  std::vector<BankVector<Kokkos::HostSpace>> dy;
  for (int k = 0; k < 5; ++k) {
    dy.emplace_back("dy", host.num_members(), 1);
    dy[k](0, 0) = 0.01;
    dy[k](1, 0) = k == 1 || k == 4 ? outlier : 0.01;
    dy[k](2, 0) = -0.02;
  }
  for (int k = 0; k < 5; ++k) {
    host.step(k, 0.01, dy[k]);
    team.step(k, 0.01, dy[k]);
    if (k == 0) pairs.step(k, 0.01, dy[k]);
    if (k == 2 || k == 4) pairs.step_pair(k - 1, 0.01, dy[k - 1], dy[k]);
    Host().fence();
    after(k);
  }
}

TEST(ParticleFilterBank, TeamKernelResumsWhenTheWeightBoundIsFarOff) {
  // The team kernel sums exp(l - s) with s = dy^T V^-1 dy / (2 dt), the largest log-weight any particle could
  // get. A large dy puts s hundreds of nats above every particle's l: the kernel must notice and sum again
  // relative to the largest l (member 1), and give what the host kernel (exact block maxima) gives. Also for
  // step_pair, with the outlier in the first step of a pair (summed again by recomputing that step) and in
  // the second (from the stored particles).
  SineModel model;
  const int members = 3, particles = 3000;
  ParticleFilterOptions block, team;
  block.kernel = ParticleKernel::host_block;
  block.ess_threshold = team.ess_threshold = 0.0;  // keep the weights: the next steps start from them
  team.kernel = ParticleKernel::team;
  ParticleFilterBank<Host, SineModel> pb(Host(), model, members, particles, seed, block);
  ParticleFilterBank<Host, SineModel> pt(Host(), model, members, particles, seed, team);
  ParticleFilterBank<Host, SineModel> pp(Host(), model, members, particles, seed, team);
  auto expect_agree = [&](const ParticleFilterBank<Host, SineModel>& p, const char* which, int k) {
    Host().fence();
    for (int m = 0; m < members; ++m) {
      ASSERT_EQ(p.status()(m), Status::ok) << which << " step " << k << " member " << m;
      const double mean = pb.posterior_mean()(m, 0), cov = pb.posterior_covariance()(m, 0);
      EXPECT_NEAR(p.posterior_mean()(m, 0), mean, 1e-12 * (1 + std::abs(mean)))
          << which << " step " << k << " member " << m;
      EXPECT_NEAR(p.posterior_covariance()(m, 0), cov, 1e-12 * cov) << which << " step " << k << " member " << m;
      EXPECT_NEAR(p.effective_sample_size()(m), pb.effective_sample_size()(m), 1e-10 * pb.effective_sample_size()(m))
          << which << " step " << k << " member " << m;
      // The normalized log-weights (step_pair leaves the stored ones relative to an earlier normalizer).
      int worst = 0;
      double worst_excess = -1.0;
      for (int j = 0; j < particles; ++j) {
        const double want = pb.log_weights()(j, m) - pb.log_normalizer()(m);
        const double got = p.log_weights()(j, m) - p.log_normalizer()(m);
        const double excess =
            std::abs(got - want) - 1e-12 * (1 + std::abs(pb.log_weights()(j, m)) + std::abs(pb.log_normalizer()(m)));
        if (excess > worst_excess) worst_excess = excess, worst = j;
      }
      EXPECT_LE(worst_excess, 0.0) << which << " step " << k << " member " << m << " particle " << worst;
    }
  };
  // s - max l ~ 0.5 * 30^2 / 0.01 at the outlier's steps
  step_through_outliers(pb, pt, pp, 30.0, [&](int k) {
    expect_agree(pt, "step", k);
    if (k == 1) {
      EXPECT_LT(pt.effective_sample_size()(1), 0.1 * particles);  // the outlier did concentrate the weights
    }
    if (k % 2 == 0) expect_agree(pp, "step_pair", k);
  });
}

/// Under fp32 and mixed (for sine: its kernels of its own) the team kernel takes exp(l - s) in float, whose normal
/// numbers end near e^-87. A dy that puts the bound s about 100 nats above every particle's l (inside fp64's 200-nat
/// gap, past float's range) must make the team sum again relative to its largest l, and give the host kernel's
/// posterior (block maxima, exp in double): the same particles up to a float's last bits, so to 1e-5. Also for
/// step_pair, the outlier in each of its steps.
template <class Real>
void expect_float_exp_team_kernel_resums(ParticlePrecision precision) {
  SineModel model;
  const int members = 3, particles = 3000;
  ParticleFilterOptions block, team;
  block.kernel = ParticleKernel::host_block;
  team.kernel = ParticleKernel::team;
  block.precision = team.precision = precision;
  block.ess_threshold = team.ess_threshold = 0.0;
  using Bank = ParticleFilterBank<Host, SineModel, Real>;
  Bank pb(Host(), model, members, particles, seed, block);
  Bank pt(Host(), model, members, particles, seed, team);
  Bank pp(Host(), model, members, particles, seed, team);
  auto expect_agree = [&](const Bank& p, const char* which, int k) {
    Host().fence();
    for (int m = 0; m < members; ++m) {
      ASSERT_EQ(p.status()(m), Status::ok) << which << " step " << k << " member " << m;
      const double mean = pb.posterior_mean()(m, 0), cov = pb.posterior_covariance()(m, 0);
      EXPECT_NEAR(p.posterior_mean()(m, 0), mean, 1e-5 * (1 + std::abs(mean)))
          << which << " step " << k << " member " << m;
      EXPECT_NEAR(p.posterior_covariance()(m, 0), cov, 1e-5 * cov) << which << " step " << k << " member " << m;
    }
  };
  step_through_outliers(pb, pt, pp, 0.7, [&](int k) {  // s = 0.7^2 / (2 r^2 dt) = 98 nats at the outlier's steps
    if (k == 1) {  // the largest l of the outlier member lies between float's range and fp64's 200 nats below s
      double top = -math::infinity();
      for (int j = 0; j < particles; ++j) top = std::max(top, double(pb.log_weights()(j, 1)));
      const double gap = 0.5 * 0.7 * 0.7 / (model.r * model.r * 0.01) - top;  // stored l: already normalized
      std::cout << "outlier: largest log-weight " << gap << " nats below the bound\n";
      EXPECT_GT(gap, 90.0);
      EXPECT_LT(gap, 200.0);
    }
    expect_agree(pt, "step", k);
    if (k % 2 == 0) expect_agree(pp, "step_pair", k);
  });
}

TEST(ParticleFilterBank, FloatExpTeamKernelsResumWhereItUnderflows) {
  expect_float_exp_team_kernel_resums<float>(ParticlePrecision::fp32);
  expect_float_exp_team_kernel_resums<double>(ParticlePrecision::mixed);
}

/// Posterior mean, covariance and ESS of every member, and the resampling counts.
struct PosteriorCopy {
  std::vector<double> mean, covariance, ess;
  std::vector<int> resamples;
};
template <class Bank, class Views>
PosteriorCopy copy_posterior(const Bank& pf, const Views& v) {
  Kokkos::fence();
  PosteriorCopy c;
  for (int m = 0; m < pf.num_members(); ++m) {
    c.mean.push_back(v.mean(m, 0));
    c.covariance.push_back(v.covariance(m, 0));
    c.ess.push_back(v.ess(m));
    c.resamples.push_back(pf.resample_count()(m));
  }
  return c;
}
void expect_close(const PosteriorCopy& got, const PosteriorCopy& want, const std::string& where) {
  for (std::size_t m = 0; m < want.mean.size(); ++m) {
    EXPECT_NEAR(got.mean[m], want.mean[m], 1e-12 * (1 + std::abs(want.mean[m]))) << where << " member " << m;
    EXPECT_NEAR(got.covariance[m], want.covariance[m], 1e-12 * want.covariance[m]) << where << " member " << m;
    EXPECT_NEAR(got.ess[m], want.ess[m], 1e-10 * want.ess[m]) << where << " member " << m;
  }
}

TEST(ParticleFilterBank, MixedAndFp32TeamKernelAgreesWithHostBlockKernel) {
  // With fp32 normals the two kernels' float math libraries (libmvec's logf and cosf in SIMD lanes, libm's scalar ones)
  // may differ in a float's last bit, about 1e-7 of a normal: after 40 steps with resampling mixed's posteriors agree
  // to that level. fp32 steps the sine particles in float (sinf in SIMD lanes or not) and the team kernel takes the
  // weights' exp in float, relative to a shift rounded to float: weights that differ by 1e-7 can move a systematic
  // point across a particle, which moves the mean by about a particle's distance over N (measured 4.4e-7 here; 3.0e-4
  // with earlier kernels). Against the finer precision they differ: mixed from fp64 by its normals' and float
  // increments' rounding, by less than 10 particles' distance over N (measured 2.4e-5, where it moved a systematic
  // point across a particle; 1.6e-7 when only the normals were floats). fp32 from mixed: by that much after one step
  // (step 0 takes mixed's normals), by its float steps and cumulative weights; after 40 by the normals of its odd steps
  // (two steps from one block: fp32_pair_normals), a Monte Carlo difference. Two runs of independent particles differ
  // on this sine model by up to 8.4 sd / sqrt(N) after 40 steps (seed 20261122 against 20261123, mixed: some posteriors
  // are bimodal, and resampling adds its own error), so fp32 against mixed is held to the median over members: within
  // 3 sqrt(2) sd / sqrt(N) (measured 0.17 of it; the largest member 3.3).
  for (auto precision : {ParticlePrecision::mixed, ParticlePrecision::fp32}) {
    ParticleFilterOptions block, team;
    block.kernel = ParticleKernel::host_block;
    team.kernel = ParticleKernel::team;
    team.team_size = std::min(2, Host::concurrency());
    block.precision = team.precision = precision;
    const auto mb = run_sine<Host>(16, 2000, 40, block);
    const auto mt = run_sine<Host>(16, 2000, 40, team);
    ParticleFilterOptions finer = block;
    finer.precision = precision == ParticlePrecision::fp32 ? ParticlePrecision::mixed : ParticlePrecision::fp64;
    const bool fp32 = precision == ParticlePrecision::fp32;
    std::vector<double> variance;
    const auto md = run_sine<Host>(16, 2000, 40, finer, &variance);
    const auto mb1 = run_sine<Host>(16, 2000, 1, block), md1 = run_sine<Host>(16, 2000, 1, finer);
    double kernels = 0.0, precisions = 0.0, one_step = 0.0;
    std::vector<double> monte_carlo;  // fp32: |fp32 - mixed| over 3 sqrt(2) sd / sqrt(N), per member
    for (int m = 0; m < 16; ++m) {
      kernels = std::max(kernels, std::abs(mt[m] - mb[m]) / (1 + std::abs(mb[m])));
      precisions = std::max(precisions, std::abs(md[m] - mb[m]) / (1 + std::abs(mb[m])));
      one_step = std::max(one_step, std::abs(md1[m] - mb1[m]) / (1 + std::abs(mb1[m])));
      monte_carlo.push_back(std::abs(md[m] - mb[m]) / (3.0 * std::sqrt(2.0 * variance[m] / 2000)));
    }
    std::nth_element(monte_carlo.begin(), monte_carlo.begin() + 8, monte_carlo.end());
    std::cout << to_string(precision) << ": team vs host kernel " << kernels << ", against "
              << to_string(finer.precision) << " " << precisions << " (median " << monte_carlo[8]
              << " of two independent runs' bound), after one step " << one_step << "\n";
    EXPECT_LT(kernels, fp32 ? 10.0 / 2000 : 1e-5) << to_string(precision);
    EXPECT_GT(precisions, 1e-12) << to_string(precision);
    EXPECT_GT(one_step, 1e-12) << to_string(precision);
    EXPECT_LT(one_step, 10.0 / 2000) << to_string(precision);
    if (fp32)
      EXPECT_LT(monte_carlo[8], 1.0);
    else
      EXPECT_LT(precisions, 10.0 / 2000);
  }
}

TEST(ParticleFilterBank, Fp32StoresFloatsAndItsPosteriorIsTheirs) {
  // fp32 keeps particles and log-weights in float: its initial particles are mixed's (the same float normals)
  // rounded once; after steps with resampling, its posterior mean and covariance are the weighted moments of
  // the stored floats (summed in double: to 1e-12) where the last step did not resample (a step's posterior comes
  // before its resampling, which replaces the stored particles), and a particle's bytes are half of fp64's.
  SineModel model;
  const int members = 5, particles = 700;
  ParticleFilterOptions mixed, fp32;
  mixed.precision = ParticlePrecision::mixed;
  fp32.precision = ParticlePrecision::fp32;
  mixed.ess_threshold = fp32.ess_threshold = 0.8;  // resample often
  ParticleFilterBank<Host, SineModel> pm(Host(), model, members, particles, seed, mixed);
  ParticleFilterBank<Host, SineModel, float> pf(Host(), model, members, particles, seed, fp32);
  Host().fence();
  static_assert(std::is_same_v<std::decay_t<decltype(pf.particles())>::value_type, float>);
  for (int m = 0; m < members; ++m)
    for (int j = 0; j < particles; ++j) ASSERT_EQ(pf.particles()(j, m, 0), static_cast<float>(pm.particles()(j, m, 0)));
  TruthBank<Host, SineModel> truth(Host(), model, members, 7);
  std::vector<int> resamples_before_last(members);
  for (int k = 0; k < 30; ++k) {
    truth.step(k, 1e-2);
    Host().fence();
    for (int m = 0; m < members; ++m) resamples_before_last[m] = pf.resample_count()(m);
    pf.step(k, 1e-2, truth.observations());
  }
  Host().fence();
  int resamples = 0, checked = 0;
  for (int m = 0; m < members; ++m) {
    resamples += pf.resample_count()(m);
    if (pf.resample_count()(m) != resamples_before_last[m]) continue;
    ++checked;
    double sw = 0.0, swx = 0.0, swxx = 0.0;
    for (int j = 0; j < particles; ++j) {
      const double w = std::exp(static_cast<double>(pf.log_weights()(j, m)) - pf.log_normalizer()(m));
      const double x = pf.particles()(j, m, 0);
      sw += w, swx += w * x, swxx += w * x * x;
    }
    const double mean = swx / sw;
    EXPECT_NEAR(sw, 1.0, 1e-12) << "member " << m;
    EXPECT_NEAR(pf.posterior_mean()(m, 0), mean, 1e-12 * (1 + std::abs(mean))) << "member " << m;
    EXPECT_NEAR(pf.posterior_covariance()(m, 0), swxx / sw - mean * mean, 1e-9) << "member " << m;
  }
  EXPECT_GT(resamples, 0);
  EXPECT_GE(checked, 2);
  using Fp64 = ParticleFilterBank<Host, SineModel>;
  EXPECT_EQ(Fp64::bytes_per_particle(fp32) - sizeof(int), (Fp64::bytes_per_particle(mixed) - sizeof(int)) / 2);
}

/// update_particle's step of one particle from x with normals z, in a bank that stores Real; with FloatIncrements as
/// mixed's kernels take it.
template <class Model, class Real, bool FloatIncrements = false>
double step_one_particle(const Model& model, const Vec<Model::noise_dim>& z, Vec<Model::state_dim>& x) {
  ParticleStepData<Model, Kokkos::HostSpace, Real> d;
  d.model = model;
  d.set_step_length(0.01);
  Mat<Model::obs_dim, Model::obs_dim> precision = Mat<Model::obs_dim, Model::obs_dim>::diagonal(4.0);
  const Vec<Model::obs_dim> vinv_dy = Vec<Model::obs_dim>::constant(0.013);
  return update_particle<false, FloatIncrements>(d, 0.0, precision, z, 0.0, -7.25, 0.125, vinv_dy,
                                                 Model::Control::zero(), x);
}

/// step_one_particle's step of a particle held in float between steps, as fp32's team kernels hold a model's particles
/// whose step computes in float (update_particle's float overload), from x0 with log-weight lw.
template <class Model>
float step_one_held_particle(const Model& model, const Vec<Model::noise_dim>& z, float lw,
                             Vec<Model::state_dim, float>& x) {
  ParticleStepData<Model, Kokkos::HostSpace, float> d;
  d.model = model;
  d.set_step_length(0.01);
  const Mat<Model::obs_dim, Model::obs_dim> precision = Mat<Model::obs_dim, Model::obs_dim>::diagonal(4.0);
  const Vec<Model::obs_dim> vinv_dy = Vec<Model::obs_dim>::constant(0.013);
  return update_particle<false>(d, 0.0, precision, z, 0.0, lw, 0.125, vinv_dy, Model::Control::zero(), x);
}

TEST(ParticleFilterBank, Fp32StepsInFloatWhereTheModelTakesFloat) {
  // fp32 computes a particle's Euler-Maruyama step in float where the model's dynamics take float (cheaper on a
  // GPU); elsewhere in double, rounded once where stored (models without float dynamics, exact transitions).
  static_assert(std::is_same_v<particle_step_scalar<SineModel, float>, float>);
  static_assert(std::is_same_v<particle_step_scalar<SineModel, double>, double>);
  static_assert(std::is_same_v<particle_step_scalar<CubicOscillatorModel, float>, double>);
  SineModel sine;
  CubicOscillatorModel cubic;
  int sine_rounded_differently = 0;
  for (int k = 0; k < 2000; ++k) {
    const double x0 = -3.0 + 6.0 * (k + 0.5) / 2000, z = std::sin(1e3 * k);
    // Sine in float: against the float expression written out here (to a few float ulps: the compilers may fuse
    // the multiply-adds differently), and, for some particles, not what the double step rounds to.
    Vec<1> xf{{x0}}, xd{{x0}};
    const double lf = step_one_particle<SineModel, float>(sine, Vec<1>{{z}}, xf);
    const double ld = step_one_particle<SineModel, double>(sine, Vec<1>{{z}}, xd);
    float x1 = static_cast<float>(x0);
    x1 = x1 + (-std::sin(x1)) * 0.01f + static_cast<float>(sine.q) * (static_cast<float>(z) * std::sqrt(0.01f));
    const float l1 = static_cast<float>(-7.25 - 0.125) + (x1 * 0.013f - 0.005f * (x1 * (4.0f * x1)));
    ASSERT_NEAR(xf[0], x1, 4e-7 * (1 + std::abs(x1))) << x0;
    ASSERT_NEAR(lf, l1, 4e-7 * std::abs(l1)) << x0;
    ASSERT_EQ(xf[0], static_cast<double>(static_cast<float>(xf[0])));  // stored as float
    sine_rounded_differently += xf[0] != static_cast<double>(static_cast<float>(xd[0]));
    // Held in float from load to store (the team kernels): the same bits.
    Vec<1, float> held{{static_cast<float>(x0)}};
    ASSERT_EQ(step_one_held_particle(sine, Vec<1>{{z}}, -7.25f, held), lf) << x0;
    ASSERT_EQ(held[0], xf[0]) << x0;
    // The cubic oscillator's dynamics are double-only: its fp32 step is the fp64 step rounded once.
    Vec<2> cf{{x0, 0.5 * x0}}, cd{{x0, 0.5 * x0}};
    const double clf = step_one_particle<CubicOscillatorModel, float>(cubic, Vec<1>{{z}}, cf);
    const double cld = step_one_particle<CubicOscillatorModel, double>(cubic, Vec<1>{{z}}, cd);
    for (int i = 0; i < 2; ++i) ASSERT_EQ(cf[i], static_cast<double>(static_cast<float>(cd[i]))) << x0;
    ASSERT_EQ(clf, static_cast<double>(static_cast<float>(cld))) << x0;
    ASSERT_NEAR(lf, ld, 1e-5 * std::abs(ld));
  }
  std::cout << "sine: fp32 step differs from the rounded fp64 step for " << sine_rounded_differently
            << " of 2000 particles\n";
  EXPECT_GT(sine_rounded_differently, 100);
  // A particle that left the numbers keeps its log-weight -inf in float too, and a dead one (-inf) stays so.
  Vec<1, float> lost{{std::nanf("")}}, dead{{0.5f}};
  EXPECT_EQ(step_one_held_particle(sine, Vec<1>{{0.3}}, -7.25f, lost), -std::numeric_limits<float>::infinity());
  EXPECT_EQ(step_one_held_particle(sine, Vec<1>{{0.3}}, -std::numeric_limits<float>::infinity(), dead),
            -std::numeric_limits<float>::infinity());
  EXPECT_TRUE(std::isfinite(dead[0]));
}

/// math::weight_exp on `Space` of each argument.
template <class Space>
std::vector<float> weight_exps(const std::vector<float>& arguments) {
  using Memory = typename Space::memory_space;
  const int count = static_cast<int>(arguments.size());
  Kokkos::View<float*, Memory> x("x", count), e("e", count);
  Kokkos::deep_copy(x, Kokkos::View<const float*, Kokkos::HostSpace>(arguments.data(), count));
  Kokkos::parallel_for(
      "test::weight_exp", Kokkos::RangePolicy<Space>(0, count),
      KOKKOS_LAMBDA(const int i) { e(i) = math::weight_exp(x(i)); });
  std::vector<float> out(count);
  Kokkos::deep_copy(Kokkos::View<float*, Kokkos::HostSpace>(out.data(), count), e);
  return out;
}

template <class Space>
class WeightExp : public ::testing::Test {};
TYPED_TEST_SUITE(WeightExp, test::ExecutionSpaces);

/// The fp32 and mixed kernels' weight exp (math::weight_exp: the special-function unit's on a GPU) against exp in
/// double on every backend, over the arguments l - shift that the team kernels give it (within 60 of the shift; past
/// that they sum again) and on to where e^x leaves the normal floats: each within its stated bound, 2^-22 (2^y's
/// 2 ulps) plus ln 2 times y = x log2(e)'s rounding to float, |x| (log2(e) 2^-24 + log2(e)'s own float rounding),
/// relative; below that at most the smallest normal float; zero for a dead particle's -inf. Also prints the largest
/// error against CUDA's stated bound for __expf, 2 + floor(1.173 |x|) ulps, which an H200 exceeded (1.11 of it).
TYPED_TEST(WeightExp, IsWithinItsBoundOfExp) {
  std::vector<float> x;
  for (int i = 0; i <= (1 << 20); ++i) x.push_back(-87.0f + 147.0f * static_cast<float>(i) / (1 << 20));
  for (float below : {-87.5f, -100.0f, -1e4f, -std::numeric_limits<float>::infinity()}) x.push_back(below);
  const std::vector<float> e = weight_exps<TypeParam>(x);
  const double log2e = 1.4426950408889634, log2e_float = 1.44269504f;
  double worst = 0.0, worst_x = 0.0, worst_cuda = 0.0, worst_cuda_x = 0.0;
  int outside = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double exact = std::exp(static_cast<double>(x[i]));
    if (exact < 0x1p-126) {
      outside += !(e[i] >= 0.0f && e[i] <= 0x1p-126f);
      continue;
    }
    const double error = std::abs(e[i] - exact) / exact;
    const double rounding = std::abs(x[i]) * (log2e_float * 0x1p-24 + std::abs(log2e_float - log2e));
    const double bound = 0x1p-22 + std::log(2.0) * rounding;
    outside += !(error <= bound);
    if (error / bound > worst) worst = error / bound, worst_x = x[i];
    int exponent;
    std::frexp(static_cast<float>(exact), &exponent);
    const double ulps = std::abs(e[i] - exact) / std::ldexp(1.0, exponent - 24);
    const double over_cuda = ulps / (2.0 + std::floor(1.173 * std::abs(x[i])));
    if (over_cuda > worst_cuda) worst_cuda = over_cuda, worst_cuda_x = x[i];
  }
  EXPECT_EQ(outside, 0) << "largest error over its bound " << worst << " at " << worst_x;
  EXPECT_EQ(e.back(), 0.0f);
  std::cout << "largest error over its bound " << worst << " at x = " << worst_x << "; over __expf's stated bound "
            << worst_cuda << " at x = " << worst_cuda_x << "\n";
}

TEST(ParticleFilterBank, MixedTakesFloatIncrementsOfADoubleState) {
  // mixed computes a particle's Euler-Maruyama increment f dt + G sqrt(dt) z in float where the model's dynamics take
  // float (cheaper on a GPU) and adds it to the state in double: the state is not rounded to float, the increment is
  // (to a few float ulps of itself against the expression written out here, and within those and the drift's change
  // over x's float rounding of fp64's step), and the log-weight is the fp64 one of the new state. Elsewhere (the cubic
  // oscillator: double-only dynamics) mixed steps as fp64 does.
  static_assert(has_float_increments<SineModel> && !has_float_increments<CubicOscillatorModel>);
  static_assert(!has_float_increments<BenesModel>);  // an exact transition: no Euler-Maruyama increment
  SineModel sine;
  int state_not_a_float = 0, increment_rounded = 0;
  for (int k = 0; k < 2000; ++k) {
    const double x0 = -3.0 + 6.0 * (k + 0.5) / 2000 + 1e-9 * k, z = std::sin(1e3 * k);
    Vec<1> xm{{x0}}, xd{{x0}};
    const double lm = step_one_particle<SineModel, double, true>(sine, Vec<1>{{z}}, xm);
    step_one_particle<SineModel, double>(sine, Vec<1>{{z}}, xd);  // fp64's step of the same particle
    const float xf = static_cast<float>(x0);
    const float dx = (-std::sin(xf)) * 0.01f + static_cast<float>(sine.q) * (static_cast<float>(z) * std::sqrt(0.01f));
    ASSERT_NEAR(xm[0] - x0, dx, 4e-7 * std::abs(dx) + 1e-15) << x0;
    // A few float ulps of the increment's two terms, and the drift at x0 rounded to float: |f'| <= 1 times 2^-24 |x0|,
    // over dt = 0.01.
    const double terms = std::abs(std::sin(x0)) * 0.01 + sine.q * std::abs(z) * 0.1;
    ASSERT_NEAR(xm[0], xd[0], 4e-7 * terms + 6e-8 * std::abs(x0) * 0.01 + 1e-15) << x0;
    Vec<1> xl = xm;  // the fp64 log-weight of the mixed state
    const double l1 = -7.25 - 0.125 + (xl[0] * 0.013 - 0.005 * (xl[0] * (4.0 * xl[0])));
    ASSERT_NEAR(lm, l1, 1e-14 * std::abs(l1)) << x0;
    state_not_a_float += xm[0] != static_cast<double>(static_cast<float>(xm[0]));
    increment_rounded += xm[0] != xd[0];
  }
  std::cout << "sine: mixed's state is not a float for " << state_not_a_float << " of 2000 particles, its step differs"
            << " from fp64's for " << increment_rounded << "\n";
  EXPECT_GT(state_not_a_float, 1900);
  EXPECT_GT(increment_rounded, 1000);
  // The bank takes float increments for mixed only: fp64 and fp32 as before, and mixed's kernels only for a model with
  // float increments.
  ParticleStepData<SineModel, Kokkos::HostSpace, double> d;
  d.fp32_normals = true;
  EXPECT_TRUE(d.float_increments());
  d.fp32_normals = false;
  EXPECT_FALSE(d.float_increments());
  ParticleStepData<SineModel, Kokkos::HostSpace, float> f;
  f.fp32_normals = true;
  EXPECT_FALSE(f.float_increments());
  ParticleStepData<CubicOscillatorModel, Kokkos::HostSpace, double> c;
  c.fp32_normals = true;
  EXPECT_FALSE(c.float_increments());
}

TEST(ParticleFilterBank, StepPairMatchesTwoSteps) {
  // step_pair's fused pass (team kernel and chunked systematic resampling, run here on the host) against
  // step() twice, after both steps of every pair. With threshold 0.9 some members resample at nearly every
  // step, so the redo of the members that a pair's first step resamples runs throughout. The sums differ in
  // their shifts (the pass cannot normalize between its steps), so the results agree to rounding, not bits.
  using Bank = ParticleFilterBank<Host, SineModel>;
  SineModel model;
  const int members = 16, particles = 2000, steps = 60;
  ParticleFilterOptions options;
  options.kernel = ParticleKernel::team;
  options.ess_threshold = 0.9;
  options.team_size = std::min(2, Host::concurrency());
  TruthBank<Host, SineModel> truth(Host(), model, members, 7);
  Bank single(Host(), model, members, particles, seed, options);
  Bank paired(Host(), model, members, particles, seed, options);
  ParticleFilterOptions block = options;  // the host kernel: step_pair is step() twice
  block.kernel = ParticleKernel::host_block;
  Bank unfused(Host(), model, members, particles, seed, block);
  ASSERT_TRUE(paired.fuses_step_pairs());
  ASSERT_FALSE(unfused.fuses_step_pairs());
  BankVector<Kokkos::HostSpace> first_dy("first_dy", members, 1);
  auto current = [](const Bank& pf) {
    return copy_posterior(pf, Bank::PosteriorViews{pf.posterior_mean(), pf.posterior_covariance(),
                                                   pf.effective_sample_size(), pf.status()});
  };
  int redone_pairs = 0;
  for (int k = 0; k < steps; k += 2) {
    truth.step(k, 1e-2);
    Kokkos::deep_copy(first_dy, truth.observations());
    single.step(k, 1e-2, first_dy);
    const PosteriorCopy first = current(single);
    truth.step(k + 1, 1e-2);
    single.step(k + 1, 1e-2, truth.observations());
    paired.step_pair(k, 1e-2, first_dy, truth.observations());
    unfused.step_pair(k, 1e-2, first_dy, truth.observations());
    for (const Bank* pf : {&paired, &unfused}) {
      const std::string which = pf == &paired ? "fused, step " : "unfused, step ";
      expect_close(copy_posterior(*pf, pf->first_step()), first, which + std::to_string(k));
      expect_close(current(*pf), current(single), which + std::to_string(k + 1));
    }
    EXPECT_EQ(current(paired).resamples, current(single).resamples) << "step " << k + 1;
    for (int m = 0; m < members; ++m) redone_pairs += first.ess[m] < options.ess_threshold * particles;
  }
  EXPECT_GT(redone_pairs, steps / 2);  // the redo path did run
}

// The user's values are checked once, where the command line is read (tests/cli/test_compare.sh checks those
// messages); the bank refuses what no caller may pass as a broken invariant.
TEST(ParticleFilterBank, RejectsBadSizesAndThresholds) {
  SineModel model;
  EXPECT_THROW((ParticleFilterBank<Host, SineModel>(Host(), model, 2, 0, seed)), std::logic_error);
  EXPECT_THROW((ParticleFilterBank<Host, SineModel>(Host(), model, 2, 16, seed, ResamplingScheme::systematic, 1.5)),
               std::logic_error);
  EXPECT_FALSE(resampling_scheme_named("systemic").has_value());
  EXPECT_FALSE(particle_precision_named("fp16").has_value());
  EXPECT_EQ(particle_precision_named("mixed"), ParticlePrecision::mixed);
  EXPECT_EQ(particle_precision_named("fp32"), ParticlePrecision::fp32);
  // The storage type must be the precision's: fp32 in a double bank, or fp64 in a float one, is a caller's bug.
  ParticleFilterOptions fp32;
  fp32.precision = ParticlePrecision::fp32;
  EXPECT_THROW((ParticleFilterBank<Host, SineModel>(Host(), model, 2, 16, seed, fp32)), std::logic_error);
  EXPECT_THROW((ParticleFilterBank<Host, SineModel, float>(Host(), model, 2, 16, seed)), std::logic_error);
  EXPECT_EQ(resampling_scheme_named("residual"), ResamplingScheme::residual);
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
    // Systematic twice: step() and step_pair (the fused pass) on the GPU, each against step() on the host.
    for (bool pairs : {false, true}) {
      if (pairs && scheme != ResamplingScheme::systematic) continue;
      const auto md = run_sine<Kokkos::Cuda>(12, 5000, 150, options, &cd, &ed, pairs);
      const std::string what = std::string(to_string(scheme)) + (pairs ? " step_pair" : "");
      for (int m = 0; m < 12; ++m) {
        EXPECT_NEAR(md[m], mh[m], 1e-12 * std::abs(mh[m]) + 1e-14) << what << " member " << m;
        EXPECT_NEAR(cd[m], ch[m], 1e-12 * ch[m]) << what << " member " << m;
        EXPECT_NEAR(ed[m], eh[m], 1e-12 * eh[m]) << what << " member " << m;
      }
      cd.clear();
      ed.clear();
    }
  }
}

TEST(ParticleFilterBank, MixedAndFp32DeviceMatchesHostToFloatRounding) {
  // fp32 normals: the GPU's Box-Muller by its special-function unit against glibc's logf, sqrtf, cosf and sinf differ
  // by about 1e-6 of a normal (kernels/rng.hpp); 40 steps with resampling, step() and step_pair. Most members agree to
  // 1e-5. A member whose resampling took one other index (a cumulative weight within float rounding of a systematic
  // point) goes its own way from there, and each later resampling flips more indices, since the flip shifts every later
  // cumulative weight: host and device in lockstep on an H200 (fp32, seed 20261122's member 1) agreed to 2e-8 for 16
  // steps, then moved 2.6 / N at the first resampling and 18 / N by step 39 after two more, 0.28 of the member's Monte
  // Carlo standard error sd / sqrt(N). So at least 9 of the 12 members agree to 1e-5, and every member within what two
  // runs with independent particles would meet, 3 sqrt(2) sd / sqrt(N). An odd N: the GPU's kernels step a batch slot
  // past a chunk's end (and drop it), and fp32's move a member's particles one at a time, not in pairs.
  for (auto precision : {ParticlePrecision::mixed, ParticlePrecision::fp32})
    for (const int particles : {5000, 4999}) {
      ParticleFilterOptions options;
      options.precision = precision;
      std::vector<double> variance;
      const auto mh = run_sine<Kokkos::DefaultHostExecutionSpace>(12, particles, 40, options, &variance);
      for (bool pairs : {false, true}) {
        const auto md = run_sine<Kokkos::Cuda>(12, particles, 40, options, nullptr, nullptr, pairs);
        int close = 0;
        for (int m = 0; m < 12; ++m) {
          const double independent_runs = 3.0 * std::sqrt(2.0 * variance[m] / particles);
          EXPECT_NEAR(md[m], mh[m], independent_runs)
              << to_string(precision) << " N " << particles << " " << pairs << " member " << m;
          close += std::abs(md[m] - mh[m]) < 1e-5 * (1 + std::abs(mh[m]));
        }
        EXPECT_GE(close, 9) << to_string(precision) << " N " << particles << " " << pairs;
      }
    }
}
#endif

#if defined(KOKKOS_ENABLE_SERIAL) && defined(KOKKOS_ENABLE_OPENMP)
TEST(ParticleFilterBank, SerialAndOpenMPGiveTheSameBits) {
  for (auto precision : {ParticlePrecision::fp64, ParticlePrecision::mixed, ParticlePrecision::fp32})
    for (auto scheme : {ResamplingScheme::systematic, ResamplingScheme::residual}) {
      ParticleFilterOptions options;
      options.scheme = scheme;
      options.precision = precision;
      std::vector<double> cs, co, es, eo;
      const auto ms = run_sine<Kokkos::Serial>(12, 1000, 150, options, &cs, &es);
      const auto mo = run_sine<Kokkos::OpenMP>(12, 1000, 150, options, &co, &eo);
      EXPECT_EQ(ms, mo) << to_string(scheme) << " " << to_string(precision);
      EXPECT_EQ(cs, co);
      EXPECT_EQ(es, eo);
    }
}
#endif

}  // namespace
}  // namespace kushner
