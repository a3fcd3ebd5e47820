#pragma once
// Sunahara (1968) Example 1, seed 000 eqs. (6.1)-(6.3):  dx = -sin(x) dt + q dw,  dy = x dt + r dv.
// The paper gives no noise levels or initial law (figures only); ours, stated in the README: q = 1, r = 0.5,
// x(0) ~ N(1, 1) for the truths and the filters' prior alike.
#include "kernels/math.hpp"
#include "kernels/small_matrix.hpp"
#include "models/initial_law.hpp"

namespace kushner {

struct SineModel : InitialLaw<1> {
  static constexpr int state_dim = 1, obs_dim = 1, noise_dim = 1, control_dim = 0;
  static constexpr bool discrete_time = false;
  static constexpr const char* name = "sine";
  static constexpr const char* description = "Sunahara 1968 Example 1: dx = -sin(x) dt + q dw, dy = x dt + r dv";
  using Control = Vec<control_dim>;

  double q = 1.0, r = 0.5;

  SineModel() { set_initial_law(Vec<1>{{1.0}}, Mat<1, 1>{{{1.0}}}); }

  template <class Visitor>
  void parameters(Visitor&& v) {
    v("q", q, "process noise intensity");
    v("r", r, "observation noise intensity");
    initial_law_parameters(v);
  }

  KOKKOS_INLINE_FUNCTION Vec<1> drift(double, const Vec<1>& x, const Control&) const { return {{-math::sin(x[0])}}; }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> drift_jacobian(double, const Vec<1>& x, const Control&) const {
    return {{{-math::cos(x[0])}}};
  }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> drift_hessian(double, const Vec<1>& x, const Control&, int) const {
    return {{{math::sin(x[0])}}};
  }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> diffusion(double, const Vec<1>&) const { return {{{q}}}; }
  KOKKOS_INLINE_FUNCTION Vec<1> observation(double, const Vec<1>& x) const { return x; }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> observation_jacobian(double, const Vec<1>&) const { return {{{1.0}}}; }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> observation_hessian(double, const Vec<1>&, int) const { return {{{0.0}}}; }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> observation_noise(double) const { return {{{r}}}; }
};

}  // namespace kushner
