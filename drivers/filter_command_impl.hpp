#pragma once
// The run behind `kushner filter` and `kushner compare` for one model type (instantiated per model in the
// filter_command_*.cpp files): select and check the filters, run the bank with the particle and exact
// references beside it, write summary.json and timeseries.csv, and for compare the chosen members'
// trajectories, the density snapshots, the plots and report.md.
#include "core/collectives.hpp"
#include "drivers/checkpoint_file.hpp"
#include "drivers/csv.hpp"
#include "drivers/fields_json.hpp"
#include "drivers/filter_command.hpp"
#include "drivers/filter_selection.hpp"
#include "drivers/memory_check.hpp"
#include "drivers/output_directory.hpp"
#include "drivers/plots.hpp"
#include "drivers/progress.hpp"
#include "drivers/run_model.hpp"
#include "drivers/trajectory_recorder.hpp"
#include "engine/backend.hpp"
#include "engine/filter_run.hpp"
#include "engine/version.hpp"
#include "models/parameters.hpp"

#include <algorithm>
#include <cstdint>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <type_traits>

namespace kushner {

namespace detail {

inline std::string filter_timeseries_csv(const FilterReport& report, const RunContext& context) {
  std::string csv = csv_comment(context) + "t,filter,rmse_truth,rmse_truth_se,nees,nees_se,diverged";
  csv += report.has_reference ? ",rmse_ref,rmse_ref_se\n" : "\n";
  for (std::size_t r = 0; r < report.times.size(); ++r)
    for (std::size_t f = 0; f < report.filters.size(); ++f) {
      const FilterSnapshot& s = report.series[r][f];
      csv += format_number(report.times[r]) + "," + report.filters[f] + "," + format_number(s.rmse_truth) + "," +
             format_number(s.rmse_truth_se) + "," + format_number(s.nees) + "," + format_number(s.nees_se) + "," +
             std::to_string(s.diverged);
      csv += report.has_reference ? "," + format_number(s.rmse_ref) + "," + format_number(s.rmse_ref_se) + "\n" : "\n";
    }
  return csv;
}

inline nlohmann::json filter_summary(const FilterReport& report) {
  nlohmann::json filters = nlohmann::json::object();
  for (std::size_t f = 0; f < report.filters.size(); ++f) {
    const FilterScores& s = report.scores[f];
    nlohmann::json j = {{"rmse_truth", s.rmse_truth.value},
                        {"rmse_truth_se", s.rmse_truth.standard_error},
                        {"nees", s.nees.value},
                        {"nees_se", s.nees.standard_error},
                        {"nees_members", s.nees.members},
                        {"diverged", s.diverged},
                        {"diverged_not_positive_definite", s.not_positive_definite},
                        {"diverged_non_finite", s.non_finite},
                        {"members_scored", s.rmse_truth.members}};
    if (report.has_reference && report.filters[f] != report.reference) {
      j["rmse_ref"] = s.rmse_ref.value;
      j["rmse_ref_se"] = s.rmse_ref.standard_error;
    }
    const auto estimator = report.estimators.find(report.filters[f]);
    if (estimator != report.estimators.end()) j["estimator"] = fields_json(estimator->second);
    const auto own = report.filter_fields.find(report.filters[f]);
    if (own != report.filter_fields.end()) add_fields(j, own->second);
    filters[report.filters[f]] = j;
  }
  return filters;
}

/// What the run's banks allocate (the recorder's small arrays aside): per member the filter bank with its
/// filters' own state (EnKBF's ensembles, ASRE's iterates) and the exact filter (a grid's masses), per
/// particle the particle filter.
struct RunMemory {
  double bank_bytes_per_member = 0.0, particle_bytes_per_particle = 0.0, total_bytes = 0.0;
};
/// Whether the particle filter of `particle` fuses its step pairs on the selected backend (by its type: the
/// options are checked before Kokkos starts).
template <class Model>
bool particle_fuses_step_pairs(const ParticleSettings& particle) {
  bool fuses = false;
  with_backend_type(selected_backend(), [&](auto* tag) {
    using ExecSpace = std::remove_pointer_t<decltype(tag)>;
    fuses = ParticleFilterBank<ExecSpace, Model>::fuses_step_pairs(particle.options, particle.particles);
  });
  return fuses;
}

template <class Model>
RunMemory run_memory(const CompareOptions& options, const std::vector<std::string>& filters,
                     const OptionValues& settings, const ParticleSettings& particle) {
  using Bank = FilterBank<Kokkos::DefaultHostExecutionSpace, Model>;
  using Particles = ParticleFilterBank<Kokkos::DefaultHostExecutionSpace, Model>;
  RunMemory memory;
  memory.bank_bytes_per_member =
      Bank::bytes_per_member(static_cast<long>(filters.size())) + Bank::own_bytes_per_member(filters, settings);
  if constexpr (has_exact_reference<Model>)
    if (std::find(filters.begin(), filters.end(), exact_filter_name) != filters.end())
      memory.bank_bytes_per_member +=
          ExactReferenceEstimator<Kokkos::DefaultHostExecutionSpace, Model>::bytes_per_member();
  const bool particle_filter = std::find(filters.begin(), filters.end(), particle_filter_name) != filters.end();
  const bool fuses = particle_filter && particle_fuses_step_pairs<Model>(particle);
  const bool pairs = particle_filter && takes_step_pairs(particle.step_pairs, fuses);
  if (pairs) memory.bank_bytes_per_member += Bank::step_pair_bytes_per_member(static_cast<long>(filters.size()));
  memory.total_bytes = static_cast<double>(options.run.members) * memory.bank_bytes_per_member;
  if (particle_filter) {
    memory.particle_bytes_per_particle = Particles::bytes_per_particle(particle.options);
    memory.total_bytes += Particles::bytes_needed(options.run.members, particle.particles, particle.options);
  }
  if (pairs && fuses) {
    memory.particle_bytes_per_particle += Particles::step_pair_bytes_per_particle(particle.options);
    memory.total_bytes += Particles::step_pair_bytes_needed(options.run.members, particle.particles, particle.options);
  }
  return memory;
}

/// The run's particle settings: the options', with step pairs off where `auto` would fuse them but the second
/// particle bank does not fit (the run then needs what it needed before pairs existed) on some MPI rank (so that
/// every rank takes the same steps and reports the same).
template <class Model>
ParticleSettings run_particle_settings(const CompareOptions& options, const std::vector<std::string>& filters,
                                       const OptionValues& settings) {
  ParticleSettings particle = particle_settings(options);
  if (particle.step_pairs == StepPairs::automatic &&
      collective::any(
          !memory_fits(run_memory<Model>(options, filters, settings, particle).total_bytes, selected_backend())))
    particle.step_pairs = StepPairs::never;
  return particle;
}

inline nlohmann::json memory_json(const RunMemory& memory) {
  return {{"bank_bytes_per_member", memory.bank_bytes_per_member},
          {"particle_bytes_per_particle", memory.particle_bytes_per_particle},
          {"total_bytes", memory.total_bytes}};
}

}  // namespace detail

template <class Model>
std::vector<std::string> check_compare_options(const Model& model, const CompareOptions& options,
                                               const OptionValues& settings) {
  const std::vector<std::string> filters = select_estimators<Model>(options.filters, model);
  const std::optional<OptionProblem> problem = filter_option_problem<Model>(filters, settings);
  KUSHNER_INPUT_REQUIRE(!problem, option_flag(problem->option) << ": " << problem->message);
  if constexpr (has_exact_reference<Model>) {
    using Grid = GridFilter<Kokkos::DefaultHostExecutionSpace, Model>;
    if (std::is_same_v<exact_reference_t<Kokkos::DefaultHostExecutionSpace, Model>, Grid> &&
        std::find(filters.begin(), filters.end(), exact_filter_name) != filters.end())
      check_covariance("filter EXACT (grid filter): prior_cov", model.prior_cov, /*allow_singular=*/false);
  }
  const ParticleSettings particle = detail::run_particle_settings<Model>(options, filters, settings);
  if (std::find(filters.begin(), filters.end(), particle_filter_name) != filters.end()) {
    // The particle kernels index (particle block, member) and their teams with int.
    const long long items = static_cast<long long>(options.run.members) * particle.particles;
    KUSHNER_INPUT_REQUIRE(items <= std::numeric_limits<std::int32_t>::max(),
                          "--particles: --members x --particles must be at most "
                              << std::numeric_limits<std::int32_t>::max() << ", the particle filter's index range (got "
                              << options.run.members << " x " << particle.particles << " = " << items << ")");
  }
  const detail::RunMemory memory = detail::run_memory<Model>(options, filters, settings, particle);
  std::ostringstream sizes, breakdown;
  sizes << "--members " << options.run.members;
  breakdown << "filter bank " << format_bytes(memory.bank_bytes_per_member) << " per member";
  if (memory.particle_bytes_per_particle > 0.0) {
    sizes << ", --particles " << particle.particles;
    breakdown << ", particle filter " << format_bytes(memory.particle_bytes_per_particle) << " per particle";
  }
  require_memory_fits(memory.total_bytes, sizes.str(), breakdown.str(), selected_backend());
  for (long m : options.trajectory_members)
    KUSHNER_INPUT_REQUIRE(m >= 0 && m < options.run.members,
                          "--trajectory-members: member " << m << " is not in 0 .. " << options.run.members - 1);
  for (double t : options.density_times)
    KUSHNER_INPUT_REQUIRE(t >= 0.0 && t <= options.run.T,
                          "--density-times: " << t << " is not in [0, T = " << options.run.T << "]");
  return filters;
}

/// Draws the plots and report.md from what `out` holds (summary.json first) and records in `summary` what they
/// wrote (or why not); rewrites summary.json.
inline void add_plots(const OutputDirectory& out, nlohmann::json& summary) {
  const PlotResult plots = write_plots_and_report(out);
  summary["plots"] = plots.ok;
  for (const auto& file : plots.files) summary["files"].push_back(file);               // report.md even without figures
  if (summary.contains("timing")) summary["timing"]["command_s"] = command_seconds();  // the plots included
  if (!plots.ok) summary["plots_error"] = plots.message;
  out.write("summary.json", summary.dump(2) + "\n");
}

namespace detail {

/// Everything a checkpoint's state depends on besides the code: a state saved by a run with other values (a
/// model file or --config file changed before `kushner resume`) is refused.
template <class Model>
std::string run_identity(const Model& model, const CompareOptions& options, const std::vector<std::string>& filters,
                         const ParticleSettings& particle, const std::vector<double>& density_times,
                         const TimeGrid& grid) {
  return nlohmann::json{{"model", model_summary(model)},
                        {"members", options.run.members},
                        {"seed", options.run.seed},
                        {"dt", grid.dt},
                        {"steps", grid.steps},
                        {"output_steps", grid.output_steps},
                        {"filters", filters},
                        {"settings", options.filter_settings},
                        {"particles", particle.particles},
                        {"resample", options.resample},
                        {"ess_threshold", options.ess_threshold},
                        {"precision", options.precision},
                        {"trajectory_members", options.trajectory_members},
                        {"density_times", density_times}}
      .dump();
}

}  // namespace detail

/// No estimators beside the bank other than those named in --filters.
struct NoExtraEstimators {
  template <class ExecSpace>
  ExtraEstimators<ExecSpace> operator()(const ExecSpace&) const {
    return {};
  }
};

/// run_compare_command with the truths following `truth_model` (same dimensions as `model`, e.g. the system a
/// Taylor model approximates, or `model` with other parameters such as sine_observation_noise) and the estimators
/// that make_extras(space) returns run beside the bank (run_filters). summary.json then also records the truths'
/// model under "truth" where it is not `model`. With options.checkpoints the run saves checkpoints into `out` (on
/// SIGINT/SIGTERM, and every options.checkpoint_every seconds when given), continues from `resume` when given, and
/// removes its checkpoint once its results are written.
template <class Model, class TruthModel, class MakeExtras = NoExtraEstimators>
nlohmann::json run_compare_with_truth(const TruthModel& truth_model, const Model& model, const CompareOptions& options,
                                      const OptionValues& settings, const TimeGrid& grid, const RunContext& context,
                                      const OutputDirectory& out, const MakeExtras& make_extras = {},
                                      const Checkpoint* resume = nullptr) {
  const std::vector<std::string> filters = check_compare_options<Model>(model, options, settings);
  const ParticleSettings particle = detail::run_particle_settings<Model>(options, filters, settings);
  std::vector<double> density_times = options.density_times;
  if (density_times.empty() && options.plots) density_times = {0.1 * options.run.T, 0.5 * options.run.T, options.run.T};
  nlohmann::json summary;
  with_backend(context.backend, [&](const auto& space) {
    using ExecSpace = std::decay_t<decltype(space)>;
    TrajectoryRecorder<ExecSpace, Model> recorder(options.trajectory_members, options.run.members, density_times);
    Progress progress(options.plots ? "compare" : "filter", progress_steps<Model>(filters, grid), !options.run.quiet);
    OutputObserver<ExecSpace, Model, TruthModel> observer;
    if (!options.trajectory_members.empty())
      observer = {std::ref(recorder), [&](const auto& bank) { return recorder.elements(bank); }};
    RunCheckpointing checkpointing;
    const std::string identity =
        options.checkpoints ? detail::run_identity(model, options, filters, particle, density_times, grid) : "";
    if (options.checkpoints) {
      checkpointing.every_seconds = options.checkpoint_every_given ? options.checkpoint_every : -1.0;
      checkpointing.resume = resume ? &resume->state : nullptr;
      checkpointing.resume_hint = ": continue with: kushner resume " + out.path().string();
      checkpointing.visit_caller_state = [&](StateArchive& archive) {
        archive.require_equal("run", identity, "model or option set");
        recorder.visit_state(archive);
      };
      const std::string working_directory = std::filesystem::current_path().string();
      checkpointing.write = [&, working_directory](const std::string& state, long step, long steps) {
        write_checkpoint(out, Checkpoint{version_string(), working_directory, context.arguments, step, steps, state});
      };
      catch_stop_signals();
    }
    const FilterReport report = run_filters(
        space, truth_model, model, options.run.members, static_cast<std::uint32_t>(options.run.seed), grid, filters,
        settings, particle, [&](long done) { progress.update(done); }, observer, make_extras(space), checkpointing);
    summary = run_metadata(context);
    summary["model"] = model_summary(model);
    bool same_truth = false;
    if constexpr (std::is_same_v<TruthModel, Model>)
      same_truth = parameter_values(truth_model) == parameter_values(model);
    if (!same_truth)
      summary["truth"] = {
          {"name", TruthModel::name},
          {"parameters", parameter_values(truth_model)},
          {"observation_noise",
           sine_observation_noise(truth_model) ? "deterministic: sin t on every component" : "Brownian"}};
    summary["members"] = options.run.members;
    summary["T"] = options.run.T;
    summary["dt"] = options.run.dt;
    summary["steps"] = grid.steps;
    summary["filters"] = detail::filter_summary(report);
    summary["filter_order"] = report.filters;
    summary["truths_escaped"] = report.truths_escaped;
    summary["memory"] = detail::memory_json(detail::run_memory<Model>(options, filters, settings, particle));
    if (report.has_reference) {
      summary["reference"] = fields_json(report.estimators.at(report.reference));
      summary["reference"]["name"] = report.reference;
    }
    std::vector<std::string> files = {"summary.json", "timeseries.csv"};
    std::vector<std::pair<std::string, std::string>> contents = {
        {"timeseries.csv", detail::filter_timeseries_csv(report, context)}};
    if (!options.trajectory_members.empty()) {
      contents.emplace_back("trajectories.csv", csv_comment(context) + recorder.trajectories_csv());
      files.push_back("trajectories.csv");
    }
    if (!recorder.density_csv().empty()) {
      contents.emplace_back("density.csv", csv_comment(context) + recorder.density_csv());
      files.push_back("density.csv");
      const auto& bimodal = recorder.most_bimodal();
      summary["density"] = {{"times", density_times},
                            {"most_bimodal",
                             {{"member", bimodal.member},
                              {"t", bimodal.t},
                              {"score", bimodal.score},
                              {"scanned_members", bimodal.scanned_members}}}};
    }
    summary["files"] = files;
    const bool particles = std::find(filters.begin(), filters.end(), particle_filter_name) != filters.end();
    const double member_steps = static_cast<double>(options.run.members) * report.steps_run;
    summary["timing"] =
        timing_json(report.step_loop_seconds, member_steps, particles ? member_steps * particle.particles : 0.0);
    contents.emplace_back("summary.json", summary.dump(2) + "\n");
    out.write_all(contents);  // all or none: a full disk leaves an earlier run's files as they were
  });
  if (options.plots) add_plots(out, summary);  // the plots read summary.json; it then records what they wrote
  if (options.checkpoints) remove_checkpoint(out);
  return summary;
}

template <class Model>
nlohmann::json run_compare_command(const Model& model, const CompareOptions& options, const OptionValues& settings,
                                   const TimeGrid& grid, const RunContext& context, const OutputDirectory& out,
                                   const Checkpoint* resume) {
  return run_compare_with_truth(model, model, options, settings, grid, context, out, NoExtraEstimators{}, resume);
}

template <class Model>
nlohmann::json run_compare_with_truth_parameters(const Model& truth_model, const Model& model,
                                                 const CompareOptions& options, const OptionValues& settings,
                                                 const TimeGrid& grid, const RunContext& context,
                                                 const OutputDirectory& out) {
  return run_compare_with_truth(truth_model, model, options, settings, grid, context, out);
}

}  // namespace kushner

/// The explicit instantiations of the filter command for one model (the generated units of drivers/CMakeLists.txt).
#define KUSHNER_INSTANTIATE_FILTER_COMMAND(Model)                                                                     \
  template std::vector<std::string> check_compare_options<Model>(const Model&, const CompareOptions&,                 \
                                                                 const OptionValues&);                                \
  template nlohmann::json run_compare_command<Model>(const Model&, const CompareOptions&, const OptionValues&,        \
                                                     const TimeGrid&, const RunContext&, const OutputDirectory&,      \
                                                     const Checkpoint*);                                              \
  template nlohmann::json run_compare_with_truth_parameters<Model>(const Model&, const Model&, const CompareOptions&, \
                                                                   const OptionValues&, const TimeGrid&,              \
                                                                   const RunContext&, const OutputDirectory&);
