#pragma once
// A host copy of any view, strided subviews included. Kokkos cannot deep_copy a non-contiguous device view
// straight to the host (no execution space reaches both), so on a device the strided view is first packed
// into a dense one in its own memory space, then copied over. On the host the view is returned as it is. Also
// where the host receives copies made again and again (HostStaging).
#include <Kokkos_Core.hpp>

namespace kushner {

/// Host memory that receives a device's results again and again (an output step's reductions): page-locked for a
/// GPU, where a copy into pageable memory passes through a staging buffer at a fraction of the bus's speed; the
/// host's own memory otherwise.
template <class MemSpace>
struct HostStaging {
  using space = Kokkos::HostSpace;
};
#if defined(KOKKOS_ENABLE_CUDA)
template <>
struct HostStaging<Kokkos::CudaSpace> {
  using space = Kokkos::CudaHostPinnedSpace;
};
#endif

template <class View>
auto host_copy(const View& v) {
  using MemSpace = typename View::memory_space;
  if constexpr (Kokkos::SpaceAccessibility<Kokkos::HostSpace, MemSpace>::accessible) {
    return Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), v);
  } else {
    using Dense = Kokkos::View<typename View::non_const_data_type, Kokkos::LayoutLeft, MemSpace>;
    Kokkos::LayoutLeft layout;
    for (unsigned r = 0; r < View::rank; ++r) layout.dimension[r] = v.extent(r);
    const Dense dense(Kokkos::view_alloc(Kokkos::WithoutInitializing, "kushner::host_copy"), layout);
    Kokkos::deep_copy(dense, v);
    return Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), dense);
  }
}

}  // namespace kushner
