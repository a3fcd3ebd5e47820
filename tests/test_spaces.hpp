#pragma once
// The execution spaces this build runs kushner's kernels on, for TYPED_TESTs that must hold on every backend:
// Kokkos::Serial only where it runs the `serial` backend (a build without OpenMP: engine/backend.hpp).
#include "engine/backend.hpp"

#include <gtest/gtest.h>
#include <Kokkos_Core.hpp>

namespace kushner::test {

using ExecutionSpaces = ::testing::Types<
#if defined(KOKKOS_ENABLE_CUDA)
    Kokkos::Cuda
#if defined(KOKKOS_ENABLE_OPENMP) || defined(KUSHNER_RUNS_SERIAL)
    ,
#endif
#endif
#if defined(KOKKOS_ENABLE_OPENMP)
    Kokkos::OpenMP
#elif defined(KUSHNER_RUNS_SERIAL)
    Kokkos::Serial
#endif
    >;

}  // namespace kushner::test
