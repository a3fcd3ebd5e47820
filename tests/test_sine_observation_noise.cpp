// Basin's deterministic observation "noise" (models/sine_observation_noise.hpp: the cars' and the reactor's parameter
// sine_observation_noise) and truths that follow another model than the filters (FilterBank's TruthModel): one step
// by hand, every member the same (to the last bits of the host's vector cos), every backend the same bits, the
// Brownian path untouched with the parameter 0 and in models without it, and a bank whose truths follow the tan car
// while its filters use the Taylor model.
#include "engine/filter_bank.hpp"
#include "engine/truth_bank.hpp"
#include "models/car_model.hpp"
#include "models/parameters.hpp"
#include "models/sine_model.hpp"
#include "tests/test_spaces.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace kushner {
namespace {

template <class Space>
class SineObservationNoiseTest : public ::testing::Test {};
TYPED_TEST_SUITE(SineObservationNoiseTest, test::ExecutionSpaces);

TYPED_TEST(SineObservationNoiseTest, IncrementIsTheIntegralOfSinOverTheStepForEveryMember) {
  using Space = TypeParam;
  CarTaylor3Model car;
  car.x0_mean = Vec<2>{{0.3, 0.2}};
  car.sine_observation_noise = 1.0;
  constexpr long members = 5;
  TruthBank<Space, CarTaylor3Model> bank(Space(), car, members, 7);
  const double dt = 0.01;
  bank.step(0, dt);  // [0, dt]
  bank.step(1, dt);  // [dt, 2 dt]
  Space().fence();
  const auto x = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), bank.state());
  const auto dy = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), bank.observations());
  // By hand: x1 = x0 + f(x0) dt; dy over [dt, 2 dt] = x1 dt + r (cos dt - cos 2dt), r = 1.
  const double d0 = 0.2, phi1 = 0.3 + (d0 + d0 * d0 * d0 / 3.0) * dt, d1 = d0 + car.u * dt;
  const double noise = std::cos(dt) - std::cos(2.0 * dt);
  // The host's truth step takes cos from glibc's vector library (within 4 ulp of libm) in the members' SIMD lanes
  // and libm's in a chunk's remainder: each cosine near 1 may differ by 4 ulp of 1 from std::cos, and the noise is
  // their difference; so members may differ from each other in those last bits too.
  const double tolerance = 8.0 * std::numeric_limits<double>::epsilon();
  for (long m = 0; m < members; ++m) {
    EXPECT_NEAR(dy(m, 0), phi1 * dt + noise, tolerance) << "member " << m;
    EXPECT_NEAR(dy(m, 1), d1 * dt + noise, tolerance) << "member " << m;
    EXPECT_EQ(x(m, 0), x(0, 0));
    EXPECT_NEAR(dy(m, 1), dy(0, 1), tolerance);
  }
}

TEST(SineObservationNoise, BrownianUnlessTheParameterIsOne) {
  using Space = Kokkos::DefaultExecutionSpace;
  EXPECT_FALSE(sine_observation_noise(SineModel()));  // a model without the option
  CarTaylor3Model car;
  car.x0_cov = Mat<2, 2>::zero();
  EXPECT_FALSE(sine_observation_noise(car));  // the default
  TruthBank<Space, CarTaylor3Model> brownian(Space(), car, 2, 3);
  apply_parameters(car, {{"sine_observation_noise", "1"}});  // as `--set sine_observation_noise=1` does
  EXPECT_TRUE(sine_observation_noise(car));
  TruthBank<Space, CarTaylor3Model> sine(Space(), car, 2, 3);
  brownian.step(0, 0.01);
  sine.step(0, 0.01);
  Space().fence();
  const auto a = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), brownian.observations());
  const auto b = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), sine.observations());
  EXPECT_NE(a(0, 0), a(1, 0)) << "Brownian members share their noise";
  EXPECT_EQ(b(0, 0), b(1, 0));
  EXPECT_DOUBLE_EQ(b(0, 0), car.r * (1.0 - std::cos(0.01)));  // phi(0) = 0
  car.sine_observation_noise = 0.5;
  EXPECT_THROW(car.validate(), InputError);
}

/// The car of seed 002 L1505 (tan truth, Taylor-model filters): the truths follow tan, not the Taylor model.
TEST(TruthModel, BankTruthsFollowTheirOwnModel) {
  using Space = Kokkos::DefaultExecutionSpace;
  CarTaylor3Model taylor;
  taylor.x0_mean = Vec<2>{{0.0, 1.0}};  // delta = 1: tan 1 = 1.557 against the Taylor model's 1.333
  CarModel tan;
  static_cast<CarBase&>(tan) = taylor;
  const double dt = 1e-3;
  FilterBank<Space, CarTaylor3Model, CarModel> bank(Space(), tan, taylor, 3, 1, {"KBL", "POLY3"});
  bank.step(0, dt, true);
  Space().fence();
  const auto x = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), bank.truths().state());
  EXPECT_DOUBLE_EQ(x(0, 0), std::tan(1.0) * dt);
  FilterBank<Space, CarTaylor3Model> same(Space(), taylor, taylor, 3, 1, {"KBL", "POLY3"});
  same.step(0, dt, true);
  Space().fence();
  const auto y = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), same.truths().state());
  EXPECT_DOUBLE_EQ(y(0, 0), (1.0 + 1.0 / 3.0) * dt);
}

}  // namespace
}  // namespace kushner
