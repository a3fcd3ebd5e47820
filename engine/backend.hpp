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

// The backend `serial` is the host on one thread. Where OpenMP is built it is OpenMP's code on one thread
// (KokkosSession starts OpenMP with one thread): the same bits as Kokkos::Serial (the reproducibility tests compared
// the two for every command), and every kernel is compiled once per host instead of twice (instance_unit_0 compiled
// side by side with and without Kokkos::Serial's copy: 155 -> 127 s, its object 7.4 -> 5.4 MB). The price is OpenMP's
// parallel region around each kernel on one thread: a one-member run of 80000 steps, 16.0 -> 18.0 s (medians of 5)
// (`reproduce basin-car-filter`). Kokkos::Serial runs it only in a build without OpenMP (KUSHNER_RUNS_SERIAL), and not
// in CI's CUDA compile check (KUSHNER_CUDA_COMPILE_CHECK), which compiles the commands for the GPU alone.
#if defined(KOKKOS_ENABLE_OPENMP)
#define KUSHNER_SERIAL_ON_OPENMP
#elif defined(KOKKOS_ENABLE_SERIAL) && !defined(KUSHNER_CUDA_COMPILE_CHECK)
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
  if (name == "openmp" || name == "serial") return f(static_cast<Kokkos::OpenMP*>(nullptr));
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

/// Kokkos::initialize / finalize around a run on the backend `backend` (an available_backends() name): OpenMP
/// starts with one thread for `serial`. Sets OMP_PROC_BIND=false when unset, which is libgomp's default anyway,
/// because Kokkos 3.4 otherwise prints a warning to stdout on every start.
class KokkosSession {
 public:
  explicit KokkosSession(const std::string& backend);
  ~KokkosSession();
  KokkosSession(const KokkosSession&) = delete;
  KokkosSession& operator=(const KokkosSession&) = delete;
};

}  // namespace kushner
