// `kushner filter`, compiled for the scalar and Sunahara models (drivers/filter_command.hpp).
#include "drivers/filter_command_impl.hpp"
#include "models/registry.hpp"

namespace kushner {

template std::vector<std::string> check_compare_options<SineModel>(const SineModel&, const CompareOptions&,
                                                                    const OptionValues&);
template nlohmann::json run_compare_command<SineModel>(const SineModel&, const CompareOptions&, const OptionValues&,
                                                  const TimeGrid&, const RunContext&, const OutputDirectory&);
template std::vector<std::string> check_compare_options<CubicOscillatorModel>(const CubicOscillatorModel&, const CompareOptions&,
                                                                    const OptionValues&);
template nlohmann::json run_compare_command<CubicOscillatorModel>(const CubicOscillatorModel&, const CompareOptions&, const OptionValues&,
                                                  const TimeGrid&, const RunContext&, const OutputDirectory&);
template std::vector<std::string> check_compare_options<BenesModel>(const BenesModel&, const CompareOptions&,
                                                                    const OptionValues&);
template nlohmann::json run_compare_command<BenesModel>(const BenesModel&, const CompareOptions&, const OptionValues&,
                                                  const TimeGrid&, const RunContext&, const OutputDirectory&);
template std::vector<std::string> check_compare_options<OuModel>(const OuModel&, const CompareOptions&,
                                                                    const OptionValues&);
template nlohmann::json run_compare_command<OuModel>(const OuModel&, const CompareOptions&, const OptionValues&,
                                                  const TimeGrid&, const RunContext&, const OutputDirectory&);

}  // namespace kushner
