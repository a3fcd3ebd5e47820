// `kushner filter`, compiled for the linear and car models (drivers/filter_command.hpp).
#include "drivers/filter_command_impl.hpp"
#include "models/registry.hpp"

namespace kushner {

template void run_filter_command<LinearModel<1>>(const LinearModel<1>&, const FilterOptions&, const FilterConfig&,
                                                 const TimeGrid&, const RunContext&);
template void run_filter_command<LinearModel<2>>(const LinearModel<2>&, const FilterOptions&, const FilterConfig&,
                                                 const TimeGrid&, const RunContext&);
template void run_filter_command<LinearModel<3>>(const LinearModel<3>&, const FilterOptions&, const FilterConfig&,
                                                 const TimeGrid&, const RunContext&);
template void run_filter_command<CarModel>(const CarModel&, const FilterOptions&, const FilterConfig&, const TimeGrid&,
                                           const RunContext&);
template void run_filter_command<CarTaylor3Model>(const CarTaylor3Model&, const FilterOptions&, const FilterConfig&,
                                                  const TimeGrid&, const RunContext&);

}  // namespace kushner
