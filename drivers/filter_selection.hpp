#pragma once
// `--filters` on the command line: names to the filters a model supports, in report order, or one clear
// InputError line ("filter POLY3 does not support model 'car' (drift is not polynomial)").
#include "drivers/name_lists.hpp"
#include "engine/exact_reference_estimator.hpp"
#include "engine/particle_reference.hpp"
#include "kernels/filters/filter_list.hpp"

#include <algorithm>
#include <string>
#include <vector>

namespace kushner {

/// What Model (and, for a --model-file polynomial, its coefficients) offers --filters.
template <class Model>
EstimatorTable estimator_table(const Model& model) {
  EstimatorTable table{Model::name,
                       {},
                       {particle_filter_name, particle_filter_unsupported<Model>()},
                       {exact_filter_name, exact_filter_unsupported(model)}};
  const std::vector<FilterSupport> own = filter_support(model);  // the filters of the model's time
  for (const std::string& name : all_filter_names()) {           // every filter, in report order
    const auto f = std::find_if(own.begin(), own.end(), [&](const FilterSupport& s) { return s.name == name; });
    table.bank.push_back({name, f != own.end()         ? f->unsupported
                                : Model::discrete_time ? "a continuous-time filter; the model is discrete-time"
                                                       : "a discrete-time filter; the model is continuous-time"});
  }
  return table;
}

/// "all", or a comma-separated list of names (case-sensitive), checked against what Model supports and, for a
/// model with a run-time check (a --model-file polynomial), against what `model`'s coefficients allow.
template <class Model>
std::vector<std::string> select_filters(const std::string& list, const Model& model) {
  return select_bank_filters(list, estimator_table(model));
}

/// `--filters` with the estimators beside the bank: the bank's filters (select_filters), then "PF" (the
/// particle filter) and "EXACT" (exact or grid filter) where named. "all" is every bank filter the model
/// supports plus PF where it applies; EXACT only on request (the grid filter is far slower than the rest).
template <class Model>
std::vector<std::string> select_estimators(const std::string& list, const Model& model) {
  return select_estimator_names(list, estimator_table(model));
}

}  // namespace kushner
