#pragma once
// Everything that differs between compilers, backends and Kokkos versions, in one place: which pass of the
// compiler is generating GPU code, loop-unrolling hints for it, and where Kokkos keeps its math functions.
#include <Kokkos_Core.hpp>

/// 1 while nvcc compiles the device side of a translation unit (CUDA intrinsics are available), else 0.
#if defined(__CUDA_ARCH__)
#define KUSHNER_CUDA_DEVICE_PASS 1
#else
#define KUSHNER_CUDA_DEVICE_PASS 0
#endif

/// Full unrolling of fixed-size loops in GPU kernels (nvcc's device pass; GCC would warn about the pragma).
#if KUSHNER_CUDA_DEVICE_PASS
#define KUSHNER_DEVICE_UNROLL _Pragma("unroll")
#else
#define KUSHNER_DEVICE_UNROLL
#endif

namespace kushner::math {

/// Kokkos 3.4 keeps its device-callable math functions in Kokkos::Experimental, Kokkos 4 in Kokkos.
#if KOKKOS_VERSION >= 40000
namespace impl = ::Kokkos;
#else
namespace impl = ::Kokkos::Experimental;
#endif

}  // namespace kushner::math
