#include "drivers/filter_command.hpp"
#include "drivers/backend.hpp"
#include "drivers/commands.hpp"
#include "models/registry.hpp"

namespace kushner {

namespace {

int run_estimation(const CompareOptions& options, const RunContext& context, const char* command) {
  validate_run_options(options.run);
  const TimeGrid grid = make_time_grid(options.run.T, options.run.dt, options.run.output_points);
  const FilterConfig config = filter_config(options);
  with_model(options.run.model, options.run.sets, [&](const auto& model) {
    using Model = std::decay_t<decltype(model)>;
    if constexpr (Model::discrete_time) {
      throw InputError(std::string("--model: '") + Model::name + "' is a discrete-time model; `kushner " + command +
                       "` runs the continuous-time filters");
    } else {
      check_compare_options<Model>(model, options, config);  // before anything is written
      const OutputDirectory out(options.run.out, "--out");
      KokkosSession kokkos;
      run_compare_command(model, options, config, grid, context, out);
    }
  });
  return 0;
}

}  // namespace

int run_filter(const FilterOptions& options, const RunContext& context) {
  CompareOptions compare;
  static_cast<FilterOptions&>(compare) = options;
  compare.trajectory_members.clear();
  compare.plots = false;
  return run_estimation(compare, context, "filter");
}

int run_compare(const CompareOptions& options, const RunContext& context) {
  return run_estimation(options, context, "compare");
}

}  // namespace kushner
