#pragma once
// POLY3, POLY4: Basin's optimal filters for a drift polynomial of degree 3 or 4 in componentwise powers,
// f = a0 + a1 x + a2 x^2 + a3 x^3 [+ a4 x^4], with a linear observation dy = (A0 + A x) dt + B dW2
// (seed 002 filter paper (9)-(10), (12)-(13)):
//   dm = E_N[f] dt + P A^T (B B^T)^{-1} (dy - (A0 + A m) dt),
//   dP = (J P + P J^T + b b^T - P A^T (B B^T)^{-1} A P) dt,
//   E_N[f] = a0 + a1 m + a2 (p + m^2) + a3 (3 p m + m^3) [+ a4 (3 p^2 + 6 p m^2 + m^4)],
//   J = a1 + 2 a2 diag(m) + 3 a3 diag(p + m^2) [+ 4 a4 diag(3 p m + m^3)],  p = diag(P).
// Lower-degree drifts are the special cases with vanishing coefficients (002 L1428).
#include "kernels/filters/filter_protocol.hpp"
#include "kernels/filters/jacobian_linearization.hpp"
#include "kernels/filters/polynomial_moments.hpp"
#include "models/model_traits.hpp"

namespace kushner {

template <class Model, int Degree>
constexpr const char* polynomial_filter_unsupported() {
  using T = ModelTraits<Model>;
  if (!T::power_polynomial)
    return T::quadratic_polynomial ? "drift has cross terms x_i x_j, not componentwise powers (BILIN handles them)"
                                   : "drift is not polynomial";
  // A run-time polynomial's degree is checked on its coefficients (unsupported_by); its type allows degree 4.
  if (T::power_degree() > Degree && !T::runtime_checked)
    return Degree == 3 ? "drift has degree above 3" : "drift has degree above 4";
  if (!T::linear_observation) return "observation is not linear";
  return nullptr;
}

/// What a run-time polynomial's coefficients must satisfy (its type allows any degree up to 4).
template <int Degree>
const char* polynomial_filter_unsupported_by(const ModelFacts& f) {
  if (f.cross_terms) return "drift has cross terms (monomials of two or more variables), not componentwise powers";
  if (f.drift_degree > Degree) return Degree == 3 ? "drift has degree above 3" : "drift has degree above 4";
  return observation_unsupported_by(f);
}

template <class Model, int Degree>
struct PolynomialStep {
  static constexpr int n = Model::state_dim, p = Model::obs_dim;
  static constexpr const char* unsupported = polynomial_filter_unsupported<Model, Degree>();

  KOKKOS_INLINE_FUNCTION static Status step(const Model& model, const StepInput<p>& in, Vec<n>& m, Mat<n, n>& P) {
    static_assert(
        unsupported == nullptr,
        "PolynomialFilter: Model must define drift_power_polynomial(t) of low enough degree and a linear observation");
    Vec<p> weighted_innovation;
    if (!kalman_update(observation_linearization(model, in.t, m), in, m, P, weighted_innovation))
      return Status::not_positive_definite;
    const GaussianDrift<n> g = gaussian_drift(truncated<Degree>(drift_power_polynomial(model, in.t)), m, P);
    euler_predict(DriftLinearization<n>{g.mean, g.jacobian, noise_intensity(model.diffusion(in.t, m))}, in.dt, m, P);
    return Status::ok;
  }
};

template <class Model, class MemSpace>
struct Polynomial3Filter {
  static constexpr int n = Model::state_dim, p = Model::obs_dim;
  static constexpr const char* name = "POLY3";
  static constexpr const char* description = "Basin's optimal filter for a third-degree polynomial drift";
  static constexpr const char* unsupported = polynomial_filter_unsupported<Model, 3>();

  static const char* unsupported_by(const ModelFacts& f) { return polynomial_filter_unsupported_by<3>(f); }

  static Polynomial3Filter create(const OptionValues&, const Model&, long) { return {}; }

  KOKKOS_INLINE_FUNCTION Status step(const Model& model, int, const StepInput<p>& in, Vec<n>& m, Mat<n, n>& P) const {
    return PolynomialStep<Model, 3>::step(model, in, m, P);
  }
};

template <class Model, class MemSpace>
struct Polynomial4Filter {
  static constexpr int n = Model::state_dim, p = Model::obs_dim;
  static constexpr const char* name = "POLY4";
  static constexpr const char* description = "Basin's optimal filter for a fourth-degree polynomial drift";
  static constexpr const char* unsupported = polynomial_filter_unsupported<Model, 4>();

  static const char* unsupported_by(const ModelFacts& f) { return polynomial_filter_unsupported_by<4>(f); }

  static Polynomial4Filter create(const OptionValues&, const Model&, long) { return {}; }

  KOKKOS_INLINE_FUNCTION Status step(const Model& model, int, const StepInput<p>& in, Vec<n>& m, Mat<n, n>& P) const {
    return PolynomialStep<Model, 4>::step(model, in, m, P);
  }
};

}  // namespace kushner
