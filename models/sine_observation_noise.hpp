#pragma once
// Basin's simulations "realize" the white observation noises as sinusoidal signals: phi_1(t) = phi_2(t) = sin t
// in the car example (seed 002 L1505) and psi_i = sin t in the terpolymerization example (002 L1770). A model with
// this option (the cars, the reactor) takes the parameter `sine_observation_noise`: 1 makes its truths' observation
// noise that deterministic path on every component, dy = h(t, x) dt + R(t) dv with dv = integral of sin over the
// step = cos t - cos(t + dt) (exact, so that dy does not depend on how the step is split); 0 (the default) keeps it
// Brownian. Only the truths read it: the filters take V = R R^T in their gains as the intensity of a white noise,
// and the process noise stays Brownian (q = 0 in both examples). Every member then sees the same observations: with
// a fixed initial state, all members are one deterministic run. A run-time parameter rather than a truth type of
// its own, so that `kushner reproduce` runs the banks every command compiles (kernels/simulate_truth.hpp).
#include "core/errors.hpp"
#include "core/math.hpp"

namespace kushner {

struct SineObservationNoiseOption {
  double sine_observation_noise = 0.0;  // 0 or 1

  KOKKOS_INLINE_FUNCTION bool observation_noise_is_sine() const { return sine_observation_noise != 0.0; }

  /// The sine path's increment over [t, t + dt], on every component.
  KOKKOS_INLINE_FUNCTION static double sine_noise_increment(double t, double dt) {
    return math::cos(t) - math::cos(t + dt);
  }

 protected:
  template <class Visitor>
  void sine_observation_noise_parameter(Visitor&& visit) {
    visit("sine_observation_noise", sine_observation_noise,
          "1: the truths' observation noise is Basin's sin t on every component (dv = cos t - cos(t + dt)); 0: "
          "Brownian");
  }
  void validate_sine_observation_noise() const {
    KUSHNER_INPUT_REQUIRE(sine_observation_noise == 0.0 || sine_observation_noise == 1.0,
                          "sine_observation_noise: must be 0 or 1 (got " << sine_observation_noise << ")");
  }
};

}  // namespace kushner
