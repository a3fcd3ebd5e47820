// EnKBF, EnKBF-S: on a linear model the ensemble filters tend to the Kalman-Bucy filter as the ensemble grows,
// with Monte Carlo error of order N^{-1/2}. Over M = 256 members the RMS distance of the ensemble mean to the
// Kalman-Bucy mean after T = 1 is measured at N = 32 and N = 1024; its log-log slope must be -1/2 within five
// standard errors (each RMS has relative standard error 1/2 SE(mean e^2)/mean e^2 from the members, the slope
// sqrt(se_32^2 + se_1024^2) / ln 32, which ignores the positive correlation of the two and so overstates it).
// Power: the same check on an ensemble filter of a wrong model (A off by 0.3) fails, its error stops falling.
// And one step of both variants on the host (the ensemble members in SIMD lanes, their normals drawn in a loop of
// their own) against the step written out here, ensemble member by ensemble member with normal_vector and libm.
#include "engine/filter_bank.hpp"
#include "models/car_model.hpp"
#include "models/linear_model.hpp"
#include "models/sine_model.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>
#include <type_traits>
#include <vector>

namespace kushner {
namespace {

using Space = Kokkos::DefaultExecutionSpace;
constexpr long num_members = 256;
constexpr long num_steps = 100;
constexpr double dt = 0.01;
constexpr std::uint32_t seed = 20261125;

LinearModel<1> linear_1d(double A = -0.7) {
  LinearModel<1> model;
  model.a0 = Vec<1>{{0.3}};
  model.A = Mat<1, 1>{{{A}}};
  model.c0 = Vec<1>{{0.1}};
  model.C = Mat<1, 1>{{{2.0}}};
  model.b = Mat<1, 1>{{{0.8}}};
  return model;
}

struct Distance {
  double rms, log_se;  // RMS over members of m_EnKBF - m_KB, and the standard error of its logarithm
};

/// EnKBF `name` with `particles` members per bank member, run on `filter_model`, against Kalman-Bucy on the
/// truths' model, both seeing the same truths and dy.
Distance distance_to_kalman_bucy(const std::string& name, long particles, const LinearModel<1>& filter_model) {
  const LinearModel<1> truth = linear_1d();
  OptionValues settings;
  settings.set("enkbf_particles", particles);
  FilterBank<Space, LinearModel<1>> kb(Space(), truth, truth, num_members, seed, {"KB"});
  FilterBank<Space, LinearModel<1>> en(Space(), truth, filter_model, num_members, seed, {name}, settings);
  for (long k = 0; k < num_steps; ++k) {
    kb.step(k, dt, false);
    en.step(k, dt, false);
  }
  double sum = 0.0, sum2 = 0.0;
  kb.with_slot("KB", [&](const auto& a) {
    en.with_slot(name, [&](const auto& b) {
      const auto ma = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), a.m);
      const auto mb = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), b.m);
      for (long member = 0; member < num_members; ++member) {
        const double e2 = (mb(member, 0) - ma(member, 0)) * (mb(member, 0) - ma(member, 0));
        sum += e2, sum2 += e2 * e2;
      }
    });
  });
  const double mean = sum / num_members, var = (sum2 / num_members - mean * mean) * num_members / (num_members - 1);
  return {std::sqrt(mean), 0.5 * std::sqrt(var / num_members) / mean};
}

struct Slope {
  double value, standard_error;
};

Slope convergence_slope(const std::string& name, const LinearModel<1>& filter_model) {
  const Distance small = distance_to_kalman_bucy(name, 32, filter_model);
  const Distance large = distance_to_kalman_bucy(name, 1024, filter_model);
  const double span = std::log(1024.0 / 32.0);
  std::cout << name << ": RMS |m - m_KB| " << small.rms << " at N = 32, " << large.rms << " at N = 1024\n";
  return {(std::log(large.rms) - std::log(small.rms)) / span,
          std::sqrt(small.log_se * small.log_se + large.log_se * large.log_se) / span};
}

void expect_inverse_square_root_convergence(const std::string& name) {
  const Slope s = convergence_slope(name, linear_1d());
  std::cout << name << ": slope " << s.value << " +- " << s.standard_error << "\n";
  EXPECT_LT(std::abs(s.value + 0.5), 5.0 * s.standard_error)
      << name << ": slope " << s.value << " +- " << s.standard_error << ", expected -0.5";
  const Slope wrong = convergence_slope(name, linear_1d(-0.4));  // power: a filter of another model
  EXPECT_GT(std::abs(wrong.value + 0.5), 5.0 * wrong.standard_error)
      << name << " on a wrong model: slope " << wrong.value << " +- " << wrong.standard_error;
}

TEST(EnsembleKalmanBucyFilter, StochasticTendsToKalmanBucyLikeInverseSqrtN) {
  expect_inverse_square_root_convergence("EnKBF-S");
}

TEST(EnsembleKalmanBucyFilter, DeterministicTendsToKalmanBucyLikeInverseSqrtN) {
  expect_inverse_square_root_convergence("EnKBF");
}

TEST(EnsembleKalmanBucyFilter, SameSeedSameNumbersOtherSeedOthers) {
  const LinearModel<1> model = linear_1d();
  OptionValues settings;
  settings.set("enkbf_particles", 16L);
  const auto final_means = [&](std::uint32_t s) {
    FilterBank<Space, LinearModel<1>> bank(Space(), model, model, 8, s, {"EnKBF-S"}, settings);
    for (long k = 0; k < 10; ++k) bank.step(k, dt, false);
    Kokkos::View<double**, Kokkos::LayoutLeft, Kokkos::HostSpace> m;
    bank.with_slot("EnKBF-S",
                   [&](const auto& slot) { m = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), slot.m); });
    return m;
  };
  const auto a = final_means(3), b = final_means(3), c = final_means(4);
  for (int member = 0; member < 8; ++member) {
    EXPECT_EQ(a(member, 0), b(member, 0));
    EXPECT_NE(a(member, 0), c(member, 0));
  }
}

/// One step of ensemble filter Filter (host) for member 1 of 3, against the step written out: the statistics, the
/// gain, then each ensemble member's update with its own normals (counter {member, ensemble member, step}: process
/// noise after the perturbation, on Stream::filter_noise), libm's sin and log. 133 ensemble members: four chunks of 32
/// lanes and a chunk of 5 (not a multiple of a vector's width). Returns the largest difference relative to the
/// value's scale.
template <template <class, class> class Filter, class Model>
double largest_difference_from_written_out_step(const Model& model) {
  constexpr int n = Model::state_dim, p = Model::obs_dim;
  constexpr bool stochastic =
      std::is_same_v<Filter<Model, Kokkos::HostSpace>, StochasticEnsembleKalmanBucyFilter<Model, Kokkos::HostSpace>>;
  constexpr int N = 133, member = 1;
  constexpr std::uint32_t step = 5;
  OptionValues options;
  options.set("enkbf_particles", static_cast<long>(N));
  const auto filter = Filter<Model, Kokkos::HostSpace>::create(options, model, 3, 11);
  std::vector<Vec<n>> x(N);
  for (int k = 0; k < N; ++k) x[k] = filter.load_member(member, k);
  Vec<p> dy;
  for (int j = 0; j < p; ++j) dy[j] = 0.01 * (j + 1);
  const Mat<p, p> R = model.observation_noise(step * dt);
  const StepInput<p> in{step * dt, dt, static_cast<std::uint32_t>(step), dy, R * transpose(R)};
  Vec<n> m = Vec<n>::zero();
  Mat<n, n> P = Mat<n, n>::zero();
  EXPECT_EQ(filter.step(model, member, in, m, P), Status::ok);

  Vec<n> x_bar = Vec<n>::zero();
  Vec<p> h_bar = Vec<p>::zero();
  for (int k = 0; k < N; ++k) {
    x_bar += x[k] * (1.0 / N);
    h_bar += model.observation(in.t, x[k]) * (1.0 / N);
  }
  Mat<n, p> Pxh = Mat<n, p>::zero();
  Mat<p, p> Phh = Mat<p, p>::zero();
  for (int k = 0; k < N; ++k) {
    const Vec<p> dh = model.observation(in.t, x[k]) - h_bar;
    Pxh += outer(x[k] - x_bar, dh) * (1.0 / (N - 1));
    Phh += outer(dh, dh) * (1.0 / (N - 1));
  }
  Mat<p, p> LS, LV;
  EXPECT_TRUE(cholesky(in.V + Phh * dt, LS) && cholesky(in.V, LV));
  Mat<n, p> K;
  for (int i = 0; i < n; ++i) {
    Vec<p> row;
    for (int l = 0; l < p; ++l) row[l] = Pxh(i, l);
    const Vec<p> gain = cholesky_solve(LS, row);
    for (int l = 0; l < p; ++l) K(i, l) = gain[l];
  }
  double largest = 0.0;
  const auto compare = [&](double ours, double written_out) {
    largest = std::max(largest, std::abs(ours - written_out) / std::max(1.0, std::abs(written_out)));
  };
  Vec<n> sum = Vec<n>::zero();
  for (int k = 0; k < N; ++k) {
    const auto ensemble_member = static_cast<std::uint32_t>(k);
    // The filter-noise stream's normals of (member, ensemble member, step): the stochastic variant's observation
    // perturbation, then dw; the deterministic variant's dw alone.
    constexpr int q = Model::noise_dim, v_count = stochastic ? p : 0;
    const Vec<v_count + q> z =
        normal_vector<v_count + q>(RngKey{11, Stream::filter_noise}, member, ensemble_member, step);
    Vec<p> zv = Vec<p>::zero();
    Vec<q> zw;
    for (int i = 0; i < v_count; ++i) zv[i] = z[i];
    for (int i = 0; i < q; ++i) zw[i] = z[v_count + i];
    const Vec<p> hx = model.observation(in.t, x[k]);
    const Vec<p> innovation = stochastic ? dy - hx * dt - LV * zv * std::sqrt(dt) : dy - (hx + h_bar) * (0.5 * dt);
    Vec<n> y = x[k] + K * innovation;
    y += model.drift(in.t, y, Model::Control::zero()) * dt + model.diffusion(in.t, y) * zw * std::sqrt(dt);
    const Vec<n> ours = filter.load_member(member, k);
    for (int i = 0; i < n; ++i) compare(ours[i], y[i]);
    sum += y;
  }
  for (int i = 0; i < n; ++i) compare(m[i], sum[i] / N);
  std::cout << Model::name << (stochastic ? " EnKBF-S" : " EnKBF") << ": largest relative difference " << largest
            << "\n";
  return largest;
}

TEST(EnsembleKalmanBucyFilter, HostStepIsTheStepWrittenOut) {
  // glibc's vector sin, log, cos in the lanes are within a few ulp of libm's; a wrong normal (another counter, the
  // streams swapped) moves a member by O(sqrt(dt)).
  constexpr double tolerance = 1e-13;
  EXPECT_LT(largest_difference_from_written_out_step<StochasticEnsembleKalmanBucyFilter>(SineModel()), tolerance);
  EXPECT_LT(largest_difference_from_written_out_step<EnsembleKalmanBucyFilter>(SineModel()), tolerance);
  CarTaylor3Model car;  // two states, two observations, two noises
  car.q = 0.3;
  EXPECT_LT(largest_difference_from_written_out_step<StochasticEnsembleKalmanBucyFilter>(car), tolerance);
  EXPECT_LT(largest_difference_from_written_out_step<EnsembleKalmanBucyFilter>(car), tolerance);
}

}  // namespace
}  // namespace kushner
