#pragma once
// A device-side list of the addresses of several bank columns, so that one kernel reduces all of them: the
// output step's moments (kernels/ensemble_moments.hpp) and divergence counts (kernels/filters/filter_metrics.hpp).
// Uploaded again only when the addresses change: a bank calls with the same columns at every output step, and on
// a GPU each allocation, copy and release would wait for the device.
#include <Kokkos_Core.hpp>

#include <cstdint>
#include <vector>

namespace kushner {

template <class MemSpace>
class DeviceAddresses {
 public:
  using View = Kokkos::View<const std::uintptr_t*, MemSpace>;

  /// The device copy of `addresses`; valid until the next call.
  template <class ExecSpace>
  const View& update(const ExecSpace& space, const std::vector<std::uintptr_t>& addresses) {
    if (addresses == addresses_) return device_;
    Kokkos::View<std::uintptr_t*, MemSpace> device(
        Kokkos::view_alloc(space, Kokkos::WithoutInitializing, "kushner::device_addresses"), addresses.size());
    const Kokkos::View<const std::uintptr_t*, Kokkos::HostSpace, Kokkos::MemoryTraits<Kokkos::Unmanaged>> host(
        addresses.data(), addresses.size());
    Kokkos::deep_copy(space, device, host);
    space.fence();  // `host` reads the caller's vector
    device_ = device;
    addresses_ = addresses;
    return device_;
  }

 private:
  std::vector<std::uintptr_t> addresses_;
  View device_;
};

}  // namespace kushner
