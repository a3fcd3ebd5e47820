#pragma once
// Options of `kushner filter`: the run options shared with `simulate`, which filters, and the settings of
// the filters that have any.
#include "drivers/run_options.hpp"
#include "kernels/filters/filter_config.hpp"

#include <CLI/CLI.hpp>

#include <string>

namespace kushner {

struct FilterOptions {
  RunOptions run;
  std::string filters = "all";
  std::string qlf_expectations = "auto";
  int gh_nodes = FilterConfig{}.gh_nodes;
  double asre_tolerance = FilterConfig{}.asre_tolerance;
  int asre_max_iterations = FilterConfig{}.asre_max_iterations;
};

/// The run options plus --filters, --qlf-expectations, --gh-nodes, --asre-tolerance, --asre-max-iterations.
void add_filter_options(CLI::App& app, FilterOptions& options);

/// The filters' settings; InputError (one line naming the option) for values no run can use. What depends
/// on the model (unsupported filters, closed forms) is checked by select_filters and the filters themselves.
FilterConfig filter_config(const FilterOptions& options);

}  // namespace kushner
