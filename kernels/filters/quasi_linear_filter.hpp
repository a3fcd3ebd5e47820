#pragma once
// QLF: Sunahara's quasi-linear (statistical-linearization) filter, seed 000 section 5, (5.27) and (5.29):
//   dm = a dt + P H2^T V^{-1} (dy - h1 dt),   dP = (B P + P B^T + W - P H2^T V^{-1} H2 P) dt,
// with a, B, h1, H2 the Gaussian expectations of kernels/filters/gaussian_expectations.hpp and W = G(m) G(m)^T
// (the paper's noise is state-independent, as in every model here).
#include "kernels/errors.hpp"
#include "kernels/filters/filter_config.hpp"
#include "kernels/filters/gaussian_expectations.hpp"
#include "kernels/filters/jacobian_linearization.hpp"

namespace kushner {

template <class Model>
constexpr const char* qlf_unsupported() {
  using T = ModelTraits<Model>;
  if (!T::gaussian_integrable) return "the drift has no Gaussian expectation";
  if (!T::closed_form_expectations && Model::state_dim > max_cubature_dim)
    return "no closed-form Gaussian expectations, and tensor Gauss-Hermite cubature is limited to state_dim <= 3";
  return nullptr;
}

/// The expectation method a run uses: `automatic` resolved, requests a model cannot meet refused (InputError).
template <class Model>
Expectations resolve_qlf_expectations(Expectations requested) {
  constexpr bool closed = ModelTraits<Model>::closed_form_expectations;
  constexpr bool cubature = Model::state_dim <= max_cubature_dim;
  if (requested == Expectations::automatic) return closed ? Expectations::closed : Expectations::cubature;
  KUSHNER_INPUT_REQUIRE(
      requested != Expectations::closed || closed,
      "--qlf-expectations: model '" << Model::name << "' has no closed-form Gaussian expectations (use cubature)");
  KUSHNER_INPUT_REQUIRE(requested != Expectations::cubature || cubature,
                        "--qlf-expectations: cubature is limited to state_dim <= "
                            << max_cubature_dim << " (model '" << Model::name << "' has " << Model::state_dim << ")");
  return requested;
}

template <class Model, class MemSpace>
struct QuasiLinearFilter {
  static constexpr int n = Model::state_dim, p = Model::obs_dim;
  static constexpr bool has_closed = ModelTraits<Model>::closed_form_expectations;
  static constexpr bool has_cubature = n <= max_cubature_dim;
  static constexpr const char* name = "QLF";
  static constexpr const char* description =
      "quasi-linear filter, Sunahara (Gaussian expectations: closed form or Gauss-Hermite cubature)";
  static constexpr const char* unsupported = qlf_unsupported<Model>();

  Expectations expectations = Expectations::closed;
  GaussHermiteRule rule;

  static QuasiLinearFilter create(const FilterConfig& config, const Model&, long) {
    QuasiLinearFilter f;
    f.expectations = resolve_qlf_expectations<Model>(config.qlf_expectations);
    if (f.expectations == Expectations::cubature) f.rule = make_gauss_hermite_rule(config.gh_nodes);
    return f;
  }

  KOKKOS_INLINE_FUNCTION Status step(const Model& model, int, const StepInput<p>& in, Vec<n>& m, Mat<n, n>& P) const {
    static_assert(unsupported == nullptr, "QuasiLinearFilter: Model has no usable Gaussian expectations");
    ObservationLinearization<n, p> obs;
    if constexpr (ModelTraits<Model>::linear_observation) {
      obs = observation_linearization(model, in.t, m);  // E_N[h] = h(m), E_N[grad h] = H exactly
    } else if constexpr (has_cubature) {
      if (!cubature_observation(model, in.t, m, P, rule, obs)) return Status::not_positive_definite;
    }
    Vec<p> weighted_innovation;
    if (!kalman_update(obs, in, m, P, weighted_innovation)) return Status::not_positive_definite;
    GaussianDrift<n> g;
    if (!expected_drift(model, in.t, m, P, g)) return Status::not_positive_definite;
    euler_predict(DriftLinearization<n>{g.mean, g.jacobian, noise_intensity(model.diffusion(in.t, m))}, in.dt, m, P);
    return Status::ok;
  }

  KOKKOS_INLINE_FUNCTION bool expected_drift(const Model& model, double t, const Vec<n>& m, const Mat<n, n>& P,
                                             GaussianDrift<n>& g) const {
    if constexpr (has_closed) {
      if (expectations == Expectations::closed) {
        g = closed_form_drift(model, t, m, P);
        return true;
      }
    }
    if constexpr (has_cubature) return cubature_drift(model, t, m, P, rule, g);
    return false;  // unreachable: create() accepts only methods the model has
  }
};

}  // namespace kushner
