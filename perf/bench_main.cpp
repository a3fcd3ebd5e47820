// Google Benchmark main for kushner: Kokkos initialized once; git hash, backend and threads or device in
// the benchmark context so that every JSON result says what produced it.
#include "drivers/backend.hpp"
#include "drivers/run_metadata.hpp"

#include <benchmark/benchmark.h>

int main(int argc, char** argv) {
  kushner::KokkosSession kokkos;
  ::benchmark::Initialize(&argc, argv);
  if (::benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  const auto backend = kushner::describe_backend(kushner::available_backends().front());
  ::benchmark::AddCustomContext("kushner", kushner::version_string());
  ::benchmark::AddCustomContext("backend", backend.dump());
  ::benchmark::RunSpecifiedBenchmarks();
  ::benchmark::Shutdown();
  return 0;
}
