#pragma once
// Clark (1971) ch. III, seed 003: the nonlinear scalar plant
//   x[k+1] = 0.995 x + 0.0025 x^3 - 0.00035 x^5 + 0.01 u + w,   z = x + v,
// v uniform on (-1, 1), w Clark's rho = 10 law. Table 3.1's columns are the plant noise's standard deviation
// sigma_w with bound 1.08 sigma_w (its header "1.08 sigma": for rho = 10, sigma = bound sqrt(11/13)); the default
// bound 0.108 is sigma_w = 0.1. The thesis states no x[0]; ours: x[0] = 0, known to the filters.
#include "core/errors.hpp"
#include "core/small_matrix.hpp"
#include "models/clark_noises.hpp"
#include "models/initial_law.hpp"

namespace kushner {

struct ClarkQuinticModel : InitialLaw<1>, ClarkNoises {
  static constexpr int state_dim = 1, obs_dim = 1, noise_dim = 1, control_dim = 1;
  static constexpr bool discrete_time = true;
  static constexpr const char* name = "clark-quintic";
  static constexpr const char* description =
      "Clark 1971 ch. III (discrete time): x[k+1] = a1 x + a3 x^3 + a5 x^5 + b u + w, z = x + v, bounded w, v";
  using Control = Vec<control_dim>;

  double a1 = 0.995, a3 = 0.0025, a5 = -0.00035, b = 0.01;

  ClarkQuinticModel() {
    w.bound = 0.108;
    set_initial_law(Vec<1>{{0.0}}, Mat<1, 1>{{{0.0}}});
  }

  template <class Visitor>
  void parameters(Visitor&& visit) {
    visit("a1", a1, "coefficient of x");
    visit("a3", a3, "coefficient of x^3");
    visit("a5", a5, "coefficient of x^5");
    visit("b", b, "control gain");
    noise_parameters(visit);
    initial_law_parameters(visit);
  }

  void validate() const { validate_noises(); }

  KOKKOS_INLINE_FUNCTION Vec<1> transition(double, const Vec<1>& x, const Control& u) const {
    const double s = x[0] * x[0];
    return {{x[0] * (a1 + s * (a3 + s * a5)) + b * u[0]}};
  }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> transition_jacobian(double, const Vec<1>& x) const {
    const double s = x[0] * x[0];
    return {{{a1 + s * (3.0 * a3 + 5.0 * a5 * s)}}};
  }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> control_input(double) const { return {{{b}}}; }
};

}  // namespace kushner
