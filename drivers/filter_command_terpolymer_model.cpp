// `kushner filter`, compiled for the 10-state terpolymer model (drivers/filter_command.hpp).
#include "drivers/filter_command_impl.hpp"
#include "models/registry.hpp"

namespace kushner {

template std::vector<std::string> check_compare_options<TerpolymerModel>(const TerpolymerModel&, const CompareOptions&,
                                                                    const OptionValues&);
template nlohmann::json run_compare_command<TerpolymerModel>(const TerpolymerModel&, const CompareOptions&, const OptionValues&,
                                                  const TimeGrid&, const RunContext&, const OutputDirectory&);

}  // namespace kushner
