// Fixed-order ensemble moments: equal to a direct two-pass computation, blind to non-finite members (counted),
// and bitwise the same on every backend.
#include "engine/member_share.hpp"
#include "kernels/ensemble_moments.hpp"
#include "tests/test_spaces.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace kushner {
namespace {

template <class ExecSpace>
class EnsembleMomentsTest : public ::testing::Test {};
TYPED_TEST_SUITE(EnsembleMomentsTest, test::ExecutionSpaces);

/// 1000 members (not a multiple of the block size), 2 columns; members 17 and 600 hold NaN / Inf.
Kokkos::View<double**, Kokkos::LayoutLeft, Kokkos::HostSpace> sample_bank() {
  Kokkos::View<double**, Kokkos::LayoutLeft, Kokkos::HostSpace> x("x", 1000, 2);
  for (int m = 0; m < 1000; ++m) {
    x(m, 0) = std::sin(0.37 * m) + 3.0;
    x(m, 1) = 1e3 + std::cos(1.3 * m);  // a large mean: a naive sum of squares would lose digits
  }
  x(17, 1) = std::numeric_limits<double>::quiet_NaN();
  x(600, 0) = std::numeric_limits<double>::infinity();
  return x;
}

TYPED_TEST(EnsembleMomentsTest, MatchesTwoPassOverFiniteMembersAndCountsTheRest) {
  const auto host = sample_bank();
  auto x = Kokkos::create_mirror_view_and_copy(typename TypeParam::memory_space(), host);
  const auto moments = ensemble_moments(TypeParam(), x);
  EXPECT_EQ(moments.non_finite, 2);
  for (int c = 0; c < 2; ++c) {
    double sum = 0.0, n = 0.0;
    for (int m = 0; m < 1000; ++m)
      if (m != 17 && m != 600) sum += host(m, c), n += 1.0;
    const double mean = sum / n;
    double ss = 0.0;
    for (int m = 0; m < 1000; ++m)
      if (m != 17 && m != 600) ss += (host(m, c) - mean) * (host(m, c) - mean);
    EXPECT_NEAR(moments.mean[c], mean, 1e-13 * std::abs(mean));
    EXPECT_NEAR(moments.variance[c], ss / (n - 1), 1e-11 * ss / (n - 1));
  }
}

// Bitwise on every host backend; a GPU contracts multiply-adds into FMAs, so there: to 1e-13 relative.
TYPED_TEST(EnsembleMomentsTest, EqualToTheSerialResult) {
  const auto host = sample_bank();
  const auto reference = ensemble_moments(Kokkos::Serial(), host);
  auto x = Kokkos::create_mirror_view_and_copy(typename TypeParam::memory_space(), host);
  const auto moments = ensemble_moments(TypeParam(), x);
  if (Kokkos::SpaceAccessibility<Kokkos::HostSpace, typename TypeParam::memory_space>::accessible) {
    EXPECT_EQ(moments.mean, reference.mean);
    EXPECT_EQ(moments.variance, reference.variance);
  } else {
    for (int c = 0; c < 2; ++c) {
      EXPECT_NEAR(moments.mean[c], reference.mean[c], 1e-13 * std::abs(reference.mean[c]));
      EXPECT_NEAR(moments.variance[c], reference.variance[c], 1e-13 * reference.variance[c]);
    }
  }
}

/// The MPI split: shares cover the members in order, start on block boundaries (so that every rank's blocks are
/// the single process's blocks and their merge gives the same bits), and differ by 256 members at most.
TEST(MemberShare, ContiguousBlockAlignedAndBalanced) {
  for (long members : {1L, 255L, 256L, 700L, 1000L, 2000L, 100000L})
    for (int ranks = 1; ranks <= 5; ++ranks) {
      long next = 0, smallest = members, largest = 0;
      for (int r = 0; r < ranks; ++r) {
        const MemberShare s = member_share(members, r, ranks);
        EXPECT_EQ(s.first, next) << members << " members, rank " << r << " of " << ranks;
        EXPECT_EQ(s.total, members);
        EXPECT_GE(s.count, 0);
        if (s.count > 0) {
          EXPECT_EQ(s.first % moment_block_size, 0) << members << " members, rank " << r << " of " << ranks;
          EXPECT_EQ(s.seed(7).first_member, static_cast<std::uint32_t>(s.first));
        }
        next = s.first + s.count;
        smallest = std::min(smallest, s.count), largest = std::max(largest, s.count);
      }
      EXPECT_EQ(next, members) << members << " members over " << ranks << " ranks";
      EXPECT_LE(largest - smallest, moment_block_size) << members << " members over " << ranks << " ranks";
    }
  EXPECT_EQ(member_share(2000, 0, 2).count, 1024);  // 8 blocks: 4 each, the last one short
  EXPECT_EQ(member_share(2000, 1, 2).count, 976);
  EXPECT_EQ(member_share(200, 0, 2).count, 0);  // one block: one rank runs none
  EXPECT_EQ(member_share(200, 1, 2).count, 200);
  EXPECT_EQ(member_share(700, 1, 2).first, 256);  // 3 blocks: 1 and 2, the short one in the larger share
  EXPECT_EQ(member_share(700, 1, 2).count, 444);
}

}  // namespace
}  // namespace kushner
