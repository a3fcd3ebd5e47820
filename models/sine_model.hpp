#pragma once
// Sunahara (1968) Example 1, seed 000 eqs. (6.1)-(6.3):  dx = -sin(x) dt + q dw,  dy = x dt + r dv.
// The paper gives no noise levels or initial law (figures only); ours, stated in the README: q = 1, r = 0.5,
// x(0) ~ N(1, 1) for the truths and the filters' prior alike. Controlled (`kushner control`): a force u on x,
// dx = (-sin(x) + B u) dt + q dw, B = 1.
#include "core/math.hpp"
#include "core/small_matrix.hpp"
#include "models/drift_forms.hpp"
#include "models/initial_law.hpp"

namespace kushner {

struct SineModel : InitialLaw<1> {
  static constexpr int state_dim = 1, obs_dim = 1, noise_dim = 1, control_dim = 1;
  static constexpr bool discrete_time = false;
  static constexpr bool time_invariant = true;  // f, G, h, R: no function of t
  static constexpr bool linear_observation = true;
  static constexpr const char* name = "sine";
  static constexpr const char* description = "Sunahara 1968 Example 1: dx = -sin(x) dt + q dw, dy = x dt + r dv";
  using Control = Vec<control_dim>;

  double q = 1.0, r = 0.5;
  Mat<1, 1> B = Mat<1, 1>::identity();

  SineModel() { set_initial_law(Vec<1>{{1.0}}, Mat<1, 1>{{{1.0}}}); }

  template <class Visitor>
  void parameters(Visitor&& v) {
    v("q", q, "process noise intensity");
    v("r", r, "observation noise intensity");
    v("B", B, "control input matrix (kushner control)");
    initial_law_parameters(v);
  }

  // Templates on the scalar: the particle filter's fp32 steps its particles in float (particle_model_traits.hpp).
  template <class T>
  KOKKOS_INLINE_FUNCTION Vec<1, T> drift(double, const Vec<1, T>& x, const Control& u) const {
    return {{-math::sin(x[0]) + static_cast<T>(B(0, 0) * u[0])}};
  }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> control_input(double) const { return B; }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> drift_jacobian(double, const Vec<1>& x, const Control&) const {
    return {{{-math::cos(x[0])}}};
  }
  /// drift, drift_jacobian and drift_hessian, the same bits, from one sine and cosine: on a GPU one range reduction
  /// for all three (math::sin_cos). nvcc did not merge the SOF's two calls of sin_cos at one mean, one for its
  /// linearization and one for its Hessian, when each took a call of its own (perf/filter_bank.md).
  KOKKOS_INLINE_FUNCTION DriftDerivatives<1> drift_derivatives(double, const Vec<1>& x, const Control& u) const {
    double s, c;
    math::sin_cos(x[0], s, c);
    return {{{-s + B(0, 0) * u[0]}}, {{{-c}}}, {{{{s}}}}};
  }
  KOKKOS_INLINE_FUNCTION DriftAndJacobian<1> drift_and_jacobian(double t, const Vec<1>& x, const Control& u) const {
    const DriftDerivatives<1> d = drift_derivatives(t, x, u);
    return {d.drift, d.jacobian};
  }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> drift_hessian(double t, const Vec<1>& x, const Control& u, int) const {
    return drift_derivatives(t, x, u).hessian[0];
  }
  template <class T>
  KOKKOS_INLINE_FUNCTION Mat<1, 1, T> diffusion(double, const Vec<1, T>&) const {
    return {{{static_cast<T>(q)}}};
  }
  template <class T>
  KOKKOS_INLINE_FUNCTION Vec<1, T> observation(double, const Vec<1, T>& x) const {
    return x;
  }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> observation_jacobian(double, const Vec<1>&) const { return {{{1.0}}}; }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> observation_hessian(double, const Vec<1>&, int) const { return {{{0.0}}}; }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> observation_noise(double) const { return {{{r}}}; }

  /// Seed 000 (6.4)-(6.5): E[-sin x] = -sin(m) e^{-p/2}, E[-cos x] = -cos(m) e^{-p/2} for x ~ N(m, p).
  KOKKOS_INLINE_FUNCTION GaussianDrift<1> gaussian_drift(double, const Vec<1>& m, const Mat<1, 1>& P) const {
    const double damping = math::exp(-0.5 * P(0, 0));
    double s, c;
    math::sin_cos(m[0], s, c);
    return {{{-s * damping}}, {{{-c * damping}}}};
  }
  /// -sin x = A(x) x with A(x) = -sin(x) / x (-1 at 0, its limit): the ASRE factorization.
  KOKKOS_INLINE_FUNCTION SdcDrift<1> sdc_drift(double, const Vec<1>& x) const {
    const double v = x[0];
    const double sinc = math::fabs(v) < 1e-4 ? 1.0 - v * v / 6.0 : math::sin(v) / v;
    return {{{{-sinc}}}, {{0.0}}};
  }
};

}  // namespace kushner
