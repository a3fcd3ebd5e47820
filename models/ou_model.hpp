#pragma once
// Scalar Ornstein-Uhlenbeck process observed in white noise: the simplest model with exact moments,
//   dx = -theta (x - mu) dt + sigma dw,   dy = x dt + r dv.
// E[x(t)] = mu + (m0 - mu) e^{-theta t},  Var[x(t)] = P0 e^{-2 theta t} + sigma^2 (1 - e^{-2 theta t}) / (2 theta).
#include "core/small_matrix.hpp"
#include "models/drift_forms.hpp"
#include "models/initial_law.hpp"

namespace kushner {

struct OuModel : InitialLaw<1> {
  static constexpr int state_dim = 1, obs_dim = 1, noise_dim = 1, control_dim = 0;
  static constexpr bool discrete_time = false;
  static constexpr bool time_invariant = true;  // f, G, h, R: no function of t
  static constexpr const char* name = "ou";
  static constexpr const char* description =
      "scalar Ornstein-Uhlenbeck: dx = -theta (x - mu) dt + sigma dw, dy = x dt + r dv";
  using Control = Vec<control_dim>;

  double theta = 1.0, mu = 0.0, sigma = 1.0, r = 0.5;

  OuModel() {
    set_initial_law(Vec<1>{{1.0}}, Mat<1, 1>{{{0.0}}});
    prior_cov = Mat<1, 1>{{{0.25}}};
  }

  template <class Visitor>
  void parameters(Visitor&& v) {
    v("theta", theta, "mean-reversion rate");
    v("mu", mu, "long-run mean");
    v("sigma", sigma, "process noise intensity");
    v("r", r, "observation noise intensity");
    initial_law_parameters(v);
  }

  // Templates on the scalar: the particle filter's fp32 steps its particles in float (particle_model_traits.hpp).
  template <class T>
  KOKKOS_INLINE_FUNCTION Vec<1, T> drift(double, const Vec<1, T>& x, const Control&) const {
    return {{-static_cast<T>(theta) * (x[0] - static_cast<T>(mu))}};
  }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> drift_jacobian(double, const Vec<1>&, const Control&) const { return {{{-theta}}}; }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> drift_hessian(double, const Vec<1>&, const Control&, int) const { return {{{0.0}}}; }
  template <class T>
  KOKKOS_INLINE_FUNCTION Mat<1, 1, T> diffusion(double, const Vec<1, T>&) const {
    return {{{static_cast<T>(sigma)}}};
  }
  template <class T>
  KOKKOS_INLINE_FUNCTION Vec<1, T> observation(double, const Vec<1, T>& x) const {
    return x;
  }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> observation_jacobian(double, const Vec<1>&) const { return {{{1.0}}}; }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> observation_hessian(double, const Vec<1>&, int) const { return {{{0.0}}}; }
  KOKKOS_INLINE_FUNCTION Mat<1, 1> observation_noise(double) const { return {{{r}}}; }

  /// -theta (x - mu) = theta mu - theta x: the coefficients the Kalman-Bucy filter reads.
  KOKKOS_INLINE_FUNCTION LinearForm<1, 1> linear_form(double) const {
    return {{{theta * mu}}, {{{-theta}}}, {{0.0}}, {{{1.0}}}};
  }
};

}  // namespace kushner
