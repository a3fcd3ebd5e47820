#pragma once
// Options of `kushner filter` and `kushner compare`: the run options shared with `simulate`, which filters,
// the settings of the filters that have any (the particle filter's among them), and what `compare` adds.
#include "core/options.hpp"
#include "drivers/cli_app.hpp"
#include "drivers/run_options.hpp"
#include "engine/particle_settings.hpp"

#include <map>
#include <string>
#include <vector>

namespace kushner {

struct FilterOptions {
  RunOptions run;
  std::string filters = "all";
  /// The filters' own settings as given (option name -> text); each filter declares its options, and the
  /// absent ones take the declared defaults (kernels/filters/filter_protocol.hpp).
  std::map<std::string, std::string> filter_settings;
  int particles = ParticleSettings{}.particles;
  std::string resample = "systematic";
  double ess_threshold = ParticleFilterOptions{}.ess_threshold;
  std::string precision = to_string(ParticleFilterOptions{}.precision);
  std::string step_pairs = "auto";
  /// --checkpoint-every SECONDS: save the run's state into --out this often (`kushner resume`); < 0: not given.
  double checkpoint_every = -1.0;
  bool checkpoint_every_given = false;
  /// Whether the run saves checkpoints at all (on SIGINT/SIGTERM, and every --checkpoint-every): the `filter`
  /// and `compare` commands, not the runs `kushner reproduce` makes.
  bool checkpoints = false;
};

/// `kushner compare`: `kushner filter`'s options plus the artefacts it writes for people to look at.
struct CompareOptions : FilterOptions {
  std::vector<long> trajectory_members = {0, 1, 2};  // members whose paths go to trajectories.csv
  std::vector<double> density_times;                 // 1-D models: density snapshots; empty = T/10, T/2, T
  bool plots = true;                                 // plots and report.md (Python with matplotlib)
};

/// The run options plus --filters, every filter's declared options (--gh-nodes, --asre-tolerance, ...),
/// --particles, --resample, --ess-threshold, --precision, --checkpoint-every.
void add_filter_options(CLI::App& app, FilterOptions& options);

/// add_filter_options plus --trajectory-members, --density-times, --no-plots.
void add_compare_options(CLI::App& app, CompareOptions& options);

/// The particle filter's settings; InputError for a particle count below 1, an unknown scheme or precision, a
/// threshold outside [0, 1].
ParticleSettings particle_settings(const FilterOptions& options);

/// The command-line spelling of an option declared as `name`: "gh_nodes" -> "--gh-nodes".
std::string option_flag(const std::string& name);

/// The filters' settings, every declared option given or defaulted; InputError (one line naming the option)
/// for a value outside its declared range. What depends on the model (unsupported filters, closed forms) is
/// checked by select_estimators and check_filter_settings.
OptionValues filter_option_values(const FilterOptions& options);

}  // namespace kushner
