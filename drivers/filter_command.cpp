#include "drivers/filter_command.hpp"
#include "drivers/commands.hpp"
#include "models/registry.hpp"

namespace kushner {

int run_filter(const FilterOptions& options, const RunContext& context) {
  validate_run_options(options.run);
  const TimeGrid grid = make_time_grid(options.run.T, options.run.dt, options.run.output_points);
  const FilterConfig config = filter_config(options);
  with_model(options.run.model, options.run.sets, [&](const auto& model) {
    using Model = std::decay_t<decltype(model)>;
    if constexpr (Model::discrete_time) {
      throw InputError(std::string("--model: '") + Model::name +
                       "' is a discrete-time model; `kushner filter` runs the continuous-time filters");
    } else {
      run_filter_command(model, options, config, grid, context);
    }
  });
  return 0;
}

}  // namespace kushner
