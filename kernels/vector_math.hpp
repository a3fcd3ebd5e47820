#pragma once
// Makes GCC vectorize sin, cos, exp and log (and sinf, cosf, logf) inside `#pragma omp simd` loops by declaring glibc's
// vector variants (libmvec: _ZGV{b,c,d,e}N{2,4,8}v_sin, ...). glibc declares them only under -ffast-math
// (bits/math-vector.h), whose other effects (finite-math-only, reassociation) we do not want; GCC also
// needs -fno-math-errno to call them (CMake sets both when KUSHNER_ENABLE_VECTOR_MATH is on).
// It is most of the host particle step's speed (perf/particle_filter.md, CPU section). With fused multiply-adds the
// host's sin, cos, exp and log of a double are core/math.hpp's own (inline: no call in the loop); libmvec's double
// functions serve builds without them, and its float ones every build. libmvec's results are within 4
// ulp of libm's, so the CPU numbers differ from a scalar build in the last bits; within one binary they are the same on
// any number of threads, because every backend calls the same block function (particle_filter/particle_block_step.hpp)
// or member chunk function (for_each_member.hpp, which includes this header so that every unit compiles it alike).
#if defined(KUSHNER_VECTOR_MATH) && defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && \
    !defined(__CUDACC__)
#include <cmath>

extern "C" {
__attribute__((simd("notinbranch"))) double sin(double) noexcept;
__attribute__((simd("notinbranch"))) double cos(double) noexcept;
__attribute__((simd("notinbranch"))) double exp(double) noexcept;
__attribute__((simd("notinbranch"))) double log(double) noexcept;
// The float ones: the particle filter's `mixed` precision draws its normals in float.
__attribute__((simd("notinbranch"))) float sinf(float) noexcept;
__attribute__((simd("notinbranch"))) float cosf(float) noexcept;
__attribute__((simd("notinbranch"))) float logf(float) noexcept;
}
#endif

// `#pragma omp simd` where GCC honours it (-fopenmp or -fopenmp-simd); nothing elsewhere (nvcc's host pass).
#define KUSHNER_PRAGMA(x) _Pragma(#x)
#if defined(_OPENMP) || defined(KUSHNER_VECTOR_MATH)
#define KUSHNER_SIMD KUSHNER_PRAGMA(omp simd)
#define KUSHNER_SIMD_REDUCTION(...) KUSHNER_PRAGMA(omp simd reduction(__VA_ARGS__))
#else
#define KUSHNER_SIMD
#define KUSHNER_SIMD_REDUCTION(...)
#endif

// A host function whose callees are all inlined into it (GCC vectorizes a loop only when every call in its body
// is inlined or has a vector variant).
#if defined(__GNUC__) && !defined(__clang__) && !defined(__CUDACC__)
#define KUSHNER_FLATTEN __attribute__((flatten))
#else
#define KUSHNER_FLATTEN
#endif
