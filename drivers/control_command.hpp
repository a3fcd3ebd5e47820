#pragma once
// `kushner control` for one model type: defined once (control_command_impl.hpp) and compiled for every model of the
// registry's list in the command units beside `filter`/`compare` (drivers/CMakeLists.txt), so that the dispatch
// (control_command.cpp) and `kushner reproduce` call those instantiations instead of compiling their own.
#include "core/options.hpp"
#include "drivers/control_options.hpp"
#include "drivers/run_metadata.hpp"
#include "engine/time_grid.hpp"
#include "models/model_list.hpp"

#include <nlohmann/json.hpp>

namespace kushner {

/// The whole `kushner control` run for one model; returns summary.json's content. InputError (one line) when the
/// model has no control input or the options do not fit it. `own_kokkos`: initialize Kokkos here (after the checks);
/// false when the caller holds a KokkosSession (`kushner reproduce`).
template <class Model>
nlohmann::json run_control_model(const Model& model, const ControlOptions& options, const OptionValues& settings,
                                 const TimeGrid& grid, const RunContext& context, bool own_kokkos);

}  // namespace kushner

// Inside namespace kushner: the instance of one model, declared extern here for every listed model and defined in
// a command unit (drivers/CMakeLists.txt) after control_command_impl.hpp.
#define KUSHNER_CONTROL_COMMAND_INSTANCE(Model)                                                                      \
  nlohmann::json run_control_model<Model>(const Model&, const ControlOptions&, const OptionValues&, const TimeGrid&, \
                                          const RunContext&, bool)
#define KUSHNER_INSTANTIATE_CONTROL_COMMAND(Model) template KUSHNER_CONTROL_COMMAND_INSTANCE(Model);
#define KUSHNER_EXTERN_CONTROL_COMMAND(Model) extern template KUSHNER_CONTROL_COMMAND_INSTANCE(Model);

namespace kushner {
KUSHNER_CONTINUOUS_MODELS(KUSHNER_EXTERN_CONTROL_COMMAND)
KUSHNER_DISCRETE_MODELS(KUSHNER_EXTERN_CONTROL_COMMAND)
KUSHNER_FILE_MODELS(KUSHNER_EXTERN_CONTROL_COMMAND)
}  // namespace kushner
