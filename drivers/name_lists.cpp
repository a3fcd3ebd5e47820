#include "drivers/name_lists.hpp"

#include "core/errors.hpp"

#include <algorithm>

namespace kushner {

namespace {

std::string joined(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

std::vector<std::string> names_of(const std::vector<NameAvailability>& entries) {
  std::vector<std::string> names;
  for (const auto& e : entries) names.push_back(e.name);
  return names;
}

const NameAvailability* find(const std::vector<NameAvailability>& entries, const std::string& name) {
  const auto it =
      std::find_if(entries.begin(), entries.end(), [&](const NameAvailability& e) { return e.name == name; });
  return it == entries.end() ? nullptr : &*it;
}

}  // namespace

std::vector<std::string> split_name_list(const std::string& list, const char* option) {
  std::vector<std::string> items;
  std::string current;
  for (std::size_t i = 0; i <= list.size(); ++i) {
    if (i == list.size() || list[i] == ',') {
      KUSHNER_INPUT_REQUIRE(!current.empty(), option << ": empty name in '" << list << "'");
      items.push_back(current);
      current.clear();
    } else if (list[i] != ' ') {
      current += list[i];
    }
  }
  return items;
}

std::vector<std::string> select_bank_filters(const std::string& list, const EstimatorTable& table) {
  std::vector<std::string> supported;
  for (const auto& f : table.bank)
    if (f.unsupported == nullptr) supported.push_back(f.name);
  if (list == "all") return supported;
  const std::vector<std::string> requested = split_name_list(list, "--filters");
  for (const auto& name : requested) {
    const NameAvailability* filter = find(table.bank, name);
    if (filter == nullptr)
      throw InputError("--filters: unknown filter '" + name + "' (known: " + joined(names_of(table.bank)) + ", " +
                       table.particle.name + ", " + table.exact.name + ", or all)");
    KUSHNER_INPUT_REQUIRE(filter->unsupported == nullptr, "filter " << name << " does not support model '"
                                                                    << table.model << "' (" << filter->unsupported
                                                                    << ")");
  }
  std::vector<std::string> ordered;  // report order, each once
  for (const auto& f : table.bank)
    if (std::find(requested.begin(), requested.end(), f.name) != requested.end()) ordered.push_back(f.name);
  return ordered;
}

std::vector<std::string> select_estimator_names(const std::string& list, const EstimatorTable& table) {
  KUSHNER_INPUT_REQUIRE(!list.empty(), "--filters: empty list");
  std::string bank_list;
  bool all = false, particle = false, exact = false;
  std::string current;
  for (std::size_t i = 0; i <= list.size(); ++i) {
    if (i < list.size() && list[i] != ',') {
      if (list[i] != ' ') current += list[i];
      continue;
    }
    KUSHNER_INPUT_REQUIRE(!current.empty(), "--filters: empty name in '" << list << "'");
    if (current == "all") {
      all = true;
    } else if (current == table.particle.name || current == table.exact.name) {
      const NameAvailability& reference = current == table.particle.name ? table.particle : table.exact;
      KUSHNER_INPUT_REQUIRE(reference.unsupported == nullptr, "filter " << reference.name << " does not support model '"
                                                                        << table.model << "' (" << reference.unsupported
                                                                        << ")");
      (current == table.particle.name ? particle : exact) = true;
    } else {
      bank_list += (bank_list.empty() ? "" : ",") + current;
    }
    current.clear();
  }
  if (all) {  // "all" anywhere in the list (e.g. all,EXACT): every bank filter, and PF where it applies
    if (!bank_list.empty()) select_bank_filters(bank_list, table);  // names beside it must still be valid
    bank_list = "all";
    particle = particle || table.particle.unsupported == nullptr;
  }
  std::vector<std::string> names =
      bank_list.empty() ? std::vector<std::string>{} : select_bank_filters(bank_list, table);
  if (particle) names.push_back(table.particle.name);
  if (exact) names.push_back(table.exact.name);
  return names;
}

std::vector<ControllerName> select_controller_names(const std::string& list, const ControllerTable& table) {
  std::vector<ControllerName> specs;
  for (const std::string& item : split_name_list(list, "--controllers")) {
    std::string expanded = item;
    for (const auto& [alias, meaning] : table.aliases)
      if (item == alias) expanded = meaning;
    const std::size_t at = expanded.find('@');
    KUSHNER_INPUT_REQUIRE(
        at != std::string::npos && at > 0 && at + 1 < expanded.size(),
        "--controllers: '" << item << "' is not LAW@ESTIMATOR or an alias (see `kushner controllers`)");
    ControllerName spec{item, expanded.substr(0, at), expanded.substr(at + 1)};
    const NameAvailability* law = find(table.laws, spec.law);
    KUSHNER_INPUT_REQUIRE(law != nullptr, "--controllers: " << item << ": unknown law '" << spec.law
                                                            << "' (known: " << joined(names_of(table.laws)) << ")");
    KUSHNER_INPUT_REQUIRE(law->unsupported == nullptr, "--controllers: " << item << ": law " << spec.law
                                                                         << " cannot control model '" << table.model
                                                                         << "' (" << law->unsupported << ")");
    if (std::find(table.estimators.begin(), table.estimators.end(), spec.estimator) == table.estimators.end()) {
      const NameAvailability* filter = find(table.bank, spec.estimator);
      if (filter != nullptr && filter->unsupported != nullptr)
        throw InputError("--controllers: " + item + ": estimator " + spec.estimator + " does not support model '" +
                         table.model + "' (" + filter->unsupported + ")");
      throw InputError("--controllers: " + item + ": unknown estimator '" + spec.estimator + "' (known for '" +
                       table.model + "': " + joined(table.estimators) + ")");
    }
    for (const auto& other : specs)
      KUSHNER_INPUT_REQUIRE(other.name != spec.name, "--controllers: " << item << " is named twice");
    specs.push_back(spec);
  }
  KUSHNER_INPUT_REQUIRE(!specs.empty(), "--controllers: empty list");
  return specs;
}

}  // namespace kushner
