#pragma once
// Device-callable math: Kokkos' functions (core/portability.hpp picks their namespace) and a few of our own.
#include "core/portability.hpp"

#include <Kokkos_Core.hpp>

#include <cstdint>
#include <cstring>

namespace kushner::math {

using impl::atan;
using impl::atan2;
using impl::cos;
using impl::cosh;
using impl::exp;
using impl::expm1;
using impl::fabs;
using impl::log;
using impl::log1p;
using impl::pow;
using impl::sinh;
using impl::sqrt;
using impl::tan;
using impl::tanh;

constexpr double pi = 3.14159265358979323846;

KOKKOS_INLINE_FUNCTION double sin(double x) { return impl::sin(x); }

/// sin in float. On a GPU: x reduced to [-pi, pi] (k = round(x / 2 pi); x - 2 pi k with 2 pi in two floats, exact
/// to a float's rounding for |x| < 1e4), then the special-function unit's sine (__sinf, absolute error 2^-21.4 on
/// [-pi, pi]): 6 instructions in place of CUDA's sinf, ~23 and a slow path. Its one user is a float particle step
/// (fp32), where the drift is multiplied by dt: an error of 4e-7 moves a state by 4e-7 dt, far below the float
/// rounding of the state itself. Elsewhere libm's (or libmvec's) sinf.
KOKKOS_INLINE_FUNCTION float sin(float x) {
#if KUSHNER_CUDA_DEVICE_PASS
  const float k = rintf(x * 0.159154943f);
  const float r = fmaf(-k, -1.74845553e-7f, fmaf(-k, 6.28318548f, x));  // 2 pi = 6.28318548f - 1.74845553e-7f
  return __sinf(r);
#else
  return impl::sin(x);
#endif
}

/// True unless v is NaN or +-Inf. Tests the exponent bits, so it stays correct under -ffinite-math-only
/// (implied by -ffast-math), where std::isfinite folds to a constant.
KOKKOS_INLINE_FUNCTION bool is_finite(double v) {
  std::uint64_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  return (bits & 0x7ff0000000000000ull) != 0x7ff0000000000000ull;
}

/// A quiet NaN, built from its bit pattern: std::numeric_limits is not device-callable everywhere.
KOKKOS_INLINE_FUNCTION double quiet_nan() {
  const std::uint64_t bits = 0x7ff8000000000000ull;
  double v;
  std::memcpy(&v, &bits, sizeof v);
  return v;
}

KOKKOS_INLINE_FUNCTION double square(double v) { return v * v; }

/// +inf (Kokkos 3.4 and 4.x both keep it in Kokkos::Experimental).
KOKKOS_INLINE_FUNCTION constexpr double infinity() { return Kokkos::Experimental::infinity<double>::value; }

/// cos(x), bit for bit, written so that GCC does not fuse it with a sin of the same x into sincos, which has no
/// vector version: a loop over members in SIMD lanes that computes both (a filter of the sine model) would not
/// vectorize. x + 0.0 is x except that -0 becomes +0, and cos is even. On a GPU plain cos.
KOKKOS_INLINE_FUNCTION double cos_apart_from_sin(double x) {
#if KUSHNER_CUDA_DEVICE_PASS
  return cos(x);
#else
  return cos(x + 0.0);
#endif
}

/// s = sin(x), c = cos(x) with the same bits as math::sin and cos_apart_from_sin (on a GPU too: test_model_forms). On a
/// GPU CUDA's sincos: one range reduction for both (nvcc does not merge those of a sin and a cos of the same x).
KOKKOS_INLINE_FUNCTION void sin_cos(double x, double& s, double& c) {
#if KUSHNER_CUDA_DEVICE_PASS
  ::sincos(x, &s, &c);
#else
  s = sin(x);
  c = cos_apart_from_sin(x);
#endif
}

/// Host: cos(2 pi u) as cos_sin_two_pi computes its c there, the same bits (one expression for both).
inline double cos_two_pi_host(double u) { return cos(2.0 * pi * u); }

/// c = cos(2 pi u), s = sin(2 pi u). On a GPU CUDA's sincospi: no range reduction and one polynomial pair for
/// both (the angle 2 pi u is never rounded); elsewhere libm's (or libmvec's) cos and sin of the rounded angle.
KOKKOS_INLINE_FUNCTION void cos_sin_two_pi(double u, double& c, double& s) {
#if KUSHNER_CUDA_DEVICE_PASS
  ::sincospi(2.0 * u, &s, &c);
#else
  // The same angle twice, as (2 pi) u and pi (2 u): equal bits (both products are exact before the one
  // rounding), but two expressions, so GCC does not fuse cos and sin into sincos, which has no vector version.
  c = cos_two_pi_host(u);
  s = sin(pi * (2.0 * u));
#endif
}

/// cos_sin_two_pi in float (CUDA's sincospif on a GPU).
KOKKOS_INLINE_FUNCTION void cos_sin_two_pi(float u, float& c, float& s) {
#if KUSHNER_CUDA_DEVICE_PASS
  ::sincospif(2.0f * u, &s, &c);
#else
  constexpr float pi_f = static_cast<float>(pi);
  c = cos(2.0f * pi_f * u);  // as in the double version: two expressions of one angle, not fused into sincosf
  s = sin(pi_f * (2.0f * u));
#endif
}

/// log(cosh(x)) without overflow for large |x|.
KOKKOS_INLINE_FUNCTION double log_cosh(double x) {
  const double a = fabs(x);
  return a + log1p(exp(-2.0 * a)) - 0.69314718055994530942;
}

}  // namespace kushner::math
