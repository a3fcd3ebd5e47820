#pragma once
// The noise and observation half of Clark's scalar discrete-time models (seed 003): z[k] = x[k] + v[k], the
// plant noise w and the measurement noise v bounded power-law laws (models/bounded_noise.hpp), Clark's
// default w with rho = 10 on (-1, 1) and v uniform on (-1, 1) (003 Ex. 1, ch. III).
//
// What the discrete-time filters and references ask of a discrete model (kernels/filters/discrete_kalman.hpp,
// kernels/reference/discrete_grid_filter.hpp, the particle filter) is, besides transition(k, x, u) and its
// Jacobian: the process noise from draws (process_noise), its covariance and CDF; the observation, its Jacobian,
// a square root of the measurement noise covariance (observation_noise), a sampler, log density and CDF.
#include "core/errors.hpp"
#include "core/small_matrix.hpp"
#include "models/bounded_noise.hpp"

namespace kushner {

struct ClarkNoises {
  static constexpr bool linear_observation = true;

  BoundedPowerNoise w{10.0, 1.0};
  BoundedPowerNoise v{0.0, 1.0};

  template <class Visitor>
  void noise_parameters(Visitor&& visit) {
    visit("rho_w", w.rho, "shape exponent of the plant noise density (0 = uniform)");
    visit("bound_w", w.bound, "bound of the plant noise");
    visit("rho_v", v.rho, "shape exponent of the measurement noise density (0 = uniform)");
    visit("bound_v", v.bound, "bound of the measurement noise");
  }

  void validate_noises() const {
    KUSHNER_INPUT_REQUIRE(w.rho >= 0.0 && v.rho >= 0.0,
                          "rho_w, rho_v: must be at least 0 (got " << w.rho << ", " << v.rho << ")");
    KUSHNER_INPUT_REQUIRE(w.bound > 0.0 && v.bound > 0.0,
                          "bound_w, bound_v: must be positive (got " << w.bound << ", " << v.bound << ")");
  }

  /// w[k] from its draws: the inverse CDF of the uniform (the normals are not used).
  KOKKOS_INLINE_FUNCTION Vec<1> process_noise(const Vec<1>&, double uniform) const { return {{w.sample(uniform)}}; }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> process_noise_covariance(double) const { return {{{w.moment(2)}}}; }
  KOKKOS_INLINE_FUNCTION double process_noise_cdf(double y) const { return w.cdf(y); }
  /// Half-width of the support of w (the grid filter's predicted support).
  KOKKOS_INLINE_FUNCTION double process_noise_bound() const { return w.bound; }

  KOKKOS_INLINE_FUNCTION Vec<1> observation(double, const Vec<1>& x) const { return x; }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> observation_jacobian(double, const Vec<1>&) const { return Mat<1, 1>::identity(); }
  /// A square root of Cov v (the Kalman filters' V = R R^T).
  KOKKOS_INLINE_FUNCTION Mat<1, 1> observation_noise(double) const { return {{{math::sqrt(v.moment(2))}}}; }
  KOKKOS_INLINE_FUNCTION Vec<1> observation_noise_sample(const Vec<1>&, double uniform) const {
    return {{v.sample(uniform)}};
  }
  KOKKOS_INLINE_FUNCTION double observation_noise_cdf(double y) const { return v.cdf(y); }
  KOKKOS_INLINE_FUNCTION double observation_log_density(const Vec<1>& r) const { return v.log_density(r[0]); }
  KOKKOS_INLINE_FUNCTION double observation_max_log_density() const { return v.max_log_density(); }
};

}  // namespace kushner
