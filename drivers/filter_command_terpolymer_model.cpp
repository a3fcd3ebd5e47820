// `kushner filter`, compiled for the 10-state terpolymer model (drivers/filter_command.hpp).
#include "drivers/filter_command_impl.hpp"
#include "models/registry.hpp"

namespace kushner {

template void run_filter_command<TerpolymerModel>(const TerpolymerModel&, const FilterOptions&, const FilterConfig&,
                                                  const TimeGrid&, const RunContext&);

}  // namespace kushner
