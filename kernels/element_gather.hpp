#pragma once
// Single elements of bank views (a few members' rows: what `kushner compare` records of its chosen members at
// every output time) copied to the host in one kernel and one copy. A host copy per row would, on a GPU, allocate,
// pack, copy and free once per row, each waiting for the device: 27 waits per output step for three members of
// a four-filter bank, more than the step itself.
#include "kernels/device_addresses.hpp"

#include <Kokkos_Core.hpp>

#include <cstdint>
#include <vector>

namespace kushner {

/// Where element (member, column) of a rank-2 view lies (computed, not read: the view may live on a device).
template <class View>
std::uintptr_t element_address(const View& v, long member, int column) {
  static_assert(View::rank == 2, "element_address: a (member, column) view");
  return reinterpret_cast<std::uintptr_t>(v.data() + member * v.stride(0) + column * v.stride(1));
}

template <class MemSpace>
struct GatherElements {
  Kokkos::View<const std::uintptr_t*, MemSpace> addresses;
  Kokkos::View<double*, MemSpace> values;
  KOKKOS_INLINE_FUNCTION void operator()(const int e) const {
    values(e) = *reinterpret_cast<const double*>(addresses(e));
  }
};

/// The doubles at `addresses` (element_address of views in ExecSpace's memory), in their order. Keeps the device
/// list and buffers from call to call: the addresses of the same rows come back at every output time.
template <class ExecSpace>
class ElementGather {
 public:
  using MemSpace = typename ExecSpace::memory_space;

  const std::vector<double>& operator()(const ExecSpace& space, const std::vector<std::uintptr_t>& addresses) {
    host_.resize(addresses.size());
    if (addresses.empty()) return host_;
    const auto& device_addresses = addresses_.update(space, addresses);
    if (values_.extent(0) != addresses.size())
      values_ = Kokkos::View<double*, MemSpace>(
          Kokkos::view_alloc(space, Kokkos::WithoutInitializing, "kushner::gathered_elements"), addresses.size());
    Kokkos::parallel_for("kushner::gather_elements",
                         Kokkos::RangePolicy<ExecSpace>(space, 0, static_cast<int>(addresses.size())),
                         GatherElements<MemSpace>{device_addresses, values_});
    space.fence();
    const Kokkos::View<double*, Kokkos::HostSpace, Kokkos::MemoryTraits<Kokkos::Unmanaged>> host(host_.data(),
                                                                                                 host_.size());
    Kokkos::deep_copy(host, values_);
    return host_;
  }

 private:
  DeviceAddresses<MemSpace> addresses_;
  Kokkos::View<double*, MemSpace> values_;
  std::vector<double> host_;
};

}  // namespace kushner
