#pragma once
// Basin's simulations "realize" the white observation noises as sinusoidal signals: phi_1(t) = phi_2(t) = sin t
// in the car example (seed 002 L1505) and psi_i = sin t in the terpolymerization example (002 L1770). As a
// truth model, SineObservationNoise<Model> is Model whose observation noise is that deterministic path on every
// component: dy = h(t, x) dt + R(t) dv with dv = integral of sin over the step = cos t - cos(t + dt) (exact, so
// that dy does not depend on how the step is split). The filters keep Model, whose V = R R^T they use in the
// gain as the intensity of a white noise; the process noise stays Brownian (q = 0 in both examples). Every
// member then sees the same observations: with a fixed initial state, all members are one deterministic run.
#include "core/math.hpp"
#include "core/small_matrix.hpp"

namespace kushner {

template <class Model>
struct SineObservationNoise : Model {
  SineObservationNoise() = default;
  explicit SineObservationNoise(const Model& model) : Model(model) {}

  /// The observation noise's increment over [t, t + dt] (kernels/simulate_truth.hpp).
  KOKKOS_INLINE_FUNCTION Vec<Model::obs_dim> observation_noise_increment(double t, double dt) const {
    return Vec<Model::obs_dim>::constant(math::cos(t) - math::cos(t + dt));
  }
};

}  // namespace kushner
