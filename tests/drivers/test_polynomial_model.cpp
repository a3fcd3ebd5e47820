// Polynomial models from a file (--model-file): the parser's reading of the tensors and terms, its refusals
// (one line naming the file and the key), the model's derivatives and forms against finite differences,
// cubature and drift() itself, the run-time filter refusals, and, on the example files, the same numbers as
// the built-in cubic oscillator and linear models: bit for bit wherever the arithmetic is the same.
#include "drivers/filter_selection.hpp"
#include "drivers/model_file.hpp"
#include "engine/filter_bank.hpp"
#include "kernels/filters/gaussian_expectations.hpp"
#include "models/registry.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace kushner {
namespace {

const std::string examples = std::string(KUSHNER_SOURCE_DIR) + "/models/examples/";

template <int N>
PolynomialModel<N> model_from_text(const std::string& text) {
  return make_polynomial_model<N>(parse_polynomial_model(text, "test.toml"), nullptr);
}

template <int N>
PolynomialModel<N> model_from_file(const std::string& name) {
  return make_polynomial_model<N>(read_polynomial_model_file(examples + name), nullptr);
}

/// The message of the InputError that reading `text` and making its model throws ("" if none).
std::string parse_error(const std::string& text) {
  try {
    const PolynomialModelSpec spec = parse_polynomial_model(text, "m.toml");
    if (spec.discrete) {
      if (spec.n == 1) make_polynomial_model<1, DiscretePolynomialModel<1>>(spec, nullptr);
      if (spec.n == 2) make_polynomial_model<2, DiscretePolynomialModel<2>>(spec, nullptr);
      if (spec.n == 3) make_polynomial_model<3, DiscretePolynomialModel<3>>(spec, nullptr);
    } else {
      if (spec.n == 1) make_polynomial_model<1>(spec, nullptr);
      if (spec.n == 2) make_polynomial_model<2>(spec, nullptr);
      if (spec.n == 3) make_polynomial_model<3>(spec, nullptr);
    }
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

const std::string minimal_tail = R"(
[diffusion]
b = [[1.0, 0.0], [0.0, 1.0]]
[observation]
C = [[1.0, 0.0], [0.0, 1.0]]
R = [[1.0, 0.0], [0.0, 1.0]]
[initial]
x0_mean = [0.0, 0.0]
x0_cov = [[1.0, 0.0], [0.0, 1.0]]
)";

/// A degree-4 drift in 3 states with every kind of term: cross terms of each degree, an asymmetric a2.
const std::string general_3d = R"(
state_dim = 3
[drift]
a0 = [0.1, -0.2, 0.3]
a1 = [[-1.0, 0.5, 0.0], [0.2, -0.8, 0.1], [0.0, 0.3, -1.2]]
a2 = [[[0.0, 0.2, 0.0], [0.1, 0.0, 0.0], [0.0, 0.0, -0.3]],
      [[0.4, 0.0, 0.0], [0.0, 0.0, 0.15], [0.0, 0.0, 0.0]],
      [[0.0, 0.0, 0.0], [0.0, -0.25, 0.0], [0.05, 0.0, 0.0]]]
[[drift.terms]]
component = 1
powers = [3, 0, 0]
coefficient = -0.2
[[drift.terms]]
component = 2
powers = [1, 1, 1]
coefficient = 0.3
[[drift.terms]]
component = 3
powers = [0, 2, 2]
coefficient = -0.05
[[drift.terms]]
component = 2
powers = [0, 0, 4]
coefficient = 0.01
[[drift.terms]]
component = 1
powers = [2, 1, 1]
coefficient = 0.07
[diffusion]
b = [[0.5, 0.0], [0.1, 0.4], [0.0, 0.2]]
[observation]
C = [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
R = [[0.5, 0.0], [0.1, 0.5]]
[initial]
x0_mean = [0.5, -0.5, 0.2]
x0_cov = [[0.3, 0.05, 0.0], [0.05, 0.2, 0.01], [0.0, 0.01, 0.4]]
)";

template <int N>
Vec<N> test_point(int k) {
  Vec<N> x;
  for (int i = 0; i < N; ++i) x[i] = 1.3 * std::sin(1.7 * k + 0.9 * i) + 0.2 * i;
  return x;
}

template <int N>
Mat<N, N> test_covariance(double s) {
  Mat<N, N> P = Mat<N, N>::zero();
  for (int i = 0; i < N; ++i)
    for (int j = 0; j < N; ++j) P(i, j) = s * (i == j ? 1.0 : 0.3 / (1 + std::abs(i - j)));
  return P;
}

/// max over entries of |a - b| / max(1, |b|), two NaNs counting as equal, for two (member, k) views.
template <class View>
double test_difference(const View& a, const View& b) {
  const auto ha = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), a);
  const auto hb = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), b);
  double worst = 0.0;
  for (std::size_t i = 0; i < ha.extent(0); ++i)
    for (std::size_t k = 0; k < ha.extent(1); ++k) {
      if (std::isnan(ha(i, k)) && std::isnan(hb(i, k))) continue;
      const double d = std::abs(ha(i, k) - hb(i, k)) / std::max(1.0, std::abs(hb(i, k)));
      worst = std::isnan(d) ? INFINITY : std::max(worst, d);
    }
  return worst;
}

template <int R, int C>
void expect_bitwise_equal(const Mat<R, C>& a, const Mat<R, C>& b, const std::string& what) {
  for (int i = 0; i < R; ++i)
    for (int j = 0; j < C; ++j) EXPECT_EQ(a(i, j), b(i, j)) << what << " (" << i << ", " << j << ")";
}
template <int N>
void expect_bitwise_equal(const Vec<N>& a, const Vec<N>& b, const std::string& what) {
  for (int i = 0; i < N; ++i) EXPECT_EQ(a[i], b[i]) << what << " [" << i << "]";
}

TEST(PolynomialModelFile, MonomialsAreNumberedByDegreeThenLexicographically) {
  EXPECT_EQ(polynomial_monomial_count(1), 3);
  EXPECT_EQ(polynomial_monomial_count(2), 12);
  EXPECT_EQ(polynomial_monomial_count(3), 31);
  const Monomial x1x2 = polynomial_monomial(2, 1);  // x1^2, x1 x2, x2^2, x1^3, ...
  EXPECT_EQ(x1x2.degree, 2);
  EXPECT_EQ(x1x2.var[0], 0);
  EXPECT_EQ(x1x2.var[1], 1);
  const Monomial x1cubed = polynomial_monomial(2, 3);
  EXPECT_EQ(x1cubed.degree, 3);
  EXPECT_EQ(x1cubed.var[2], 0);
  const Monomial last = polynomial_monomial(3, 30);
  EXPECT_EQ(last.degree, 4);
  EXPECT_EQ(last.var[0], 2);
}

TEST(PolynomialModelFile, TensorsAndTermsAreSummedPerMonomial) {
  // a2[0][0][1] and a2[0][1][0] are both x1 x2 in f1: one coefficient 0.2 + 0.1.
  const PolynomialModelSpec spec = parse_polynomial_model(general_3d, "test.toml");
  EXPECT_EQ(spec.n, 3);
  EXPECT_EQ(spec.p, 2);
  EXPECT_EQ(spec.q, 2);
  const PolynomialModel<3> model = make_polynomial_model<3>(spec, nullptr);
  const int x1x2 = 1;  // x1^2, x1 x2, x1 x3, ...
  EXPECT_DOUBLE_EQ(model.coefficient[0][x1x2], 0.2 + 0.1);
  EXPECT_EQ(model.model_facts().drift_degree, 4);
  EXPECT_TRUE(model.model_facts().cross_terms);
  // No prior in the file: the filters start from the truths' law.
  expect_bitwise_equal(model.prior_mean, model.x0_mean, "prior_mean");
  // p = 2 observation rows, run as 3 with a third channel of pure noise.
  EXPECT_EQ(model.C(2, 0), 0.0);
  EXPECT_EQ(model.R(2, 2), 1.0);
  EXPECT_EQ(model.R(2, 0), 0.0);
  // q = 2 diffusion columns, the third zero.
  EXPECT_EQ(model.b(1, 2), 0.0);
  const Vec<3> x = test_point<3>(1);
  const double x1 = x[0], x2 = x[1], x3 = x[2];
  const double f1 = 0.1 - x1 + 0.5 * x2 + 0.3 * x1 * x2 - 0.3 * x3 * x3 - 0.2 * x1 * x1 * x1 + 0.07 * x1 * x1 * x2 * x3;
  const double f2 = -0.2 + 0.2 * x1 - 0.8 * x2 + 0.1 * x3 + 0.4 * x1 * x1 + 0.15 * x2 * x3 + 0.3 * x1 * x2 * x3 +
                    0.01 * x3 * x3 * x3 * x3;
  const double f3 = 0.3 + 0.3 * x2 - 1.2 * x3 - 0.25 * x2 * x2 + 0.05 * x3 * x1 - 0.05 * x2 * x2 * x3 * x3;
  const Vec<3> f = model.drift(0.0, x, PolynomialModel<3>::Control::zero());
  EXPECT_NEAR(f[0], f1, 1e-14);
  EXPECT_NEAR(f[1], f2, 1e-14);
  EXPECT_NEAR(f[2], f3, 1e-14);
}

template <int N>
void expect_derivatives_and_forms_match(const PolynomialModel<N>& model, bool componentwise, bool quadratic) {
  const auto u = PolynomialModel<N>::Control::zero();
  const double h = 1e-5;
  for (int point = 0; point < 6; ++point) {
    const Vec<N> x = test_point<N>(point);
    const Vec<N> f = model.drift(0.0, x, u);
    const Mat<N, N> J = model.drift_jacobian(0.0, x, u);
    for (int j = 0; j < N; ++j) {
      Vec<N> up = x, down = x;
      up[j] += h;
      down[j] -= h;
      const Vec<N> fd = (model.drift(0.0, up, u) - model.drift(0.0, down, u)) * (0.5 / h);
      const Mat<N, N> Jd = (model.drift_jacobian(0.0, up, u) - model.drift_jacobian(0.0, down, u)) * (0.5 / h);
      for (int k = 0; k < N; ++k) {
        EXPECT_NEAR(J(k, j), fd[k], 1e-7 * (1 + std::abs(fd[k]))) << "d f" << k << " / d x" << j;
        const Mat<N, N> H = model.drift_hessian(0.0, x, u, k);
        for (int i = 0; i < N; ++i)
          EXPECT_NEAR(H(i, j), Jd(k, i), 1e-7 * (1 + std::abs(Jd(k, i))))
              << "Hessian of f" << k << " (" << i << j << ")";
      }
    }
    const SdcDrift<N> sdc = model.sdc_drift(0.0, x);
    const Vec<N> Ax = sdc.A * x + sdc.b;
    for (int k = 0; k < N; ++k) EXPECT_NEAR(Ax[k], f[k], 1e-13 * (1 + std::abs(f[k]))) << "A(x) x + b";
    if (componentwise) {
      const Vec<N> pf = model.drift_power_polynomial(0.0)(x);
      for (int k = 0; k < N; ++k) EXPECT_NEAR(pf[k], f[k], 1e-13 * (1 + std::abs(f[k]))) << "power polynomial";
    }
    if (quadratic) {
      const Vec<N> qf = model.drift_quadratic_polynomial(0.0)(x);
      for (int k = 0; k < N; ++k) EXPECT_NEAR(qf[k], f[k], 1e-13 * (1 + std::abs(f[k]))) << "quadratic polynomial";
    }
    // Exact Gaussian moments against 20-node Gauss-Hermite cubature (exact for degree <= 39).
    const GaussHermiteRule rule = make_gauss_hermite_rule(20);
    for (double s : {0.01, 0.5}) {
      const Mat<N, N> P = test_covariance<N>(s);
      GaussianDrift<N> cubature;
      ASSERT_TRUE(cubature_drift(model, 0.0, x, P, rule, cubature));
      const GaussianDrift<N> closed = closed_form_drift(model, 0.0, x, P);
      for (int i = 0; i < N; ++i) {
        EXPECT_NEAR(closed.mean[i], cubature.mean[i], 1e-11 * (1 + std::abs(cubature.mean[i]))) << "E[f]";
        for (int j = 0; j < N; ++j)
          EXPECT_NEAR(closed.jacobian(i, j), cubature.jacobian(i, j), 1e-11 * (1 + std::abs(cubature.jacobian(i, j))))
              << "E[grad f] (" << i << ", " << j << ")";
      }
    }
  }
}

TEST(PolynomialModel, DerivativesExpectationsAndFormsMatchTheDrift) {
  expect_derivatives_and_forms_match(model_from_text<3>(general_3d), false, false);
  expect_derivatives_and_forms_match(model_from_file<2>("van_der_pol.toml"), false, false);
  expect_derivatives_and_forms_match(model_from_file<2>("cubic_oscillator.toml"), true, false);
  const auto quadratic = model_from_text<2>(
      "state_dim = 2\n[drift]\na2 = [[[0.0, 1.0], [0.0, -0.5]], [[0.3, 0.0], "
      "[0.2, 0.0]]]\n" +
      minimal_tail);
  expect_derivatives_and_forms_match(quadratic, false, true);
  const auto quartic_1d = model_from_text<1>(R"(
state_dim = 1
[drift]
a0 = [0.5]
a1 = [[-1.0]]
a2 = [[[0.3]]]
a4 = [[[[[-0.1]]]]]
[diffusion]
b = [[1.0]]
[observation]
C = [[1.0]]
R = [[1.0]]
[initial]
x0_mean = [0.0]
x0_cov = [[1.0]]
)");
  expect_derivatives_and_forms_match(quartic_1d, true, false);
}

/// A 2-D model whose observation has terms of degree 2 and 3 (tensors c2, c3 and [[observation.terms]]), p = 2.
const std::string polynomial_observation = R"(
state_dim = 2
[drift]
a1 = [[-1.0, 0.5], [0.0, -0.5]]
[diffusion]
b = [[1.0, 0.0], [0.0, 1.0]]
[observation]
c0 = [0.1, -0.2]
C = [[1.0, 0.0], [0.0, 0.5]]
c2 = [[[0.0, 0.4], [0.0, 0.0]], [[0.0, 0.0], [0.0, -0.3]]]
c3 = [[[[0.0, 0.0], [0.0, 0.0]], [[0.0, 0.0], [0.0, 0.0]]], [[[0.2, 0.0], [0.0, 0.0]], [[0.0, 0.0], [0.0, 0.0]]]]
R = [[1.0, 0.0], [0.0, 1.0]]
[[observation.terms]]
component = 1
powers = [1, 2]
coefficient = -0.25
[[observation.terms]]
component = 2
powers = [0, 2]
coefficient = 0.1
[initial]
x0_mean = [0.0, 0.0]
x0_cov = [[1.0, 0.0], [0.0, 1.0]]
)";

TEST(PolynomialModel, ObservationPolynomialMatchesItsDerivativesAndForms) {
  const auto model = model_from_text<2>(polynomial_observation);
  EXPECT_EQ(model.observation_degree, 3);
  EXPECT_EQ(model.model_facts().observation_degree, 3);
  EXPECT_EQ(model.obs_rows, 2);
  const double step = 1e-5;
  const GaussHermiteRule rule = make_gauss_hermite_rule(20);
  for (int point = 0; point < 6; ++point) {
    const Vec<2> x = test_point<2>(point);
    const double x1 = x[0], x2 = x[1];
    // c2's (0,1) and the terms: h1 = 0.1 + x1 + 0.4 x1 x2 - 0.25 x1 x2^2; h2 = -0.2 + 0.5 x2 - 0.3 x2^2 + 0.2 x1^3
    // + 0.1 x2^2.
    const double h1 = 0.1 + x1 + 0.4 * x1 * x2 - 0.25 * x1 * x2 * x2;
    const double h2 = -0.2 + 0.5 * x2 - 0.2 * x2 * x2 + 0.2 * x1 * x1 * x1;
    const Vec<2> h = model.observation(0.0, x);
    EXPECT_NEAR(h[0], h1, 1e-14);
    EXPECT_NEAR(h[1], h2, 1e-14);
    const Mat<2, 2> H = model.observation_jacobian(0.0, x);
    for (int j = 0; j < 2; ++j) {
      Vec<2> up = x, down = x;
      up[j] += step;
      down[j] -= step;
      const Vec<2> hd = (model.observation(0.0, up) - model.observation(0.0, down)) * (0.5 / step);
      const Mat<2, 2> Hd = (model.observation_jacobian(0.0, up) - model.observation_jacobian(0.0, down)) * (0.5 / step);
      for (int k = 0; k < 2; ++k) {
        EXPECT_NEAR(H(k, j), hd[k], 1e-7 * (1 + std::abs(hd[k]))) << "d h" << k << " / d x" << j;
        const Mat<2, 2> second = model.observation_hessian(0.0, x, k);
        for (int i = 0; i < 2; ++i)
          EXPECT_NEAR(second(i, j), Hd(k, i), 1e-7 * (1 + std::abs(Hd(k, i)))) << "Hessian of h" << k;
      }
    }
    const SdcObservation<2, 2> sdc = model.sdc_observation(0.0, x);
    const Vec<2> Cx = sdc.C * x + sdc.c0;
    for (int k = 0; k < 2; ++k) EXPECT_NEAR(Cx[k], h[k], 1e-13 * (1 + std::abs(h[k]))) << "C(x) x + c0";
    for (double s : {0.01, 0.5}) {
      const Mat<2, 2> P = test_covariance<2>(s);
      ObservationLinearization<2, 2> cubature;
      ASSERT_TRUE(cubature_observation(model, 0.0, x, P, rule, cubature));
      const GaussianObservation<2, 2> closed = model.gaussian_observation(0.0, x, P);
      for (int i = 0; i < 2; ++i) {
        EXPECT_NEAR(closed.mean[i], cubature.h[i], 1e-12 * (1 + std::abs(cubature.h[i]))) << "E[h]";
        for (int j = 0; j < 2; ++j)
          EXPECT_NEAR(closed.jacobian(i, j), cubature.H(i, j), 1e-12 * (1 + std::abs(cubature.H(i, j))))
              << "E[grad h] (" << i << ", " << j << ")";
      }
    }
  }
}

TEST(PolynomialModel, FileEqualToTheCubicSensorGivesItsObservationBitForBit) {
  const auto file = model_from_file<1>("cubic_sensor.toml");
  const CubicSensorModel builtin;
  for (int point = 0; point < 20; ++point) {
    const Vec<1> x = test_point<1>(point) * (1.0 + point);
    expect_bitwise_equal(file.observation(0.0, x), builtin.observation(0.0, x), "h");
    expect_bitwise_equal(file.observation_jacobian(0.0, x), builtin.observation_jacobian(0.0, x), "h'");
    expect_bitwise_equal(file.observation_hessian(0.0, x, 0), builtin.observation_hessian(0.0, x, 0), "h''");
    expect_bitwise_equal(file.sdc_observation(0.0, x).C, builtin.sdc_observation(0.0, x).C, "C(x)");
  }
}

TEST(PolynomialModel, FileEqualToTheCubicOscillatorGivesItsNumbersBitForBit) {
  const auto file = model_from_file<2>("cubic_oscillator.toml");
  const CubicOscillatorModel builtin;
  const auto u = PolynomialModel<2>::Control::zero();
  const auto ub = CubicOscillatorModel::Control::zero();
  for (int point = 0; point < 20; ++point) {
    const Vec<2> x = test_point<2>(point) * (1.0 + point);
    expect_bitwise_equal(file.drift(0.0, x, u), builtin.drift(0.0, x, ub), "drift");
    expect_bitwise_equal(file.drift_jacobian(0.0, x, u), builtin.drift_jacobian(0.0, x, ub), "Jacobian");
    for (int k = 0; k < 2; ++k)
      expect_bitwise_equal(file.drift_hessian(0.0, x, u, k), builtin.drift_hessian(0.0, x, ub, k), "Hessian");
    expect_bitwise_equal(file.sdc_drift(0.0, x).A, builtin.sdc_drift(0.0, x).A, "A(x)");
    expect_bitwise_equal(noise_intensity(file.diffusion(0.0, x)), noise_intensity(builtin.diffusion(0.0, x)), "b b^T");
  }
  expect_bitwise_equal(file.x0_mean, builtin.x0_mean, "x0_mean");
  expect_bitwise_equal(file.prior_cov, builtin.prior_cov, "prior_cov");
  expect_bitwise_equal(file.observation_noise(0.0), builtin.observation_noise(0.0), "R");
}

TEST(PolynomialModel, FileEqualToTheLinearModelGivesItsNumbersBitForBit) {
  const auto file = model_from_file<2>("linear2.toml");
  const LinearModel<2> builtin;
  for (int point = 0; point < 20; ++point) {
    const Vec<2> x = test_point<2>(point);
    expect_bitwise_equal(file.drift(0.0, x, PolynomialModel<2>::Control::zero()),
                         builtin.drift(0.0, x, LinearModel<2>::Control::zero()), "drift");
    expect_bitwise_equal(file.observation(0.0, x), builtin.observation(0.0, x), "observation");
  }
  expect_bitwise_equal(file.linear_form(0.0).A, builtin.linear_form(0.0).A, "A");
  expect_bitwise_equal(file.b, builtin.b, "b");
  expect_bitwise_equal(file.x0_cov, builtin.x0_cov, "x0_cov");
  expect_bitwise_equal(file.prior_cov, builtin.prior_cov, "prior_cov");
}

TEST(PolynomialModel, DiscreteFileEqualToTheLinearDiscreteModelGivesItsNumbersBitForBit) {
  const PolynomialModelSpec spec = read_polynomial_model_file(examples + "linear_discrete.toml");
  ASSERT_TRUE(spec.discrete);
  const auto file = make_polynomial_model<2, DiscretePolynomialModel<2>>(spec, nullptr);
  const LinearDiscreteModel builtin;
  const Vec<1> u{{0.7}};
  for (int point = 0; point < 20; ++point) {
    const Vec<2> x = test_point<2>(point);
    expect_bitwise_equal(file.transition(3.0, x, u), builtin.transition(3.0, x, u), "transition");
    expect_bitwise_equal(file.transition_jacobian(3.0, x), builtin.transition_jacobian(3.0, x), "jacobian");
    expect_bitwise_equal(file.process_noise(x, 0.5), builtin.process_noise(x, 0.5), "process noise");
    expect_bitwise_equal(file.observation(4.0, x), builtin.observation(4.0, x), "observation");
    expect_bitwise_equal(file.observation_noise_sample(x, 0.5), builtin.observation_noise_sample(x, 0.5), "v");
    EXPECT_EQ(file.observation_log_density(x), builtin.observation_log_density(x));
  }
  expect_bitwise_equal(file.process_noise_covariance(0.0), builtin.process_noise_covariance(0.0), "Q");
  expect_bitwise_equal(file.control_input(0.0), builtin.control_input(0.0), "B");
  expect_bitwise_equal(file.prior_cov, builtin.prior_cov, "prior_cov");
  // The same text without time = "discrete" is not a continuous model with other names: its tables are refused.
  EXPECT_EQ(parse_error("state_dim = 2\n[transition]\na1 = [[1.0, 0.0], [0.0, 1.0]]\n" + minimal_tail),
            "m.toml: transition: a continuous-time model has [drift] and [diffusion]; [transition] and "
            "[process_noise] are a discrete one's (time = \"discrete\")");
  EXPECT_EQ(parse_error("state_dim = 2\ntime = 1\n" + minimal_tail),
            "m.toml: time: expected \"continuous\" or \"discrete\"");
}

TEST(PolynomialModel, FiltersTheCoefficientsRuleOutAreRefusedAtSelection) {
  const auto cubic = model_from_file<2>("cubic_oscillator.toml");
  const auto vdp = model_from_file<2>("van_der_pol.toml");
  const auto linear = model_from_file<2>("linear2.toml");
  using Cubic = PolynomialModel<2>;
  EXPECT_EQ(select_filters<Cubic>("all", linear), filter_names<Cubic>()) << "a linear file supports every filter";
  // "all" is every filter but those the coefficients rule out (the list is the filter list's, in its order).
  const auto all_but = [](std::vector<std::string> refused) {
    std::vector<std::string> names;
    for (const auto& n : filter_names<Cubic>())
      if (std::find(refused.begin(), refused.end(), n) == refused.end()) names.push_back(n);
    return names;
  };
  EXPECT_EQ(select_filters<Cubic>("all", cubic), all_but({"KB", "BILIN"}));
  EXPECT_EQ(select_filters<Cubic>("all", vdp), all_but({"KB", "POLY3", "POLY4", "BILIN"}));
  auto refusal = [](const auto& model, const std::string& list) {
    try {
      select_estimators<std::decay_t<decltype(model)>>(list, model);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(refusal(vdp, "POLY3"),
            "filter POLY3 does not support model 'polynomial' (drift has cross terms (monomials of two or more "
            "variables), not componentwise powers)");
  EXPECT_EQ(refusal(cubic, "KB"),
            "filter KB does not support model 'polynomial' (drift is not linear (the file has terms of degree 2 or "
            "more))");
  EXPECT_EQ(refusal(cubic, "BILIN"),
            "filter BILIN does not support model 'polynomial' (drift is not bilinear (degree "
            "above 2))");
  EXPECT_EQ(refusal(cubic, "EKF,EXACT"), "");
  const auto correlated = model_from_text<3>(general_3d);  // b b^T has off-diagonal entries
  EXPECT_EQ(refusal(correlated, "POLY4"),
            "filter POLY4 does not support model 'polynomial' (drift has cross terms (monomials of two or more "
            "variables), not componentwise powers)");
  const auto quartic = model_from_text<2>(
      "state_dim = 2\n[drift]\na4 = [[[[[1.0, 0.0], [0.0, 0.0]], [[0.0, 0.0], "
      "[0.0, 0.0]]], [[[0.0, 0.0], [0.0, 0.0]], [[0.0, 0.0], [0.0, 0.0]]]], "
      "[[[[0.0, 0.0], [0.0, 0.0]], [[0.0, 0.0], [0.0, 0.0]]], [[[0.0, 0.0], [0.0, "
      "0.0]], [[0.0, 0.0], [0.0, 0.0]]]]]\n[diffusion]\nb = [[1.0, 0.5], [0.0, "
      "1.0]]" +
      minimal_tail.substr(minimal_tail.find("[observation]") - 1));
  EXPECT_EQ(refusal(quartic, "POLY3"), "filter POLY3 does not support model 'polynomial' (drift has degree above 3)");
  // A polynomial observation: the filters that need a linear one refuse it at selection.
  const auto observed = model_from_text<2>(polynomial_observation);
  EXPECT_EQ(select_filters<Cubic>("all", observed), all_but({"KB", "POLY3", "POLY4", "BILIN", "MIXED"}));
  for (const char* name : {"KB", "POLY3", "POLY4", "BILIN", "MIXED"})
    EXPECT_EQ(refusal(observed, name), std::string("filter ") + name +
                                           " does not support model 'polynomial' (observation is not linear (the "
                                           "file has terms of degree 2 or more))");
  EXPECT_EQ(refusal(quartic, "POLY4"), "");
  EXPECT_EQ(refusal(quartic, "EXACT"),
            "filter EXACT does not support model 'polynomial' (the grid filter needs axis-aligned noise (b b^T "
            "diagonal))");
}

/// Every filter of the bank on the cubic-oscillator file and on the built-in model, same seed: the same
/// estimates bit for bit, except QLF and MIXED, whose Gaussian expectation E_N[f] the built-in model takes
/// from its hand-written closed form (seed 000 (6.14)) and its componentwise-power form, and the file model
/// from its monomial moments (Isserlis): the same mathematics, different rounding (an ulp per step), so
/// equal to 1e-12 relative over the run. On the host, where CPU builds compile with -ffp-contract=off: a GPU
/// contracts a*b+c into FMAs wherever its compiler sees the pattern, which the two forms offer in different places.
TEST(PolynomialModel, CubicOscillatorFileRunsTheBuiltinFiltersNumbers) {
  using Space = Kokkos::DefaultHostExecutionSpace;
  const auto file = model_from_file<2>("cubic_oscillator.toml");
  const CubicOscillatorModel builtin;
  const std::vector<std::string> filters = supported_filters(builtin);
  ASSERT_EQ(filters, select_filters<PolynomialModel<2>>("all", file));
  OptionValues settings;
  settings.set("asre_max_iterations", 3L);
  constexpr long members = 40, steps = 400;
  FilterBank<Space, CubicOscillatorModel> a(Space(), builtin, builtin, members, 11, filters, settings);
  FilterBank<Space, PolynomialModel<2>> b(Space(), file, file, members, 11, filters, settings);
  for (long k = 0; k < steps; ++k) {
    a.step(k, 0.005, false);
    b.step(k, 0.005, false);
  }
  for (const auto& name : filters) {
    a.with_slot(name, [&](const auto& sa) {
      b.with_slot(name, [&](const auto& sb) {
        const double tolerance = name == "QLF" || name == "MIXED" ? 1e-12 : 0.0;
        EXPECT_LE(test_difference(sa.m, sb.m), tolerance) << name << " m";
        EXPECT_LE(test_difference(sa.P, sb.P), tolerance) << name << " P";
      });
    });
  }
}

TEST(PolynomialModelFile, BadFilesNameTheFileAndTheKey) {
  const std::string ok = "state_dim = 2\n" + minimal_tail;
  EXPECT_EQ(parse_error(ok), "");
  EXPECT_EQ(parse_error(minimal_tail), "m.toml: state_dim: missing (required: the state dimension, 1, 2 or 3)");
  EXPECT_EQ(parse_error("state_dim = 4\n" + minimal_tail), "m.toml: state_dim: must be 1, 2 or 3 (got 4)");
  EXPECT_EQ(parse_error("state_dim = 2.0\n" + minimal_tail), "m.toml: state_dim: expected an integer, got a number");
  EXPECT_EQ(parse_error("state_dim = 2\nstates = 3\n" + minimal_tail),
            "m.toml: states: unknown key (known here: state_dim, time, name, description, drift, diffusion, "
            "observation, control, initial)");
  EXPECT_EQ(parse_error("state_dim = 2\n[drift]\na5 = [1.0, 2.0]\n" + minimal_tail),
            "m.toml: drift.a5: unknown key (known here: a0, a1, a2, a3, a4, terms)");
  EXPECT_EQ(parse_error("state_dim = 2\n[drift]\na2 = [[1.0, 2.0], [3.0, 4.0]]\n" + minimal_tail),
            "m.toml: drift.a2: expected a 2x2x2 array, but drift.a2[0][0] is a number");
  EXPECT_EQ(parse_error("state_dim = 2\n[drift]\na1 = [[1.0, 2.0], [3.0, 4.0, 5.0]]\n" + minimal_tail),
            "m.toml: drift.a1: expected a 2x2 array, but drift.a1[1] has 3 entries");
  EXPECT_EQ(parse_error("state_dim = 2\n[drift]\na0 = [1.0, 'x']\n" + minimal_tail),
            "m.toml: drift.a0: expected a 2 array, but drift.a0[1] is a string");
  EXPECT_EQ(parse_error("state_dim = 2\n[drift]\na0 = [1.0, nan]\n" + minimal_tail), "m.toml: drift.a0[1]: not finite");
  EXPECT_EQ(parse_error("state_dim = 2\n[drift]\na0 = [1.0]\n" + minimal_tail),
            "m.toml: drift.a0: expected a 2 array, but it has 1 entry");
  EXPECT_EQ(parse_error("state_dim = 2\n[drift\n" + minimal_tail).rfind("m.toml: line 2, column ", 0), 0u);
  const std::string no_R = "state_dim = 2\n" + minimal_tail.substr(0, minimal_tail.find("R = ")) +
                           minimal_tail.substr(minimal_tail.find("[initial]"));
  EXPECT_EQ(parse_error(no_R), "m.toml: observation.R: missing (required: a 2x2 array)");
  // The observation's polynomial and the control input.
  const std::string head =
      "state_dim = 2\n[diffusion]\nb = [[1.0, 0.0], [0.0, 1.0]]\n[initial]\nx0_mean = [0.0, 0.0]\n"
      "x0_cov = [[1.0, 0.0], [0.0, 1.0]]\n[observation]\nR = [[1.0]]\n";
  EXPECT_EQ(parse_error(head),
            "m.toml: observation.C: missing (required: the observation's linear part C, p x n, or "
            "one of c1, c2, c3)");
  EXPECT_EQ(parse_error(head + "C = [[1.0, 0.0]]\nc1 = [[1.0, 0.0]]\n"),
            "m.toml: observation.C: give C or c1 (the same matrix), not both");
  EXPECT_EQ(parse_error(head + "c2 = [[[0.0, 1.0], [0.0, 0.0]]]\nc3 = [[[[1.0]]]]\n"),
            "m.toml: observation.c3: expected a 1x2x2x2 array, but observation.c3[0] has 1 entry");
  EXPECT_EQ(parse_error(head + "c2 = [[[0.0, 1.0], [0.0, 0.0]]]\n"), "");  // p = 1 from c2, no linear part
  EXPECT_EQ(parse_error(head + "C = [[1.0, 0.0]]\n[[observation.terms]]\ncomponent = 1\npowers = [2, 2]\n"
                               "coefficient = 1.0\n"),
            "m.toml: observation.terms[0].powers: total degree above 3");
  EXPECT_EQ(parse_error(head + "C = [[1.0, 0.0]]\n[[observation.terms]]\ncomponent = 2\npowers = [2, 0]\n"
                               "coefficient = 1.0\n"),
            "m.toml: observation.terms[0].component: must be in 1 .. 1 (got 2)");
  EXPECT_EQ(parse_error(head + "C = [[1.0, 0.0]]\n[control]\nB = [1.0]\n"),
            "m.toml: control.B: expected a 2 array, but it has 1 entry");
  EXPECT_EQ(parse_error(head + "C = [[1.0, 0.0]]\n[control]\nB = [[1.0, 0.0], [0.0, 1.0]]\n"),
            "m.toml: control.B: expected a 2x1 array, but control.B[0] has 2 entries");
  EXPECT_EQ(parse_error(head + "C = [[1.0, 0.0]]\n[control]\nu = [1.0, 0.0]\n"),
            "m.toml: control.u: unknown key (known here: B)");
  EXPECT_EQ(parse_error("state_dim = 2\n" + minimal_tail.substr(0, minimal_tail.find("[initial]"))),
            "m.toml: initial: missing (required table [initial])");
  EXPECT_EQ(parse_error("state_dim = 1\n" + minimal_tail),
            "m.toml: diffusion.b: expected a 1xk array, but it has 2 entries");
  EXPECT_EQ(
      parse_error("state_dim = 2\n[[drift.terms]]\ncomponent = 3\npowers = [1, 1]\ncoefficient = 1.0\n" + minimal_tail),
      "m.toml: drift.terms[0].component: must be in 1 .. 2 (got 3)");
  EXPECT_EQ(
      parse_error("state_dim = 2\n[[drift.terms]]\ncomponent = 1\npowers = [4, 1]\ncoefficient = 1.0\n" + minimal_tail),
      "m.toml: drift.terms[0].powers: total degree above 4");
  EXPECT_EQ(parse_error("state_dim = 2\n[[drift.terms]]\ncomponent = 1\npowers = [1, 1]\n" + minimal_tail),
            "m.toml: drift.terms[0].coefficient: missing");
  std::string singular_R = ok;
  singular_R.replace(singular_R.find("R = [[1.0, 0.0], [0.0, 1.0]]"), 28, "R = [[1.0, 0.0], [1.0, 0.0]]");
  EXPECT_EQ(parse_error(singular_R), "m.toml: observation.R: R R^T: not positive definite (pivot 2)");
  std::string indefinite = ok;
  indefinite.replace(indefinite.find("x0_cov = [[1.0"), 14, "x0_cov = [[-1.0");
  EXPECT_EQ(parse_error(indefinite).rfind("m.toml: initial.x0_cov: not positive semidefinite", 0), 0u);
  EXPECT_THROW(read_polynomial_model_file(examples + "missing.toml"), InputError);
}

TEST(PolynomialModelFile, SetChangesTheInitialLawAndRefusesTheRest) {
  with_model_file(examples + "cubic_oscillator.toml", {"x0_mean=15,10"}, [](const auto& model) {
    EXPECT_EQ(model.x0_mean[0], 15.0);
    EXPECT_EQ(model.x0_mean[1], 10.0);
    ASSERT_NE(model.source, nullptr);
    EXPECT_STREQ(model.source->label, "cubic oscillator (file)");
  });
  try {
    with_model_file(examples + "cubic_oscillator.toml", {"q=1"}, [](const auto&) {});
    FAIL() << "--set q accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "--set q: a --model-file model takes x0_mean, x0_cov, prior_mean, prior_cov (the "
              "other coefficients are edited in " +
                  examples + "cubic_oscillator.toml)");
  }
  EXPECT_THROW(with_model_file(examples + "cubic_oscillator.toml", {"x0_cov=-1,0;0,1"}, [](const auto&) {}),
               InputError);
}

}  // namespace
}  // namespace kushner
