#pragma once
// QLF: Sunahara's quasi-linear (statistical-linearization) filter, seed 000 section 5, (5.27) and (5.29):
//   dm = a dt + P H2^T V^{-1} (dy - h1 dt),   dP = (B P + P B^T + W - P H2^T V^{-1} H2 P) dt,
// with a, B, h1, H2 the Gaussian expectations of kernels/filters/gaussian_expectations.hpp and W = G(m) G(m)^T
// (the paper's noise is state-independent, as in every model here).
#include "core/errors.hpp"
#include "kernels/filters/filter_protocol.hpp"
#include "kernels/filters/gauss_hermite.hpp"
#include "kernels/filters/gaussian_expectations.hpp"
#include "kernels/filters/jacobian_linearization.hpp"

#include <optional>
#include <string>
#include <vector>

namespace kushner {

/// How QLF obtains its Gaussian expectations E_N[f], E_N[grad f], E_N[h], E_N[grad h].
enum class Expectations {
  closed,    // the model's formulas (seed 000 (6.4)-(6.5), (6.14)) or exact moments of a polynomial drift
  cubature,  // tensor-product Gauss-Hermite, any model of state dimension <= 3
};

template <class Model>
constexpr const char* qlf_unsupported() {
  using T = ModelTraits<Model>;
  if (!T::gaussian_integrable) return "the drift has no Gaussian expectation";
  if (!T::closed_form_expectations && Model::state_dim > max_cubature_dim)
    return "no closed-form Gaussian expectations, and tensor Gauss-Hermite cubature is limited to state_dim <= 3";
  return nullptr;
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

  static std::vector<OptionSpec> options() {
    return {OptionSpec::choice("qlf_expectations", "auto", {"auto", "closed", "cubature"},
                               "QLF's Gaussian expectations: closed (the model's formulas), cubature (Gauss-Hermite), "
                               "or auto (closed where the model has them)"),
            OptionSpec::integer("gh_nodes", 8, 1, max_gauss_hermite_nodes,
                                "Gauss-Hermite nodes per axis for QLF cubature")};
  }

  /// A requested method this model does not have.
  static std::optional<OptionProblem> check(const OptionValues& options) {
    const std::string& requested = options.word("qlf_expectations");
    if (requested == "closed" && !has_closed)
      return OptionProblem{"qlf_expectations", std::string("model '") + Model::name +
                                                   "' has no closed-form Gaussian expectations (use cubature)"};
    if (requested == "cubature" && !has_cubature)
      return OptionProblem{"qlf_expectations",
                           "cubature is limited to state_dim <= " + std::to_string(max_cubature_dim) + " (model '" +
                               Model::name + "' has " + std::to_string(n) + ")"};
    return std::nullopt;
  }

  /// The method a run uses: `auto` is closed form where the model has it, else cubature.
  static Expectations resolve(const std::string& requested) {
    if (requested == "closed") return Expectations::closed;
    if (requested == "cubature") return Expectations::cubature;
    return has_closed ? Expectations::closed : Expectations::cubature;
  }

  static QuasiLinearFilter create(const OptionValues& options, const Model&, long) {
    const std::optional<OptionProblem> problem = check(options);
    KUSHNER_REQUIRE(!problem, problem->message);
    QuasiLinearFilter f;
    f.expectations = resolve(options.word("qlf_expectations"));
    if (f.expectations == Expectations::cubature)
      f.rule = make_gauss_hermite_rule(static_cast<int>(options.integer("gh_nodes")));
    return f;
  }

  /// summary.json: the method used ("closed", "cubature") and, for cubature, the nodes per axis.
  Fields summary_fields() const {
    if (expectations == Expectations::closed) return {{"expectations", std::string("closed")}};
    return {{"expectations", std::string("cubature")}, {"gh_nodes", static_cast<long>(rule.order)}};
  }

  KOKKOS_INLINE_FUNCTION Status step(const Model& model, int, const StepInput<p>& in, Vec<n>& m, Mat<n, n>& P) const {
    return step_with<runtime_method>(model, in, m, P);
  }

  /// QLF with its method fixed at compile time (closed_method, cubature_method): the same step without the other
  /// method's branch, so that a loop over members in SIMD lanes (FilterBankStep::filter_lanes) vectorizes the
  /// closed form (cubature's loop over nodes would stop it).
  template <int Method>
  struct FixedMethod {
    QuasiLinearFilter filter;
    KOKKOS_INLINE_FUNCTION Status step(const Model& model, int, const StepInput<p>& in, Vec<n>& m, Mat<n, n>& P) const {
      return filter.template step_with<Method>(model, in, m, P);
    }
  };
  /// f(FixedMethod<the method of this run>{*this}).
  template <class F>
  void with_fixed_method(F&& f) const {
    if (expectations == Expectations::closed)
      f(FixedMethod<closed_method>{*this});
    else
      f(FixedMethod<cubature_method>{*this});
  }

  static constexpr int runtime_method = 0, closed_method = 1, cubature_method = 2;

  template <int Method>
  KOKKOS_INLINE_FUNCTION bool closed() const {
    if constexpr (Method == runtime_method)
      return expectations == Expectations::closed;
    else
      return Method == closed_method;
  }

  template <int Method>
  KOKKOS_INLINE_FUNCTION Status step_with(const Model& model, const StepInput<p>& in, Vec<n>& m, Mat<n, n>& P) const {
    static_assert(unsupported == nullptr, "QuasiLinearFilter: Model has no usable Gaussian expectations");
    ObservationLinearization<n, p> obs;
    // A run-time polynomial's type offers a linear observation, but its h may have terms of degree 2 and 3.
    if constexpr (ModelTraits<Model>::linear_observation && !ModelTraits<Model>::runtime_checked) {
      obs = observation_linearization(model, in.t, m);  // E_N[h] = h(m), E_N[grad h] = H exactly
    } else if (!expected_observation<Method>(model, in.t, m, P, obs)) {
      return Status::not_positive_definite;
    }
    Vec<p> weighted_innovation;
    if (!kalman_update(obs, in, m, P, weighted_innovation)) return Status::not_positive_definite;
    GaussianDrift<n> g;
    if (!expected_drift<Method>(model, in.t, m, P, g)) return Status::not_positive_definite;
    euler_predict(DriftLinearization<n>{g.mean, g.jacobian, noise_intensity(model.diffusion(in.t, m))}, in.dt, m, P);
    return Status::ok;
  }

  /// E_N[h], E_N[grad h] of a nonlinear observation: the model's closed form (seed 000 (5.9)-(5.10)) or cubature.
  template <int Method = runtime_method>
  KOKKOS_INLINE_FUNCTION bool expected_observation(const Model& model, double t, const Vec<n>& m, const Mat<n, n>& P,
                                                   ObservationLinearization<n, p>& obs) const {
    if constexpr (detail::has_gaussian_observation<Model>::value) {
      if (closed<Method>()) {
        const GaussianObservation<n, p> g = model.gaussian_observation(t, m, P);
        obs = ObservationLinearization<n, p>{g.mean, g.jacobian};
        return true;
      }
    }
    if constexpr (has_cubature) return cubature_observation(model, t, m, P, rule, obs);
    return false;  // unreachable: create() accepts only methods the model has
  }

  template <int Method = runtime_method>
  KOKKOS_INLINE_FUNCTION bool expected_drift(const Model& model, double t, const Vec<n>& m, const Mat<n, n>& P,
                                             GaussianDrift<n>& g) const {
    if constexpr (has_closed) {
      if (closed<Method>()) {
        g = closed_form_drift(model, t, m, P);
        return true;
      }
    }
    if constexpr (has_cubature) return cubature_drift(model, t, m, P, rule, g);
    return false;  // unreachable: create() accepts only methods the model has
  }
};

}  // namespace kushner
