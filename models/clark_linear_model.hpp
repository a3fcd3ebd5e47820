#pragma once
// Clark (1971) Example 1, seed 003 eqs. (2.22)-(2.23): a discrete-time linear system with bounded
// non-Gaussian noise,  x[k+1] = a x[k] + u[k] + w[k],  z[k+1] = x[k+1] + v[k+1],
// w with density (11/2) w^10 on |w| < 1 (rho_w = 10), v uniform on (-1, 1) (rho_v = 0). a = 0.1.
// The thesis does not state x[0]; ours: x[0] = 0 for the truths, the filters' prior N(0, 1).
#include "core/errors.hpp"
#include "core/small_matrix.hpp"
#include "models/bounded_noise.hpp"
#include "models/initial_law.hpp"

namespace kushner {

struct ClarkLinearModel : InitialLaw<1> {
  static constexpr int state_dim = 1, obs_dim = 1, noise_dim = 1, control_dim = 1;
  static constexpr bool discrete_time = true;
  static constexpr const char* name = "clark-linear";
  static constexpr const char* description =
      "Clark 1971 Example 1 (discrete time): x[k+1] = a x[k] + u + w, z = x + v, bounded non-Gaussian w, v";
  using Control = Vec<control_dim>;

  double a = 0.1;
  BoundedPowerNoise w{10.0, 1.0};
  BoundedPowerNoise v{0.0, 1.0};

  ClarkLinearModel() {
    x0_mean = Vec<1>{{0.0}};
    x0_cov = Mat<1, 1>{{{0.0}}};
    prior_mean = Vec<1>{{0.0}};
    prior_cov = Mat<1, 1>{{{1.0}}};
  }

  template <class Visitor>
  void parameters(Visitor&& visit) {
    visit("a", a, "state transition coefficient");
    visit("rho_w", w.rho, "shape exponent of the plant noise density (0 = uniform)");
    visit("bound_w", w.bound, "bound of the plant noise");
    visit("rho_v", v.rho, "shape exponent of the measurement noise density (0 = uniform)");
    visit("bound_v", v.bound, "bound of the measurement noise");
    initial_law_parameters(visit);
  }

  void validate() const {
    KUSHNER_INPUT_REQUIRE(w.rho > -1.0 && v.rho > -1.0,
                          "rho_w, rho_v: must exceed -1 (got " << w.rho << ", " << v.rho << ")");
    KUSHNER_INPUT_REQUIRE(w.bound > 0.0 && v.bound > 0.0,
                          "bound_w, bound_v: must be positive (got " << w.bound << ", " << v.bound << ")");
  }

  KOKKOS_INLINE_FUNCTION Vec<1> transition(int, const Vec<1>& x, const Control& u) const { return {{a * x[0] + u[0]}}; }
  KOKKOS_INLINE_FUNCTION Vec<1> process_noise(const Vec<1>& uniform) const { return {{w.sample(uniform[0])}}; }
  KOKKOS_INLINE_FUNCTION Vec<1> observation(int, const Vec<1>& x) const { return x; }
  KOKKOS_INLINE_FUNCTION Vec<1> observation_noise_sample(const Vec<1>& uniform) const {
    return {{v.sample(uniform[0])}};
  }
};

}  // namespace kushner
