#pragma once
// The run behind `kushner control` for one model type (drivers/control_command.hpp), compiled in the command
// units; `kushner reproduce` runs its control examples through the same code (drivers/reproduce/): select and
// check the controllers, run the closed loops and the optimal-cost reference, write summary.json,
// timeseries.csv, the plots and report.md.
#include "core/eigen_helpers.hpp"
#include "drivers/commands.hpp"
#include "drivers/control_command.hpp"
#include "drivers/control_options.hpp"
#include "drivers/csv.hpp"
#include "drivers/fields_json.hpp"
#include "drivers/memory_check.hpp"
#include "drivers/name_lists.hpp"
#include "drivers/output_directory.hpp"
#include "drivers/plots.hpp"
#include "drivers/progress.hpp"
#include "drivers/run_model.hpp"
#include "engine/backend.hpp"
#include "engine/control/control_run.hpp"
#include "engine/control/cost_reference.hpp"
#include "kernels/filters/filter_list.hpp"
#include "models/parameters.hpp"
#include "models/registry.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

namespace kushner::control_detail {

/// The estimators a controller of Model can use: the state, the filters the model supports, the particle filter.
template <class Model>
std::vector<std::string> known_estimators(const Model& model) {
  std::vector<std::string> names = {state_estimator_name};
  for (const auto& f : supported_filters(model)) names.push_back(f);
  if (particle_filter_unsupported<Model>() == nullptr) names.push_back(particle_filter_name);
  return names;
}

/// --controllers as specs; one InputError line for an unknown law or estimator, a law the model cannot use, or a
/// controller named twice (drivers/name_lists.hpp).
template <class Model>
std::vector<ControllerSpec> select_controllers(const std::string& list, const Model& model) {
  ControllerTable table{Model::name, controller_aliases(), {}, known_estimators(model), {}};
  for (const LawInfo& law : law_list()) table.laws.push_back({law.name, law_unsupported<Model>(law.name)});
  for (const FilterSupport& f : filter_support(model)) table.bank.push_back({f.name, f.unsupported});
  std::vector<ControllerSpec> specs;
  for (const ControllerName& c : select_controller_names(list, table)) specs.push_back({c.name, c.law, c.estimator});
  return specs;
}

/// The cost's weights as a parameter set, so that --cost reads them as --set reads a model's.
template <int N, int M>
struct CostParameters {
  QuadraticCost<N, M>& cost;
  template <class Visitor>
  void parameters(Visitor&& v) {
    v("F", cost.F, "terminal weight");
    v("Q", cost.Q, "running state weight");
    v("R", cost.R, "control weight");
    v("target", cost.target, "target state x*");
    v("D", cost.D, "estimation-error weight: (x - x_hat)'D(x - x_hat) in the running cost (Clark 1971 (2.3))");
  }
};

/// --cost as a QuadraticCost (F = Q = I, R = I, x* = 0 unless given); InputError for an unknown key, a malformed
/// value, F or Q not positive semidefinite, R not positive definite.
template <class Model>
QuadraticCost<Model::state_dim, Model::control_dim> parse_cost(const std::vector<std::string>& assignments) {
  constexpr int n = Model::state_dim, m = Model::control_dim;
  QuadraticCost<n, m> cost;
  cost.F = Mat<n, n>::identity();
  cost.Q = Mat<n, n>::identity();
  cost.R = Mat<m, m>::identity();
  CostParameters<n, m> parameters{cost};
  for (const std::string& assignment : assignments) {
    const auto [key, text] = split_assignment(assignment);
    ParameterSetter setter(key, text, "--cost");
    parameters.parameters(setter);
    KUSHNER_INPUT_REQUIRE(setter.found(), "--cost " << key << ": unknown weight (known: F, Q, R, target, D)");
  }
  check_covariance("--cost F", cost.F, /*allow_singular=*/true);
  check_covariance("--cost Q", cost.Q, /*allow_singular=*/true);
  check_covariance("--cost R", cost.R, /*allow_singular=*/false);
  check_covariance("--cost D", cost.D, /*allow_singular=*/true);
  return cost;
}

template <int N, int M>
nlohmann::json cost_json(QuadraticCost<N, M> cost) {
  ParameterRecorder recorder;
  CostParameters<N, M>{cost}.parameters(recorder);
  return recorder.values();
}

struct MeanSe {
  double mean = std::nan(""), se = std::nan("");
  long count = 0;
};

/// Mean and standard error over the members where `value(i)` is finite.
template <class Value>
MeanSe mean_se(std::size_t members, Value&& value) {
  double sum = 0.0, sum2 = 0.0;
  MeanSe r;
  for (std::size_t i = 0; i < members; ++i) {
    const double v = value(i);
    if (!std::isfinite(v)) continue;
    sum += v, sum2 += v * v, ++r.count;
  }
  if (r.count == 0) return r;
  r.mean = sum / r.count;
  r.se = r.count > 1 ? std::sqrt(std::max(0.0, sum2 / r.count - r.mean * r.mean) / (r.count - 1)) : std::nan("");
  return r;
}

/// Every controller's entry of summary.json. J_gap is J - J* against the reference where there is one (its SE
/// the controller's: J* is a number), else the paired difference to the best controller, member by member.
/// estimation_error: the time average of |x - x_hat|^2 over the horizon, x_hat the estimate the law reads.
inline nlohmann::json controllers_json(const ControlReport& report, const std::optional<CostReference>& reference,
                                       double horizon, std::string& best) {
  const auto& runs = report.controllers;
  std::size_t best_index = 0;
  std::vector<MeanSe> J(runs.size());
  for (std::size_t c = 0; c < runs.size(); ++c) {
    J[c] = mean_se(runs[c].cost.size(), [&](std::size_t i) { return runs[c].cost[i]; });
    if (std::isfinite(J[c].mean) && (!std::isfinite(J[best_index].mean) || J[c].mean < J[best_index].mean))
      best_index = c;
  }
  best = runs[best_index].spec.name;
  nlohmann::json all = nlohmann::json::object();
  for (std::size_t c = 0; c < runs.size(); ++c) {
    const ControllerRun& run = runs[c];
    // Paired with the best controller, member by member, over the members both kept finite.
    MeanSe gap = mean_se(run.cost.size(), [&](std::size_t i) { return run.cost[i] - runs[best_index].cost[i]; });
    if (reference) gap = MeanSe{J[c].mean - reference->J, J[c].se, J[c].count};
    const MeanSe energy = mean_se(run.control_energy.size(), [&](std::size_t i) {
      return std::isfinite(run.cost[i]) ? run.control_energy[i] : std::nan("");
    });
    const MeanSe squared_error = mean_se(run.squared_error.size(), [&](std::size_t i) {
      return std::isfinite(run.cost[i]) ? run.squared_error[i] / horizon : std::nan("");
    });
    nlohmann::json j = {{"law", run.spec.law},
                        {"estimator", run.spec.estimator},
                        {"J", J[c].mean},
                        {"J_se", J[c].se},
                        {"J_gap", gap.mean},
                        {"J_gap_se", gap.se},
                        {"gap_to", reference ? "reference" : best},
                        {"members_scored", J[c].count},
                        {"control_energy", energy.mean},
                        {"control_energy_se", energy.se},
                        {"estimation_error", squared_error.mean},
                        {"estimation_error_se", squared_error.se},
                        {"terminal_mean", run.terminal_mean},
                        {"truths_escaped", run.truths_escaped},
                        {"diverged", run.truths_escaped + run.estimator_diverged},
                        {"estimator_diverged", run.estimator_diverged},
                        {"law_details", fields_json(run.law_fields)}};
    if (!run.estimator_fields.empty()) j["estimator_details"] = fields_json(run.estimator_fields);
    all[run.spec.name] = j;
  }
  return all;
}

inline std::string control_timeseries_csv(const ControlReport& report, const RunContext& context, int n, int m) {
  std::string csv = csv_comment(context) + "t,controller,running_cost_mean";
  for (int i = 0; i < n; ++i) csv += ",state_mean_" + std::to_string(i);
  for (int j = 0; j < m; ++j) csv += ",control_mean_" + std::to_string(j);
  for (int i = 0; i < n; ++i) csv += ",member_state_" + std::to_string(i);
  for (int i = 0; i < n; ++i) csv += ",member_estimate_" + std::to_string(i);
  for (int j = 0; j < m; ++j) csv += ",member_control_" + std::to_string(j);
  csv += "\n";
  for (const ControllerRun& run : report.controllers)
    for (std::size_t r = 0; r < report.times.size(); ++r) {
      csv += format_number(report.times[r]) + "," + run.spec.name + "," + format_number(run.running_cost_mean[r]);
      for (const auto* row : {&run.state_mean[r], &run.control_mean[r], &run.member_state[r], &run.member_estimate[r],
                              &run.member_control[r]})
        for (double v : *row) csv += "," + format_number(v);
      csv += "\n";
    }
  return csv;
}

inline void print_summary(const nlohmann::json& summary, const std::string& out) {
  const bool referenced = summary.contains("reference");
  if (referenced)
    std::printf("reference J* = %.6g (%s, discretization error <= %.2g)\n", summary["reference"]["J"].get<double>(),
                summary["reference"]["kind"].get<std::string>().c_str(), summary["reference"]["error"].get<double>());
  std::printf("%-16s %24s %24s %12s %9s\n", "controller", "J", referenced ? "J - J*" : "J - best (paired)", "energy",
              "diverged");
  for (const auto& name : summary["controller_order"]) {
    const nlohmann::json& c = summary["controllers"][name.get<std::string>()];
    auto number = [&](const char* key) { return c[key].is_number() ? c[key].get<double>() : std::nan(""); };
    std::printf("%-16s %11.5g +- %-9.2g %11.4g +- %-9.2g %12.4g %9ld\n", name.get<std::string>().c_str(), number("J"),
                number("J_se"), number("J_gap"), number("J_gap_se"), number("control_energy"),
                c["diverged"].get<long>());
  }
  if (summary.contains("plots_error"))
    std::fprintf(stderr, "kushner: warning: %s\n", summary["plots_error"].get<std::string>().c_str());
  if (summary.contains("timing")) print_timing(summary["timing"]);
  std::printf("written to %s/\n", out.c_str());
}

/// run_control_model for a model with a control input.
template <class Model>
nlohmann::json run_controlled_model(const Model& model, const ControlOptions& options, const OptionValues& settings,
                                    const TimeGrid& grid, const RunContext& context, bool own_kokkos) {
  constexpr int n = Model::state_dim, m = Model::control_dim;
  // Everything is checked before the output directory is opened.
  const std::vector<ControllerSpec> specs = select_controllers(options.controllers, model);
  const QuadraticCost<n, m> cost = parse_cost<Model>(options.cost);
  KUSHNER_INPUT_REQUIRE(
      !Model::discrete_time || options.reference == "auto" || options.reference == "none",
      "--reference " << options.reference << ": no reference solver for discrete-time models (use none)");
  KUSHNER_INPUT_REQUIRE(!cost.weighs_estimation() || options.reference == "auto" || options.reference == "none",
                        "--reference " << options.reference << ": the reference solvers' cost has no estimation-error "
                                       << "term (D = 0 only; use --reference none)");
  if (options.reference == "direct")
    KUSHNER_INPUT_REQUIRE(deterministic_problem(model),
                          "--reference direct: the problem is stochastic (process noise "
                          "or a random start); the direct method needs a deterministic one");
  if (options.reference == "hjb")
    KUSHNER_INPUT_REQUIRE(hjb_solvable<Model>(),
                          "--reference hjb: model '" << Model::name << "' is not of dimension 1-2 with one control");
  const ParticleSettings particle = particle_settings(options);
  KUSHNER_INPUT_REQUIRE(particle.options.precision != ParticlePrecision::fp32,
                        "--precision fp32: not available in control (its particle filter stores particles in fp64; "
                        "use fp64 or mixed)");
  KUSHNER_INPUT_REQUIRE(particle.step_pairs != StepPairs::always,
                        "--step-pairs always: a closed loop's particle filter takes one step at a time (each control "
                        "needs the step before)");
  KUSHNER_INPUT_REQUIRE(
      options.trace_member >= 0 && options.trace_member < options.run.members,
      "--trace-member: member " << options.trace_member << " is not in 0 .. " << options.run.members - 1);
  const bool uses_particles = std::any_of(specs.begin(), specs.end(),
                                          [](const ControllerSpec& s) { return s.estimator == particle_filter_name; });
  if (uses_particles) {
    const long long items = static_cast<long long>(options.run.members) * particle.particles;
    KUSHNER_INPUT_REQUIRE(items <= std::numeric_limits<std::int32_t>::max(),
                          "--particles: --members x --particles must be at most "
                              << std::numeric_limits<std::int32_t>::max() << " (got " << items << ")");
  }
  // One loop at a time: its truths, controls and totals, its filter and the particle filter when it has one.
  using Particles = ParticleFilterBank<Kokkos::DefaultHostExecutionSpace, Model>;
  const double per_member = FilterBank<Kokkos::DefaultHostExecutionSpace, Model>::bytes_per_member(1) +
                            sizeof(double) * (m + num_loop_columns);
  double total = options.run.members * per_member;
  std::ostringstream sizes, breakdown;
  sizes << "--members " << options.run.members;
  breakdown << "closed loop " << format_bytes(per_member) << " per member";
  if (uses_particles) {
    total += Particles::bytes_needed(options.run.members, particle.particles, particle.options);
    sizes << ", --particles " << particle.particles;
    breakdown << ", particle filter " << format_bytes(Particles::bytes_per_particle(particle.options))
              << " per particle";
  }
  require_memory_fits(total, sizes.str(), breakdown.str(), selected_backend());

  const OutputDirectory out(options.run.out, "--out");
  std::optional<KokkosSession> kokkos;
  if (own_kokkos) kokkos.emplace(context.backend);
  nlohmann::json summary;
  with_backend(context.backend, [&](const auto& space) {
    Progress progress("control", control_progress_steps<Model>(specs, grid), !options.run.quiet);
    const ControlReport report = run_control(
        space, model, options.run.members, static_cast<std::uint32_t>(options.run.seed), grid, specs, cost, settings,
        particle, [&](long done) { progress.update(done); }, options.trace_member);
    const std::optional<CostReference> reference = cost_reference(model, cost, grid, options.reference);
    summary = run_metadata(context);
    summary["command_kind"] = "control";
    if (reference) {
      summary["reference"] = fields_json(reference->fields);
      summary["reference"]["kind"] = reference->kind;
      summary["reference"]["J"] = reference->J;
      summary["reference"]["error"] = reference->error;
    }
    summary["model"] = model_summary(model);
    summary["members"] = options.run.members;
    summary["T"] = options.run.T;
    summary["dt"] = options.run.dt;
    summary["steps"] = grid.steps;
    summary["cost"] = cost_json(cost);
    summary["cost"]["form"] = Model::discrete_time ? "J = (x[N]-x*)'F(x[N]-x*) + sum_{k<N} (x-x*)'Q(x-x*) + u'Ru + "
                                                     "(x-x_hat)'D(x-x_hat)"
                                                   : "J = (x(T)-x*)'F(x(T)-x*) + int_0^T (x-x*)'Q(x-x*) + u'Ru + "
                                                     "(x-x_hat)'D(x-x_hat) dt";
    std::string best;
    summary["controllers"] = controllers_json(report, reference, grid.steps * grid.dt, best);
    summary["best"] = best;
    std::vector<std::string> order;
    for (const auto& spec : specs) order.push_back(spec.name);
    summary["controller_order"] = order;
    summary["trace_member"] = options.trace_member;
    summary["common_random_numbers"] = true;
    summary["files"] = {"summary.json", "timeseries.csv"};
    double loop_seconds = 0.0, particle_steps = 0.0;
    for (const auto& run : report.controllers) {
      loop_seconds += run.step_loop_seconds;
      if (run.spec.estimator == particle_filter_name)
        particle_steps += static_cast<double>(options.run.members) * grid.steps * particle.particles;
    }
    summary["timing"] =
        timing_json(loop_seconds, static_cast<double>(options.run.members) * grid.steps * report.controllers.size(),
                    particle_steps);
    out.write_all(
        {{"timeseries.csv", control_timeseries_csv(report, context, n, m)}, {"summary.json", summary.dump(2) + "\n"}});
  });
  if (options.plots) {
    const PlotResult plots =
        write_plots_and_report(out, "control_plots.py", {"control_paths", "running_cost", "ranking"});
    summary["plots"] = plots.ok;
    for (const auto& file : plots.files) summary["files"].push_back(file);
    if (!plots.ok) summary["plots_error"] = plots.message;
    summary["timing"]["command_s"] = command_seconds();  // the plots included
    out.write("summary.json", summary.dump(2) + "\n");
  }
  if (!options.run.quiet) print_summary(summary, options.run.out);
  return summary;
}

}  // namespace kushner::control_detail

namespace kushner {

template <class Model>
nlohmann::json run_control_model(const Model& model, const ControlOptions& options, const OptionValues& settings,
                                 const TimeGrid& grid, const RunContext& context, bool own_kokkos) {
  if constexpr (!ModelTraits<Model>::controlled) {
    throw InputError(std::string("--model: '") + Model::name +
                     "' has no control input (controlled models: linear, sine, cubic-oscillator, car, car-taylor3, "
                     "clark-linear, clark-quintic, linear-discrete, and a --model-file with a [control] table)");
  } else {
    if constexpr (is_polynomial_model<Model>::value) {
      bool has_input = false;
      for (int i = 0; i < Model::state_dim; ++i) has_input = has_input || model.B(i, 0) != 0.0;
      KUSHNER_INPUT_REQUIRE(has_input, "--model-file " << options.run.model_file
                                                       << ": no control input (add a [control] table with B, the "
                                                          "input's column, e.g. B = [0.0, 1.0])");
    }
    return control_detail::run_controlled_model(model, options, settings, grid, context, own_kokkos);
  }
}

}  // namespace kushner
