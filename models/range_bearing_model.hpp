#pragma once
// A target moving in the plane (an Ornstein-Uhlenbeck position) seen by a sensor at s that measures range and
// bearing, the 2-D tracking case of the nonlinear-observation literature:
//   dx = -theta x dt + q dw (w two-dimensional),   dy = (|x - s|, atan2(x2 - s2, x1 - s1)) dt + R dv,
// R = diag(r_range, r_bearing). Ours: theta = 0.5, q = 1 (stationary spread 1 per axis), s = (-4, 0), so the
// target stays well away from the sensor and the bearing away from its branch cut at +-pi; r_range = 0.5,
// r_bearing = 0.1; x(0) ~ N(0, I).
#include "core/math.hpp"
#include "core/small_matrix.hpp"
#include "models/drift_forms.hpp"
#include "models/initial_law.hpp"

namespace kushner {

struct RangeBearingModel : InitialLaw<2> {
  static constexpr int state_dim = 2, obs_dim = 2, noise_dim = 2, control_dim = 0;
  static constexpr bool discrete_time = false;
  static constexpr bool time_invariant = true;  // f, G, h, R: no function of t
  static constexpr const char* name = "range-bearing";
  static constexpr const char* description =
      "planar target, range and bearing sensor: dx = -theta x dt + q dw, dy = (|x - s|, atan2(x - s)) dt + R dv";
  using Control = Vec<control_dim>;

  double theta = 0.5, q = 1.0, r_range = 0.5, r_bearing = 0.1;
  Vec<2> sensor{{-4.0, 0.0}};

  RangeBearingModel() { set_initial_law(Vec<2>::zero(), Mat<2, 2>::identity()); }

  template <class Visitor>
  void parameters(Visitor&& v) {
    v("theta", theta, "mean-reversion rate of the position");
    v("q", q, "process noise intensity (each axis)");
    v("r_range", r_range, "range noise intensity");
    v("r_bearing", r_bearing, "bearing noise intensity (rad)");
    v("sensor", sensor, "sensor position s");
    initial_law_parameters(v);
  }

  KOKKOS_INLINE_FUNCTION Vec<2> drift(double, const Vec<2>& x, const Control&) const { return x * (-theta); }
  KOKKOS_INLINE_FUNCTION Mat<2, 2> drift_jacobian(double, const Vec<2>&, const Control&) const {
    return Mat<2, 2>::diagonal(-theta);
  }
  KOKKOS_INLINE_FUNCTION Mat<2, 2> drift_hessian(double, const Vec<2>&, const Control&, int) const {
    return Mat<2, 2>::zero();
  }
  KOKKOS_INLINE_FUNCTION Mat<2, 2> diffusion(double, const Vec<2>&) const { return Mat<2, 2>::diagonal(q); }
  KOKKOS_INLINE_FUNCTION Vec<2> observation(double, const Vec<2>& x) const {
    const double d1 = x[0] - sensor[0], d2 = x[1] - sensor[1];
    return {{math::sqrt(d1 * d1 + d2 * d2), math::atan2(d2, d1)}};
  }
  /// d range = d^T / rho, d bearing = (-d2, d1) / rho^2, d = x - s, rho = |d|.
  KOKKOS_INLINE_FUNCTION Mat<2, 2> observation_jacobian(double, const Vec<2>& x) const {
    const double d1 = x[0] - sensor[0], d2 = x[1] - sensor[1], rho2 = d1 * d1 + d2 * d2, rho = math::sqrt(rho2);
    return {{{d1 / rho, d2 / rho}, {-d2 / rho2, d1 / rho2}}};
  }
  /// Range: (I - d d^T / rho^2) / rho. Bearing: [[2 d1 d2, d2^2 - d1^2], [d2^2 - d1^2, -2 d1 d2]] / rho^4.
  KOKKOS_INLINE_FUNCTION Mat<2, 2> observation_hessian(double, const Vec<2>& x, int k) const {
    const double d1 = x[0] - sensor[0], d2 = x[1] - sensor[1], rho2 = d1 * d1 + d2 * d2;
    if (k == 0) {
      const double rho3 = rho2 * math::sqrt(rho2);
      return {{{d2 * d2 / rho3, -d1 * d2 / rho3}, {-d1 * d2 / rho3, d1 * d1 / rho3}}};
    }
    const double rho4 = rho2 * rho2;
    return {{{2.0 * d1 * d2 / rho4, (d2 * d2 - d1 * d1) / rho4}, {(d2 * d2 - d1 * d1) / rho4, -2.0 * d1 * d2 / rho4}}};
  }
  KOKKOS_INLINE_FUNCTION Mat<2, 2> observation_noise(double) const { return {{{r_range, 0.0}, {0.0, r_bearing}}}; }

  /// E_N[-theta x] = -theta m, E_N[-theta I] = -theta I.
  KOKKOS_INLINE_FUNCTION GaussianDrift<2> gaussian_drift(double, const Vec<2>& m, const Mat<2, 2>&) const {
    return {m * (-theta), Mat<2, 2>::diagonal(-theta)};
  }
  /// -theta x = A x with A = -theta I (ASRE; the observation has no factorization C(x) x: h(0) depends on s).
  KOKKOS_INLINE_FUNCTION SdcDrift<2> sdc_drift(double, const Vec<2>&) const {
    return {Mat<2, 2>::diagonal(-theta), Vec<2>::zero()};
  }
};

}  // namespace kushner
