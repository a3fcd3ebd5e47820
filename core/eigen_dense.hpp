#pragma once
// Eigen's dense module, as every file of kushner includes it (not <Eigen/Dense> itself): with GCC's warnings about
// Eigen's own code left out. GCC 12 (Debian 12's) reports, in a -march=native build,
// - "'__Y' may be used uninitialized" inside its AVX-512 intrinsics wherever Eigen's packet code inlines them (GCC
//   bug 105593: _mm256_undefined_pd initializes a variable from itself): 3318 of the 3535 warnings of a fresh build;
// - "array subscript 1 is outside array bounds" in the swap of a 1 x 1 LDLT's transpositions, a loop that never
//   runs (the discrete LQR with one control: 164), and a 2-vector read as a packet it never takes (2).
// GCC 12 drops a warning where a pragma disables it at any location of the inlined calls that lead to it; Eigen's
// code lies between this push and pop, so what Eigen's templates inline is covered wherever they are instantiated,
// and kushner's own code keeps both warnings. Clang has no -Wmaybe-uninitialized; nvcc passes the pragmas to g++.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Warray-bounds"
#endif
#include <Eigen/Dense>
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif
