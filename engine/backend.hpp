#pragma once
// Which Kokkos execution space a run uses. The command line says what to compute; the environment says
// where: KUSHNER_BACKEND=serial|openmp|cuda (default: Kokkos' default execution space) and OMP_NUM_THREADS.
// So the recorded command, and every per-member number, is the same whatever backend ran it.
#include "core/errors.hpp"
#include "engine/backend_session.hpp"

#include <Kokkos_Core.hpp>

#include <string>
#include <type_traits>

// The backend `serial` is the host on one thread. Where OpenMP is built it is OpenMP's code on one thread
// (KokkosSession starts OpenMP with one thread): the same bits as Kokkos::Serial (the reproducibility tests compared
// the two for every command), and every kernel is compiled once per host instead of twice (instance_unit_0 compiled
// side by side with and without Kokkos::Serial's copy: 155 -> 127 s, its object 7.4 -> 5.4 MB). The price is OpenMP's
// parallel region around each kernel on one thread: a one-member run of 80000 steps, 16.0 -> 18.0 s (medians of 5)
// (`reproduce basin-car-filter`). Kokkos::Serial runs it only in a build without OpenMP (KUSHNER_RUNS_SERIAL), and not
// in a CUDA build for the GPU alone (KUSHNER_GPU_BACKEND_ONLY: CI's CUDA compile check, and the CMake option).
#if defined(KOKKOS_ENABLE_OPENMP)
#define KUSHNER_SERIAL_ON_OPENMP
#elif defined(KOKKOS_ENABLE_SERIAL) && !defined(KUSHNER_GPU_BACKEND_ONLY)
#define KUSHNER_RUNS_SERIAL
#endif

namespace kushner {

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

}  // namespace kushner
