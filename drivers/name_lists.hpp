#pragma once
// `--filters` and `--controllers`: comma-separated names checked against what one model offers. The tables of
// what a model offers come from its type (drivers/filter_selection.hpp, drivers/control_command_impl.hpp); the
// checks here take them as plain data, so that they include neither Kokkos nor the kernels and the fuzz target
// of tests/fuzz/ builds them alone.
#include <string>
#include <utility>
#include <vector>

namespace kushner {

/// A name and why the model cannot use it (nullptr: it can).
struct NameAvailability {
  std::string name;
  const char* unsupported;
};

/// `list` split at commas, blanks dropped; InputError "<option>: empty name in '<list>'" for an empty item.
std::vector<std::string> split_name_list(const std::string& list, const char* option);

/// What one model offers `--filters`.
struct EstimatorTable {
  std::string model;                   // its name, for messages
  std::vector<NameAvailability> bank;  // every bank filter, in report order
  NameAvailability particle, exact;    // the particle filter (PF) and the exact or grid filter (EXACT)
};

/// "all" (every supported bank filter) or a list of bank filters, in report order, each once; InputError for an
/// unknown name or one the model does not support.
std::vector<std::string> select_bank_filters(const std::string& list, const EstimatorTable& table);

/// The bank's filters (select_bank_filters), then PF and EXACT where named. "all" anywhere is every supported
/// bank filter plus PF where the model supports it; EXACT only on request (the grid filter is slow).
std::vector<std::string> select_estimator_names(const std::string& list, const EstimatorTable& table);

/// What one model offers `--controllers`.
struct ControllerTable {
  std::string model;
  std::vector<std::pair<std::string, std::string>> aliases;  // alias -> LAW@ESTIMATOR
  std::vector<NameAvailability> laws;                        // every law, with why this model cannot use it
  std::vector<std::string> estimators;                       // the estimators a controller may use here
  std::vector<NameAvailability> bank;                        // every bank filter, for why one is not an estimator
};

struct ControllerName {
  std::string name;  // as given: LAW@ESTIMATOR or an alias
  std::string law, estimator;
};

/// The controllers of `list`, in its order; one InputError line for an item that is not LAW@ESTIMATOR or an
/// alias, an unknown law or estimator, a law or filter the model cannot use, a controller named twice, or an
/// empty list.
std::vector<ControllerName> select_controller_names(const std::string& list, const ControllerTable& table);

}  // namespace kushner
