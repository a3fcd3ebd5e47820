#pragma once
// Which Kokkos execution space a run uses. The command line says what to compute; the environment says
// where: KUSHNER_BACKEND=serial|openmp|cuda (default: Kokkos' default execution space) and OMP_NUM_THREADS.
// So the recorded command, and every per-member number, is the same whatever backend ran it.
#include "core/errors.hpp"

#include <Kokkos_Core.hpp>

#include <optional>
#include <string>
#include <type_traits>
#include <vector>

// The serial backend, where Kokkos has it; not in CI's CUDA compile check (KUSHNER_CUDA_COMPILE_CHECK), which
// compiles the commands for the GPU alone: the host backends' code is the host build's, and leaving it out there
// saved a quarter of each unit's compile (instance_unit_0: 58.9 -> 45.1 s).
#if defined(KOKKOS_ENABLE_SERIAL) && !defined(KUSHNER_CUDA_COMPILE_CHECK)
#define KUSHNER_RUNS_SERIAL
#endif

namespace kushner {

/// Backends compiled into this binary, default first.
std::vector<std::string> available_backends();

/// KUSHNER_BACKEND if set (checked against available_backends(): InputError otherwise), else the default.
/// InputError in a CUDA build where no GPU is usable (Kokkos could not start, whatever the backend).
std::string selected_backend();

/// What a run records about where it ran. Needs Kokkos initialized.
struct BackendDescription {
  std::string name;    // an available_backends() name
  std::string kokkos;  // Kokkos version, "3.4.1"
  int threads = 0;     // host backends; 0 on a GPU
  std::string device;  // GPU name; empty on the host
};
BackendDescription describe_backend(const std::string& name);

/// Bytes of memory the backend `name` can still allocate: free device memory for a GPU, MemAvailable of
/// /proc/meminfo on the host; nullopt where unknown. For the GPU it needs Kokkos initialized.
std::optional<double> available_memory_bytes(const std::string& name);

/// Calls f(tag), tag a null pointer to the execution space called `name`: for what depends on its type only,
/// also before Kokkos is initialized (an instance needs an initialized Kokkos; Kokkos 3.4's Cuda() complains).
template <class F>
void with_backend_type(const std::string& name, F&& f) {
#if defined(KOKKOS_ENABLE_CUDA)
  if (name == "cuda") return f(static_cast<Kokkos::Cuda*>(nullptr));
#endif
#if defined(KOKKOS_ENABLE_OPENMP)
  if (name == "openmp") return f(static_cast<Kokkos::OpenMP*>(nullptr));
#endif
#if defined(KUSHNER_RUNS_SERIAL)
  if (name == "serial") return f(static_cast<Kokkos::Serial*>(nullptr));
#endif
  KUSHNER_REQUIRE(false, "backend '" << name << "' is not compiled in");
}

/// Calls f(space) with an instance of the execution space called `name` (Kokkos initialized).
template <class F>
void with_backend(const std::string& name, F&& f) {
  with_backend_type(name, [&](auto* tag) { f(std::remove_pointer_t<decltype(tag)>()); });
}

/// Kokkos::initialize / finalize around a run. Sets OMP_PROC_BIND=false when unset, which is libgomp's
/// default anyway, because Kokkos 3.4 otherwise prints a warning to stdout on every start.
class KokkosSession {
 public:
  KokkosSession();
  ~KokkosSession();
  KokkosSession(const KokkosSession&) = delete;
  KokkosSession& operator=(const KokkosSession&) = delete;
};

}  // namespace kushner
