#pragma once
// The ensemble bank: structure-of-arrays Kokkos Views, member index contiguous, and gather/scatter of one
// member's small vectors and matrices. LayoutLeft is spelled out because the default layout differs between
// backends; with it x(member, i) is stride-1 in member, and particles(particle, member, i) is stride-1 in
// particle within a member.
#include "core/small_matrix.hpp"

#include <Kokkos_Core.hpp>

#include <limits>

namespace kushner {

/// (member, i): states, estimates, observation increments.
template <class MemSpace>
using BankVector = Kokkos::View<double**, Kokkos::LayoutLeft, MemSpace>;

/// (member, k): symmetric matrices (covariances) packed by rows of the upper triangle, k = 0 .. N(N+1)/2-1.
/// Storing each off-diagonal entry once keeps P symmetric by construction.
template <class MemSpace>
using BankSymmetric = Kokkos::View<double**, Kokkos::LayoutLeft, MemSpace>;

/// (member, i, j): general matrices (gains, Jacobians) when a filter keeps one.
template <class MemSpace>
using BankMatrix = Kokkos::View<double***, Kokkos::LayoutLeft, MemSpace>;

/// (particle, member, i): particle states, particle index contiguous within a member; stored as Real (float in the
/// particle filter's fp32 precision).
template <class MemSpace, class Real = double>
using ParticleBank = Kokkos::View<Real***, Kokkos::LayoutLeft, MemSpace>;

/// (particle, member): one number per particle (log-weights), stored as Real.
template <class MemSpace, class Real = double>
using ParticleColumn = Kokkos::View<Real**, Kokkos::LayoutLeft, MemSpace>;

/// `v` as it is stored in a Real: rounded to float in the particle filter's fp32 precision, so that what a kernel
/// keeps in registers (and sums into moments, or steps again in a fused pair) is what it stores.
template <class Real>
KOKKOS_INLINE_FUNCTION double stored_value(double v) {
  // IEEE 754 conversion: to nearest, and past float's range to the infinity of the value's sign.
  static_assert(std::numeric_limits<Real>::is_iec559, "particles are stored in IEEE 754 numbers");
  return static_cast<double>(static_cast<Real>(v));
}

/// (member): one scalar per member (status, counts, log-normalizers).
template <class T, class MemSpace>
using BankScalar = Kokkos::View<T*, Kokkos::LayoutLeft, MemSpace>;

KOKKOS_INLINE_FUNCTION constexpr int packed_size(int n) { return n * (n + 1) / 2; }

/// Index of (i, j), i <= j, in the packed upper triangle.
KOKKOS_INLINE_FUNCTION constexpr int packed_index(int n, int i, int j) { return i * n - i * (i - 1) / 2 + (j - i); }

template <int N, class View>
KOKKOS_INLINE_FUNCTION Vec<N> load(const View& x, int member) {
  Vec<N> v;
  for (int i = 0; i < N; ++i) v[i] = x(member, i);
  return v;
}

template <int N, class View>
KOKKOS_INLINE_FUNCTION void store(const View& x, int member, const Vec<N>& v) {
  for (int i = 0; i < N; ++i) x(member, i) = v[i];
}

template <int N, class View>
KOKKOS_INLINE_FUNCTION Mat<N, N> load_symmetric(const View& packed, int member) {
  Mat<N, N> m;
  for (int i = 0; i < N; ++i)
    for (int j = i; j < N; ++j) m(i, j) = m(j, i) = packed(member, packed_index(N, i, j));
  return m;
}

/// Stores the symmetric part of m (symmetrize's).
template <int N, class View>
KOKKOS_INLINE_FUNCTION void store_symmetric(const View& packed, int member, const Mat<N, N>& m) {
  const Mat<N, N> s = symmetrize(m);
  for (int i = 0; i < N; ++i)
    for (int j = i; j < N; ++j) packed(member, packed_index(N, i, j)) = s(i, j);
}

template <int N, class View>
KOKKOS_INLINE_FUNCTION Vec<N> load_particle(const View& particles, int particle, int member) {
  Vec<N> v;
  for (int i = 0; i < N; ++i) v[i] = particles(particle, member, i);
  return v;
}

template <int N, class View>
KOKKOS_INLINE_FUNCTION void store_particle(const View& particles, int particle, int member, const Vec<N>& v) {
  for (int i = 0; i < N; ++i) particles(particle, member, i) = v[i];
}

}  // namespace kushner
