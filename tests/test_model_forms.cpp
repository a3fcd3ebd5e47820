// The structured forms each model hands the filters describe the same drift as drift() itself: linear
// forms, componentwise and bilinear polynomials, SDC factorizations A(x) x + b and C(x) x + c0, linear
// observations, and the closed-form Gaussian expectations of drift and observation (seed 000 (6.4)-(6.5), (6.14);
// polynomial moments; the cubic sensor's and pendulum's E[h]) against 20-node Gauss-Hermite cubature, and the
// float dynamics of a model that has them (fp32's particle step) against its double ones. Every continuous-time
// model of the registry is checked for every form it has.
#include "kernels/filters/gaussian_expectations.hpp"
#include "kernels/filters/linearized_kalman_bucy_filter.hpp"
#include "kernels/particle_filter/particle_model_traits.hpp"
#include "models/registry.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>

namespace kushner {
namespace {

template <int N>
void expect_vectors_near(const Vec<N>& a, const Vec<N>& b, double tolerance, const std::string& what) {
  for (int i = 0; i < N; ++i) EXPECT_NEAR(a[i], b[i], tolerance * (1 + std::abs(b[i]))) << what << " [" << i << "]";
}

template <class Model>
Vec<Model::state_dim> test_point(int k) {
  Vec<Model::state_dim> x;
  for (int i = 0; i < Model::state_dim; ++i) x[i] = 0.6 * std::sin(1.3 * k + 0.7 * i) + 0.1 * i;
  return x;
}

/// A positive definite covariance with correlations, scaled by s.
template <int N>
Mat<N, N> test_covariance(double s) {
  Mat<N, N> P = Mat<N, N>::zero();
  for (int i = 0; i < N; ++i)
    for (int j = 0; j < N; ++j) P(i, j) = s * (i == j ? 1.0 : 0.3 / (1 + std::abs(i - j)));
  return P;
}

template <class Model>
void expect_forms_match_drift(const Model& model) {
  constexpr int n = Model::state_dim;
  using T = ModelTraits<Model>;
  const typename Model::Control u = Model::Control::zero();
  const double t = 0.4;
  const std::string name = Model::name;
  for (int k = 0; k < 5; ++k) {
    const Vec<n> x = test_point<Model>(k);
    const Vec<n> f = model.drift(t, x, u);
    typename Model::Control pushed = Model::Control::zero();  // a control input as well, for a model that has one
    for (int i = 0; i < Model::control_dim; ++i) pushed[i] = 0.7 - 0.2 * i;
    for (const auto& control : {u, pushed}) {
      const DriftAndJacobian<n> together = drift_and_jacobian(model, t, x, control);
      const Vec<n> drift = model.drift(t, x, control);
      const Mat<n, n> J = model.drift_jacobian(t, x, control);
      for (int i = 0; i < n; ++i) {
        EXPECT_EQ(together.drift[i], drift[i]) << name << " drift_and_jacobian's drift [" << i << "]";
        for (int j = 0; j < n; ++j)
          EXPECT_EQ(together.jacobian(i, j), J(i, j)) << name << " drift_and_jacobian's (" << i << ", " << j << ")";
      }
      if constexpr (detail::has_drift_derivatives<Model>::value) {
        const DriftDerivatives<n> all = model.drift_derivatives(t, x, control);
        for (int i = 0; i < n; ++i) {
          EXPECT_EQ(all.drift[i], drift[i]) << name << " drift_derivatives' drift [" << i << "]";
          const Mat<n, n> H = model.drift_hessian(t, x, control, i);
          for (int j = 0; j < n; ++j) {
            EXPECT_EQ(all.jacobian(i, j), J(i, j)) << name << " drift_derivatives' (" << i << ", " << j << ")";
            for (int l = 0; l < n; ++l)
              EXPECT_EQ(all.hessian[i](j, l), H(j, l)) << name << " drift_derivatives' Hessian " << i;
          }
        }
      }
    }
    if constexpr (T::power_polynomial)
      expect_vectors_near(drift_power_polynomial(model, t)(x), f, 1e-13, name + " power polynomial");
    if constexpr (T::quadratic_polynomial)
      expect_vectors_near(drift_quadratic_polynomial(model, t)(x), f, 1e-13, name + " quadratic polynomial");
    if constexpr (T::sdc) {
      const SdcDrift<n> s = drift_sdc(model, t, x);
      expect_vectors_near(s.A * x + s.b, f, 1e-13, name + " A(x) x + b");
    }
    if constexpr (T::linear) {
      const auto lf = model.linear_form(t);
      expect_vectors_near(lf.a0 + lf.A * x, f, 1e-13, name + " linear form drift");
      expect_vectors_near(lf.c0 + lf.C * x, model.observation(t, x), 1e-13, name + " linear form observation");
    }
    if constexpr (T::linear_observation) {
      const auto h0 = model.observation(t, Vec<n>::zero());
      expect_vectors_near(h0 + model.observation_jacobian(t, x) * x, model.observation(t, x), 1e-13,
                          name + " linear observation");
    }
    if constexpr (detail::has_sdc_observation<Model>::value) {
      const auto c = observation_sdc(model, t, x);
      expect_vectors_near(c.C * x + c.c0, model.observation(t, x), 1e-13, name + " C(x) x + c0");
    }
    if constexpr (detail::has_gaussian_observation<Model>::value) {
      const GaussHermiteRule rule = make_gauss_hermite_rule(20);
      for (double s : {0.01, 0.5}) {
        const Mat<n, n> P = test_covariance<n>(s);
        ObservationLinearization<n, Model::obs_dim> cubature;
        ASSERT_TRUE(cubature_observation(model, t, x, P, rule, cubature));
        const auto closed = model.gaussian_observation(t, x, P);
        expect_vectors_near(closed.mean, cubature.h, 1e-11, name + " E[h]");
        for (int i = 0; i < Model::obs_dim; ++i)
          for (int j = 0; j < n; ++j)
            EXPECT_NEAR(closed.jacobian(i, j), cubature.H(i, j), 1e-11 * (1 + std::abs(cubature.H(i, j))))
                << name << " E[grad h] (" << i << ", " << j << ")";
      }
    }
    if constexpr (has_float_dynamics<Model>::value) {  // the same functions, to float's precision
      const Vec<n, float> xf = convert<float>(x);
      const Vec<n> x_rounded = convert<double>(xf);
      expect_vectors_near(convert<double>(model.drift(t, xf, u)), model.drift(t, x_rounded, u), 1e-6,
                          name + " float drift");
      expect_vectors_near(convert<double>(model.observation(t, xf)), model.observation(t, x_rounded), 1e-6,
                          name + " float observation");
      const auto gf = model.diffusion(t, xf);
      const auto gd = model.diffusion(t, x_rounded);
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < Model::noise_dim; ++j)
          EXPECT_NEAR(gf(i, j), gd(i, j), 1e-6 * (1 + std::abs(gd(i, j)))) << name << " float diffusion";
    }
    if constexpr (T::closed_form_expectations && n <= max_cubature_dim) {
      const GaussHermiteRule rule = make_gauss_hermite_rule(20);
      for (double s : {0.01, 0.5}) {
        const Mat<n, n> P = test_covariance<n>(s);
        GaussianDrift<n> cubature;
        ASSERT_TRUE(cubature_drift(model, t, x, P, rule, cubature));
        const GaussianDrift<n> closed = closed_form_drift(model, t, x, P);
        expect_vectors_near(closed.mean, cubature.mean, 1e-11, name + " E[f]");
        for (int i = 0; i < n; ++i)
          for (int j = 0; j < n; ++j)
            EXPECT_NEAR(closed.jacobian(i, j), cubature.jacobian(i, j), 1e-11 * (1 + std::abs(cubature.jacobian(i, j))))
                << name << " E[grad f] (" << i << ", " << j << ")";
      }
    }
  }
}

TEST(ModelForms, EveryFormAModelHasDescribesItsDrift) {
  int checked = 0, with_float_dynamics = 0;
  detail::for_each_model_type([&](auto* tag) {
    using Model = std::remove_pointer_t<decltype(tag)>;
    if constexpr (!Model::discrete_time) {
      expect_forms_match_drift(Model{});
      ++checked;
      with_float_dynamics += has_float_dynamics<Model>::value;
    }
  });
  EXPECT_EQ(checked, 13);             // ou, sine, cubic-oscillator, linear 1-3, car, car-taylor3, terpolymer, benes,
                                      // cubic-sensor, pendulum, range-bearing
  EXPECT_EQ(with_float_dynamics, 5);  // ou, sine, linear 1-3
}

/// The same bit patterns (a NaN too: range-bearing's dh/dx at the origin).
using math::bits_of;
template <int R, int C>
void expect_same_bits(const Mat<R, C>& a, const Mat<R, C>& b, const std::string& what) {
  for (int i = 0; i < R; ++i)
    for (int j = 0; j < C; ++j)
      EXPECT_EQ(bits_of(a(i, j)), bits_of(b(i, j))) << what << " (" << i << ", " << j << "): " << a(i, j);
}
template <int N>
void expect_same_bits(const Vec<N>& a, const Vec<N>& b, const std::string& what) {
  for (int i = 0; i < N; ++i) EXPECT_EQ(bits_of(a[i]), bits_of(b[i])) << what << " [" << i << "]: " << a[i];
}

/// A model that states it is time invariant: f, df/dx, G, h, dh/dx and R the same at every t, at the origin (where
/// KBL and MIXED evaluate them, once) and elsewhere; and KBL's linearization at the origin, taken once, what its
/// evaluation at each step gives.
template <class Model>
void expect_time_invariant(const Model& model) {
  constexpr int n = Model::state_dim;
  const std::string name = Model::name;
  const auto u = Model::Control::zero();
  for (int k = -1; k < 3; ++k) {
    const Vec<n> x = k < 0 ? Vec<n>::zero() : test_point<Model>(k);
    for (const double t : {0.4, 3.7, 120.0}) {
      const std::string at = name + " at t = " + std::to_string(t) + ", point " + std::to_string(k);
      const DriftAndJacobian<n> f0 = drift_and_jacobian(model, 0.0, x, u), f = drift_and_jacobian(model, t, x, u);
      expect_same_bits(f.drift, f0.drift, at + " f");
      expect_same_bits(f.jacobian, f0.jacobian, at + " df/dx");
      expect_same_bits(model.diffusion(t, x), model.diffusion(0.0, x), at + " G");
      expect_same_bits(model.observation(t, x), model.observation(0.0, x), at + " h");
      expect_same_bits(model.observation_jacobian(t, x), model.observation_jacobian(0.0, x), at + " dh/dx");
      expect_same_bits(model.observation_noise(t), model.observation_noise(0.0), at + " R");
    }
  }
  const auto once = OriginLinearization<Model, true>::of(model);
  const OriginLinearization<Model, false> each_step;
  for (const double t : {0.0, 0.4, 3.7}) {
    expect_same_bits(once.drift(model, t).a, each_step.drift(model, t).a, name + " a0");
    expect_same_bits(once.drift(model, t).J, each_step.drift(model, t).J, name + " F0");
    expect_same_bits(once.drift(model, t).W, each_step.drift(model, t).W, name + " W0");
    expect_same_bits(once.observation(model, t).h, each_step.observation(model, t).h, name + " c0");
    expect_same_bits(once.observation(model, t).H, each_step.observation(model, t).H, name + " H0");
  }
}

TEST(ModelForms, ATimeInvariantModelIsTheSameAtEveryTime) {
  int checked = 0;
  detail::for_each_model_type([&](auto* tag) {
    using Model = std::remove_pointer_t<decltype(tag)>;
    if constexpr (!Model::discrete_time && ModelTraits<Model>::time_invariant) {
      expect_time_invariant(Model{});
      ++checked;
    }
  });
  EXPECT_EQ(checked, 10);  // ou, sine, cubic-oscillator, linear 1-3, benes, cubic-sensor, pendulum, range-bearing
}

/// Counts the points where the sine model's drift_and_jacobian differs from its drift and drift_jacobian, and its
/// drift_derivatives' Hessian from the sine of its drift: arguments up to 100, and every 7th up to 1e6 (the slow range
/// reduction past ~2^20 too), of both signs.
struct SineDriftAndJacobianMismatches {
  SineModel sine;
  int points;
  KOKKOS_INLINE_FUNCTION void operator()(const int i, int& count) const {
    const double r = static_cast<double>(i) / points;
    const Vec<1> x{{(i % 2 == 0 ? 1.0 : -1.0) * r * r * (i % 7 == 0 ? 1e6 : 100.0)}};
    const auto u = SineModel::Control::zero();
    const DriftAndJacobian<1> together = sine.drift_and_jacobian(0.0, x, u);
    count += together.drift[0] == sine.drift(0.0, x, u)[0] ? 0 : 1;
    count += together.jacobian(0, 0) == sine.drift_jacobian(0.0, x, u)(0, 0) ? 0 : 1;
    // The Hessian sin(x) (drift_derivatives') against -drift with no control, math::sin's.
    count += sine.drift_derivatives(0.0, x, u).hessian[0](0, 0) == -sine.drift(0.0, x, u)[0] ? 0 : 1;
  }
};

/// Where the kernels run (a GPU in a CUDA build, where drift_and_jacobian takes one sincos): the same bits.
TEST(ModelForms, SineDriftAndJacobianAreItsDriftAndJacobianWhereKernelsRun) {
  using Space = Kokkos::DefaultExecutionSpace;
  constexpr int points = 200000;
  int differ = 0;
  Kokkos::parallel_reduce("test::sine_drift_and_jacobian", Kokkos::RangePolicy<Space>(0, points),
                          SineDriftAndJacobianMismatches{SineModel{}, points}, differ);
  EXPECT_EQ(differ, 0) << "of " << 3 * points << " values, on " << Space::name();
}

TEST(ModelForms, ClosedFormExpectationsDifferFromThePointValues) {  // power: E_N[f] != f(m) for nonlinear f
  const SineModel sine;
  const GaussianDrift<1> g = closed_form_drift(sine, 0.0, Vec<1>{{1.0}}, Mat<1, 1>{{{0.5}}});
  EXPECT_GT(std::abs(g.mean[0] - sine.drift(0.0, Vec<1>{{1.0}}, SineModel::Control::zero())[0]), 0.1);
}

}  // namespace
}  // namespace kushner
