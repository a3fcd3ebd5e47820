#pragma once
// The execution spaces this build runs kushner's kernels on, for TYPED_TESTs that must hold on every backend: the
// GPU's and the host's, which is Kokkos' default host space (OpenMP where built, which then also runs the `serial`
// backend, else Serial: engine/backend.hpp).
#include <gtest/gtest.h>
#include <Kokkos_Core.hpp>

namespace kushner::test {

using ExecutionSpaces = ::testing::Types<
#if defined(KOKKOS_ENABLE_CUDA)
    Kokkos::Cuda,
#endif
    Kokkos::DefaultHostExecutionSpace>;

}  // namespace kushner::test
