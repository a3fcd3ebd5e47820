#pragma once
// What a filter of the bank is, in one place. A filter is a struct template Filter<Model, MemSpace> with
//
//   static constexpr const char* name, description;  // "QLF", and a line for `kushner filters`
//   static constexpr const char* unsupported;         // why Model's type rules it out (nullptr: it does not)
//   static Filter create(const OptionValues&, const Model&, long members);
//   KOKKOS_INLINE_FUNCTION Status step(const Model&, int member, const StepInput<p>&, Vec<n>& m, Mat<n, n>& P) const;
//
// (a discrete-time filter's step also takes `const Vec<n>& known_input`, a closed loop's B u[k], which enters its
// prediction before the update with z[k+1]; the filter lists of the two times are kernels/filters/filter_list.hpp's)
//
// and, where it needs them, these optional parts, which the engine, the command line, `kushner filters` and the
// summary discover from the filter list (kernels/filters/filter_list.hpp) without naming the filter:
//
//   static std::vector<OptionSpec> options();                 // its settings: name, default, range, help
//   static std::optional<OptionProblem> check(const OptionValues&);  // a setting this Model cannot use
//   static const char* unsupported_by(const ModelFacts&);     // run-time: coefficients it cannot run
//   static constexpr int prepass_passes;                      // passes over the horizon before the run, and
//   template <class RunAlone>                                 // the pre-pass itself: run_alone(filter) runs the
//   static Filter prepare(const OptionValues&, const Model&, long members, RunAlone&&);  // truths with it alone
//   Fields summary_fields() const;                            // what it adds to its summary.json entry
//   KOKKOS_INLINE_FUNCTION void apply_known_input(int member, const Vec<n>& shift) const;  // a filter with means
//                                                 // of its own besides m (ASRE's iterates) adds a closed loop's
//                                                 // B u dt to them after its step (kernels/filters/filter_slot.hpp)
//   static Filter create(const OptionValues&, const Model&, long members, Seed seed);  // instead of
//                                                             // the create above: a filter that draws random
//   static constexpr bool randomized = true;                  // numbers gets the run's seed, and says so
//   template <class Archive> void visit_state(Archive&);      // per-member state of its own besides m, P
//                                                             // (views): what a checkpoint must hold
//                                                             // (archive.view(name, view): engine/state_archive.hpp)
//   static double own_bytes_per_member(const OptionValues&);  // and the bytes it allocates for it per member
//                                                             // (the memory check before a run)
//   void follow_nominal(const std::vector<Vec<m>>& u_bar);    // a filter linearized along a nominal path
//                                                             // follows a closed loop law's (LQR-NOM's) path
//
// Filters may declare the same option (equal OptionSpec): it is one setting, shared.
#include "core/fields.hpp"
#include "core/options.hpp"
#include "kernels/rng.hpp"
#include "models/model_facts.hpp"
#include "models/model_traits.hpp"

#include <cstdint>
#include <optional>
#include <type_traits>
#include <utility>
#include <vector>

namespace kushner {

namespace detail {
template <class Filter, class = void>
struct has_options : std::false_type {};
template <class Filter>
struct has_options<Filter, std::void_t<decltype(Filter::options())>> : std::true_type {};

template <class Filter, class = void>
struct has_option_check : std::false_type {};
template <class Filter>
struct has_option_check<Filter, std::void_t<decltype(Filter::check(std::declval<const OptionValues&>()))>>
    : std::true_type {};

template <class Filter, class = void>
struct has_runtime_support : std::false_type {};
template <class Filter>
struct has_runtime_support<Filter, std::void_t<decltype(Filter::unsupported_by(std::declval<const ModelFacts&>()))>>
    : std::true_type {};

template <class Filter, class = void>
struct has_prepass : std::false_type {};
template <class Filter>
struct has_prepass<Filter, std::void_t<decltype(Filter::prepass_passes)>> : std::true_type {};

template <class Filter, int N, class = void>
struct has_known_input : std::false_type {};
template <class Filter, int N>
struct has_known_input<
    Filter, N, std::void_t<decltype(std::declval<const Filter&>().apply_known_input(0, std::declval<const Vec<N>&>()))>>
    : std::true_type {};

template <class Filter, class Archive, class = void>
struct has_own_state : std::false_type {};
template <class Filter, class Archive>
struct has_own_state<Filter, Archive,
                     std::void_t<decltype(std::declval<Filter&>().visit_state(std::declval<Archive&>()))>>
    : std::true_type {};

template <class Filter, class = void>
struct has_own_bytes : std::false_type {};
template <class Filter>
struct has_own_bytes<Filter, std::void_t<decltype(Filter::own_bytes_per_member(std::declval<const OptionValues&>()))>>
    : std::true_type {};

template <class Filter, class Model, class = void>
struct has_seeded_create : std::false_type {};
template <class Filter, class Model>
struct has_seeded_create<Filter, Model,
                         std::void_t<decltype(Filter::create(std::declval<const OptionValues&>(),
                                                             std::declval<const Model&>(), 0L, Seed{}))>>
    : std::true_type {};

template <class Filter, class = void>
struct is_randomized : std::false_type {};
template <class Filter>
struct is_randomized<Filter, std::enable_if_t<Filter::randomized>> : std::true_type {};

template <class Filter, int M, class = void>
struct follows_nominal : std::false_type {};
template <class Filter, int M>
struct follows_nominal<
    Filter, M,
    std::void_t<decltype(std::declval<Filter&>().follow_nominal(std::declval<const std::vector<Vec<M>>&>()))>>
    : std::true_type {};

template <class Filter, class = void>
struct has_summary_fields : std::false_type {};
template <class Filter>
struct has_summary_fields<Filter, std::void_t<decltype(std::declval<const Filter&>().summary_fields())>>
    : std::true_type {};
}  // namespace detail

/// The settings Filter declares (empty for most).
template <class Filter>
std::vector<OptionSpec> filter_options() {
  if constexpr (detail::has_options<Filter>::value)
    return Filter::options();
  else
    return {};
}

/// A setting Filter cannot use with its model, if any.
/// For the filters that need a linear observation: a run-time model's observation degree (its type offers
/// linear_form, which describes its whole observation only where the degree is at most 1).
inline const char* observation_unsupported_by(const ModelFacts& f) {
  return f.observation_degree > 1 ? "observation is not linear (the file has terms of degree 2 or more)" : nullptr;
}

template <class Filter>
std::optional<OptionProblem> check_filter_options(const OptionValues& values) {
  if constexpr (detail::has_option_check<Filter>::value)
    return Filter::check(values.with_defaults(filter_options<Filter>()));
  else
    return std::nullopt;
}

/// Why Filter cannot run `model`: its type (Filter::unsupported), then, for a model known only at run time,
/// its coefficients (Filter::unsupported_by); nullptr when it can.
template <class Filter, class Model>
const char* filter_unsupported(const Model& model) {
  if (Filter::unsupported != nullptr) return Filter::unsupported;
  if constexpr (ModelTraits<Model>::runtime_checked && detail::has_runtime_support<Filter>::value)
    return Filter::unsupported_by(model.model_facts());
  else
    return nullptr;
}

/// Filter::create; a randomized filter's create also takes the run's seed.
template <class Filter, class Model>
Filter create_filter(const OptionValues& options, const Model& model, long members, Seed seed) {
  if constexpr (detail::has_seeded_create<Filter, Model>::value)
    return Filter::create(options, model, members, seed);
  else
    return Filter::create(options, model, members);
}

/// Whether Filter draws random numbers (a Monte Carlo filter: equal to another only in the limit).
template <class Filter>
constexpr bool filter_randomized() {
  return detail::is_randomized<Filter>::value;
}

/// How many passes over the horizon Filter's pre-pass takes (0: none).
template <class Filter>
constexpr int filter_prepass_passes() {
  if constexpr (detail::has_prepass<Filter>::value)
    return Filter::prepass_passes;
  else
    return 0;
}

/// What Filter adds to its entry of summary.json.
template <class Filter>
Fields filter_summary_fields(const Filter& filter) {
  if constexpr (detail::has_summary_fields<Filter>::value)
    return filter.summary_fields();
  else
    return {};
}

}  // namespace kushner
