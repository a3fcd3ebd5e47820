#pragma once
// The filters of the bank, in the order runs report them, and which of them a model supports. A filter that
// needs something a model lacks (a polynomial drift, a factorization, Gaussian expectations) says why in its
// `unsupported` string; the bank instantiates only the supported ones (so no filter ever runs on a model it
// cannot handle, and each filter's step static_asserts its own requirements).
#include "kernels/filters/asre_filter.hpp"
#include "kernels/filters/bilinear_filter.hpp"
#include "kernels/filters/detchmendy_sridhar_filter.hpp"
#include "kernels/filters/extended_kalman_filter.hpp"
#include "kernels/filters/kalman_bucy_filter.hpp"
#include "kernels/filters/linearized_kalman_bucy_filter.hpp"
#include "kernels/filters/mixed_filter.hpp"
#include "kernels/filters/polynomial_filter.hpp"
#include "kernels/filters/quasi_linear_filter.hpp"
#include "kernels/filters/second_order_filter.hpp"

#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace kushner {

template <class Model, class MemSpace>
using AllFilters =
    std::tuple<KalmanBucyFilter<Model, MemSpace>, ExtendedKalmanFilter<Model, MemSpace>,
               DetchmendySridharFilter<Model, MemSpace>, SecondOrderFilter<Model, MemSpace>,
               SchwartzBassFilter<Model, MemSpace>, QuasiLinearFilter<Model, MemSpace>,
               Polynomial3Filter<Model, MemSpace>, Polynomial4Filter<Model, MemSpace>, BilinearFilter<Model, MemSpace>,
               MixedFilter<Model, MemSpace>, AsreFilter<Model, MemSpace>, LinearizedKalmanBucyFilter<Model, MemSpace>>;

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
};

/// Every filter, in report order, with whether (and why not) it supports Model.
template <class Model>
std::vector<FilterSupport> filter_support() {
  std::vector<FilterSupport> list;
  for_each_filter_type<Model, Kokkos::HostSpace>([&](auto* tag) {
    using Filter = std::remove_pointer_t<decltype(tag)>;
    list.push_back({Filter::name, Filter::description, Filter::unsupported});
  });
  return list;
}

}  // namespace kushner
