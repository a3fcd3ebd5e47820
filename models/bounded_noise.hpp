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
};

}  // namespace kushner
