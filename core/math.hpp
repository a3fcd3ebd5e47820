#pragma once
// Device-callable math: Kokkos' functions (core/portability.hpp picks their namespace) and a few of our own.
#include "core/portability.hpp"

#include <Kokkos_Core.hpp>

#include <cmath>
#include <cstdint>
#include <cstring>

namespace kushner::math {

using impl::atan;
using impl::atan2;
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

/// sin and cos of a double on a host: one range reduction for both, written out so that a loop over members in SIMD
/// lanes computes it inline (a libmvec call clobbers every vector register, and GCC has no vector sincos).
#if !KUSHNER_CUDA_DEVICE_PASS && (defined(__FMA__) || defined(__ARM_FEATURE_FMA))
#define KUSHNER_HOST_SIN_COS 1
#else
#define KUSHNER_HOST_SIN_COS 0
#endif

struct SinCos {
  double sin, cos;
};

#if KUSHNER_HOST_SIN_COS
/// Largest |x| that host_sin_cos reduces: q = x 2/pi stays below 2^44, where the shift below rounds it exactly and
/// pi/2 in three doubles leaves r within 2^-54. An ulp of x is 2^-9 there; past it both results are NaN (a model's
/// state that far out has diverged, and NaN marks it so).
constexpr double host_sin_cos_limit = 17592186044416.0;  // 2^44

/// x = q pi/2 + r with |r| <= pi/4 (q rounded from the exact product by adding 1.5 2^52, whose last two bits are then
/// q mod 4; r by fused multiply-adds with pi/2 = c1 + c2 + c3), then fdlibm's minimax polynomials for sin and cos on
/// [-pi/4, pi/4] (k_sin.c, k_cos.c, Sun Microsystems 1993) and the quadrant's signs. Errors against long double's
/// sinl and cosl (test_math): at most 1.1 2^-53 in absolute value below the limit (glibc's sin: 0.5), within an ulp of
/// the result for |x| <= pi/4 and near the zeros of either. sin(-0) is +0. Every multiply-add is a std::fma, so
/// scalar and SIMD code give the same bits. Always inlined: a call in a loop stops GCC from vectorizing it.
__attribute__((always_inline)) inline SinCos host_sin_cos(const double x) {
  constexpr double shift = 6755399441055744.0;  // 1.5 2^52
  constexpr double c1 = 1.5707963267948966, c2 = 6.123233995736766e-17, c3 = -1.4973849048591698e-33;
  const double shifted = std::fma(x, 0.63661977236758134, shift);
  const double q = shifted - shift;
  std::uint64_t bits;
  std::memcpy(&bits, &shifted, sizeof bits);
  const double r0 = std::fma(-q, c1, x);
  const double r1 = std::fma(-q, c2, r0);
  const double r = std::fma(-q, c3, r1);
  const double z = r * r;
  double ps = std::fma(z, 1.58969099521155010221e-10, -2.50507602534068634195e-08);
  ps = std::fma(z, ps, 2.75573137070700676789e-06);
  ps = std::fma(z, ps, -1.98412698298579493134e-04);
  ps = std::fma(z, ps, 8.33333333332248946124e-03);
  const double sin_r = std::fma(r * z, std::fma(z, ps, -1.66666666666666324348e-01), r);
  double pc = std::fma(z, -1.13596475577881948265e-11, 2.08757232129817482790e-09);
  pc = std::fma(z, pc, -2.75573143513906633035e-07);
  pc = std::fma(z, pc, 2.48015872894767294178e-05);
  pc = std::fma(z, pc, -1.38888888888741095749e-03);
  pc = std::fma(z, pc, 4.16666666666666019037e-02);
  const double w = std::fma(-0.5, z, 1.0);                                   // 1 - z/2 rounded (z/2 is exact),
  const double cos_r = w + std::fma(z * z, pc, std::fma(-0.5, z, 1.0 - w));  // its rounding error added back
  // sin x, cos x = (s, c), (c, -s), (-s, -c), (-c, s) for q mod 4 = 0, 1, 2, 3.
  const bool odd = (bits & 1) != 0, sin_negative = (bits & 2) != 0, cos_negative = ((bits + 1) & 2) != 0;
  const double s = odd ? cos_r : sin_r, c = odd ? sin_r : cos_r;
  const bool reduced = std::fabs(x) < host_sin_cos_limit;
  return {reduced ? (sin_negative ? -s : s) : quiet_nan(), reduced ? (cos_negative ? -c : c) : quiet_nan()};
}
#endif

KOKKOS_FORCEINLINE_FUNCTION double sin(double x) {
#if KUSHNER_HOST_SIN_COS
  return host_sin_cos(x).sin;
#else
  return impl::sin(x);
#endif
}

KOKKOS_FORCEINLINE_FUNCTION double cos(double x) {
#if KUSHNER_HOST_SIN_COS
  return host_sin_cos(x).cos;
#else
  return impl::cos(x);
#endif
}

KOKKOS_INLINE_FUNCTION float cos(float x) { return impl::cos(x); }

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

KOKKOS_INLINE_FUNCTION double square(double v) { return v * v; }

/// +inf (Kokkos 3.4 and 4.x both keep it in Kokkos::Experimental).
KOKKOS_INLINE_FUNCTION constexpr double infinity() { return Kokkos::Experimental::infinity<double>::value; }

/// s = sin(x), c = cos(x) with the same bits as math::sin and math::cos (on a GPU too: test_model_forms), from one
/// range reduction: on a GPU CUDA's sincos (nvcc does not merge those of a sin and a cos of the same x), on a host with
/// fused multiply-adds host_sin_cos.
KOKKOS_FORCEINLINE_FUNCTION void sin_cos(double x, double& s, double& c) {
#if KUSHNER_CUDA_DEVICE_PASS
  ::sincos(x, &s, &c);
#elif KUSHNER_HOST_SIN_COS
  const SinCos both = host_sin_cos(x);
  s = both.sin;
  c = both.cos;
#else
  s = sin(x);
  c = cos(x + 0.0);  // x + 0.0: not a call GCC fuses with sin(x) into sincos, which has no vector version
#endif
}

/// Host: cos(2 pi u) as cos_sin_two_pi computes its c there, the same bits (one expression for both).
inline double cos_two_pi_host(double u) { return cos(2.0 * pi * u); }

/// c = cos(2 pi u), s = sin(2 pi u). On a GPU CUDA's sincospi: no range reduction and one polynomial pair for
/// both (the angle 2 pi u is never rounded); elsewhere sin_cos of the rounded angle.
KOKKOS_INLINE_FUNCTION void cos_sin_two_pi(double u, double& c, double& s) {
#if KUSHNER_CUDA_DEVICE_PASS
  ::sincospi(2.0 * u, &s, &c);
#else
  sin_cos(2.0 * pi * u, s, c);  // c: cos_two_pi_host's bits
#endif
}

/// cos_sin_two_pi in float (CUDA's sincospif on a GPU).
KOKKOS_INLINE_FUNCTION void cos_sin_two_pi(float u, float& c, float& s) {
#if KUSHNER_CUDA_DEVICE_PASS
  ::sincospif(2.0f * u, &s, &c);
#else
  constexpr float pi_f = static_cast<float>(pi);
  c = cos(2.0f * pi_f * u);  // two expressions of one angle: GCC does not fuse them into sincosf (no vector version)
  s = sin(pi_f * (2.0f * u));
#endif
}

/// log(cosh(x)) without overflow for large |x|.
KOKKOS_INLINE_FUNCTION double log_cosh(double x) {
  const double a = fabs(x);
  return a + log1p(exp(-2.0 * a)) - 0.69314718055994530942;
}

}  // namespace kushner::math
