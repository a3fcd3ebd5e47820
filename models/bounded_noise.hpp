#pragma once
// Clark's bounded non-Gaussian noise (seed 003, eq. (4.4)): density (rho + 1) / (2 c) |y / c|^rho on |y| < c.
// rho = 0 is uniform on (-c, c); rho = 10 is Clark's "inverted bell" plant noise.
#include "core/math.hpp"

namespace kushner {

struct BoundedPowerNoise {
  double rho = 0.0;    // shape exponent
  double bound = 1.0;  // c

  /// Exact sample by the inverse CDF, F(y) = 1/2 + sign(y) |y/c|^{rho+1} / 2, from u uniform in (0, 1).
  KOKKOS_INLINE_FUNCTION double sample(double u) const {
    const double s = 2.0 * u - 1.0;
    const double magnitude = bound * math::pow(math::fabs(s), 1.0 / (rho + 1.0));
    return s < 0.0 ? -magnitude : magnitude;
  }
  /// E[y^k]: zero for odd k, c^k (rho + 1) / (rho + 1 + k) for even k.
  KOKKOS_INLINE_FUNCTION double moment(int k) const {
    if (k % 2 == 1) return 0.0;
    return math::pow(bound, k) * (rho + 1.0) / (rho + 1.0 + k);
  }
  /// t^(rho + 1), by multiplication for a whole rho up to 16 (the grid filter calls this O(cells^2) times per
  /// step; Clark's rho = 10 and 0 are whole): pow's cost dominated it.
  KOKKOS_INLINE_FUNCTION double mass_power(double t) const {
    const int whole = static_cast<int>(rho);
    if (static_cast<double>(whole) != rho || whole > 16) return math::pow(t, rho + 1.0);
    double p = t;
    for (int i = 0; i < whole; ++i) p *= t;
    return p;
  }
  /// P(Y <= y), exact (the grid filter's cell masses).
  KOKKOS_INLINE_FUNCTION double cdf(double y) const {
    if (y <= -bound) return 0.0;
    if (y >= bound) return 1.0;
    const double half_mass = 0.5 * mass_power(math::fabs(y) / bound);
    return y < 0.0 ? 0.5 - half_mass : 0.5 + half_mass;
  }
  /// The density at y: zero outside (-c, c).
  KOKKOS_INLINE_FUNCTION double density(double y) const {
    const double a = math::fabs(y);
    if (a >= bound) return 0.0;
    return rho == 0.0 ? 0.5 / bound : 0.5 * (rho + 1.0) / bound * math::pow(a / bound, rho);
  }
  /// log density(y); -inf outside (-c, c) and, for rho > 0, at 0.
  KOKKOS_INLINE_FUNCTION double log_density(double y) const {
    const double d = density(y);
    return d > 0.0 ? math::log(d) : -math::infinity();
  }
  /// The largest log density: at the bounds for rho > 0, everywhere inside for rho = 0.
  KOKKOS_INLINE_FUNCTION double max_log_density() const { return math::log(0.5 * (rho + 1.0) / bound); }
};

}  // namespace kushner
