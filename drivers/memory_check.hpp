#pragma once
// A run whose arrays cannot fit is refused before anything is allocated (otherwise Kokkos' allocator stops it
// with an internal error, or the host starts swapping), with the size it needs and where the bytes go.
#include <string>

namespace kushner {

/// "412 B", "3.4 MiB", "2.55 TiB".
std::string format_bytes(double bytes);

/// InputError unless `bytes` fit in what `backend` can still allocate (engine/backend_session.hpp); `sizes` names the
/// options that set them ("--members 100000, --particles 1000000"), `breakdown` where they go. Passes where
/// the free memory is unknown.
void require_memory_fits(double bytes, const std::string& sizes, const std::string& breakdown,
                         const std::string& backend);

/// Whether require_memory_fits would pass.
bool memory_fits(double bytes, const std::string& backend);

}  // namespace kushner
