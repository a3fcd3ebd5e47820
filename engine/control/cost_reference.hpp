#pragma once
// A reference for the optimal cost J*, as the particle filter is for filtering (issue 14 part 4): controllers are
// scored by their gap J - J*.
//   direct  a deterministic problem (no process noise, a fixed start): the open-loop optimum of the loop's own
//           Euler scheme by the adjoint gradient and L-BFGS (direct_optimum.hpp), exact to its gradient tolerance;
//   hjb     a fully observed stochastic problem of dimension 1-2 with one control: E V(0, x0) by Kushner's Markov
//           chain approximation on two grids, h and h/2, extrapolated (Richardson, first-order scheme:
//           2 J(h/2) - J(h)); `error` is |J(h/2) - J(h)|, a bound on what the extrapolation leaves.
// Neither knows the estimator: J* is the full-information optimum, which no controller can beat in expectation.
#include "core/fields.hpp"
#include "engine/control/control_laws.hpp"
#include "engine/control/direct_optimum.hpp"
#include "engine/control/hjb_markov_chain.hpp"
#include "engine/time_grid.hpp"

#include <cmath>
#include <optional>
#include <string>

namespace kushner {

struct CostReference {
  std::string kind;  // "direct" or "hjb"
  double J = 0.0;
  double error = 0.0;  // what the reference's own discretization may leave
  Fields fields;
};

/// Whether the model's truths are deterministic: no process noise at the start's mean and a fixed start.
template <class Model>
bool deterministic_problem(const Model& model) {
  if constexpr (Model::discrete_time) {
    return false;  // the discrete-time models have noise of their own law (no direct solver for them)
  } else {
    const auto G = model.diffusion(0.0, model.x0_mean);
    for (int i = 0; i < Model::state_dim; ++i) {
      for (int j = 0; j < Model::noise_dim; ++j)
        if (G(i, j) != 0.0) return false;
      for (int j = 0; j < Model::state_dim; ++j)
        if (model.x0_cov(i, j) != 0.0) return false;
    }
    return true;
  }
}

/// The reference `kind` asks for ("auto": direct for a deterministic problem, else hjb where it applies; "none"),
/// or nullopt where none applies. InputError for a kind the model cannot have.
template <class Model>
std::optional<CostReference> cost_reference(const Model& model,
                                            const QuadraticCost<Model::state_dim, Model::control_dim>& cost,
                                            const TimeGrid& grid, const std::string& kind) {
  constexpr int n = Model::state_dim;
  const bool deterministic = deterministic_problem(model);
  const bool estimation_weight = cost.weighs_estimation();
  KUSHNER_INPUT_REQUIRE(!estimation_weight || kind == "auto" || kind == "none",
                        "--reference " << kind << ": the reference solvers' cost has no estimation-error term (D = 0 "
                                       << "only; use --reference none)");
  if (estimation_weight || (Model::discrete_time && kind == "auto")) return std::nullopt;
  KUSHNER_INPUT_REQUIRE(!Model::discrete_time || kind == "none",
                        "--reference " << kind << ": no reference solver for discrete-time models (use none)");
  std::string chosen = kind;
  if (kind == "auto") chosen = deterministic ? "direct" : hjb_solvable<Model>() ? "hjb" : "none";
  if (chosen == "none") return std::nullopt;
  if constexpr (!Model::discrete_time) {
    if (chosen == "direct") {
      KUSHNER_INPUT_REQUIRE(deterministic,
                            "--reference direct: the problem is stochastic (process noise or a random "
                            "start); the direct method needs a deterministic one");
      const auto optimum = direct_optimum(model, cost, model.x0_mean, grid.steps, grid.dt);
      return CostReference{"direct",
                           optimum.J,
                           0.0,
                           {{"iterations", static_cast<long>(optimum.iterations)},
                            {"gradient_norm", optimum.gradient_norm},
                            {"converged", static_cast<long>(optimum.converged)},
                            {"reason", optimum.reason}}};
    }
  }
  KUSHNER_INPUT_REQUIRE(chosen == "hjb", "--reference: unknown kind '" << kind << "' (auto, hjb, direct, none)");
  if constexpr (hjb_solvable<Model>()) {
    const double T = grid.steps * grid.dt;
    HjbOptions<n> coarse, fine;
    coarse.points.fill(n == 1 ? 201 : 41);
    fine.points.fill(n == 1 ? 401 : 81);
    const HjbSolution<n> a = hjb_markov_chain(model, cost, T, coarse);
    const HjbSolution<n> b = hjb_markov_chain(model, cost, T, fine);
    return CostReference{"hjb",
                         2.0 * b.J - a.J,
                         std::fabs(b.J - a.J),
                         {{"J_coarse", a.J},
                          {"J_fine", b.J},
                          {"points_coarse", static_cast<long>(coarse.points[0])},
                          {"points_fine", static_cast<long>(fine.points[0])},
                          {"bound_active_fraction", b.bound_active_fraction}}};
  }
  throw InputError(std::string("--reference hjb: model '") + Model::name +
                   "' is not of dimension 1-2 with one control");
}

}  // namespace kushner
