#pragma once
// The banks and closed loops of every model of the registry's lists (models/model_list.hpp) on every execution space
// of the build are compiled once, in the engine's instance units (engine/instance_unit.cpp.in), and the headers that
// define them declare them extern here: the commands, tests and benchmarks that run them link those instead of
// compiling the same kernels again (CMake option KUSHNER_SHARED_INSTANCES; off in CI's sanitizer build, which builds
// a few tests and compiles what each uses). Only members defined outside the class body are shared (GCC compiles
// inline members where they are used, extern or not), so these classes define outside their bodies the members that
// launch kernels.
//
// A header expands KUSHNER_FOR_EACH_SHARED_INSTANCE after defining KUSHNER_SHARED_INSTANCE(Space, Model) as the
// declaration of its class for one space and model; the instance units define it as the instantiation.
#include "engine/backend.hpp"
#include "models/model_list.hpp"

#include <Kokkos_Core.hpp>

#if defined(KUSHNER_RUNS_SERIAL)
#define KUSHNER_SHARED_IN_SERIAL(Model) KUSHNER_SHARED_INSTANCE(Kokkos::Serial, Model)
#else
#define KUSHNER_SHARED_IN_SERIAL(Model)
#endif
#if defined(KOKKOS_ENABLE_OPENMP)
#define KUSHNER_SHARED_IN_OPENMP(Model) KUSHNER_SHARED_INSTANCE(Kokkos::OpenMP, Model)
#else
#define KUSHNER_SHARED_IN_OPENMP(Model)
#endif
#if defined(KOKKOS_ENABLE_CUDA)
#define KUSHNER_SHARED_IN_CUDA(Model) KUSHNER_SHARED_INSTANCE(Kokkos::Cuda, Model)
#else
#define KUSHNER_SHARED_IN_CUDA(Model)
#endif

/// KUSHNER_SHARED_INSTANCE(Space, Model) for every space of the build.
#define KUSHNER_SHARED_MODEL(Model) \
  KUSHNER_SHARED_IN_SERIAL(Model) KUSHNER_SHARED_IN_OPENMP(Model) KUSHNER_SHARED_IN_CUDA(Model)

#if defined(KUSHNER_SHARED_INSTANCES)
#define KUSHNER_FOR_EACH_SHARED_INSTANCE          \
  KUSHNER_CONTINUOUS_MODELS(KUSHNER_SHARED_MODEL) \
  KUSHNER_DISCRETE_MODELS(KUSHNER_SHARED_MODEL) KUSHNER_FILE_MODELS(KUSHNER_SHARED_MODEL)
#else
#define KUSHNER_FOR_EACH_SHARED_INSTANCE
#endif

#include <type_traits>

namespace kushner {

/// The model type a class is shared for: Model where the class runs it, else NotShared<Model>, for which the class
/// has an empty specialization: nothing is compiled for a model no command runs with it (the particle filter's
/// classes above its largest dimension, the closed loop without a control input).
template <class Model>
struct NotShared {};
template <class Model, bool runs>
using SharedModel = std::conditional_t<runs, Model, NotShared<Model>>;

}  // namespace kushner
