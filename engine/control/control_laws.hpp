#pragma once
// The gain laws a controller can use, by name, and how each is made for a model and a cost on the run's grid:
// the one place a law name becomes a ControlLaw (the command line lists and checks names from law_list()).
//   NONE   no control: the plant left alone, the baseline;
//   LQR    the affine LQR of the model linearized at the origin (engine/control/gain_laws.hpp);
//   ASRE   Cimen & Banks' approximating sequence of Riccati equations on the nominal path (gain_laws.hpp).
#include "core/errors.hpp"
#include "core/fields.hpp"
#include "engine/control/gain_laws.hpp"
#include "engine/time_grid.hpp"
#include "kernels/control/control_law.hpp"
#include "models/model_traits.hpp"

#include <string>
#include <vector>

namespace kushner {

struct LawInfo {
  std::string name, description;
};

inline std::vector<LawInfo> law_list() {
  return {{"NONE", "no control (u = 0): the uncontrolled plant, a baseline"},
          {"LQR", "linear-quadratic regulator of the model linearized at the origin, affine in the target"},
          {"ASRE", "Cimen-Banks approximating sequence of Riccati equations (seed 001 Th. 3), on the nominal path"}};
}

/// Why `law` cannot control Model, or nullptr.
template <class Model>
const char* law_unsupported(const std::string& law) {
  if (!ModelTraits<Model>::controlled) return "the model has no control input";
  if (law == "ASRE" && !ModelTraits<Model>::sdc) return "the model has no factorization f = A(x) x + b";
  return nullptr;
}

/// A law made for the device, and what its construction found (iterations, convergence) for summary.json.
template <class Model, class MemSpace>
struct MadeLaw {
  ControlLaw<Model::state_dim, Model::control_dim, MemSpace> law;
  Fields fields;
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
  if constexpr (ModelTraits<Model>::controlled) {
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
  KUSHNER_REQUIRE(false, "make_law: unknown law " << name);
  return made;
}

}  // namespace kushner
