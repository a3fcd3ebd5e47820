// The host's sin, cos, exp and log (core/math.hpp): within their stated errors of long double's values, sin and cos
// near their zeros too, their limits and special values, and the same bits in SIMD lanes as in scalar code.
#include "core/math.hpp"
#include "kernels/vector_math.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace kushner {
namespace {

#if KUSHNER_HOST_MATH

/// |a - b| in units of 2^-53 (an ulp of a value in [0.5, 1), half an ulp of one in [1, 2)).
long double absolute_error(double a, long double b) { return std::fabs(static_cast<long double>(a) - b) * 0x1p53L; }

/// |a - b| in ulps of b (a subnormal b's ulp is 2^-1074).
long double relative_error(double a, long double b) {
  int exponent;
  std::frexp(static_cast<double>(b), &exponent);
  return std::fabs(static_cast<long double>(a) - b) / std::ldexp(1.0L, std::max(exponent, -1021) - 53);
}

using math::bits_of;

TEST(HostSinCos, IsWithinItsErrorOfTheExactValues) {
  constexpr int points = 100000;
  for (const double range : {math::pi / 4, 10.0, 1e6, 1.7e13}) {
    long double worst_absolute = 0, worst_relative = 0;
    for (int i = 0; i < points; ++i) {
      const double r = static_cast<double>(i) / points;
      const double x = (i % 2 == 0 ? 1.0 : -1.0) * r * r * range;
      const math::SinCos v = math::host_sin_cos(x);
      const long double s = sinl(x), c = cosl(x);
      worst_absolute = std::max({worst_absolute, absolute_error(v.sin, s), absolute_error(v.cos, c)});
      if (range <= math::pi / 4)
        worst_relative = std::max({worst_relative, relative_error(v.sin, s), relative_error(v.cos, c)});
    }
    EXPECT_LE(worst_absolute, 1.1L) << "|x| up to " << range;  // measured 0.66 .. 1.09
    EXPECT_LE(worst_relative, 1.0L) << "|x| up to " << range;  // measured 0.75 (no reduction: r = x)
  }
}

/// Near the zeros the reduced argument is small and its every bit counts: pi/2's third part (c3) keeps the error
/// within an ulp of the small result (without it: 2.6e5 ulps at k ~ 1e6).
TEST(HostSinCos, IsWithinAnUlpNearTheZeros) {
  long double worst = 0;
  for (long k = 1; k <= 2000000; k += 3) {
    const double x = static_cast<double>(k * 1.5707963267948966192313216916397514L);
    const math::SinCos v = math::host_sin_cos(x);
    worst = std::max(worst, k % 2 == 0 ? relative_error(v.sin, sinl(x)) : relative_error(v.cos, cosl(x)));
  }
  EXPECT_LE(worst, 1.0L);
}

TEST(HostSinCos, IsNaNFromItsLimitOn) {
  for (const double x :
       {math::host_sin_cos_limit, -math::host_sin_cos_limit, 1e300, HUGE_VAL, -HUGE_VAL, math::quiet_nan()}) {
    EXPECT_TRUE(std::isnan(math::host_sin_cos(x).sin)) << x;
    EXPECT_TRUE(std::isnan(math::host_sin_cos(x).cos)) << x;
  }
  const double below = std::nextafter(math::host_sin_cos_limit, 0.0);
  EXPECT_LE(absolute_error(math::host_sin_cos(below).sin, sinl(below)), 1.1L);
  EXPECT_LE(absolute_error(math::host_sin_cos(below).cos, cosl(below)), 1.1L);
}

TEST(HostExpLog, AreWithinAnUlpOfTheExactValues) {
  constexpr int points = 200000;
  long double worst_exp = 0, worst_log = 0;
  for (int i = 0; i <= points; ++i) {
    const double t = static_cast<double>(i) / points;
    const double x = -745.0 + t * (709.7 + 745.0);  // exp's whole range, subnormal results included
    worst_exp = std::max(worst_exp, relative_error(math::host_exp(x), expl(x)));
    const double y = std::exp2(-1074.0 + t * (1024.0 + 1074.0 - 1e-9));  // log's: subnormal to the largest doubles
    worst_log = std::max(worst_log, relative_error(math::host_log(y), logl(y)));
    const double near_one = 0.75 + 0.5 * t;  // where log is small and f = x - 1 carries it
    worst_log = std::max(worst_log, relative_error(math::host_log(near_one), logl(near_one)));
  }
  EXPECT_LE(worst_exp, 1.0L);  // measured 0.87 (glibc's exp: 0.51)
  EXPECT_LE(worst_log, 1.0L);  // 0.84 at random points on [0.5, 2] (glibc: 0.52)
}

TEST(HostExpLog, TakeTheirLimitsAndSpecialValues) {
  const double inf = HUGE_VAL;
  EXPECT_EQ(math::host_exp(709.78), std::exp(709.78));
  EXPECT_EQ(math::host_exp(709.79), inf);
  EXPECT_EQ(math::host_exp(inf), inf);
  EXPECT_EQ(math::host_exp(-745.13), 0x1p-1074);  // the least subnormal
  EXPECT_EQ(math::host_exp(-745.14), 0.0);
  EXPECT_EQ(math::host_exp(-inf), 0.0);
  EXPECT_EQ(math::host_exp(0.0), 1.0);
  EXPECT_TRUE(std::isnan(math::host_exp(math::quiet_nan())));
  EXPECT_EQ(math::host_log(1.0), 0.0);
  EXPECT_EQ(math::host_log(0.0), -inf);
  EXPECT_EQ(math::host_log(-0.0), -inf);
  EXPECT_EQ(math::host_log(inf), inf);
  EXPECT_EQ(math::host_log(0x1p-1074), std::log(0x1p-1074));
  for (const double x : {-1.0, -0x1p-1074, -inf, math::quiet_nan()}) EXPECT_TRUE(std::isnan(math::host_log(x))) << x;
}

__attribute__((noinline)) math::SinCos scalar_sin_cos(double x) { return math::host_sin_cos(x); }
__attribute__((noinline)) double scalar_exp(double x) { return math::host_exp(x); }
__attribute__((noinline)) double scalar_log(double x) { return math::host_log(x); }

/// A filter's lanes compute these in SIMD registers, a member stepped alone in scalar ones: both must round alike.
TEST(HostSinCos, SimdLanesGiveTheScalarBits) {
  constexpr int n = 4096;
  std::vector<double> x(n), s(n), c(n), e(n), l(n);
  for (int i = 0; i < n; ++i) x[i] = (i % 2 == 0 ? 1.0 : -1.0) * 1e-3 * i * i;
  const double* const xs = x.data();
  double* const ss = s.data();
  double* const cs = c.data();
  double* const es = e.data();
  double* const ls = l.data();
  KUSHNER_SIMD
  for (int i = 0; i < n; ++i) {
    math::sin_cos(xs[i], ss[i], cs[i]);
    es[i] = math::exp(xs[i] * 1e-4);
    ls[i] = math::log(math::fabs(xs[i]));
  }
  int differ = 0;
  for (int i = 0; i < n; ++i) {
    const math::SinCos v = scalar_sin_cos(x[i]);
    differ += bits_of(v.sin) != bits_of(s[i]) || bits_of(v.cos) != bits_of(c[i]);
    differ +=
        bits_of(scalar_exp(x[i] * 1e-4)) != bits_of(e[i]) || bits_of(scalar_log(std::fabs(x[i]))) != bits_of(l[i]);
  }
  EXPECT_EQ(differ, 0);
}

TEST(HostSinCos, SinCosIsSinAndCos) {
  for (int i = -1000; i <= 1000; ++i) {
    const double x = 0.0137 * i * std::abs(i), u = (i + 1000.5) / 2001.0;
    double s, c;
    math::sin_cos(x, s, c);
    EXPECT_EQ(bits_of(s), bits_of(math::sin(x))) << x;
    EXPECT_EQ(bits_of(c), bits_of(math::cos(x))) << x;
    math::cos_sin_two_pi(u, c, s);
    EXPECT_EQ(bits_of(c), bits_of(math::cos_two_pi_host(u))) << u;
    EXPECT_LE(absolute_error(c, cosl(2.0 * math::pi * u)), 1.1L) << u;  // of the angle as rounded
  }
}

#else

TEST(HostMath, IsLibmWithoutFusedMultiplyAdds) {
  GTEST_SKIP() << "built without fused multiply-adds: math::sin, cos, exp and log are libm's";
}

#endif

}  // namespace
}  // namespace kushner
