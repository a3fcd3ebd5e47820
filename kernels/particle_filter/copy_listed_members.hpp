#pragma once
// Copies the particles and log-weights of the listed members from one bank to another, for a list whose
// length stays on the device: a fixed number of work items loops over (listed member, particle).
#include "kernels/bank.hpp"

#include <Kokkos_Core.hpp>

namespace kushner {

template <int N, class MemSpace, class Real = double>
struct CopyListedMembers {
  ParticleBank<MemSpace, Real> from_x, to_x;      // (particle, member, i)
  ParticleColumn<MemSpace, Real> from_lw, to_lw;  // (particle, member)
  Kokkos::View<const int*, MemSpace> members;
  Kokkos::View<const int, MemSpace> member_count;
  int num_particles;
  long work_items;  // the range this functor runs over

  KOKKOS_INLINE_FUNCTION void operator()(const long first) const {
    const long items = static_cast<long>(member_count()) * num_particles;
    for (long item = first; item < items; item += work_items) {
      const int member = members(static_cast<int>(item / num_particles)), j = static_cast<int>(item % num_particles);
      for (int i = 0; i < N; ++i) to_x(j, member, i) = from_x(j, member, i);
      to_lw(j, member) = from_lw(j, member);
    }
  }
};

/// to <- from for the members listed in members(0 .. member_count() - 1). No fence.
template <int N, class ExecSpace, class MemSpace, class Real>
void copy_listed_members(const ExecSpace& space, const CopyListedMembers<N, MemSpace, Real>& copy) {
  Kokkos::parallel_for("kushner::copy_listed_members", Kokkos::RangePolicy<ExecSpace>(space, 0, copy.work_items), copy);
}

}  // namespace kushner
