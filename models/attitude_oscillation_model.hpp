#pragma once
// Tarushkin (1972) §4, seed 004 (4.1)-(4.8): small forced attitude oscillations of a body in a circular orbit,
// seen by one reference-vector sensor. The sensor measures the reference vector in body axes,
//   H_body = A(psi, theta, phi) H_orbit(t) + v,   E v v^T = R,                                        (4.1)
// and the three angles are short Fourier series of a known frequency omega, 15 coefficients d_1 .. d_15:
//   psi = d1 + d2 sin wt + d3 cos wt + d4 sin 2wt + d5 cos 2wt,  theta = d6 + ...,  phi = d11 + ... .
// About a zero approximation d0, d = d0 + x and the discrepancy (4.5) eta = H_body - A(d0) H_orbit is
// z = H(t) x + v (4.6) with H(t) = d(A H_orbit)/dd at d0, a 3 x 15 matrix.
//
// What the paper leaves open, ours (stated here and in the README):
// - Axes as printed: x0 transversal (along the velocity), z0 along the radius vector, y0 = z0 x x0 the orbit
//   normal. The angles' names are lost in the translation ("pitch, yaw and bank" for psi, theta, phi): we take
//   psi = pitch about y0, theta = yaw about z, phi = bank about x, applied in that order,
//   A = R_x(phi) R_z(theta) R_y(psi) (frame rotations); small angles give A ~ I - [alpha x], alpha = (phi, psi, theta).
// - The reference vector: the geomagnetic field of a dipole on the Earth's axis, in units of its equatorial
//   strength at the orbit's radius, H_orbit = (sin i cos u, cos i, -2 sin i sin u), u = orbit_rate t + u0
//   (the sensor a magnetometer: the usual single reference vector of the Leningrad school, ref. [9]).
// - omega = 2 orbit_rate (the paper: "a known frequency"). Not omega = orbit_rate: the field's components are
//   then in the span of the series, so are the rotations about the field itself, lambda(t) H_orbit(t) with
//   lambda in {1, sin u, cos u}, which no reading of the vector can see: the 15 coefficients are not
//   observable (rank 12; tests/test_least_squares.cpp shows it).
// - A 90-minute orbit, inclination 51.6 deg, sensor noise 0.01 per component and sample (1% of the field).
#include "core/math.hpp"
#include "core/small_matrix.hpp"

namespace kushner {

struct AttitudeOscillationModel {
  static constexpr int state_dim = 15, obs_dim = 3, num_harmonics = 5;
  static constexpr const char* name = "tarushkin-attitude";
  static constexpr const char* description =
      "Tarushkin 1972 §4: attitude angles as 15 Fourier coefficients, one reference vector (geomagnetic field)";

  double orbit_rate = 2.0 * math::pi / 5400.0;   // rad/s: a 90-minute circular orbit
  double omega = 2.0 * 2.0 * math::pi / 5400.0;  // rad/s: the oscillations' known frequency
  double inclination = 51.6 * math::pi / 180.0;  // rad
  double u0 = 0.0;                               // rad: argument of latitude at t = 0
  double sigma = 0.01;                           // sensor noise per component, in units of the field
  Vec<state_dim> d0 = Vec<state_dim>::zero();    // the zero approximation, rad

  template <class Visitor>
  void parameters(Visitor&& v) {
    v("orbit_rate", orbit_rate, "orbital angular rate (rad/s)");
    v("omega", omega, "known frequency of the forced oscillations (rad/s)");
    v("inclination", inclination, "orbit inclination (rad)");
    v("u0", u0, "argument of latitude at t = 0 (rad)");
    v("sigma", sigma, "sensor noise standard deviation per component and sample (field units)");
    v("d0", d0, "zero approximation of the 15 Fourier coefficients (rad)");
  }

  /// The series' basis at t: 1, sin wt, cos wt, sin 2wt, cos 2wt.
  KOKKOS_INLINE_FUNCTION Vec<num_harmonics> harmonics(double t) const {
    const double a = omega * t;
    return {{1.0, math::sin(a), math::cos(a), math::sin(2.0 * a), math::cos(2.0 * a)}};
  }

  /// (psi, theta, phi) at t for the coefficients d.
  KOKKOS_INLINE_FUNCTION Vec<3> angles(double t, const Vec<state_dim>& d) const {
    const Vec<num_harmonics> h = harmonics(t);
    Vec<3> a = Vec<3>::zero();
    for (int angle = 0; angle < 3; ++angle)
      for (int k = 0; k < num_harmonics; ++k) a[angle] += h[k] * d[num_harmonics * angle + k];
    return a;
  }

  /// The reference vector in orbital axes (x0 transversal, y0 normal, z0 radial): a dipole field.
  KOKKOS_INLINE_FUNCTION Vec<3> reference(double t) const {
    const double u = orbit_rate * t + u0, si = math::sin(inclination);
    return {{si * math::cos(u), math::cos(inclination), -2.0 * si * math::sin(u)}};
  }

  /// Orbital to body axes, A = R_x(phi) R_z(theta) R_y(psi); with `derivative` = 0, 1, 2 the derivative of A
  /// with respect to psi, theta or phi instead.
  KOKKOS_INLINE_FUNCTION static Mat<3, 3> attitude(const Vec<3>& a, int derivative = -1) {
    const double cp = math::cos(a[0]), sp = math::sin(a[0]), ct = math::cos(a[1]), st = math::sin(a[1]),
                 cf = math::cos(a[2]), sf = math::sin(a[2]);
    Mat<3, 3> ry{{{cp, 0.0, -sp}, {0.0, 1.0, 0.0}, {sp, 0.0, cp}}};
    Mat<3, 3> rz{{{ct, st, 0.0}, {-st, ct, 0.0}, {0.0, 0.0, 1.0}}};
    Mat<3, 3> rx{{{1.0, 0.0, 0.0}, {0.0, cf, sf}, {0.0, -sf, cf}}};
    if (derivative == 0) ry = Mat<3, 3>{{{-sp, 0.0, -cp}, {0.0, 0.0, 0.0}, {cp, 0.0, -sp}}};
    if (derivative == 1) rz = Mat<3, 3>{{{-st, ct, 0.0}, {-ct, -st, 0.0}, {0.0, 0.0, 0.0}}};
    if (derivative == 2) rx = Mat<3, 3>{{{0.0, 0.0, 0.0}, {0.0, -sf, cf}, {0.0, -cf, -sf}}};
    return rx * (rz * ry);
  }

  /// The sensor's noise-free reading (4.1): the reference vector in body axes for the coefficients d.
  KOKKOS_INLINE_FUNCTION Vec<3> observation(double t, const Vec<state_dim>& d) const {
    return attitude(angles(t, d)) * reference(t);
  }

  /// d observation / dd at d (3 x 15): column 5 a + k is (dA/d angle_a) H_orbit times the k-th harmonic.
  KOKKOS_INLINE_FUNCTION Mat<obs_dim, state_dim> observation_jacobian(double t, const Vec<state_dim>& d) const {
    const Vec<3> a = angles(t, d), r = reference(t);
    const Vec<num_harmonics> h = harmonics(t);
    Mat<obs_dim, state_dim> J;
    for (int angle = 0; angle < 3; ++angle) {
      const Vec<3> column = attitude(a, angle) * r;
      for (int k = 0; k < num_harmonics; ++k)
        for (int i = 0; i < obs_dim; ++i) J(i, num_harmonics * angle + k) = column[i] * h[k];
    }
    return J;
  }

  /// H(t) of (4.6): the Jacobian at the zero approximation. The paper writes d eta / d d0, the negative of this:
  /// with d = d0 + x, z = eta(t, d0) = H x + v needs the sign used here.
  KOKKOS_INLINE_FUNCTION Mat<obs_dim, state_dim> observation_matrix(double t) const {
    return observation_jacobian(t, d0);
  }

  /// The discrepancy (4.5) of a reading at t about the zero approximation: z of (4.6).
  KOKKOS_INLINE_FUNCTION Vec<3> discrepancy(double t, const Vec<3>& reading) const {
    return reading - observation(t, d0);
  }

  /// R of one sample: sigma^2 I.
  KOKKOS_INLINE_FUNCTION Mat<obs_dim, obs_dim> observation_noise_cov() const {
    return Mat<obs_dim, obs_dim>::identity() * (sigma * sigma);
  }
};

}  // namespace kushner
