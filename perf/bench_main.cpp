// Google Benchmark main for kushner: Kokkos initialized once; git hash, backend and threads or device in
// the benchmark context so that every JSON result says what produced it.
#include "engine/backend_session.hpp"
#include "engine/version.hpp"

#include <benchmark/benchmark.h>

int main(int argc, char** argv) {
  kushner::KokkosSession kokkos(kushner::available_backends().front());
  ::benchmark::Initialize(&argc, argv);
  if (::benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  const kushner::BackendDescription backend = kushner::describe_backend(kushner::available_backends().front());
  ::benchmark::AddCustomContext("kushner", kushner::version_string());
  ::benchmark::AddCustomContext(
      "backend", backend.name + (backend.device.empty() ? "" : " (" + backend.device + ")") +
                     (backend.threads > 0 ? " (" + std::to_string(backend.threads) + " threads)" : "") + ", Kokkos " +
                     backend.kokkos);
  ::benchmark::RunSpecifiedBenchmarks();
  ::benchmark::Shutdown();
  return 0;
}
