#pragma once
// Clark (1971) Example 1, seed 003 eqs. (2.22)-(2.23): a discrete-time linear system with bounded
// non-Gaussian noise,  x[k+1] = a x[k] + u[k] + w[k],  z[k+1] = x[k+1] + v[k+1],
// w with density (11/2) w^10 on |w| < 1 (rho_w = 10), v uniform on (-1, 1) (rho_v = 0). a = 0.1.
// The thesis does not state x[0]; ours: x[0] = 0, known to the filters (prior = the truths' law), so every
// filter starts from the same exact posterior and their differences are the filters' own.
#include "core/errors.hpp"
#include "core/small_matrix.hpp"
#include "models/clark_noises.hpp"
#include "models/initial_law.hpp"

namespace kushner {

struct ClarkLinearModel : InitialLaw<1>, ClarkNoises {
  static constexpr int state_dim = 1, obs_dim = 1, noise_dim = 1, control_dim = 1;
  static constexpr bool discrete_time = true;
  static constexpr bool linear_transition = true;
  static constexpr const char* name = "clark-linear";
  static constexpr const char* description =
      "Clark 1971 Example 1 (discrete time): x[k+1] = a x[k] + u + w, z = x + v, bounded non-Gaussian w, v";
  using Control = Vec<control_dim>;

  double a = 0.1;

  ClarkLinearModel() { set_initial_law(Vec<1>{{0.0}}, Mat<1, 1>{{{0.0}}}); }

  template <class Visitor>
  void parameters(Visitor&& visit) {
    visit("a", a, "state transition coefficient");
    noise_parameters(visit);
    initial_law_parameters(visit);
  }

  void validate() const { validate_noises(); }

  KOKKOS_INLINE_FUNCTION Vec<1> transition(double, const Vec<1>& x, const Control& u) const {
    return {{a * x[0] + u[0]}};
  }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> transition_jacobian(double, const Vec<1>&) const { return {{{a}}}; }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> control_input(double) const { return Mat<1, 1>::identity(); }
};

}  // namespace kushner
