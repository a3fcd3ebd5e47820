#pragma once
// The banks of every model of the registry's lists (models/model_list.hpp) on every execution space of the build
// are compiled once, in the engine's instance units (engine/instance_unit.cpp.in), and the headers that define them
// declare them extern here: the commands, tests and benchmarks that run them link those instead of compiling the
// same kernels again (CMake option KUSHNER_SHARED_INSTANCES, off in the sanitizer build, which compiles what each
// file uses). Only members defined outside the class body are shared (GCC compiles inline members where they are
// used, extern or not), so the banks define outside their classes the members that launch kernels.
//
// A header expands KUSHNER_FOR_EACH_SHARED_INSTANCE after defining KUSHNER_SHARED_INSTANCE(Space, Model) as the
// declaration of its class for one space and model; the instance units define it as the instantiation.
#include "models/model_list.hpp"

#include <Kokkos_Core.hpp>

#if defined(KOKKOS_ENABLE_SERIAL)
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
