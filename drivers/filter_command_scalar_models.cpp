// `kushner filter`, compiled for the scalar and Sunahara models (drivers/filter_command.hpp).
#include "drivers/filter_command_impl.hpp"
#include "models/registry.hpp"

namespace kushner {

template void run_filter_command<SineModel>(const SineModel&, const FilterOptions&, const FilterConfig&,
                                            const TimeGrid&, const RunContext&);
template void run_filter_command<CubicOscillatorModel>(const CubicOscillatorModel&, const FilterOptions&,
                                                       const FilterConfig&, const TimeGrid&, const RunContext&);
template void run_filter_command<BenesModel>(const BenesModel&, const FilterOptions&, const FilterConfig&,
                                             const TimeGrid&, const RunContext&);
template void run_filter_command<OuModel>(const OuModel&, const FilterOptions&, const FilterConfig&, const TimeGrid&,
                                          const RunContext&);

}  // namespace kushner
