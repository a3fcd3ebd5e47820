// `kushner filter`, compiled for the linear and car models (drivers/filter_command.hpp).
#include "drivers/filter_command_impl.hpp"
#include "models/registry.hpp"

namespace kushner {

template std::vector<std::string> check_compare_options<LinearModel<1>>(const LinearModel<1>&, const CompareOptions&,
                                                                    const OptionValues&);
template nlohmann::json run_compare_command<LinearModel<1>>(const LinearModel<1>&, const CompareOptions&, const OptionValues&,
                                                  const TimeGrid&, const RunContext&, const OutputDirectory&);
template std::vector<std::string> check_compare_options<LinearModel<2>>(const LinearModel<2>&, const CompareOptions&,
                                                                    const OptionValues&);
template nlohmann::json run_compare_command<LinearModel<2>>(const LinearModel<2>&, const CompareOptions&, const OptionValues&,
                                                  const TimeGrid&, const RunContext&, const OutputDirectory&);
template std::vector<std::string> check_compare_options<LinearModel<3>>(const LinearModel<3>&, const CompareOptions&,
                                                                    const OptionValues&);
template nlohmann::json run_compare_command<LinearModel<3>>(const LinearModel<3>&, const CompareOptions&, const OptionValues&,
                                                  const TimeGrid&, const RunContext&, const OutputDirectory&);
template std::vector<std::string> check_compare_options<CarModel>(const CarModel&, const CompareOptions&,
                                                                    const OptionValues&);
template nlohmann::json run_compare_command<CarModel>(const CarModel&, const CompareOptions&, const OptionValues&,
                                                  const TimeGrid&, const RunContext&, const OutputDirectory&);
template std::vector<std::string> check_compare_options<CarTaylor3Model>(const CarTaylor3Model&, const CompareOptions&,
                                                                    const OptionValues&);
template nlohmann::json run_compare_command<CarTaylor3Model>(const CarTaylor3Model&, const CompareOptions&, const OptionValues&,
                                                  const TimeGrid&, const RunContext&, const OutputDirectory&);

}  // namespace kushner
