#pragma once
// The cubic sensor: a Brownian motion observed through its cube,
//   dx = sigma dw,   dy = x^3 dt + r dv,
// the standard case for which no finite-dimensional filter exists (Hazewinkel, Marcus and Sussmann 1983).
// Seed 000's general equations (4.7), (5.27)-(5.29) and Tables 1-2 apply with h = x^3, h' = 3 x^2, h'' = 6 x,
// so the Detchmendy-Sridhar and Schwartz covariance terms (rows [13], [9]) are not zero here. Ours: sigma = 1,
// r = 1, x(0) ~ N(1, 1) for the truths and the filters alike (near x = 0 the sensor sees nothing: h'(0) = 0).
#include "core/small_matrix.hpp"
#include "models/drift_forms.hpp"
#include "models/initial_law.hpp"

namespace kushner {

struct CubicSensorModel : InitialLaw<1> {
  static constexpr int state_dim = 1, obs_dim = 1, noise_dim = 1, control_dim = 0;
  static constexpr bool discrete_time = false;
  static constexpr bool time_invariant = true;  // f, G, h, R: no function of t
  static constexpr const char* name = "cubic-sensor";
  static constexpr const char* description = "cubic sensor: dx = sigma dw, dy = x^3 dt + r dv";
  using Control = Vec<control_dim>;

  double sigma = 1.0, r = 1.0;

  CubicSensorModel() { set_initial_law(Vec<1>{{1.0}}, Mat<1, 1>{{{1.0}}}); }

  template <class Visitor>
  void parameters(Visitor&& v) {
    v("sigma", sigma, "process noise intensity");
    v("r", r, "observation noise intensity");
    initial_law_parameters(v);
  }

  KOKKOS_INLINE_FUNCTION Vec<1> drift(double, const Vec<1>&, const Control&) const { return {{0.0}}; }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> drift_jacobian(double, const Vec<1>&, const Control&) const { return {{{0.0}}}; }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> drift_hessian(double, const Vec<1>&, const Control&, int) const { return {{{0.0}}}; }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> diffusion(double, const Vec<1>&) const { return {{{sigma}}}; }
  KOKKOS_INLINE_FUNCTION Vec<1> observation(double, const Vec<1>& x) const { return {{x[0] * x[0] * x[0]}}; }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> observation_jacobian(double, const Vec<1>& x) const {
    return {{{3.0 * x[0] * x[0]}}};
  }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> observation_hessian(double, const Vec<1>& x, int) const { return {{{6.0 * x[0]}}}; }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> observation_noise(double) const { return {{{r}}}; }

  /// E_N[0] = 0: the drift's Gaussian expectations (the quasi-linear filter's a, B).
  KOKKOS_INLINE_FUNCTION GaussianDrift<1> gaussian_drift(double, const Vec<1>&, const Mat<1, 1>&) const {
    return {{{0.0}}, {{{0.0}}}};
  }
  /// E[x^3] = m^3 + 3 m p, E[3 x^2] = 3 (m^2 + p) for x ~ N(m, p): seed 000 (5.9)-(5.10) in closed form.
  KOKKOS_INLINE_FUNCTION GaussianObservation<1, 1> gaussian_observation(double, const Vec<1>& m,
                                                                        const Mat<1, 1>& P) const {
    const double v = m[0], p = P(0, 0);
    return {{{v * v * v + 3.0 * v * p}}, {{{3.0 * (v * v + p)}}}};
  }
  /// 0 = A x with A = 0: the ASRE factorization of the drift.
  KOKKOS_INLINE_FUNCTION SdcDrift<1> sdc_drift(double, const Vec<1>&) const { return {{{{0.0}}}, {{0.0}}}; }
  /// x^3 = C(x) x with C(x) = x^2 (seed 001 (5)).
  KOKKOS_INLINE_FUNCTION SdcObservation<1, 1> sdc_observation(double, const Vec<1>& x) const {
    return {{{{x[0] * x[0]}}}, {{0.0}}};
  }
};

}  // namespace kushner
