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
using impl::expm1;
using impl::fabs;
using impl::log1p;
using impl::pow;
using impl::sinh;
using impl::sqrt;
using impl::tan;
using impl::tanh;

constexpr double pi = 3.14159265358979323846;

/// A double's bit pattern, and the double of a bit pattern (std::bit_cast is C++20).
KOKKOS_FORCEINLINE_FUNCTION std::uint64_t bits_of(double v) {
  std::uint64_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  return bits;
}
KOKKOS_FORCEINLINE_FUNCTION double from_bits(std::uint64_t bits) {
  double v;
  std::memcpy(&v, &bits, sizeof v);
  return v;
}

/// True unless v is NaN or +-Inf. Tests the exponent bits, so it stays correct under -ffinite-math-only
/// (implied by -ffast-math), where std::isfinite folds to a constant.
KOKKOS_INLINE_FUNCTION bool is_finite(double v) {
  return (bits_of(v) & 0x7ff0000000000000ull) != 0x7ff0000000000000ull;
}

/// is_finite of a float, from its exponent bits as is_finite(double).
KOKKOS_INLINE_FUNCTION bool is_finite(float v) {
  std::uint32_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  return (bits & 0x7f800000u) != 0x7f800000u;
}

/// A quiet NaN, built from its bit pattern: std::numeric_limits is not device-callable everywhere.
KOKKOS_INLINE_FUNCTION double quiet_nan() { return from_bits(0x7ff8000000000000ull); }

/// sin, cos, exp and log of a double on a host, written out so that a loop over members in SIMD lanes computes them
/// inline: a libmvec call clobbers every vector register (the lanes' values are spilled around it), and GCC has no
/// vector sincos. Where there are no fused multiply-adds, libm's (and libmvec's).
#if !KUSHNER_CUDA_DEVICE_PASS && (defined(__FMA__) || defined(__ARM_FEATURE_FMA))
#define KUSHNER_HOST_MATH 1
#else
#define KUSHNER_HOST_MATH 0
#endif

struct SinCos {
  double sin, cos;
};

#if KUSHNER_HOST_MATH
/// Largest |x| that host_sin_cos reduces: q = x 2/pi stays below 2^44, where the shift below rounds it exactly and
/// pi/2 in three doubles leaves r within 2^-54. An ulp of x is 2^-9 there; past it both results are NaN (a model's
/// state that far out has diverged, and NaN marks it so).
constexpr double host_sin_cos_limit = 17592186044416.0;  // 2^44

/// q = x c rounded to the nearest integer (ties to even) from the exact product, for |x c| < 2^51: adding 1.5 2^52
/// leaves q in the sum's last bits, so `bits` is q in two's complement (its low bits q mod 4, q mod 2^k).
struct NearestInteger {
  double value;
  std::uint64_t bits;
};
__attribute__((always_inline)) inline NearestInteger nearest_integer_of_product(const double x, const double c) {
  constexpr double shift = 6755399441055744.0;  // 1.5 2^52
  const double shifted = std::fma(x, c, shift);
  return {shifted - shift, bits_of(shifted) - bits_of(shift)};
}

/// x = q pi/2 + r with |r| <= pi/4 (q by nearest_integer_of_product; r by fused multiply-adds with pi/2 = c1 + c2 +
/// c3), then fdlibm's minimax polynomials for sin and cos on
/// [-pi/4, pi/4] (k_sin.c, k_cos.c, Sun Microsystems 1993) and the quadrant's signs. Errors against long double's
/// sinl and cosl (test_math): at most 1.1 2^-53 in absolute value below the limit (glibc's sin: 0.5), within an ulp of
/// the result for |x| <= pi/4 and near the zeros of either. sin(-0) is +0. Every multiply-add is a std::fma, so
/// scalar and SIMD code give the same bits. Always inlined: a call in a loop stops GCC from vectorizing it.
/// host_sin_cos_below_limit: for |x| < host_sin_cos_limit (the caller bounds x: Box-Muller's angle 2 pi u), the same
/// bits without the test.
__attribute__((always_inline)) inline SinCos host_sin_cos_below_limit(const double x) {
  constexpr double c1 = 1.5707963267948966, c2 = 6.123233995736766e-17, c3 = -1.4973849048591698e-33;
  const NearestInteger rounded = nearest_integer_of_product(x, 0.63661977236758134);  // x 2/pi
  const double q = rounded.value;
  const std::uint64_t bits = rounded.bits;
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
  return {sin_negative ? -s : s, cos_negative ? -c : c};
}
__attribute__((always_inline)) inline SinCos host_sin_cos(const double x) {
  const SinCos both = host_sin_cos_below_limit(x);
  const bool reduced = std::fabs(x) < host_sin_cos_limit;
  return {reduced ? both.sin : quiet_nan(), reduced ? both.cos : quiet_nan()};
}

/// exp x = 2^k exp r with k = round(x / ln 2) (nearest_integer_of_product) and |r| <= ln2 / 2 (ln 2 in two
/// doubles), exp r by its Taylor series to r^13 (truncated below 2^-57 relative), and 2^k applied as two powers of two,
/// so that results in the subnormal range are rounded once. x is clamped to [-745.2, 709.8], past which exp is 0 and
/// +inf. Within 1 ulp of long double's expl (test_math).
__attribute__((always_inline)) inline double host_exp(const double x) {
  constexpr double ln2_hi = 0.6931471805599453, ln2_lo = 2.3190468138462996e-17;
  const double clamped = x > 709.8 ? 709.8 : (x < -745.2 ? -745.2 : x);                    // NaN stays NaN
  const NearestInteger rounded = nearest_integer_of_product(clamped, 1.4426950408889634);  // x / ln 2
  const double k = rounded.value;
  const double r = std::fma(-k, ln2_lo, std::fma(-k, ln2_hi, clamped));
  double p = std::fma(1.0 / 6227020800.0, r, 1.0 / 479001600.0);  // 1 / 13!, 1 / 12!, ...
  p = std::fma(p, r, 1.0 / 39916800.0);
  p = std::fma(p, r, 1.0 / 3628800.0);
  p = std::fma(p, r, 1.0 / 362880.0);
  p = std::fma(p, r, 1.0 / 40320.0);
  p = std::fma(p, r, 1.0 / 5040.0);
  p = std::fma(p, r, 1.0 / 720.0);
  p = std::fma(p, r, 1.0 / 120.0);
  p = std::fma(p, r, 1.0 / 24.0);
  p = std::fma(p, r, 1.0 / 6.0);
  p = std::fma(p, r, 0.5);
  p = std::fma(p, r, 1.0);
  p = std::fma(p, r, 1.0);
  const std::int64_t k_int = static_cast<std::int64_t>(rounded.bits), k1 = k_int >> 1, k2 = k_int - k1;
  // 2^k1 and 2^k2 from their exponent fields (k1, k2 in [-538, 512]).
  return p * from_bits(static_cast<std::uint64_t>(k1 + 1023) << 52) *
         from_bits(static_cast<std::uint64_t>(k2 + 1023) << 52);
}

/// log x = k ln 2 + log m with x = 2^k m, m in [sqrt(2)/2, sqrt(2)) (subnormal x scaled by 2^54 first), and log m by
/// fdlibm's e_log.c (Sun Microsystems 1993): s = f / (2 + f) for f = m - 1, its minimax polynomial in s^2 and the
/// same sums (not fused: the native build's -ffp-contract=off makes scalar and SIMD code round them alike). log 0 =
/// -inf, log of a negative x or NaN is NaN, log inf = inf. Within 1 ulp of long double's logl (test_math).
/// host_log_of_normal: log (2^-scale x) for a positive, normal, finite x (2^scale times a subnormal in host_log;
/// Box-Muller's uniforms as they are), the same bits without the selects of the other cases.
__attribute__((always_inline)) inline double host_log_of_normal(const double x, const int scale = 0) {
  constexpr double ln2_hi = 6.93147180369123816490e-01, ln2_lo = 1.90821492927058770002e-10;  // k ln2_hi exact
  const std::uint64_t bits = bits_of(x);  // unsigned: a negative x's bits would overflow an int64, k << 52 too
  // k + 1024 with k = x's exponent counted from sqrt(2)/2 (0x3fe6a09e667f3bcd: its bits), by a logical shift of a
  // sum that stays in [0, 2^64) for every positive x: AVX2 has no 64-bit arithmetic shift.
  const std::uint64_t k_biased = (bits - 0x3fe6a09e667f3bcdull + (1024ull << 52)) >> 52;
  const double m = from_bits(bits - (k_biased << 52) + (1024ull << 52));
  const double f = m - 1.0, s = f / (2.0 + f), z = s * s, w = z * z;
  const double t1 = w * (3.999999999940941908e-01 + w * (2.222219843214978396e-01 + w * 1.531383769920937332e-01));
  const double t2 =
      z * (6.666666666666735130e-01 +
           w * (2.857142874366239149e-01 + w * (1.818357216161805012e-01 + w * 1.479819860511658591e-01)));
  const double R = t2 + t1, half_f_squared = 0.5 * f * f;
  // k - scale as a double from bits: 2^52 + k_biased is exact, and so is the difference of two such integers. A
  // static_cast of an int64 has no AVX2 instruction (AVX-512DQ's vcvtqq2pd): it kept every loop that takes a log
  // (Box-Muller's) scalar there.
  const double dk = from_bits(0x4330000000000000ull | k_biased) - (0x1.0p52 + 1024.0 + scale);
  return dk * ln2_hi - ((half_f_squared - (s * (half_f_squared + R) + dk * ln2_lo)) - f);
}
__attribute__((always_inline)) inline double host_log(const double x) {
  // Every operation is taken for every x and the special values are put in by selects of bits: GCC does not vectorize
  // a loop in which a select's arm would have to compute (a division or product may trap).
  const bool subnormal = x < 0x1p-1022;
  const double log_x = host_log_of_normal(x * (subnormal ? 0x1p54 : 1.0), subnormal ? 54 : 0);
  const double inf = 0x1p1023 * 2.0;
  const double special = x == 0.0 ? -inf : (x == inf ? inf : quiet_nan());
  const std::uint64_t regular = (x > 0.0) & (x < inf) ? ~0ull : 0ull;
  return from_bits((bits_of(log_x) & regular) | (bits_of(special) & ~regular));
}
#endif

KOKKOS_FORCEINLINE_FUNCTION double exp(double x) {
#if KUSHNER_HOST_MATH
  return host_exp(x);
#else
  return impl::exp(x);
#endif
}

KOKKOS_FORCEINLINE_FUNCTION double log(double x) {
#if KUSHNER_HOST_MATH
  return host_log(x);
#else
  return impl::log(x);
#endif
}

/// log x for a positive, normal, finite x (Box-Muller's uniforms): log's bits, without its other cases on a host.
KOKKOS_FORCEINLINE_FUNCTION double log_of_normal(double x) {
#if KUSHNER_HOST_MATH
  return host_log_of_normal(x);
#else
  return impl::log(x);
#endif
}

KOKKOS_INLINE_FUNCTION float exp(float x) { return impl::exp(x); }
KOKKOS_INLINE_FUNCTION float log(float x) { return impl::log(x); }

KOKKOS_FORCEINLINE_FUNCTION double sin(double x) {
#if KUSHNER_HOST_MATH
  return host_sin_cos(x).sin;
#else
  return impl::sin(x);
#endif
}

KOKKOS_FORCEINLINE_FUNCTION double cos(double x) {
#if KUSHNER_HOST_MATH
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

/// e^x in float for a particle's weight, exp(l - shift) with |l - shift| <= 60 or e^x far below a float's range. On
/// a GPU the special-function unit's 2^y of y = x log2(e) rounded to float, as CUDA's __expf computes it, in its
/// flush-to-zero form (2 instructions against expf's 8; e^x below 2^-126, x < -87.3, is 0). Within 2^-22 (2^y's 2
/// ulps) + 7.3e-8 |x| relative (y's rounding, and log2(e)'s, times ln 2): 4.6e-6 at |x| = 60, about the 3.6e-6 by
/// which rounding x = l - shift to float already moves e^x (tests/test_particle_filter.cpp, WeightExp). Elsewhere expf.
KOKKOS_INLINE_FUNCTION float weight_exp(float x) {
#if KUSHNER_CUDA_DEVICE_PASS
  float e;
  asm("ex2.approx.ftz.f32 %0, %1;" : "=f"(e) : "f"(x * 1.44269504f));
  return e;
#else
  return impl::exp(x);
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
#elif KUSHNER_HOST_MATH
  const SinCos both = host_sin_cos(x);
  s = both.sin;
  c = both.cos;
#else
  s = sin(x);
  c = cos(x + 0.0);  // x + 0.0: not a call GCC fuses with sin(x) into sincos, which has no vector version
#endif
}

/// Host: sin_cos of the angle 2 pi u for u in [0, 1] (cos_sin_two_pi and cos_two_pi_host: one expression for both),
/// without host_sin_cos' test of its limit.
inline SinCos sin_cos_two_pi_host(double u) {
#if KUSHNER_HOST_MATH
  return host_sin_cos_below_limit(2.0 * pi * u);
#else
  SinCos both;
  sin_cos(2.0 * pi * u, both.sin, both.cos);
  return both;
#endif
}

/// Host: cos(2 pi u) as cos_sin_two_pi computes its c there, the same bits.
inline double cos_two_pi_host(double u) {
#if KUSHNER_HOST_MATH
  return sin_cos_two_pi_host(u).cos;
#else
  return cos(2.0 * pi * u);
#endif
}

/// c = cos(2 pi u), s = sin(2 pi u) for u in [0, 1]. On a GPU CUDA's sincospi: no range reduction and one polynomial
/// pair for both (the angle 2 pi u is never rounded); elsewhere sin_cos of the rounded angle.
KOKKOS_INLINE_FUNCTION void cos_sin_two_pi(double u, double& c, double& s) {
#if KUSHNER_CUDA_DEVICE_PASS
  ::sincospi(2.0 * u, &s, &c);
#else
  const SinCos both = sin_cos_two_pi_host(u);
  s = both.sin;
  c = both.cos;
#endif
}

/// log(cosh(x)) without overflow for large |x|.
KOKKOS_INLINE_FUNCTION double log_cosh(double x) {
  const double a = fabs(x);
  return a + log1p(exp(-2.0 * a)) - 0.69314718055994530942;
}

}  // namespace kushner::math
