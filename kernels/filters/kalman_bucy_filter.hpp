#pragma once
// KB: the Kalman-Bucy filter of a linear model dx = (a0 + A x) dt + G dw, dy = (c0 + C x) dt + R dv
// (seed 002 filter paper section 2, ACC03 (4)-(5); seed 004 (2.3)-(2.4)):
//   dm = (a0 + A m) dt + P C^T V^{-1} (dy - (c0 + C m) dt),   dP = (A P + P A^T + G G^T - P C^T V^{-1} C P) dt.
#include "kernels/filters/filter_protocol.hpp"
#include "kernels/filters/filter_step.hpp"
#include "models/model_traits.hpp"

namespace kushner {

template <class Model, class MemSpace>
struct KalmanBucyFilter {
  static constexpr int n = Model::state_dim, p = Model::obs_dim;
  static constexpr const char* name = "KB";
  static constexpr const char* description = "Kalman-Bucy (linear models)";
  static constexpr const char* unsupported = ModelTraits<Model>::linear ? nullptr : "model is not linear";

  static const char* unsupported_by(const ModelFacts& f) {
    if (f.drift_degree > 1) return "drift is not linear (the file has terms of degree 2 or more)";
    return observation_unsupported_by(f);
  }

  static KalmanBucyFilter create(const OptionValues&, const Model&, long) { return {}; }

  KOKKOS_INLINE_FUNCTION Status step(const Model& model, int, const StepInput<p>& in, Vec<n>& m, Mat<n, n>& P) const {
    static_assert(ModelTraits<Model>::linear, "KalmanBucyFilter: Model must define linear_form(t)");
    const auto lf = model.linear_form(in.t);
    Vec<p> weighted_innovation;
    if (!kalman_update(ObservationLinearization<n, p>{lf.c0 + lf.C * m, lf.C}, in, m, P, weighted_innovation))
      return Status::not_positive_definite;
    const Mat<n, n> W = noise_intensity(model.diffusion(in.t, m));
    euler_predict(DriftLinearization<n>{lf.a0 + lf.A * m, lf.A, W}, in.dt, m, P);
    return Status::ok;
  }
};

}  // namespace kushner
