#pragma once
// The Benes model (Benes 1981, "Exact finite-dimensional filters for certain diffusions with nonlinear
// drift", Stochastics 5, 65-92; Bain & Crisan 2009, "Fundamentals of Stochastic Filtering", section 6.1):
//   dx = tanh(x) dt + dw,   dy = x dt + r dv.
// Its drift is the gradient of log cosh, which makes the filter finite-dimensional: the posterior is cosh(x)
// times a Gaussian (kernels/reference/benes_filter.hpp). The transition density is known too,
//   p(x' | x) = cosh(x') N(x'; x, dt) / (e^{dt/2} cosh x) = w+ N(x + dt, dt) + w- N(x - dt, dt),
// w+- = (1 +- tanh x) / 2, so the particle filter samples it exactly (sample_exact_transition).
// Ours: r = 0.5, x(0) ~ N(0.5, 1) for truths and prior alike.
#include "core/math.hpp"
#include "core/small_matrix.hpp"
#include "models/drift_forms.hpp"
#include "models/initial_law.hpp"

namespace kushner {

struct BenesModel : InitialLaw<1> {
  static constexpr int state_dim = 1, obs_dim = 1, noise_dim = 1, control_dim = 0;
  static constexpr bool discrete_time = false;
  static constexpr bool time_invariant = true;  // f, G, h, R: no function of t
  static constexpr bool linear_observation = true;
  static constexpr const char* name = "benes";
  static constexpr const char* description = "Benes: dx = tanh(x) dt + dw, dy = x dt + r dv (exact filter known)";
  using Control = Vec<control_dim>;

  double r = 0.5;

  BenesModel() { set_initial_law(Vec<1>{{0.5}}, Mat<1, 1>{{{1.0}}}); }

  template <class Visitor>
  void parameters(Visitor&& v) {
    v("r", r, "observation noise intensity");
    initial_law_parameters(v);
  }

  KOKKOS_INLINE_FUNCTION Vec<1> drift(double, const Vec<1>& x, const Control&) const { return {{math::tanh(x[0])}}; }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> drift_jacobian(double, const Vec<1>& x, const Control&) const {
    const double t = math::tanh(x[0]);
    return {{{1.0 - t * t}}};
  }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> drift_hessian(double, const Vec<1>& x, const Control&, int) const {
    const double t = math::tanh(x[0]);
    return {{{-2.0 * t * (1.0 - t * t)}}};
  }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> diffusion(double, const Vec<1>&) const { return {{{1.0}}}; }
  KOKKOS_INLINE_FUNCTION Vec<1> observation(double, const Vec<1>& x) const { return x; }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> observation_jacobian(double, const Vec<1>&) const { return {{{1.0}}}; }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> observation_hessian(double, const Vec<1>&, int) const { return {{{0.0}}}; }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> observation_noise(double) const { return {{{r}}}; }

  /// tanh x = A(x) x with A(x) = tanh(x) / x (1 at 0): the ASRE factorization.
  KOKKOS_INLINE_FUNCTION SdcDrift<1> sdc_drift(double, const Vec<1>& x) const {
    const double v = x[0];
    return {{{{math::fabs(v) < 1e-4 ? 1.0 - v * v / 3.0 : math::tanh(v) / v}}}, {{0.0}}};
  }

  /// Exact draw from p(x' | x) above: the sign s = +1 with probability (1 + tanh x) / 2 (from u), then
  /// x' = x + s dt + sqrt(dt) z.
  KOKKOS_INLINE_FUNCTION Vec<1> sample_exact_transition(double, const Vec<1>& x, double dt, const Vec<1>& z,
                                                        double u) const {
    const double s = 2.0 * u < 1.0 + math::tanh(x[0]) ? 1.0 : -1.0;
    return {{x[0] + s * dt + math::sqrt(dt) * z[0]}};
  }
};

}  // namespace kushner
