#pragma once
// The pendulum observed through the sine of its angle (the pendulum example of Sarkka, Bayesian Filtering and
// Smoothing, 2013, and of dynamax, here in continuous time):
//   dx1 = x2 dt,   dx2 = -g sin(x1) dt + q dw,   dy = sin(x1) dt + r dv.
// sin x1 does not tell x1 from pi - x1, so near |x1| = pi/2 the posterior of the angle has two modes that a
// Gaussian filter cannot represent. Ours: g = 9.81, q = 0.5, r = 0.5, x(0) ~ N((1.5, 0), diag(0.1, 0.1)) for the
// truths and the filters alike (energy well below the top, 2 g, so that few truths go over it). Euler-Maruyama
// gains energy on an oscillator: the amplitude grows like exp(g dt t / 2), 10% over T = 10 at dt = 2e-3 (the
// compare default) but 60% at dt = 1e-2, where many truths then swing over the top: use dt <= 2e-3.
#include "core/math.hpp"
#include "core/small_matrix.hpp"
#include "models/drift_forms.hpp"
#include "models/initial_law.hpp"

namespace kushner {

struct PendulumModel : InitialLaw<2> {
  static constexpr int state_dim = 2, obs_dim = 1, noise_dim = 1, control_dim = 0;
  static constexpr bool discrete_time = false;
  static constexpr bool time_invariant = true;  // f, G, h, R: no function of t
  static constexpr const char* name = "pendulum";
  static constexpr const char* description =
      "pendulum: dx1 = x2 dt, dx2 = -g sin(x1) dt + q dw, dy = sin(x1) dt + r dv";
  using Control = Vec<control_dim>;

  double g = 9.81, q = 0.5, r = 0.5;

  PendulumModel() { set_initial_law(Vec<2>{{1.5, 0.0}}, Mat<2, 2>::diagonal(0.1)); }

  template <class Visitor>
  void parameters(Visitor&& v) {
    v("g", g, "gravity over length (1/s^2)");
    v("q", q, "process noise intensity (on x2)");
    v("r", r, "observation noise intensity");
    initial_law_parameters(v);
  }

  KOKKOS_INLINE_FUNCTION Vec<2> drift(double, const Vec<2>& x, const Control&) const {
    return {{x[1], -g * math::sin(x[0])}};
  }
  KOKKOS_INLINE_FUNCTION Mat<2, 2> drift_jacobian(double, const Vec<2>& x, const Control&) const {
    return {{{0.0, 1.0}, {-g * math::cos(x[0]), 0.0}}};
  }
  KOKKOS_INLINE_FUNCTION Mat<2, 2> drift_hessian(double, const Vec<2>& x, const Control&, int k) const {
    Mat<2, 2> h = Mat<2, 2>::zero();
    if (k == 1) h(0, 0) = g * math::sin(x[0]);
    return h;
  }
  KOKKOS_INLINE_FUNCTION Mat<2, 1> diffusion(double, const Vec<2>&) const { return {{{0.0}, {q}}}; }
  KOKKOS_INLINE_FUNCTION Vec<1> observation(double, const Vec<2>& x) const { return {{math::sin(x[0])}}; }
  KOKKOS_INLINE_FUNCTION Mat<1, 2> observation_jacobian(double, const Vec<2>& x) const {
    return {{{math::cos(x[0]), 0.0}}};
  }
  KOKKOS_INLINE_FUNCTION Mat<2, 2> observation_hessian(double, const Vec<2>& x, int) const {
    return {{{-math::sin(x[0]), 0.0}, {0.0, 0.0}}};
  }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> observation_noise(double) const { return {{{r}}}; }

  /// E[sin x1] = sin(m1) e^{-p11/2}, E[cos x1] = cos(m1) e^{-p11/2} for x ~ N(m, P) (as seed 000 (6.4)-(6.5)).
  KOKKOS_INLINE_FUNCTION GaussianDrift<2> gaussian_drift(double, const Vec<2>& m, const Mat<2, 2>& P) const {
    const double damping = math::exp(-0.5 * P(0, 0));
    return {{{m[1], -g * math::sin(m[0]) * damping}}, {{{0.0, 1.0}, {-g * math::cos(m[0]) * damping, 0.0}}}};
  }
  KOKKOS_INLINE_FUNCTION GaussianObservation<2, 1> gaussian_observation(double, const Vec<2>& m,
                                                                        const Mat<2, 2>& P) const {
    const double damping = math::exp(-0.5 * P(0, 0));
    return {{{math::sin(m[0]) * damping}}, {{{math::cos(m[0]) * damping, 0.0}}}};
  }
  /// sin x1 = sinc(x1) x1: A(x) = [[0, 1], [-g sinc x1, 0]], C(x) = [sinc x1, 0] (ASRE, seed 001 (4)-(5)).
  KOKKOS_INLINE_FUNCTION static double sinc(double v) {
    return math::fabs(v) < 1e-4 ? 1.0 - v * v / 6.0 : math::sin(v) / v;
  }
  KOKKOS_INLINE_FUNCTION SdcDrift<2> sdc_drift(double, const Vec<2>& x) const {
    return {{{{0.0, 1.0}, {-g * sinc(x[0]), 0.0}}}, Vec<2>::zero()};
  }
  KOKKOS_INLINE_FUNCTION SdcObservation<2, 1> sdc_observation(double, const Vec<2>& x) const {
    return {{{{sinc(x[0]), 0.0}}}, {{0.0}}};
  }
};

}  // namespace kushner
