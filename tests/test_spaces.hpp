#pragma once
// The execution spaces this build turns on, for TYPED_TESTs that must hold on every backend.
#include <gtest/gtest.h>
#include <Kokkos_Core.hpp>

namespace kushner::test {

using ExecutionSpaces = ::testing::Types<
#if defined(KOKKOS_ENABLE_CUDA)
    Kokkos::Cuda,
#endif
#if defined(KOKKOS_ENABLE_OPENMP)
    Kokkos::OpenMP,
#endif
#if defined(KOKKOS_ENABLE_SERIAL)
    Kokkos::Serial
#endif
    >;

}  // namespace kushner::test
