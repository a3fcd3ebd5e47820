#pragma once
// Options of `kushner filter` and `kushner compare`: the run options shared with `simulate`, which filters,
// the settings of the filters that have any (the particle filter's among them), and what `compare` adds.
#include "drivers/particle_reference.hpp"
#include "drivers/run_options.hpp"
#include "kernels/filters/filter_config.hpp"

#include <CLI/CLI.hpp>

#include <string>
#include <vector>

namespace kushner {

struct FilterOptions {
  RunOptions run;
  std::string filters = "all";
  std::string qlf_expectations = "auto";
  int gh_nodes = FilterConfig{}.gh_nodes;
  double asre_tolerance = FilterConfig{}.asre_tolerance;
  int asre_max_iterations = FilterConfig{}.asre_max_iterations;
  int particles = ParticleSettings{}.particles;
  std::string resample = "systematic";
  double ess_threshold = ParticleFilterOptions{}.ess_threshold;
};

/// `kushner compare`: `kushner filter`'s options plus the artefacts it writes for people to look at.
struct CompareOptions : FilterOptions {
  std::vector<long> trajectory_members = {0, 1, 2};  // members whose paths go to trajectories.csv
  std::vector<double> density_times;                 // 1-D models: density snapshots; empty = T/10, T/2, T
  bool plots = true;                                 // plots and report.md (Python with matplotlib)
};

/// The run options plus --filters, --qlf-expectations, --gh-nodes, --asre-tolerance, --asre-max-iterations,
/// --particles, --resample, --ess-threshold.
void add_filter_options(CLI::App& app, FilterOptions& options);

/// add_filter_options plus --trajectory-members, --density-times, --no-plots.
void add_compare_options(CLI::App& app, CompareOptions& options);

/// The particle filter's settings; InputError for a particle count below 1, an unknown scheme, a threshold
/// outside [0, 1].
ParticleSettings particle_settings(const FilterOptions& options);

/// The filters' settings; InputError (one line naming the option) for values no run can use. What depends
/// on the model (unsupported filters, closed forms) is checked by select_filters and the filters themselves.
FilterConfig filter_config(const FilterOptions& options);

}  // namespace kushner
