#pragma once
// What a model offers the filters, detected at compile time, and the structured drift forms derived from the
// most specific one a model has (a linear model is also a degree-1 polynomial and its own SDC factorization).
// Filters read these to decide, at compile time, whether they support a model (kernels/filters/filter_list.hpp).
#include "models/drift_forms.hpp"
#include "models/model_facts.hpp"

#include <type_traits>
#include <utility>

namespace kushner {

namespace detail {
template <class Model, class = void>
struct has_linear_form : std::false_type {};
template <class Model>
struct has_linear_form<Model, std::void_t<decltype(std::declval<const Model&>().linear_form(0.0))>> : std::true_type {};

template <class Model, class = void>
struct has_power_polynomial : std::false_type {};
template <class Model>
struct has_power_polynomial<Model, std::void_t<decltype(std::declval<const Model&>().drift_power_polynomial(0.0))>>
    : std::true_type {};

template <class Model, class = void>
struct has_quadratic_polynomial : std::false_type {};
template <class Model>
struct has_quadratic_polynomial<Model,
                                std::void_t<decltype(std::declval<const Model&>().drift_quadratic_polynomial(0.0))>>
    : std::true_type {};

template <class Model, class = void>
struct has_gaussian_drift : std::false_type {};
template <class Model>
struct has_gaussian_drift<Model, std::void_t<decltype(std::declval<const Model&>().gaussian_drift(
                                     0.0, std::declval<const Vec<Model::state_dim>&>(),
                                     std::declval<const Mat<Model::state_dim, Model::state_dim>&>()))>>
    : std::true_type {};

template <class Model, class = void>
struct has_sdc_drift : std::false_type {};
template <class Model>
struct has_sdc_drift<Model, std::void_t<decltype(std::declval<const Model&>().sdc_drift(
                                0.0, std::declval<const Vec<Model::state_dim>&>()))>> : std::true_type {};

template <class Model, class = void>
struct has_drift_and_jacobian : std::false_type {};
template <class Model>
struct has_drift_and_jacobian<
    Model, std::void_t<decltype(std::declval<const Model&>().drift_and_jacobian(
               0.0, std::declval<const Vec<Model::state_dim>&>(), std::declval<const typename Model::Control&>()))>>
    : std::true_type {};

template <class Model, class = void>
struct has_drift_derivatives : std::false_type {};
template <class Model>
struct has_drift_derivatives<
    Model, std::void_t<decltype(std::declval<const Model&>().drift_derivatives(
               0.0, std::declval<const Vec<Model::state_dim>&>(), std::declval<const typename Model::Control&>()))>>
    : std::true_type {};

template <class Model, class = void>
struct has_gaussian_observation : std::false_type {};
template <class Model>
struct has_gaussian_observation<Model, std::void_t<decltype(std::declval<const Model&>().gaussian_observation(
                                           0.0, std::declval<const Vec<Model::state_dim>&>(),
                                           std::declval<const Mat<Model::state_dim, Model::state_dim>&>()))>>
    : std::true_type {};

template <class Model, class = void>
struct has_sdc_observation : std::false_type {};
template <class Model>
struct has_sdc_observation<Model, std::void_t<decltype(std::declval<const Model&>().sdc_observation(
                                      0.0, std::declval<const Vec<Model::state_dim>&>()))>> : std::true_type {};

template <class Model, class = void>
struct declares_linear_observation : std::false_type {};
template <class Model>
struct declares_linear_observation<Model, std::enable_if_t<Model::linear_observation>> : std::true_type {};

/// `ModelFacts model_facts() const`: a model whose structure is known only at run time (a --model-file
/// polynomial) states what its coefficients are.
template <class Model, class = void>
struct has_model_facts : std::false_type {};
template <class Model>
struct has_model_facts<Model, std::void_t<decltype(std::declval<const Model&>().model_facts())>> : std::true_type {};

template <class Model, class = void>
struct declares_time_invariant : std::false_type {};
template <class Model>
struct declares_time_invariant<Model, std::enable_if_t<Model::time_invariant>> : std::true_type {};

template <class Model, class = void>
struct declares_non_integrable_drift : std::false_type {};
template <class Model>
struct declares_non_integrable_drift<Model, std::enable_if_t<!Model::drift_gaussian_integrable>> : std::true_type {};
}  // namespace detail

/// Capabilities of a continuous-time model, as the filters see them. For a model with run-time facts
/// (`runtime_checked`) they say what its type can offer; its forms (linear_form, drift_power_polynomial,
/// drift_quadratic_polynomial) describe the whole drift only where its model_facts() allow, which every filter
/// checks before it runs (kernels/filters/filter_protocol.hpp).
template <class Model>
struct ModelTraits {
  static constexpr bool runtime_checked = detail::has_model_facts<Model>::value;
  static constexpr bool linear = detail::has_linear_form<Model>::value;
  /// h(t, x) = h(t, 0) + H x, H = observation_jacobian(t, .) constant in x.
  static constexpr bool linear_observation = linear || detail::declares_linear_observation<Model>::value;
  static constexpr bool power_polynomial = linear || detail::has_power_polynomial<Model>::value;
  static constexpr bool quadratic_polynomial = linear || detail::has_quadratic_polynomial<Model>::value;
  static constexpr bool polynomial = power_polynomial || quadratic_polynomial;
  static constexpr bool sdc = linear || detail::has_sdc_drift<Model>::value;
  /// f, G, h and R do not depend on t (the model states `time_invariant = true`; test_model_forms checks it): a
  /// filter may evaluate what depends on them alone once (KBL's linearization at the origin).
  static constexpr bool time_invariant = detail::declares_time_invariant<Model>::value;
  /// dx = (f(t, x) + B(t) u) dt: the model has a control input, B = control_input(t) (`kushner control`).
  static constexpr bool controlled = Model::control_dim > 0;
  /// h(t, x) = C(t, x) x + c0(t): linear, or the model's sdc_observation (seed 001 (5)).
  static constexpr bool sdc_observation = linear_observation || detail::has_sdc_observation<Model>::value;
  /// E_N[h], E_N[grad h] in closed form: exact for a linear observation, else the model's gaussian_observation.
  static constexpr bool closed_form_observation = linear_observation || detail::has_gaussian_observation<Model>::value;
  /// E_N[f] exists for every Gaussian (false for tan: E|tan x| is infinite).
  static constexpr bool gaussian_integrable = !detail::declares_non_integrable_drift<Model>::value;
  /// E_N[f], E_N[grad f] (and E_N[h], E_N[grad h]) in closed form: the model's own formulas, or exact Gaussian
  /// moments of a polynomial.
  static constexpr bool closed_form_expectations =
      gaussian_integrable && closed_form_observation && (detail::has_gaussian_drift<Model>::value || polynomial);

  static constexpr int power_degree() {
    if constexpr (detail::has_power_polynomial<Model>::value)
      return decltype(std::declval<const Model&>().drift_power_polynomial(0.0))::degree;
    else
      return linear ? 1 : 0;
  }
};

/// f(t, x, u) and df/dx(t, x, u): the model's drift_and_jacobian where it has one (e.g. a sine and a cosine of one
/// argument, one range reduction on a GPU: math::sin_cos), else drift and drift_jacobian.
template <class Model>
KOKKOS_INLINE_FUNCTION DriftAndJacobian<Model::state_dim> drift_and_jacobian(const Model& model, double t,
                                                                             const Vec<Model::state_dim>& x,
                                                                             const typename Model::Control& u) {
  if constexpr (detail::has_drift_and_jacobian<Model>::value)
    return model.drift_and_jacobian(t, x, u);
  else
    return {model.drift(t, x, u), model.drift_jacobian(t, x, u)};
}

/// The drift as a componentwise power polynomial (degree 1 for a linear model).
template <class Model>
KOKKOS_INLINE_FUNCTION auto drift_power_polynomial(const Model& model, double t) {
  constexpr int n = Model::state_dim;
  if constexpr (detail::has_power_polynomial<Model>::value) {
    return model.drift_power_polynomial(t);
  } else {
    static_assert(ModelTraits<Model>::linear,
                  "drift_power_polynomial: Model has neither drift_power_polynomial(t) nor linear_form(t)");
    const auto lf = model.linear_form(t);
    auto poly = PowerPolynomial<n, 1>::zero();
    poly.a0 = lf.a0;
    poly.coefficient[1] = lf.A;
    return poly;
  }
}

/// The drift as a quadratic polynomial with bilinear terms (no terms for a linear model).
template <class Model>
KOKKOS_INLINE_FUNCTION auto drift_quadratic_polynomial(const Model& model, double t) {
  if constexpr (detail::has_quadratic_polynomial<Model>::value) {
    return model.drift_quadratic_polynomial(t);
  } else {
    static_assert(ModelTraits<Model>::linear,
                  "drift_quadratic_polynomial: Model has neither drift_quadratic_polynomial(t) nor linear_form(t)");
    const auto lf = model.linear_form(t);
    QuadraticPolynomial<Model::state_dim, 0> poly;
    poly.a0 = lf.a0;
    poly.a1 = lf.A;
    return poly;
  }
}

/// h(t, x) = C(x) x + c0 (seed 001 (5)); for a linear observation C = H, c0 = h(t, 0).
template <class Model>
KOKKOS_INLINE_FUNCTION SdcObservation<Model::state_dim, Model::obs_dim> observation_sdc(
    const Model& model, double t, const Vec<Model::state_dim>& x) {
  if constexpr (detail::has_sdc_observation<Model>::value) {
    return model.sdc_observation(t, x);
  } else {
    static_assert(ModelTraits<Model>::linear_observation,
                  "observation_sdc: Model has neither sdc_observation(t, x) nor a linear observation");
    return {model.observation_jacobian(t, x), model.observation(t, Vec<Model::state_dim>::zero())};
  }
}

/// f(t, x) = A(x) x + b (seed 001 (4), with the known input b of Theorem 3 (ii)).
template <class Model>
KOKKOS_INLINE_FUNCTION SdcDrift<Model::state_dim> drift_sdc(const Model& model, double t,
                                                            const Vec<Model::state_dim>& x) {
  if constexpr (detail::has_sdc_drift<Model>::value) {
    return model.sdc_drift(t, x);
  } else {
    static_assert(ModelTraits<Model>::linear, "drift_sdc: Model has neither sdc_drift(t, x) nor linear_form(t)");
    const auto lf = model.linear_form(t);
    return {lf.A, lf.a0};
  }
}

namespace detail {
template <class Model, class = void>
struct declares_linear_transition : std::false_type {};
template <class Model>
struct declares_linear_transition<Model, std::enable_if_t<Model::linear_transition>> : std::true_type {};

template <class Model, class = void>
struct has_bounded_noises : std::false_type {};
template <class Model>
struct has_bounded_noises<
    Model, std::void_t<decltype(std::declval<const Model&>().w.bound), decltype(std::declval<const Model&>().v.bound)>>
    : std::true_type {};
}  // namespace detail

/// Capabilities of a discrete-time model (x[k+1] = F(k, x, u) + w, z = h(k, x) + v), as its filters see them.
template <class Model>
struct DiscreteModelTraits {
  /// F(k, x, u) = A(k) x + F(k, 0, u), A = transition_jacobian(k, .) constant in x.
  static constexpr bool linear = detail::declares_linear_transition<Model>::value;
  static constexpr bool linear_observation = detail::declares_linear_observation<Model>::value;
  /// Scalar w and v of Clark's bounded power-law family (members w, v: models/clark_noises.hpp).
  static constexpr bool bounded_noises = detail::has_bounded_noises<Model>::value;
};

}  // namespace kushner
