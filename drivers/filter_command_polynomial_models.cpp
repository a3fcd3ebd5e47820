// `kushner filter`, compiled for the polynomial models of `--model-file` (drivers/filter_command.hpp).
#include "drivers/filter_command_impl.hpp"
#include "models/polynomial_model.hpp"

namespace kushner {

template std::vector<std::string> check_compare_options<PolynomialModel<1>>(const PolynomialModel<1>&,
                                                                            const CompareOptions&, const OptionValues&);
template nlohmann::json run_compare_command<PolynomialModel<1>>(const PolynomialModel<1>&, const CompareOptions&,
                                                                const OptionValues&, const TimeGrid&, const RunContext&,
                                                                const OutputDirectory&);
template std::vector<std::string> check_compare_options<PolynomialModel<2>>(const PolynomialModel<2>&,
                                                                            const CompareOptions&, const OptionValues&);
template nlohmann::json run_compare_command<PolynomialModel<2>>(const PolynomialModel<2>&, const CompareOptions&,
                                                                const OptionValues&, const TimeGrid&, const RunContext&,
                                                                const OutputDirectory&);
template std::vector<std::string> check_compare_options<PolynomialModel<3>>(const PolynomialModel<3>&,
                                                                            const CompareOptions&, const OptionValues&);
template nlohmann::json run_compare_command<PolynomialModel<3>>(const PolynomialModel<3>&, const CompareOptions&,
                                                                const OptionValues&, const TimeGrid&, const RunContext&,
                                                                const OutputDirectory&);

}  // namespace kushner
