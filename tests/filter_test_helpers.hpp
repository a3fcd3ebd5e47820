#pragma once
// Helpers shared by the filter and bank tests: comparing two banks (estimates, states) member by member.
#include <Kokkos_Core.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace kushner::test {

/// max over members (rows) of |a - b|_inf / |b|_inf, for two (member, k) views.
template <class ViewA, class ViewB>
double largest_relative_difference(const ViewA& a, const ViewB& b) {
  const auto ha = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), a);
  const auto hb = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), b);
  double worst = 0.0;
  for (std::size_t member = 0; member < ha.extent(0); ++member) {
    double diff = 0.0, scale = 0.0;
    for (std::size_t k = 0; k < ha.extent(1); ++k) {
      diff = std::max(diff, std::abs(ha(member, k) - hb(member, k)));
      scale = std::max(scale, std::abs(hb(member, k)));
    }
    worst = std::max(worst, diff / scale);
  }
  return worst;
}

/// a and b are the same bits (NaN equals NaN).
inline bool same_bits(double a, double b) {
  std::uint64_t x, y;
  std::memcpy(&x, &a, sizeof x);
  std::memcpy(&y, &b, sizeof y);
  return x == y;
}

/// Entries of two (member, k) views of the same shape that are not the same bits.
template <class ViewA, class ViewB>
long entries_not_the_same_bits(const ViewA& a, const ViewB& b) {
  const auto ha = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), a);
  const auto hb = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), b);
  long differ = 0;
  for (std::size_t member = 0; member < ha.extent(0); ++member)
    for (std::size_t k = 0; k < ha.extent(1); ++k) differ += same_bits(ha(member, k), hb(member, k)) ? 0 : 1;
  return differ;
}

}  // namespace kushner::test
