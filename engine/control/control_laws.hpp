#pragma once
// The gain laws a controller can use, by name, and how each is made for a model and a cost on the run's grid:
// the one place a law name becomes a ControlLaw (the command line lists and checks names from law_list()).
//   NONE   no control: the plant left alone, the baseline;
//   LQR    the affine LQR of the model linearized at the origin (engine/control/gain_laws.hpp); for a
//          discrete-time model the discrete Riccati recursion (Clark's Riccati controller);
//   LQR-NOM  Clark's perturbation loop (discrete time): the Riccati controller of the deviations from the
//          noise-free optimal nominal path (engine/control/perturbation_loop.hpp); its nominal control goes to the
//          filters linearized along the same path (KF-NOM, MOM-NOM);
//   ASRE   Cimen & Banks' approximating sequence of Riccati equations on the nominal path (gain_laws.hpp);
//   POLY3  Basin's polynomial regulator along its nominal path, the two-point problem solved by the sweep and by
//          Newton (poly3_regulator.hpp);
//   HJB    the optimal feedback of the Hamilton-Jacobi-Bellman equation by Kushner's Markov chain approximation,
//          tabulated (hjb_markov_chain.hpp; dimension 1-2, one control); with `state` it is the reference law.
#include "core/errors.hpp"
#include "core/fields.hpp"
#include "engine/control/gain_laws.hpp"
#include "engine/control/hjb_markov_chain.hpp"
#include "engine/control/perturbation_loop.hpp"
#include "engine/control/poly3_regulator.hpp"
#include "engine/time_grid.hpp"
#include "kernels/control/control_law.hpp"
#include "models/model_traits.hpp"

#include <string>
#include <vector>

namespace kushner {

/// POLY3's Newton solve of the two-point problem runs up to this many steps (its dense Jacobian is O(steps^3)).
constexpr long max_poly3_exact_steps = 600;

struct LawInfo {
  std::string name, description;
};

inline std::vector<LawInfo> law_list() {
  return {{"NONE", "no control (u = 0): the uncontrolled plant, a baseline"},
          {"LQR", "linear-quadratic regulator of the model linearized at the origin, affine in the target"},
          {"LQR-NOM",
           "Clark's perturbation loop (discrete time): Riccati controller of the deviations from the noise-free "
           "optimal nominal path (seed 003 (3.4)-(3.12))"},
          {"ASRE", "Cimen-Banks approximating sequence of Riccati equations (seed 001 Th. 3), on the nominal path"},
          {"POLY3",
           "Basin's polynomial regulator of degree 3 (seed 002 (16)-(17)), two-point problem by sweep and "
           "Newton"},
          {"HJB", "optimal feedback of the HJB equation by Kushner's Markov chain approximation (dim 1-2, tabulated)"}};
}

/// POLY3 designs on a power polynomial of degree <= 3: the model's drift, or its design_polynomial (the car's
/// Taylor model).
template <class Model>
constexpr bool poly3_designable() {
  if constexpr (!ModelTraits<Model>::controlled || Model::discrete_time)
    return false;
  else if constexpr (detail::has_design_polynomial<Model>::value)
    return true;
  else
    return ModelTraits<Model>::power_polynomial && ModelTraits<Model>::power_degree() <= 3 &&
           !ModelTraits<Model>::runtime_checked;
}

/// HJB's chain: dimension 1 or 2, one control.
template <class Model>
constexpr bool hjb_solvable() {
  return !Model::discrete_time && Model::state_dim <= 2 && Model::control_dim == 1;
}

/// Why `law` cannot control Model, or nullptr.
template <class Model>
const char* law_unsupported(const std::string& law) {
  if (!ModelTraits<Model>::controlled) return "the model has no control input";
  if (law == "LQR-NOM" && !Model::discrete_time) return "Clark's perturbation loop is for discrete-time plants";
  if (Model::discrete_time && law != "NONE" && law != "LQR" && law != "LQR-NOM")
    return "discrete time: the Riccati controllers (LQR, LQR-NOM) and NONE only";
  if (law == "ASRE" && !ModelTraits<Model>::sdc) return "the model has no factorization f = A(x) x + b";
  if (law == "POLY3" && !poly3_designable<Model>()) return "the drift is not a polynomial of degree <= 3";
  if (law == "HJB" && !hjb_solvable<Model>()) return "the Markov chain approximation needs dimension 1-2, one control";
  return nullptr;
}

/// A law made for the device, and what its construction found (iterations, convergence) for summary.json.
template <class Model, class MemSpace>
struct MadeLaw {
  ControlLaw<Model::state_dim, Model::control_dim, MemSpace> law;
  Fields fields;
  std::vector<Vec<Model::control_dim>> nominal_control;  // LQR-NOM: u_bar, for the filters along its path
};

template <class Model, class MemSpace>
MadeLaw<Model, MemSpace> make_law(const std::string& name, const Model& model,
                                  const QuadraticCost<Model::state_dim, Model::control_dim>& cost,
                                  const TimeGrid& grid) {
  constexpr int n = Model::state_dim, m = Model::control_dim;
  KUSHNER_REQUIRE(law_unsupported<Model>(name) == nullptr,
                  "make_law: " << name << ": " << law_unsupported<Model>(name));
  MadeLaw<Model, MemSpace> made;
  if (name == "NONE") {
    made.fields = {{"law", std::string("none")}};
    return made;
  }
  if constexpr (ModelTraits<Model>::controlled && Model::discrete_time) {
    if (name == "LQR") {
      const auto solution = discrete_lqr_solution(model, cost, grid.steps);
      KUSHNER_INPUT_REQUIRE(solution.finite, "LQR: the Riccati recursion escapes to infinity over the horizon");
      made.law = affine_law<n, m, MemSpace>(solution.gains);
      made.fields = {{"law", std::string("LQR")},
                     {"form", std::string("discrete Riccati recursion (Clark 1971 (2.5)-(2.7))")},
                     {"linearized_at", std::string("origin")}};
      return made;
    }
    if (name == "LQR-NOM") {
      const PerturbationLoop<Model> loop = perturbation_loop(model, cost, grid.steps);
      KUSHNER_INPUT_REQUIRE(loop.finite, "LQR-NOM: the nominal path or its Riccati recursion escapes to infinity");
      KUSHNER_INPUT_REQUIRE(loop.converged, "LQR-NOM: the nominal path did not settle (change "
                                                << loop.last_change << " after " << loop.iterations
                                                << " linearizations)");
      made.law = affine_law<n, m, MemSpace>(loop.gains);
      made.nominal_control = loop.nominal.u;
      made.fields = {{"law", std::string("LQR-NOM")},
                     {"form", std::string("Riccati controller of the deviations (Clark 1971 (3.12))")},
                     {"nominal_J", loop.nominal.J},
                     {"nominal_x_T", loop.nominal.x.back()[0]},
                     {"nominal_iterations", static_cast<long>(loop.iterations)}};
      return made;
    }
  } else if constexpr (ModelTraits<Model>::controlled) {
    if (name == "LQR") {
      const auto solution = lqr_solution(model, cost, grid.steps, grid.dt, Vec<n>::zero());
      KUSHNER_INPUT_REQUIRE(solution.finite, "LQR: the Riccati equation escapes to infinity over [0, T]");
      made.law = affine_law<n, m, MemSpace>(solution.gains);
      made.fields = {{"law", std::string("LQR")}, {"linearized_at", std::string("origin")}};
      return made;
    }
    if constexpr (ModelTraits<Model>::sdc) {
      if (name == "ASRE") {
        const auto solution = asre_solution(model, cost, grid.steps, grid.dt);
        KUSHNER_INPUT_REQUIRE(solution.riccati.finite, "ASRE: a Riccati equation of the sequence escapes to infinity");
        made.law = affine_law<n, m, MemSpace>(solution.riccati.gains);
        made.fields = {{"law", std::string("ASRE")},
                       {"iterations", static_cast<long>(solution.iterations)},
                       {"converged", static_cast<long>(solution.converged)},
                       {"last_change", solution.last_change}};
        return made;
      }
    }
  }
  if constexpr (poly3_designable<Model>()) {
    if (name == "POLY3") {
      Poly3Options poly3;
      poly3.run_exact = grid.steps <= max_poly3_exact_steps;  // Newton's dense Jacobian: O(steps^3)
      const auto solution = poly3_regulator(model, cost, model.prior_mean, grid.steps, grid.dt, poly3);
      KUSHNER_INPUT_REQUIRE(solution.converged(), "POLY3: the two-point boundary problem was not solved: sweep: "
                                                      << solution.sweep.reason << "; exact: " << solution.exact.reason);
      made.law = affine_law<n, m, MemSpace>(solution.gains);
      made.fields = {
          {"law", std::string("POLY3")},
          {"reading", std::string(poly3_reading_name(poly3.reading))},
          {"sweep.converged", static_cast<long>(solution.sweep.converged)},
          {"sweep.iterations", static_cast<long>(solution.sweep.iterations)},
          {"sweep.reason", solution.sweep.reason},
          {"exact.converged", static_cast<long>(solution.exact.converged)},
          {"exact.iterations", static_cast<long>(solution.exact.iterations)},
          {"exact.reason", poly3.run_exact ? solution.exact.reason : std::string("not run: more than 600 steps")},
          {"nominal_J", solution.nominal.J}};
      return made;
    }
  }
  if constexpr (hjb_solvable<Model>()) {
    if (name == "HJB") {
      const HjbSolution<n> solution = hjb_markov_chain(model, cost, grid.steps * grid.dt);
      made.law = table_law<n, m, MemSpace>(solution.table, grid.dt);
      made.fields = {{"law", std::string("HJB")},
                     {"J_star", solution.J},
                     {"chain_dt", solution.dt},
                     {"u_bound", solution.u_bound},
                     {"bound_active_fraction", solution.bound_active_fraction}};
      return made;
    }
  }
  KUSHNER_REQUIRE(false, "make_law: unknown law " << name);
  return made;
}

}  // namespace kushner
