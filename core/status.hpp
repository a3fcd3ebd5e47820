#pragma once
// Per-member outcome of a filter or simulation. A diverged member is a result, not a crash: kernels set
// its status, stop updating it, and the host counts and reports it.
#include <cstdint>

namespace kushner {

enum class Status : std::uint8_t {
  ok = 0,
  not_positive_definite = 1,  // a covariance lost positive definiteness
  non_finite = 2,             // a NaN or Inf appeared in a state, estimate or covariance
};

inline const char* to_string(Status s) {
  switch (s) {
    case Status::ok: return "ok";
    case Status::not_positive_definite: return "not_positive_definite";
    case Status::non_finite: return "non_finite";
  }
  return "unknown";
}

}  // namespace kushner
