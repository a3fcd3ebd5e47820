// One step of every filter, computed by hand from the step's own dy (kernels/filters/filter_step.hpp:
// update with dy at (m, P), then Euler prediction at the updated (m', P')), on scalar models where each
// filter's formulas can be written out: the sine model (EKF, SOF, QLF (6.4)-(6.5), ASRE, KBL), a model with a
// quadratic observation (the dy-driven covariance terms of EKF-DS and SOF, and QLF's cubature of h), scalar
// polynomial drifts (POLY3, POLY4, BILIN, MIXED) and the Ornstein-Uhlenbeck model (KB).
#include "engine/filter_bank.hpp"
#include "models/ou_model.hpp"
#include "models/sine_model.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <type_traits>

namespace kushner {
namespace {

using Space = Kokkos::DefaultExecutionSpace;
constexpr double dt = 0.01;
constexpr double exact = 1e-13;  // relative: only rounding separates the bank from the formulas below

/// dx = -a x dt + q dw, dy = (x + c x^2) dt + r dv: h'' = 2 c, so EKF-DS and SOF have dy terms in P.
struct QuadraticObservationModel : InitialLaw<1> {
  static constexpr int state_dim = 1, obs_dim = 1, noise_dim = 1, control_dim = 0;
  static constexpr bool discrete_time = false;
  static constexpr const char* name = "quadratic-observation";
  using Control = Vec<0>;
  double a = 0.8, q = 0.6, r = 0.4, c = 0.3;
  QuadraticObservationModel() { set_initial_law(Vec<1>{{0.7}}, Mat<1, 1>{{{0.5}}}); }
  KOKKOS_INLINE_FUNCTION Vec<1> drift(double, const Vec<1>& x, const Control&) const { return {{-a * x[0]}}; }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> drift_jacobian(double, const Vec<1>&, const Control&) const { return {{{-a}}}; }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> drift_hessian(double, const Vec<1>&, const Control&, int) const { return {{{0.0}}}; }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> diffusion(double, const Vec<1>&) const { return {{{q}}}; }
  KOKKOS_INLINE_FUNCTION Vec<1> observation(double, const Vec<1>& x) const { return {{x[0] + c * x[0] * x[0]}}; }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> observation_jacobian(double, const Vec<1>& x) const {
    return {{{1.0 + 2.0 * c * x[0]}}};
  }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> observation_hessian(double, const Vec<1>&, int) const { return {{{2.0 * c}}}; }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> observation_noise(double) const { return {{{r}}}; }
};

/// dx = (a0 + a1 x + a2 x^2 + a3 x^3 + a4 x^4) dt + q dw with the terms above Degree zero, dy = x dt + r dv.
template <int Degree>
struct ScalarPolynomialModel : InitialLaw<1> {
  static constexpr int state_dim = 1, obs_dim = 1, noise_dim = 1, control_dim = 0;
  static constexpr bool discrete_time = false;
  static constexpr bool linear_observation = true;
  static constexpr const char* name = "scalar-polynomial";
  using Control = Vec<0>;
  double a[5] = {0.2, -1.0, Degree >= 2 ? 0.3 : 0.0, Degree >= 3 ? -0.25 : 0.0, Degree >= 4 ? -0.05 : 0.0};
  double q = 0.5, r = 0.3;
  ScalarPolynomialModel() { set_initial_law(Vec<1>{{0.6}}, Mat<1, 1>{{{0.4}}}); }
  KOKKOS_INLINE_FUNCTION Vec<1> drift(double, const Vec<1>& x, const Control&) const {
    const double v = x[0];
    return {{a[0] + v * (a[1] + v * (a[2] + v * (a[3] + v * a[4])))}};
  }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> drift_jacobian(double, const Vec<1>& x, const Control&) const {
    const double v = x[0];
    return {{{a[1] + v * (2 * a[2] + v * (3 * a[3] + v * 4 * a[4]))}}};
  }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> drift_hessian(double, const Vec<1>& x, const Control&, int) const {
    const double v = x[0];
    return {{{2 * a[2] + v * (6 * a[3] + v * 12 * a[4])}}};
  }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> diffusion(double, const Vec<1>&) const { return {{{q}}}; }
  KOKKOS_INLINE_FUNCTION Vec<1> observation(double, const Vec<1>& x) const { return x; }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> observation_jacobian(double, const Vec<1>&) const { return {{{1.0}}}; }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> observation_hessian(double, const Vec<1>&, int) const { return {{{0.0}}}; }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> observation_noise(double) const { return {{{r}}}; }
  KOKKOS_INLINE_FUNCTION PowerPolynomial<1, Degree> drift_power_polynomial(double) const {
    auto poly = PowerPolynomial<1, Degree>::zero();
    poly.a0[0] = a[0];
    for (int k = 1; k <= Degree; ++k) poly.coefficient[k](0, 0) = a[k];
    return poly;
  }
  template <int D = Degree, std::enable_if_t<(D <= 2), int> = 0>
  KOKKOS_INLINE_FUNCTION QuadraticPolynomial<1, 1> drift_quadratic_polynomial(double) const {
    QuadraticPolynomial<1, 1> poly;
    poly.a0[0] = a[0];
    poly.a1(0, 0) = a[1];
    poly.add(0, 0, 0, a[2]);
    return poly;
  }
};

struct OneStep {
  double m0, P0, dy, m, P;
};

/// One step of filter `name` for one member; m0, P0 the prior, dy the step's increment, m, P the result.
template <class Model>
OneStep one_step(const Model& model, const std::string& name, const OptionValues& settings = {}) {
  FilterBank<Space, Model> bank(Space(), model, model, 1, 99, {name}, settings);
  bank.step(0, dt, false);
  OneStep s{model.prior_mean[0], model.prior_cov(0, 0), 0.0, 0.0, 0.0};
  s.dy = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), bank.truths().observations())(0, 0);
  bank.with_slot(name, [&](const auto& slot) {
    s.m = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), slot.m)(0, 0);
    s.P = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), slot.P)(0, 0);
  });
  return s;
}

/// The update with dy for a scalar observation rate h_hat, its derivative H and noise intensity r.
struct Update {
  double S, K, innovation;
};
Update update(double P, double H, double h_hat, double r, double dy) {
  const double S = r * r + dt * H * H * P;
  return {S, P * H / S, dy - h_hat * dt};
}

void expect_step(const OneStep& s, double m, double P, const char* what) {
  EXPECT_NEAR(s.m, m, exact * std::abs(m)) << what << " m";
  EXPECT_NEAR(s.P, P, exact * std::abs(P)) << what << " P";
}

TEST(FilterSingleStep, SineEkfSofQlfAsreKbl) {
  const SineModel model;
  const double q = model.q, r = model.r;
  for (const char* name : {"EKF", "EKF-DS", "SOF", "SOF-B", "QLF", "ASRE", "KBL"}) {
    OptionValues settings;
    settings.set("asre_max_iterations", 2L);
    const OneStep s = one_step(model, name, settings);
    const Update u = update(s.P0, 1.0, s.m0, r, s.dy);  // every filter here predicts the observation as m
    const double m = s.m0 + u.K * u.innovation, P = s.P0 - dt * u.K * s.P0;
    double a = 0.0, J = 0.0;
    const std::string n = name;
    if (n == "EKF" || n == "EKF-DS") a = -std::sin(m), J = -std::cos(m);
    if (n == "SOF" || n == "SOF-B") a = -std::sin(m) + 0.5 * std::sin(m) * P, J = -std::cos(m);    // (6.10)-(6.11)
    if (n == "QLF") a = -std::sin(m) * std::exp(-0.5 * P), J = -std::cos(m) * std::exp(-0.5 * P);  // (6.4)-(6.5)
    if (n == "ASRE") J = -std::sin(s.m0) / s.m0, a = J * m;  // every iterate linearizes at m(0) on the first step
    if (n == "KBL") a = -m, J = -1.0;
    expect_step(s, m + a * dt, (1 + J * dt) * (1 + J * dt) * P + q * q * dt, name);
  }
}

TEST(FilterSingleStep, QuadraticObservationCurvatureTerms) {
  const QuadraticObservationModel model;
  const double a = model.a, q = model.q, r = model.r, c = model.c;
  for (const char* name : {"EKF", "EKF-DS", "SOF", "SOF-B", "QLF", "KBL"}) {
    const OneStep s = one_step(model, name);
    const double m0 = s.m0, P0 = s.P0, h = m0 + c * m0 * m0, H = 1 + 2 * c * m0;
    const std::string n = name;
    double m = 0.0, P = 0.0;
    if (n == "EKF" || n == "EKF-DS") {
      const Update u = update(P0, H, h, r, s.dy);
      m = m0 + u.K * u.innovation;
      P = P0 - dt * u.K * H * P0 + (n == "EKF-DS" ? 0.5 * P0 * 2 * c * P0 * u.innovation / u.S : 0.0);  // row [13]
    } else if (n == "SOF" || n == "SOF-B") {
      const Update u = update(P0, H, h + c * P0, r, s.dy);  // h_bar = h + 1/2 h'' P
      m = m0 + u.K * u.innovation;
      P = P0 - dt * u.K * H * P0 + (n == "SOF" ? P0 * 2 * c * P0 * u.innovation / u.S : 0.0);  // row [9]
    } else if (n == "QLF") {  // E[h] = m + c (m^2 + P), E[h'] = 1 + 2 c m
      const Update u = update(P0, H, m0 + c * (m0 * m0 + P0), r, s.dy);
      m = m0 + u.K * u.innovation;
      P = P0 - dt * u.K * H * P0;
    } else {  // KBL: h linearized at 0 is x
      const Update u = update(P0, 1.0, m0, r, s.dy);
      m = m0 + u.K * u.innovation;
      P = P0 - dt * u.K * P0;
    }
    expect_step(s, m - a * m * dt, (1 - a * dt) * (1 - a * dt) * P + q * q * dt, name);
  }
}

template <int Degree>
void expect_polynomial_filters_step(std::initializer_list<const char*> names) {
  const ScalarPolynomialModel<Degree> model;
  const double* c = model.a;
  for (const char* name : names) {
    const OneStep s = one_step(model, name);
    const Update u = update(s.P0, 1.0, s.m0, model.r, s.dy);
    const double m = s.m0 + u.K * u.innovation, P = s.P0 - dt * u.K * s.P0;
    const double e2 = P + m * m, e3 = 3 * P * m + m * m * m, e4 = 3 * P * P + 6 * P * m * m + m * m * m * m;
    const double a = c[0] + c[1] * m + c[2] * e2 + c[3] * e3 + c[4] * e4;  // seed 002 (9), (12)
    const std::string n = name;
    const double J = n == "MIXED" ? c[1]  // the Kalman-Bucy covariance of the origin linearization
                                  : c[1] + 2 * c[2] * m + 3 * c[3] * e2 + 4 * c[4] * e3;  // (10), (13)
    expect_step(s, m + a * dt, (1 + J * dt) * (1 + J * dt) * P + model.q * model.q * dt, name);
  }
}

TEST(FilterSingleStep, PolynomialFilters) {
  expect_polynomial_filters_step<2>({"POLY3", "POLY4", "BILIN", "MIXED"});
  expect_polynomial_filters_step<3>({"POLY3", "POLY4", "MIXED"});
  expect_polynomial_filters_step<4>({"POLY4", "MIXED"});
}

TEST(FilterSingleStep, KalmanBucyOnOrnsteinUhlenbeck) {
  OuModel model;
  model.mu = 0.4;
  const OneStep s = one_step(model, "KB");
  const Update u = update(s.P0, 1.0, s.m0, model.r, s.dy);
  const double m = s.m0 + u.K * u.innovation, P = s.P0 - dt * u.K * s.P0;
  expect_step(s, m - model.theta * (m - model.mu) * dt,
              (1 - model.theta * dt) * (1 - model.theta * dt) * P + model.sigma * model.sigma * dt, "KB");
}

TEST(FilterSingleStep, FiltersRefuseModelsTheyCannotHandle) {
  using Quartic = ScalarPolynomialModel<4>;
  using Cubic = ScalarPolynomialModel<3>;
  EXPECT_STREQ((Polynomial3Filter<Quartic, Kokkos::HostSpace>::unsupported), "drift has degree above 3");
  EXPECT_EQ((Polynomial4Filter<Quartic, Kokkos::HostSpace>::unsupported), nullptr);
  EXPECT_STREQ((BilinearFilter<Cubic, Kokkos::HostSpace>::unsupported), "drift is not bilinear");
  EXPECT_STREQ((AsreFilter<QuadraticObservationModel, Kokkos::HostSpace>::unsupported),
               "model has no factorization f = A(x) x + b");
}

}  // namespace
}  // namespace kushner
