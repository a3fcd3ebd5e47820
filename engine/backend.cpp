#include "engine/backend.hpp"

#include "engine/processes.hpp"

#include <sched.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <thread>

#if defined(KOKKOS_ENABLE_CUDA)
#include <cuda_runtime_api.h>
#endif
#if defined(KOKKOS_ENABLE_OPENMP)
#include <omp.h>
#endif

namespace kushner {

namespace {

/// Kokkos::initialize sets up every backend compiled in, CUDA's included, so a CUDA build cannot start without a
/// usable GPU, not even on a host backend: say so in one line instead of Kokkos' "cudaGetDeviceCount ...
/// insufficient driver" internal error.
void require_usable_gpu() {
#if defined(KOKKOS_ENABLE_CUDA)
  int count = 0;
  const cudaError_t error = cudaGetDeviceCount(&count);
  if (error != cudaSuccess || count == 0)
    throw InputError(std::string("no usable GPU (cudaGetDeviceCount: ") +
                     (error != cudaSuccess ? cudaGetErrorString(error) : "no device") +
                     "); a CUDA build needs one whatever KUSHNER_BACKEND says: on this machine use a build made "
                     "with -DKUSHNER_ENABLE_CUDA=OFF");
#endif
}

/// The node's GPUs as the CUDA runtime counts them (1 where it counts none, or in a build without CUDA): what the
/// ranks' GPUs (rank_gpu) and the ranks sharing one's memory (ranks_sharing_memory) are counted from.
int node_gpus() {
  int devices = 1;
#if defined(KOKKOS_ENABLE_CUDA)
  if (cudaGetDeviceCount(&devices) != cudaSuccess || devices < 1) devices = 1;
#endif
  return devices;
}

/// The GPU this process runs on: its local rank's, round robin over the node's GPUs (two ranks may share one).
int rank_gpu() { return local_rank() % node_gpus(); }

}  // namespace

std::vector<std::string> available_backends() {
  std::vector<std::string> names;
#if defined(KOKKOS_ENABLE_CUDA)
  names.emplace_back("cuda");
#endif
#if defined(KOKKOS_ENABLE_OPENMP)
  names.emplace_back("openmp");
#endif
#if defined(KUSHNER_SERIAL_ON_OPENMP) || defined(KUSHNER_RUNS_SERIAL)
  names.emplace_back("serial");
#endif
  return names;
}

std::string selected_backend() {
  require_usable_gpu();
  const auto names = available_backends();
  const char* env = std::getenv("KUSHNER_BACKEND");
  if (env == nullptr || *env == '\0') return names.front();
  for (const auto& n : names)
    if (n == env) return n;
  std::string known;
  for (const auto& n : names) known += (known.empty() ? "" : ", ") + n;
  throw InputError(std::string("KUSHNER_BACKEND: backend '") + env + "' is not available (built: " + known + ")");
}

BackendDescription describe_backend(const std::string& name) {
  std::ostringstream kokkos;
  kokkos << KOKKOS_VERSION / 10000 << "." << (KOKKOS_VERSION / 100) % 100 << "." << KOKKOS_VERSION % 100;
  BackendDescription d;
  d.name = name;
  d.kokkos = kokkos.str();
#if defined(KOKKOS_ENABLE_CUDA)
  if (name == "cuda") d.device = Kokkos::Cuda().cuda_device_prop().name;
#endif
#if defined(KOKKOS_ENABLE_OPENMP)
  if (name == "openmp" || name == "serial") d.threads = Kokkos::OpenMP().concurrency();  // serial: KokkosSession's 1
#else
  if (name == "serial") d.threads = 1;
#endif
  return d;
}

std::optional<double> available_memory_bytes(const std::string& name) {
#if defined(KOKKOS_ENABLE_CUDA)
  if (name == "cuda") {
    // The memory check runs before Kokkos starts: without choosing the rank's GPU first, every rank asked GPU 0 (the
    // runtime's default), and a rank of another GPU read GPU 0's free memory and opened a context there (the
    // memory and start-up time of a second context, and a share of GPU 0 under its neighbour).
    std::size_t free_bytes = 0, total_bytes = 0;
    if (cudaSetDevice(rank_gpu()) != cudaSuccess || cudaMemGetInfo(&free_bytes, &total_bytes) != cudaSuccess)
      return std::nullopt;
    return static_cast<double>(free_bytes);
  }
#endif
  (void)name;
  std::ifstream meminfo("/proc/meminfo");
  std::string key;
  double kib = 0.0;
  std::string unit;
  while (meminfo >> key >> kib >> unit)
    if (key == "MemAvailable:") return kib * 1024.0;
  return std::nullopt;
}

namespace {
void set_openmp_threads(unsigned threads) {
#if defined(KOKKOS_ENABLE_OPENMP)
  omp_set_num_threads(static_cast<int>(threads));
#else
  (void)threads;
#endif
}
}  // namespace

int ranks_sharing_memory(const std::string& name) {
  const int devices = name == "cuda" ? node_gpus() : 1;
  return (local_ranks() + devices - 1) / devices;
}

KokkosSession::KokkosSession(const std::string& backend) {
  setenv("OMP_PROC_BIND", "false", /*overwrite=*/0);
  std::vector<std::string> args = {"kushner"};
#if defined(KUSHNER_SERIAL_ON_OPENMP)
  const bool one_thread = backend == "serial";
  if (one_thread) args.push_back("--kokkos-threads=1");
#else
  (void)backend;
  const bool one_thread = false;
#endif
  if (local_ranks() > 1) {
    // Ranks on one node share it: each takes the GPU of its local rank (round robin when there are fewer GPUs,
    // e.g. two ranks on one GPU), and, when mpirun left it unbound and OMP_NUM_THREADS is unset, its share of
    // the cores (a rank bound to cores gets as many threads as it has cores from OpenMP itself).
    args.push_back("--kokkos-device-id=" + std::to_string(rank_gpu()));
    cpu_set_t mask;
    const unsigned hardware = std::thread::hardware_concurrency();
    const bool unbound =
        sched_getaffinity(0, sizeof mask, &mask) == 0 && CPU_COUNT(&mask) >= static_cast<int>(hardware);
    // OpenMP read OMP_NUM_THREADS when it was loaded: set its thread count itself.
    if (unbound && std::getenv("OMP_NUM_THREADS") == nullptr && !one_thread)
      set_openmp_threads(std::max(1u, hardware / local_ranks()));
  }
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  int argc = static_cast<int>(args.size());
  Kokkos::initialize(argc, argv.data());
}

KokkosSession::~KokkosSession() { Kokkos::finalize(); }

}  // namespace kushner
