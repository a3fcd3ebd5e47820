#include "drivers/backend.hpp"
#include "drivers/commands.hpp"
#include "models/registry.hpp"

#include <iostream>

namespace kushner {

int run_models(bool json) {
  const nlohmann::json models = describe_models();
  if (json) {
    std::cout << models.dump(2) << "\n";
    return 0;
  }
  for (const auto& m : models) {
    std::cout << m["name"].get<std::string>() << "  (" << m["time"].get<std::string>() << " time, state_dim "
              << m["state_dim"] << ", obs_dim " << m["obs_dim"] << ")\n    " << m["description"].get<std::string>()
              << "\n";
    for (const auto& p : m["parameters"])
      std::cout << "    --set " << p["name"].get<std::string>() << "=" << p["default"].dump() << "  "
                << p["description"].get<std::string>() << "\n";
  }
  return 0;
}

int run_version() {
  const std::string backend = selected_backend();
  KokkosSession kokkos;
  const nlohmann::json b = describe_backend(backend);
  std::cout << version_string() << "\nKokkos " << b["kokkos"].get<std::string>() << "\nbackend: " << backend;
  if (b.contains("threads")) std::cout << " (" << b["threads"] << " threads)";
  if (b.contains("device")) std::cout << " (device: " << b["device"].get<std::string>() << ")";
  std::cout << "\navailable backends:";
  for (const auto& n : available_backends()) std::cout << " " << n;
  std::cout << " (select with KUSHNER_BACKEND)\n";
  return 0;
}

}  // namespace kushner
