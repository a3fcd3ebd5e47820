#pragma once
// KBL: the Kalman-Bucy filter of the model linearized at the origin (seed 002 automotive (22), terpolymer
// (20)-(21): "only the linear terms and innovations processes"):
//   a0 = f(t, 0), F0 = df/dx(t, 0), c0 = h(t, 0), H0 = dh/dx(t, 0), W0 = G(t, 0) G(t, 0)^T,
//   dm = (a0 + F0 m) dt + P H0^T V^{-1} (dy - (c0 + H0 m) dt),   dP = (F0 P + P F0^T + W0 - P H0^T V^{-1} H0 P) dt.
#include "kernels/filters/filter_protocol.hpp"
#include "kernels/filters/jacobian_linearization.hpp"

namespace kushner {

/// The linearizations at the origin, (a0, F0, W0) and (c0, H0): at each step's t, or, where the model does not depend
/// on t (ModelTraits::time_invariant), once when the filter is created. Every member computed the same values at every
/// step: on a GPU the sine model's sine and cosine polynomials at 0, ~45 instructions of the sine bank's ~1520 per
/// member-step (perf/filter_bank.md).
template <class Model, bool = ModelTraits<Model>::time_invariant>
struct OriginLinearization {
  static constexpr int n = Model::state_dim, p = Model::obs_dim;
  static OriginLinearization of(const Model&) { return {}; }
  KOKKOS_INLINE_FUNCTION DriftLinearization<n> drift(const Model& model, double t) const {
    return drift_linearization(model, t, Vec<n>::zero());
  }
  KOKKOS_INLINE_FUNCTION ObservationLinearization<n, p> observation(const Model& model, double t) const {
    return observation_linearization(model, t, Vec<n>::zero());
  }
};
template <class Model>
struct OriginLinearization<Model, true> {
  static constexpr int n = Model::state_dim, p = Model::obs_dim;
  DriftLinearization<n> drift_at_origin;
  ObservationLinearization<n, p> observation_at_origin;
  static OriginLinearization of(const Model& model) {  // the time-varying form's, at t = 0
    const OriginLinearization<Model, false> at_each_step;
    return {at_each_step.drift(model, 0.0), at_each_step.observation(model, 0.0)};
  }
  KOKKOS_INLINE_FUNCTION DriftLinearization<n> drift(const Model&, double) const { return drift_at_origin; }
  KOKKOS_INLINE_FUNCTION ObservationLinearization<n, p> observation(const Model&, double) const {
    return observation_at_origin;
  }
};

/// The linearizations at the origin evaluated at m: (a0 + F0 m, F0, W0) and (c0 + H0 m, H0).
template <class Model, bool TimeInvariant>
KOKKOS_INLINE_FUNCTION DriftLinearization<Model::state_dim> drift_linearization_at_origin(
    const OriginLinearization<Model, TimeInvariant>& origin, const Model& model, double t,
    const Vec<Model::state_dim>& m) {
  DriftLinearization<Model::state_dim> d = origin.drift(model, t);
  d.a += d.J * m;
  return d;
}
template <class Model, bool TimeInvariant>
KOKKOS_INLINE_FUNCTION ObservationLinearization<Model::state_dim, Model::obs_dim> observation_linearization_at_origin(
    const OriginLinearization<Model, TimeInvariant>& origin, const Model& model, double t,
    const Vec<Model::state_dim>& m) {
  ObservationLinearization<Model::state_dim, Model::obs_dim> o = origin.observation(model, t);
  o.h += o.H * m;
  return o;
}

template <class Model, class MemSpace>
struct LinearizedKalmanBucyFilter {
  static constexpr int n = Model::state_dim, p = Model::obs_dim;
  static constexpr const char* name = "KBL";
  static constexpr const char* description = "Kalman-Bucy on the model linearized at the origin";
  static constexpr const char* unsupported = nullptr;

  OriginLinearization<Model> origin;

  static LinearizedKalmanBucyFilter create(const OptionValues&, const Model& model, long) {
    return {OriginLinearization<Model>::of(model)};
  }

  KOKKOS_INLINE_FUNCTION Status step(const Model& model, int, const StepInput<p>& in, Vec<n>& m, Mat<n, n>& P) const {
    Vec<p> weighted_innovation;
    if (!kalman_update(observation_linearization_at_origin(origin, model, in.t, m), in, m, P, weighted_innovation))
      return Status::not_positive_definite;
    euler_predict(drift_linearization_at_origin(origin, model, in.t, m), in.dt, m, P);
    return Status::ok;
  }
};

}  // namespace kushner
