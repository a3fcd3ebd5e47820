#pragma once
// Basin & Alcorta-Garcia's kinematic car, seed 002 filter paper section 7, (18)-(19) (002 L1474-1480): the
// orientation phi and steering angle delta,
//   dphi = (v / l) tan(delta) dt,   ddelta = u dt,   dz = (phi, delta) dt + r dv
// (the positions x, y are decoupled and unobserved: not estimated). `car` is this model, `car-taylor3` its
// degree-3 Taylor model (20), dphi = (v / l)(delta + delta^3 / 3) dt (002 L1486).
// Paper values (002 L1505): v = l = 1, u = 0.05, truth from phi(0) = delta(0) = 0, filters from
// m(0) = (10, 0.1), P(0) = [[100, 10], [10, 1]] (singular: every filter here works without P^{-1}), V = I
// (r = 1), no process noise (q = 0). The paper "realizes" the observation noises as sin t; here they are
// Brownian unless sine_observation_noise = 1. The constant u is the open-loop steering rate; `kushner control` adds a
// control w to it, ddelta = (u + w) dt (B = (0, 1), as in Basin's regulator and controller, 002 (14), (16)).
#include "core/errors.hpp"
#include "core/math.hpp"
#include "core/small_matrix.hpp"
#include "models/drift_forms.hpp"
#include "models/initial_law.hpp"
#include "models/sine_observation_noise.hpp"

namespace kushner {

/// What the two car models share: parameters, initial laws, noise and the observation of both angles; the truths'
/// observation noise Brownian or, with sine_observation_noise = 1, the paper's sin t (`kushner reproduce basin-car-*`).
struct CarBase : InitialLaw<2>, SineObservationNoiseOption {
  static constexpr int state_dim = 2, obs_dim = 2, noise_dim = 2, control_dim = 1;
  static constexpr bool discrete_time = false;
  static constexpr bool linear_observation = true;
  using Control = Vec<control_dim>;

  double v = 1.0, l = 1.0, u = 0.05, q = 0.0, r = 1.0;

  // Device-callable: nvcc takes the cars' implicit constructors for __host__ __device__ and warned (#20011-D, in
  // every CUDA unit with a car) that they called this one while it was host-only.
  KOKKOS_INLINE_FUNCTION CarBase() {
    x0_mean = Vec<2>::zero();
    x0_cov = Mat<2, 2>::zero();
    prior_mean = Vec<2>{{10.0, 0.1}};
    prior_cov = Mat<2, 2>{{{100.0, 10.0}, {10.0, 1.0}}};
  }

  template <class Visitor>
  void parameters(Visitor&& visit) {
    visit("v", v, "velocity (seed 002: 1)");
    visit("l", l, "wheelbase (seed 002: 1)");
    visit("u", u, "steering rate, constant and known (seed 002: 0.05)");
    visit("q", q, "process noise intensity on both angles (paper: 0)");
    visit("r", r, "observation noise intensity of both angles (seed 002: V = I)");
    sine_observation_noise_parameter(visit);
    initial_law_parameters(visit);
  }

  void validate() const {
    KUSHNER_INPUT_REQUIRE(l != 0.0, "l: the wheelbase must not be 0");
    validate_sine_observation_noise();
  }

  KOKKOS_INLINE_FUNCTION Mat<2, 1> control_input(double) const { return {{{0.0}, {1.0}}}; }
  KOKKOS_INLINE_FUNCTION Mat<2, 2> diffusion(double, const Vec<2>&) const { return Mat<2, 2>::diagonal(q); }
  KOKKOS_INLINE_FUNCTION Vec<2> observation(double, const Vec<2>& x) const { return x; }
  KOKKOS_INLINE_FUNCTION Mat<2, 2> observation_jacobian(double, const Vec<2>&) const { return Mat<2, 2>::identity(); }
  KOKKOS_INLINE_FUNCTION Mat<2, 2> observation_hessian(double, const Vec<2>&, int) const { return Mat<2, 2>::zero(); }
  KOKKOS_INLINE_FUNCTION Mat<2, 2> observation_noise(double) const { return Mat<2, 2>::diagonal(r); }
};

struct CarModel : CarBase {
  static constexpr const char* name = "car";
  static constexpr const char* description =
      "Basin's kinematic car (orientation, steering angle): dphi = (v/l) tan(delta) dt, ddelta = u dt, dz = x dt + r "
      "dv";
  /// E|tan(delta)| is infinite for Gaussian delta (poles at +-pi/2): no quasi-linear filter exists.
  static constexpr bool drift_gaussian_integrable = false;

  KOKKOS_INLINE_FUNCTION Vec<2> drift(double, const Vec<2>& x, const Control& w) const {
    return {{v / l * math::tan(x[1]), u + w[0]}};
  }
  KOKKOS_INLINE_FUNCTION Mat<2, 2> drift_jacobian(double, const Vec<2>& x, const Control&) const {
    const double c = math::cos(x[1]);
    return {{{0.0, v / l / (c * c)}, {0.0, 0.0}}};
  }
  KOKKOS_INLINE_FUNCTION Mat<2, 2> drift_hessian(double, const Vec<2>& x, const Control&, int k) const {
    Mat<2, 2> h = Mat<2, 2>::zero();
    const double c = math::cos(x[1]);
    if (k == 0) h(1, 1) = 2.0 * v / l * math::tan(x[1]) / (c * c);
    return h;
  }
  /// A(x) = [[0, (v/l) tan(delta) / delta], [0, 0]] (tan(delta) / delta = 1 at delta = 0), b = (0, u): then
  /// A(x) x + b = ((v/l) tan(delta), u) = f(x).
  KOKKOS_INLINE_FUNCTION SdcDrift<2> sdc_drift(double, const Vec<2>& x) const {
    const double d = x[1];
    const double tan_over = math::fabs(d) < 1e-4 ? 1.0 + d * d / 3.0 : math::tan(d) / d;
    return {{{{0.0, v / l * tan_over}, {0.0, 0.0}}}, {{0.0, u}}};
  }
  /// The polynomial a controller is designed on (Basin's regulator, 002 control paper (10)): the degree-3 Taylor
  /// model of car-taylor3, since tan has no power-polynomial form (engine/control/poly3_regulator.hpp).
  KOKKOS_INLINE_FUNCTION PowerPolynomial<2, 3> design_polynomial(double) const;
};

struct CarTaylor3Model : CarBase {
  static constexpr const char* name = "car-taylor3";
  static constexpr const char* description =
      "Basin's car, degree-3 Taylor model: dphi = (v/l)(delta + delta^3/3) dt, ddelta = u dt, dz = x dt + r dv";

  KOKKOS_INLINE_FUNCTION Vec<2> drift(double, const Vec<2>& x, const Control& w) const {
    const double d = x[1];
    return {{v / l * (d + d * d * d / 3.0), u + w[0]}};
  }
  KOKKOS_INLINE_FUNCTION Mat<2, 2> drift_jacobian(double, const Vec<2>& x, const Control&) const {
    return {{{0.0, v / l * (1.0 + x[1] * x[1])}, {0.0, 0.0}}};
  }
  KOKKOS_INLINE_FUNCTION Mat<2, 2> drift_hessian(double, const Vec<2>& x, const Control&, int k) const {
    Mat<2, 2> h = Mat<2, 2>::zero();
    if (k == 0) h(1, 1) = 2.0 * v / l * x[1];
    return h;
  }
  /// a0 = (0, u), a1 = [[0, v/l], [0, 0]], a3 = [[0, v/(3l)], [0, 0]]: the Taylor drift (v/l)(delta + delta^3/3), u.
  KOKKOS_INLINE_FUNCTION PowerPolynomial<2, 3> drift_power_polynomial(double) const {
    auto poly = PowerPolynomial<2, 3>::zero();
    poly.a0 = Vec<2>{{0.0, u}};
    poly.coefficient[1](0, 1) = v / l;
    poly.coefficient[3](0, 1) = v / (3.0 * l);
    return poly;
  }
  /// A(x) = [[0, (v/l)(1 + delta^2 / 3)], [0, 0]], b = (0, u).
  KOKKOS_INLINE_FUNCTION SdcDrift<2> sdc_drift(double, const Vec<2>& x) const {
    return {{{{0.0, v / l * (1.0 + x[1] * x[1] / 3.0)}, {0.0, 0.0}}}, {{0.0, u}}};
  }
};

KOKKOS_INLINE_FUNCTION PowerPolynomial<2, 3> CarModel::design_polynomial(double t) const {
  CarTaylor3Model taylor;
  taylor.v = v;
  taylor.l = l;
  taylor.u = u;
  return taylor.drift_power_polynomial(t);
}

}  // namespace kushner
