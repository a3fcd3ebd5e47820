#pragma once
// `--filters` on the command line: names to the filters a model supports, in report order, or one clear
// InputError line ("filter POLY3 does not support model 'car' (drift is not polynomial)").
#include "core/errors.hpp"
#include "engine/exact_reference_estimator.hpp"
#include "engine/particle_reference.hpp"
#include "kernels/filters/filter_list.hpp"

#include <algorithm>
#include <string>
#include <vector>

namespace kushner {

/// "all", or a comma-separated list of names (case-sensitive), checked against what Model supports and, for a
/// model with a run-time check (a --model-file polynomial), against what `model`'s coefficients allow.
template <class Model>
std::vector<std::string> select_filters(const std::string& list, const Model& model) {
  if (list == "all") return supported_filters(model);
  const std::vector<FilterSupport> support = filter_support(model);
  std::vector<std::string> requested;
  std::string current;
  for (std::size_t i = 0; i <= list.size(); ++i) {
    if (i == list.size() || list[i] == ',') {
      KUSHNER_INPUT_REQUIRE(!current.empty(), "--filters: empty name in '" << list << "'");
      requested.push_back(current);
      current.clear();
    } else if (list[i] != ' ') {
      current += list[i];
    }
  }
  for (const auto& name : requested) {
    const auto it =
        std::find_if(support.begin(), support.end(), [&](const FilterSupport& f) { return f.name == name; });
    if (it == support.end()) {
      std::string known;
      for (const auto& f : support) known += (known.empty() ? "" : ", ") + f.name;
      throw InputError("--filters: unknown filter '" + name + "' (known: " + known + ", " + particle_filter_name +
                       ", " + exact_filter_name + ", or all)");
    }
    KUSHNER_INPUT_REQUIRE(it->unsupported == nullptr, "filter " << name << " does not support model '" << Model::name
                                                                << "' (" << it->unsupported << ")");
  }
  std::vector<std::string> ordered;  // report order, each once
  for (const auto& f : support)
    if (std::find(requested.begin(), requested.end(), f.name) != requested.end()) ordered.push_back(f.name);
  return ordered;
}

/// `--filters` with the estimators beside the bank: the bank's filters (select_filters), then "PF" (the
/// particle filter) and "EXACT" (exact or grid filter) where named. "all" is every bank filter the model
/// supports plus PF where it applies; EXACT only on request (the grid filter is far slower than the rest).
template <class Model>
std::vector<std::string> select_estimators(const std::string& list, const Model& model) {
  KUSHNER_INPUT_REQUIRE(!list.empty(), "--filters: empty list");
  std::string bank_list;
  bool all = false, particle = false, exact = false;
  std::string current;
  for (std::size_t i = 0; i <= list.size(); ++i) {
    if (i < list.size() && list[i] != ',') {
      if (list[i] != ' ') current += list[i];
      continue;
    }
    if (current == "all") {
      all = true;
    } else if (current == particle_filter_name) {
      KUSHNER_INPUT_REQUIRE(particle_filter_unsupported<Model>() == nullptr,
                            "filter " << particle_filter_name << " does not support model '" << Model::name << "' ("
                                      << particle_filter_unsupported<Model>() << ")");
      particle = true;
    } else if (current == exact_filter_name) {
      const char* why_not = exact_filter_unsupported(model);
      KUSHNER_INPUT_REQUIRE(why_not == nullptr, "filter " << exact_filter_name << " does not support model '"
                                                          << Model::name << "' (" << why_not << ")");
      exact = true;
    } else {
      bank_list += (bank_list.empty() ? "" : ",") + current;
    }
    current.clear();
  }
  if (all) {  // "all" anywhere in the list (e.g. all,EXACT): every bank filter, and PF where it applies
    if (!bank_list.empty()) select_filters<Model>(bank_list, model);  // names beside it must still be valid
    bank_list = "all";
    particle = particle || particle_filter_unsupported<Model>() == nullptr;
  }
  std::vector<std::string> names =
      bank_list.empty() ? std::vector<std::string>{} : select_filters<Model>(bank_list, model);
  if (particle) names.push_back(particle_filter_name);
  if (exact) names.push_back(exact_filter_name);
  return names;
}

}  // namespace kushner
