#pragma once
// The filters of the bank, in the order runs report them: adding a filter is its header and one entry in
// AllFilters. Everything else (the command line and its options, `kushner filters`, the summary, the tests that
// loop over filters) is generated from this list and each filter's declarations
// (kernels/filters/filter_protocol.hpp). A filter that needs something a model lacks (a polynomial drift, a
// factorization, Gaussian expectations) says why in its `unsupported` string; the bank instantiates only the
// supported ones (so no filter ever runs on a model it cannot handle, and each filter's step static_asserts its
// own requirements).
#include "kernels/filters/asre_filter.hpp"
#include "kernels/filters/bilinear_filter.hpp"
#include "kernels/filters/clark_approximate_filter.hpp"
#include "kernels/filters/clark_specific_estimate.hpp"
#include "kernels/filters/detchmendy_sridhar_filter.hpp"
#include "kernels/filters/discrete_kalman_filter.hpp"
#include "kernels/filters/ensemble_kalman_bucy_filter.hpp"
#include "kernels/filters/extended_kalman_filter.hpp"
#include "kernels/filters/filter_protocol.hpp"
#include "kernels/filters/kalman_bucy_filter.hpp"
#include "kernels/filters/linearized_kalman_bucy_filter.hpp"
#include "kernels/filters/mixed_filter.hpp"
#include "kernels/filters/moment_filter.hpp"
#include "kernels/filters/nominal_path_filters.hpp"
#include "kernels/filters/polynomial_filter.hpp"
#include "kernels/filters/quasi_linear_filter.hpp"
#include "kernels/filters/second_order_filter.hpp"
#include "kernels/filters/unscented_kalman_filter.hpp"

#include "models/clark_linear_model.hpp"
#include "models/linear_model.hpp"

#include <algorithm>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace kushner {

template <class Model, class MemSpace>
using ContinuousTimeFilters =
    std::tuple<KalmanBucyFilter<Model, MemSpace>, ExtendedKalmanFilter<Model, MemSpace>,
               DetchmendySridharFilter<Model, MemSpace>, SecondOrderFilter<Model, MemSpace>,
               SchwartzBassFilter<Model, MemSpace>, QuasiLinearFilter<Model, MemSpace>,
               UnscentedKalmanFilter<Model, MemSpace>, Polynomial3Filter<Model, MemSpace>,
               Polynomial4Filter<Model, MemSpace>, BilinearFilter<Model, MemSpace>, MixedFilter<Model, MemSpace>,
               AsreFilter<Model, MemSpace>, LinearizedKalmanBucyFilter<Model, MemSpace>,
               EnsembleKalmanBucyFilter<Model, MemSpace>, StochasticEnsembleKalmanBucyFilter<Model, MemSpace>>;

template <class Model, class MemSpace>
using DiscreteTimeFilters = std::tuple<
    KalmanFilter<Model, MemSpace>, InformationFilter<Model, MemSpace>, ExtendedKalmanFilterD<Model, MemSpace>,
    MomentFilter<Model, MemSpace>, ClarkMidpointFilter<Model, MemSpace>, ClarkLeastSquaresFilter<Model, MemSpace>,
    ClarkStraightLineFilter<Model, MemSpace>, ClarkHyperbolicFilter<Model, MemSpace>,
    ClarkSpecificEstimate<Model, MemSpace>, NominalKalmanFilter<Model, MemSpace>, NominalMomentFilter<Model, MemSpace>>;

/// The filters of Model's time (continuous or discrete): a model's filters are never compiled for the other time.
template <class Model, class MemSpace>
using AllFilters = std::conditional_t<Model::discrete_time, DiscreteTimeFilters<Model, MemSpace>,
                                      ContinuousTimeFilters<Model, MemSpace>>;

namespace detail {
template <class Tuple>
struct supported_only;
template <class... Filters>
struct supported_only<std::tuple<Filters...>> {
  using type = decltype(std::tuple_cat(
      std::declval<std::conditional_t<Filters::unsupported == nullptr, std::tuple<Filters>, std::tuple<>>>()...));
};

template <class Tuple, class F, std::size_t... I>
void for_each_filter_type(F&& f, std::index_sequence<I...>) {
  (f(static_cast<std::tuple_element_t<I, Tuple>*>(nullptr)), ...);
}
}  // namespace detail

/// The filters a model supports, as a std::tuple of filter types (a compile-time list; never instantiated).
template <class Model, class MemSpace>
using SupportedFilters = typename detail::supported_only<AllFilters<Model, MemSpace>>::type;

/// Calls f(static_cast<Filter*>(nullptr)) for every filter type of AllFilters<Model, MemSpace>, in order.
template <class Model, class MemSpace, class F>
void for_each_filter_type(F&& f) {
  using All = AllFilters<Model, MemSpace>;
  detail::for_each_filter_type<All>(f, std::make_index_sequence<std::tuple_size_v<All>>{});
}

struct FilterSupport {
  std::string name, description;
  const char* unsupported;  // nullptr: supported
  std::vector<OptionSpec> options;
};

/// Every filter, in report order, with whether (and why not) it can run `model`: its type, and for a model
/// known only at run time (a --model-file polynomial) its coefficients.
template <class Model>
std::vector<FilterSupport> filter_support(const Model& model) {
  std::vector<FilterSupport> list;
  for_each_filter_type<Model, Kokkos::HostSpace>([&](auto* tag) {
    using Filter = std::remove_pointer_t<decltype(tag)>;
    list.push_back({Filter::name, Filter::description, filter_unsupported<Filter>(model), filter_options<Filter>()});
  });
  return list;
}

/// The names of the filters that can run `model`, in report order.
template <class Model>
std::vector<std::string> supported_filters(const Model& model) {
  std::vector<std::string> names;
  for (const auto& f : filter_support(model))
    if (f.unsupported == nullptr) names.push_back(f.name);
  return names;
}

/// Calls f(static_cast<Filter*>(nullptr)) for every filter of both times, continuous first: what does not depend
/// on the model (names, options, randomness) is read from these instances.
template <class F>
void for_each_named_filter(F&& f) {
  for_each_filter_type<LinearModel<1>, Kokkos::HostSpace>(f);
  for_each_filter_type<ClarkLinearModel, Kokkos::HostSpace>(f);
}

/// Every filter name, in report order (names do not depend on the model).
inline std::vector<std::string> all_filter_names() {
  std::vector<std::string> names;
  for_each_named_filter([&](auto* tag) { names.push_back(std::remove_pointer_t<decltype(tag)>::name); });
  return names;
}

/// The names of the filters of Model's time (continuous or discrete), in report order, supported or not.
template <class Model>
std::vector<std::string> filter_names() {
  std::vector<std::string> names;
  for_each_filter_type<Model, Kokkos::HostSpace>(
      [&](auto* tag) { names.push_back(std::remove_pointer_t<decltype(tag)>::name); });
  return names;
}

/// The names of the filters that draw random numbers (filter_randomized), in report order.
inline std::vector<std::string> randomized_filter_names() {
  std::vector<std::string> names;
  for_each_named_filter([&](auto* tag) {
    using Filter = std::remove_pointer_t<decltype(tag)>;
    if (filter_randomized<Filter>()) names.push_back(Filter::name);
  });
  return names;
}

/// Every filter's options, in report order (they do not depend on the model).
inline std::vector<OptionSpec> all_filter_options() {
  std::vector<OptionSpec> options;
  for_each_named_filter([&](auto* tag) {
    for (auto& o : filter_options<std::remove_pointer_t<decltype(tag)>>())
      if (std::none_of(options.begin(), options.end(), [&](const OptionSpec& s) { return s.name == o.name; }))
        options.push_back(std::move(o));  // a setting two filters share is declared once
  });
  return options;
}

/// The first setting among the filters `names` that Model cannot use.
template <class Model>
std::optional<OptionProblem> filter_option_problem(const std::vector<std::string>& names, const OptionValues& values) {
  std::optional<OptionProblem> problem;
  for_each_filter_type<Model, Kokkos::HostSpace>([&](auto* tag) {
    using Filter = std::remove_pointer_t<decltype(tag)>;
    if (problem || std::find(names.begin(), names.end(), Filter::name) == names.end()) return;
    if constexpr (Filter::unsupported == nullptr) problem = check_filter_options<Filter>(values);
  });
  return problem;
}

}  // namespace kushner
