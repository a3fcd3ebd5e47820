#pragma once
// First-order (Taylor) linearizations at a point, shared by the EKF family, the second-order filters and KBL.
#include "kernels/filters/filter_step.hpp"
#include "models/model_traits.hpp"

namespace kushner {

/// h_hat = h(t, x), H = dh/dx(t, x).
template <class Model>
KOKKOS_INLINE_FUNCTION ObservationLinearization<Model::state_dim, Model::obs_dim> observation_linearization(
    const Model& model, double t, const Vec<Model::state_dim>& x) {
  return {model.observation(t, x), model.observation_jacobian(t, x)};
}

/// (a, J) = f and W = G(t, x) G(t, x)^T.
template <class Model>
KOKKOS_INLINE_FUNCTION DriftLinearization<Model::state_dim> drift_linearization_of(
    const Model& model, double t, const Vec<Model::state_dim>& x, const DriftAndJacobian<Model::state_dim>& f) {
  return {f.drift, f.jacobian, noise_intensity(model.diffusion(t, x))};
}

/// a = f(t, x), J = df/dx(t, x), W = G(t, x) G(t, x)^T.
template <class Model>
KOKKOS_INLINE_FUNCTION DriftLinearization<Model::state_dim> drift_linearization(const Model& model, double t,
                                                                                const Vec<Model::state_dim>& x) {
  return drift_linearization_of(model, t, x, drift_and_jacobian(model, t, x, Model::Control::zero()));
}

}  // namespace kushner
