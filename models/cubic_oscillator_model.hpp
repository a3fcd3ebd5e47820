#pragma once
// Sunahara (1968) Example 2, seed 000 eqs. (6.12)-(6.13): a damped oscillator with a cubic spring,
//   dx1 = x2 dt,  dx2 = (-x2 - x1 + x1^3 / 8) dt + q dw,  dy1 = x1 dt + r dv1,  dy2 = x2 dt + r dv2.
// The paper prints x(0) = (15, 10) for the truth and 0 for the filters (Fig. 6), but with this softening
// spring (restoring force negative for |x1| > sqrt(8)) the noise-free path from (15, 10) escapes to infinity
// at t ~ 0.34. We read a lost decimal point: the truth starts at (1.5, 1.0) (`--set x0_mean=15,10` gives the
// printed start). The paper gives neither q, r nor the filters' initial covariance; ours: q = r = 0.5,
// prior N(0, I). Even so, a few percent of noisy paths escape over long horizons: such members are counted
// as diverged, not averaged in. Controlled (`kushner control`): a force u on x2, B = (0, 1).
#include "core/small_matrix.hpp"
#include "models/drift_forms.hpp"
#include "models/initial_law.hpp"

namespace kushner {

struct CubicOscillatorModel : InitialLaw<2> {
  static constexpr int state_dim = 2, obs_dim = 2, noise_dim = 1, control_dim = 1;
  static constexpr bool discrete_time = false;
  static constexpr bool time_invariant = true;  // f, G, h, R: no function of t
  static constexpr bool linear_observation = true;
  static constexpr const char* name = "cubic-oscillator";
  static constexpr const char* description =
      "Sunahara 1968 Example 2: dx1 = x2 dt, dx2 = (-x2 - x1 + x1^3/8) dt + q dw, dy = x dt + r dv";
  using Control = Vec<control_dim>;

  double q = 0.5, r = 0.5;
  Mat<2, 1> B{{{0.0}, {1.0}}};

  CubicOscillatorModel() {
    x0_mean = Vec<2>{{1.5, 1.0}};
    x0_cov = Mat<2, 2>::zero();
    prior_mean = Vec<2>::zero();
    prior_cov = Mat<2, 2>::identity();
  }

  template <class Visitor>
  void parameters(Visitor&& v) {
    v("q", q, "process noise intensity (on x2)");
    v("r", r, "observation noise intensity (both components)");
    v("B", B, "control input matrix (kushner control)");
    initial_law_parameters(v);
  }

  KOKKOS_INLINE_FUNCTION Vec<2> drift(double, const Vec<2>& x, const Control& u) const {
    return Vec<2>{{x[1], -x[1] - x[0] + x[0] * x[0] * x[0] / 8.0}} + B * u;
  }
  KOKKOS_INLINE_FUNCTION Mat<2, 1> control_input(double) const { return B; }
  KOKKOS_INLINE_FUNCTION Mat<2, 2> drift_jacobian(double, const Vec<2>& x, const Control&) const {
    return {{{0.0, 1.0}, {-1.0 + 3.0 * x[0] * x[0] / 8.0, -1.0}}};
  }
  /// Hessian of drift component k.
  KOKKOS_INLINE_FUNCTION Mat<2, 2> drift_hessian(double, const Vec<2>& x, const Control&, int k) const {
    Mat<2, 2> h = Mat<2, 2>::zero();
    if (k == 1) h(0, 0) = 6.0 * x[0] / 8.0;
    return h;
  }
  KOKKOS_INLINE_FUNCTION Mat<2, 1> diffusion(double, const Vec<2>&) const { return {{{0.0}, {q}}}; }
  KOKKOS_INLINE_FUNCTION Vec<2> observation(double, const Vec<2>& x) const { return x; }
  KOKKOS_INLINE_FUNCTION Mat<2, 2> observation_jacobian(double, const Vec<2>&) const { return Mat<2, 2>::identity(); }
  KOKKOS_INLINE_FUNCTION Mat<2, 2> observation_hessian(double, const Vec<2>&, int) const { return Mat<2, 2>::zero(); }
  KOKKOS_INLINE_FUNCTION Mat<2, 2> observation_noise(double) const { return Mat<2, 2>::diagonal(r); }

  /// Seed 000 (6.14) and the unnumbered B(t) after it: E_N[f] and E_N[grad f] for x ~ N(m, P).
  KOKKOS_INLINE_FUNCTION GaussianDrift<2> gaussian_drift(double, const Vec<2>& m, const Mat<2, 2>& P) const {
    const double m1 = m[0], m2 = m[1], p11 = P(0, 0);
    const double beta = -1.0 + 3.0 / 8.0 * m1 * m1 + 3.0 / 8.0 * p11;
    return {{{m2, -m2 - m1 + m1 * m1 * m1 / 8.0 + 3.0 / 8.0 * p11 * m1}}, {{{0.0, 1.0}, {beta, -1.0}}}};
  }
  /// f = a1 x + a3 x^3 componentwise: a1 = [[0, 1], [-1, -1]], a3 = [[0, 0], [1/8, 0]] (f2 = -x2 - x1 + x1^3/8).
  KOKKOS_INLINE_FUNCTION PowerPolynomial<2, 3> drift_power_polynomial(double) const {
    auto poly = PowerPolynomial<2, 3>::zero();
    poly.coefficient[1] = Mat<2, 2>{{{0.0, 1.0}, {-1.0, -1.0}}};
    poly.coefficient[3](1, 0) = 1.0 / 8.0;
    return poly;
  }
  /// f = A(x) x with A(x) = [[0, 1], [-1 + x1^2 / 8, -1]]: the ASRE factorization.
  KOKKOS_INLINE_FUNCTION SdcDrift<2> sdc_drift(double, const Vec<2>& x) const {
    return {{{{0.0, 1.0}, {-1.0 + x[0] * x[0] / 8.0, -1.0}}}, Vec<2>::zero()};
  }
};

}  // namespace kushner
