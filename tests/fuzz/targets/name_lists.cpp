// `--filters` and `--controllers` against one model's table: an accepted list names only what the model
// supports, each once, filters in report order. The first byte picks the option, the rest is the list.
#include "drivers/name_lists.hpp"
#include "core/errors.hpp"
#include "tests/fuzz/fuzz_check.hpp"
#include "tests/fuzz/fuzz_targets.hpp"

#include <algorithm>
#include <string>
#include <vector>

namespace kushner::fuzz {

namespace {

// A model's tables as the drivers build them (the names are the real ones; which are unsupported is made up,
// so that every kind of refusal can be reached).
EstimatorTable estimators() {
  return {"fuzz-model",
          {{"KB", "the model is not linear"},
           {"EKF", nullptr},
           {"EKF-DS", nullptr},
           {"QLF", nullptr},
           {"POLY3", "drift is not polynomial"},
           {"UKF", nullptr}},
          {"PF", nullptr},
          {"EXACT", "dimension above 2"}};
}

ControllerTable controllers() {
  return {"fuzz-model",
          {{"LQG", "LQR@KB"}, {"ASRE-C", "ASRE@ASRE"}, {"POLYREG", "POLY3@state"}, {"BROKEN", "LQR"}},
          {{"NONE", nullptr}, {"LQR", nullptr}, {"ASRE", "no factorization"}, {"POLY3", nullptr}, {"HJB", nullptr}},
          {"state", "EKF", "EKF-DS", "QLF", "UKF", "PF"},
          estimators().bank};
}

void check_filters(const std::string& list) {
  const EstimatorTable table = estimators();
  const std::vector<std::string> names = select_estimator_names(list, table);
  FUZZ_CHECK(!names.empty(), "an accepted --filters list selects nothing");
  std::size_t last = 0;  // report order: the bank's, then PF, then EXACT
  std::vector<std::string> order;
  for (const auto& f : table.bank) order.push_back(f.name);
  order.push_back(table.particle.name);
  order.push_back(table.exact.name);
  for (std::size_t i = 0; i < names.size(); ++i) {
    const auto at = std::find(order.begin(), order.end(), names[i]);
    FUZZ_CHECK(at != order.end(), "a selected filter that does not exist");
    const std::size_t index = static_cast<std::size_t>(at - order.begin());
    FUZZ_CHECK(i == 0 || index > last, "selected filters out of report order or twice");
    last = index;
    const char* why = index < table.bank.size()         ? table.bank[index].unsupported
                      : names[i] == table.particle.name ? table.particle.unsupported
                                                        : table.exact.unsupported;
    FUZZ_CHECK(why == nullptr, "a selected filter the model does not support");
  }
}

void check_controllers(const std::string& list) {
  const ControllerTable table = controllers();
  const std::vector<ControllerName> specs = select_controller_names(list, table);
  FUZZ_CHECK(!specs.empty(), "an accepted --controllers list selects nothing");
  for (std::size_t i = 0; i < specs.size(); ++i) {
    const auto law = std::find_if(table.laws.begin(), table.laws.end(),
                                  [&](const NameAvailability& l) { return l.name == specs[i].law; });
    FUZZ_CHECK(law != table.laws.end() && law->unsupported == nullptr, "a controller with a law it cannot use");
    FUZZ_CHECK(std::count(table.estimators.begin(), table.estimators.end(), specs[i].estimator) == 1,
               "a controller with an estimator it cannot use");
    for (std::size_t j = 0; j < i; ++j) FUZZ_CHECK(specs[j].name != specs[i].name, "a controller named twice");
  }
}

}  // namespace

int name_lists(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string list(reinterpret_cast<const char*>(data) + 1, size - 1);
  try {
    if (data[0] & 1)
      check_controllers(list);
    else
      check_filters(list);
  } catch (const InputError&) {
  }
  return 0;
}

}  // namespace kushner::fuzz
