// One step of every filter, computed by hand from the step's own dy (kernels/filters/filter_step.hpp:
// update with dy at (m, P), then Euler prediction at the updated (m', P')), on scalar models where each
// filter's formulas can be written out: the sine model (EKF, SOF, QLF (6.4)-(6.5), ASRE, KBL), a model with a
// quadratic observation (the dy-driven covariance terms of EKF-DS and SOF, and QLF's cubature of h), scalar
// polynomial drifts (POLY3, POLY4, BILIN, MIXED) and the Ornstein-Uhlenbeck model (KB); and on the models with a
// nonlinear observation, the cubic sensor (h = x^3) and the pendulum (h = sin x1), where EKF-DS differs from EKF
// and SOF from SOF-B by the h'' terms of seed 000 Tables 1-2 rows [13] and [9] (and QLF, ASRE, UKF use h too).
#include "engine/filter_bank.hpp"
#include "models/cubic_sensor_model.hpp"
#include "models/ou_model.hpp"
#include "models/pendulum_model.hpp"
#include "models/sine_model.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <type_traits>

namespace kushner {
// The test's models, outside the anonymous namespace: nvcc warns (#177-D) about members of its classes that this file
// never reads (control_dim, linear_observation), which every model declares.
namespace single_step_models {

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

}  // namespace single_step_models
using single_step_models::QuadraticObservationModel;
using single_step_models::ScalarPolynomialModel;

namespace {

using Space = Kokkos::DefaultExecutionSpace;
constexpr double dt = 0.01;
constexpr double exact = 1e-13;  // relative: only rounding separates the bank from the formulas below

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

/// The cubic sensor dx = sigma dw, dy = x^3 dt + r dv: h' = 3 x^2, h'' = 6 x; no drift, so the prediction
/// only adds sigma^2 dt to P.
TEST(FilterSingleStep, CubicSensorUsesTheNonlinearObservation) {
  const CubicSensorModel model;
  const double sigma = model.sigma, r = model.r;
  double ekf_P = 0.0, ekf_ds_P = 0.0, sof_P = 0.0, sof_b_P = 0.0;
  for (const char* name : {"EKF", "EKF-DS", "SOF", "SOF-B", "QLF", "ASRE", "UKF", "KBL"}) {
    OptionValues settings;
    settings.set("asre_max_iterations", 2L);
    const OneStep s = one_step(model, name, settings);
    const double m0 = s.m0, P0 = s.P0, h = m0 * m0 * m0, H = 3 * m0 * m0, h2 = 6 * m0;
    const std::string n = name;
    double m = 0.0, P = 0.0;
    if (n == "EKF" || n == "EKF-DS") {  // rows [14], [13]
      const Update u = update(P0, H, h, r, s.dy);
      m = m0 + u.K * u.innovation;
      P = P0 - dt * u.K * H * P0 + (n == "EKF-DS" ? 0.5 * P0 * h2 * P0 * u.innovation / u.S : 0.0);
    } else if (n == "SOF" || n == "SOF-B") {  // rows [9], [12]: h_bar = h + 1/2 h'' P
      const Update u = update(P0, H, h + 0.5 * h2 * P0, r, s.dy);
      m = m0 + u.K * u.innovation;
      P = P0 - dt * u.K * H * P0 + (n == "SOF" ? P0 * h2 * P0 * u.innovation / u.S : 0.0);
    } else if (n == "QLF") {  // (5.9)-(5.10): E[x^3] = m^3 + 3 m P, E[3 x^2] = 3 (m^2 + P)
      const Update u = update(P0, 3 * (m0 * m0 + P0), h + 3 * m0 * P0, r, s.dy);
      m = m0 + u.K * u.innovation;
      P = P0 - dt * u.K * 3 * (m0 * m0 + P0) * P0;
    } else if (n == "ASRE") {  // seed 001 (11)-(12) with C(x) = x^2 at m^[i-1] = m(0): h_hat = C m, H = C
      const double C = m0 * m0;
      const Update u = update(P0, C, C * m0, r, s.dy);
      m = m0 + u.K * u.innovation;
      P = P0 - dt * u.K * C * P0;
    } else if (n == "UKF") {  // alpha = 1, beta = 0, kappa = 0: sigma points m0 +- sqrt(P0), weights 1/2
      const double d = std::sqrt(P0), hp = std::pow(m0 + d, 3), hm = std::pow(m0 - d, 3), h_bar = 0.5 * (hp + hm);
      const double Cxh = 0.5 * d * (hp - hm), Chh = 0.5 * ((hp - h_bar) * (hp - h_bar) + (hm - h_bar) * (hm - h_bar));
      const double S = r * r + dt * Chh, K = Cxh / S;
      m = m0 + K * (s.dy - h_bar * dt);
      P = P0 - dt * K * Cxh;
    } else {  // KBL: h linearized at 0 is 0, so no update
      m = m0, P = P0;
    }
    expect_step(s, m, P + sigma * sigma * dt, name);
    if (n == "EKF") ekf_P = s.P;
    if (n == "EKF-DS") ekf_ds_P = s.P;
    if (n == "SOF") sof_P = s.P;
    if (n == "SOF-B") sof_b_P = s.P;
  }
  // The h'' terms are of order P^2 h'' (dy - h dt) / r^2, far above rounding: EKF-DS != EKF, SOF != SOF-B.
  EXPECT_GT(std::abs(ekf_ds_P - ekf_P), 1e-6) << "EKF-DS " << ekf_ds_P << " EKF " << ekf_P;
  EXPECT_GT(std::abs(sof_P - sof_b_P), 1e-6) << "SOF " << sof_P << " SOF-B " << sof_b_P;
}

/// One step of filter `name` on a model of any dimension: prior, dy and the result.
template <class Model>
struct OneStepN {
  Vec<Model::state_dim> m0, m;
  Mat<Model::state_dim, Model::state_dim> P0, P;
  Vec<Model::obs_dim> dy;
};
template <class Model>
OneStepN<Model> one_step_n(const Model& model, const std::string& name, const OptionValues& settings = {}) {
  constexpr int n = Model::state_dim;
  FilterBank<Space, Model> bank(Space(), model, model, 1, 99, {name}, settings);
  bank.step(0, dt, false);
  OneStepN<Model> s{model.prior_mean, model.prior_mean, model.prior_cov, model.prior_cov, {}};
  const auto dy = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), bank.truths().observations());
  for (int l = 0; l < Model::obs_dim; ++l) s.dy[l] = dy(0, l);
  bank.with_slot(name, [&](const auto& slot) {
    const auto m = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), slot.m);
    const auto P = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), slot.P);
    for (int i = 0; i < n; ++i) s.m[i] = m(0, i);
    for (int i = 0; i < n; ++i)
      for (int j = i; j < n; ++j) s.P(i, j) = s.P(j, i) = P(0, packed_index(n, i, j));
  });
  return s;
}

/// The pendulum dx1 = x2 dt, dx2 = -g sin x1 dt + q dw, dy = sin x1 dt + r dv, written out component by
/// component: H = (cos m1, 0), h'' only in (1, 1): -sin m1; f2'' only in (1, 1): g sin x1.
TEST(FilterSingleStep, PendulumUsesTheNonlinearObservation) {
  const PendulumModel model;
  const double g = model.g, q = model.q, r = model.r;
  Mat<2, 2> ekf_P = Mat<2, 2>::zero(), ekf_ds_P = ekf_P, sof_P = ekf_P, sof_b_P = ekf_P;
  for (const char* name : {"EKF", "EKF-DS", "SOF", "SOF-B"}) {
    const auto s = one_step_n(model, name);
    const std::string n = name;
    const bool second_order = n == "SOF" || n == "SOF-B";
    const double a = s.m0[0], b = s.m0[1], p11 = s.P0(0, 0), p12 = s.P0(0, 1), p22 = s.P0(1, 1);
    // Update: K = P H^T / S with P H^T = cos(a) (p11, p12), S = r^2 + dt cos(a)^2 p11.
    const double c = std::cos(a), S = r * r + dt * c * c * p11;
    const double h_hat = std::sin(a) - (second_order ? 0.5 * std::sin(a) * p11 : 0.0);
    const double innovation = s.dy[0] - h_hat * dt, k1 = c * p11 / S, k2 = c * p12 / S;
    double m1 = a + k1 * innovation, m2 = b + k2 * innovation;
    double P11 = p11 - dt * c * c * p11 * p11 / S, P12 = p12 - dt * c * c * p11 * p12 / S,
           P22 = p22 - dt * c * c * p12 * p12 / S;
    // dy terms: w P Hess(h) P, Hess(h) = -sin(a) e1 e1^T, so P Hess P = -sin(a) (p11, p12)(p11, p12)^T.
    const double weight = n == "EKF-DS" ? 0.5 : n == "SOF" ? 1.0 : 0.0, w = weight * innovation / S * -std::sin(a);
    P11 += w * p11 * p11, P12 += w * p11 * p12, P22 += w * p12 * p12;
    // Prediction at the updated (m, P): J = [[0, 1], [-g cos m1, 0]]; SOF adds 1/2 g sin(m1) P11 to f2.
    const double f2 = -g * std::sin(m1) + (second_order ? 0.5 * g * std::sin(m1) * P11 : 0.0), j21 = -g * std::cos(m1);
    const double new_m1 = m1 + m2 * dt, new_m2 = m2 + f2 * dt;
    // (I + J dt) P (I + J dt)^T + diag(0, q^2) dt
    const double e11 = 1, e12 = dt, e21 = j21 * dt, e22 = 1;
    const double A11 = e11 * P11 + e12 * P12, A12 = e11 * P12 + e12 * P22, A21 = e21 * P11 + e22 * P12,
                 A22 = e21 * P12 + e22 * P22;
    const double N11 = A11 * e11 + A12 * e12, N12 = A11 * e21 + A12 * e22, N22 = A21 * e21 + A22 * e22 + q * q * dt;
    EXPECT_NEAR(s.m[0], new_m1, exact * std::abs(new_m1)) << name;
    EXPECT_NEAR(s.m[1], new_m2, exact * std::abs(new_m2)) << name;
    EXPECT_NEAR(s.P(0, 0), N11, exact * std::abs(N11)) << name;
    EXPECT_NEAR(s.P(0, 1), N12, 1e-12 * std::abs(N11)) << name;
    EXPECT_NEAR(s.P(1, 1), N22, exact * std::abs(N22)) << name;
    (n == "EKF" ? ekf_P : n == "EKF-DS" ? ekf_ds_P : n == "SOF" ? sof_P : sof_b_P) = s.P;
  }
  EXPECT_GT(std::abs(ekf_ds_P(0, 0) - ekf_P(0, 0)), 1e-6) << "EKF-DS = EKF on the pendulum";
  EXPECT_GT(std::abs(sof_P(0, 0) - sof_b_P(0, 0)), 1e-6) << "SOF = SOF-B on the pendulum";
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

/// A scalar covariance's definiteness (every filter's check after its step, written without branches for N = 1) as
/// the general factorization's loops decide it: a pivot within tolerance * max(a, 0) of zero is zero, below minus that
/// or not finite is indefinite; the factor sqrt(a) where definite, else 0.
TEST(FilterSingleStep, AScalarCovarianceIsJudgedAsTheFactorizationLoopsJudgeIt) {
  using limits = std::numeric_limits<double>;
  const double inf = limits::infinity(), tiny = limits::denorm_min(), big = limits::max(), nan = limits::quiet_NaN();
  const double values[] = {0.0, -0.0, tiny,  -tiny,  1e-300, -1e-300, 1e-10, 0.25,
                           1.0, -1.0, 1e300, -1e300, big,    inf,     -inf,  nan};
  int checked = 0;
  for (const double tolerance : {0.0, covariance_tolerance, 0.5})
    for (const double a : values) {
      const double zero = tolerance * (a > 0.0 ? a : 0.0);
      const Definiteness expected = !std::isfinite(a) || a < -zero ? Definiteness::indefinite
                                    : a <= zero                    ? Definiteness::singular
                                                                   : Definiteness::positive_definite;
      Mat<1, 1> L;
      EXPECT_EQ(semidefinite_cholesky(Mat<1, 1>{{{a}}}, L, tolerance), expected) << a << ", tolerance " << tolerance;
      EXPECT_EQ(L(0, 0), expected == Definiteness::positive_definite ? std::sqrt(a) : 0.0) << a;
      ++checked;
    }
  EXPECT_EQ(checked, 48);
  EXPECT_TRUE(all_finite(Vec<3>{{1.0, -2.0, 1e308}}));
  EXPECT_FALSE(all_finite(Vec<3>{{1.0, inf, 0.0}}));
  EXPECT_FALSE(all_finite(Mat<2, 2>{{{1.0, 0.0}, {0.0, nan}}}));
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
