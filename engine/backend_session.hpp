#pragma once
// Which backend a run uses, what it records about it, and the Kokkos session around it: the declarations that need no
// Kokkos header, so that the sources which only name a backend (the command line, the run's metadata, the memory
// check) compile on the host alone (cmake/host_only.cmake). engine/backend.hpp adds the calls that take Kokkos' types.
#include <optional>
#include <string>
#include <vector>

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
