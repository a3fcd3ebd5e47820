// Fixed-order ensemble moments: equal to a direct two-pass computation, blind to non-finite members (counted),
// and bitwise the same on every backend.
#include "engine/member_share.hpp"
#include "kernels/ensemble_moments.hpp"
#include "kernels/filters/filter_metrics.hpp"
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

/// Expects `moments` to be, column by column, the direct two-pass mean and sample variance of `host` over every
/// member but `left_out` and `also_left_out`.
void expect_two_pass_moments(const Kokkos::View<double**, Kokkos::LayoutLeft, Kokkos::HostSpace>& host,
                             const EnsembleMoments& moments, int left_out, int also_left_out) {
  const int members = static_cast<int>(host.extent(0)), columns = static_cast<int>(host.extent(1));
  const auto kept = [&](int m) { return m != left_out && m != also_left_out; };
  for (int c = 0; c < columns; ++c) {
    double sum = 0.0, n = 0.0;
    for (int m = 0; m < members; ++m)
      if (kept(m)) sum += host(m, c), n += 1.0;
    const double mean = sum / n;
    double ss = 0.0;
    for (int m = 0; m < members; ++m)
      if (kept(m)) ss += (host(m, c) - mean) * (host(m, c) - mean);
    EXPECT_NEAR(moments.mean[c], mean, 1e-13 * std::abs(mean)) << columns << " columns, column " << c;
    EXPECT_NEAR(moments.variance[c], ss / (n - 1), 1e-11 * ss / (n - 1)) << columns << " columns, column " << c;
  }
}

TYPED_TEST(EnsembleMomentsTest, MatchesTwoPassOverFiniteMembersAndCountsTheRest) {
  const auto host = sample_bank();
  auto x = Kokkos::create_mirror_view_and_copy(typename TypeParam::memory_space(), host);
  const auto moments = ensemble_moments(TypeParam(), x);
  EXPECT_EQ(moments.non_finite, 2);
  expect_two_pass_moments(host, moments, 17, 600);
}

// Every column count ensemble_moments dispatches on (1 to 4 at compile time, more at run time): a member with a
// non-finite entry in its last column, another in its first, are left out of every column; one with a -0 entry is
// kept.
TYPED_TEST(EnsembleMomentsTest, LeavesOutRowsWithANonFiniteEntryForEveryColumnCount) {
  for (int columns = 1; columns <= 6; ++columns) {
    Kokkos::View<double**, Kokkos::LayoutLeft, Kokkos::HostSpace> host("x", 700, columns);
    for (int m = 0; m < 700; ++m)
      for (int c = 0; c < columns; ++c) host(m, c) = std::sin(0.37 * m + c) + c + 2.0;
    host(5, 0) = -0.0;
    host(33, columns - 1) = std::numeric_limits<double>::quiet_NaN();
    host(401, 0) = -std::numeric_limits<double>::infinity();
    auto x = Kokkos::create_mirror_view_and_copy(typename TypeParam::memory_space(), host);
    const auto moments = ensemble_moments(TypeParam(), x);
    EXPECT_EQ(moments.non_finite, 2) << columns << " columns";
    expect_two_pass_moments(host, moments, 33, 401);
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

/// ColumnMoments (the bank's output steps) gives, column by column, ensemble_moments of that column alone, bit for
/// bit on the host (and to 1e-13 on a GPU), with a member left out of a column only where that column is not
/// finite; also with blocks shorter than a block or its 32 lanes (1003 and 5 members), when the same object is
/// called again with the same columns (its kept buffers) or with other ones, and in both forms of its kernel (one
/// thread per block and column, or a team: a GPU's default).
TYPED_TEST(EnsembleMomentsTest, ColumnMomentsEqualEachColumnsEnsembleMoments) {
  using MemSpace = typename TypeParam::memory_space;
  const bool host_space = Kokkos::SpaceAccessibility<Kokkos::HostSpace, MemSpace>::accessible;
  for (const bool teams : {false, true})
    for (const int members : {1003, 5}) {
      Kokkos::View<double**, Kokkos::LayoutLeft, Kokkos::HostSpace> host("x", members, 3);
      for (int m = 0; m < members; ++m) {
        host(m, 0) = std::sin(0.37 * m) + 3.0;
        host(m, 1) = 1e3 + std::cos(1.3 * m);
        host(m, 2) = 1e-3 * m * m;
      }
      host(members - 1, 1) = std::numeric_limits<double>::quiet_NaN();
      host(members / 2, 2) = -std::numeric_limits<double>::infinity();
      auto x = Kokkos::create_mirror_view_and_copy(MemSpace(), host);
      ColumnMoments<TypeParam> moments(teams);
      for (const std::vector<int>& order :
           {std::vector<int>{0, 1, 2}, std::vector<int>{0, 1, 2}, std::vector<int>{2, 0}}) {
        std::vector<typename ColumnMoments<TypeParam>::Column> columns;
        for (const int c : order) columns.push_back(Kokkos::subview(x, Kokkos::ALL, c));
        const auto result = moments(TypeParam(), columns);
        ASSERT_EQ(result.size(), order.size());
        for (std::size_t i = 0; i < order.size(); ++i) {
          const int c = order[i];
          const auto alone =
              ensemble_moments(Kokkos::Serial(), Kokkos::subview(host, Kokkos::ALL, std::make_pair(c, c + 1)));
          EXPECT_EQ(result[i].non_finite, (c == 0 ? 0 : 1)) << members << " members, column " << c;
          EXPECT_EQ(result[i].members, members);
          double sum = 0.0, n = 0.0, ss = 0.0;  // directly, over the column's finite values
          for (int m = 0; m < members; ++m)
            if (std::isfinite(host(m, c))) sum += host(m, c), n += 1.0;
          for (int m = 0; m < members; ++m)
            if (std::isfinite(host(m, c))) ss += (host(m, c) - sum / n) * (host(m, c) - sum / n);
          EXPECT_NEAR(result[i].mean[0], sum / n, 1e-13 * std::abs(sum / n)) << members << " members, column " << c;
          EXPECT_NEAR(result[i].variance[0], ss / (n - 1), 1e-12 * ss / (n - 1)) << members << " members, column " << c;
          if (host_space) {
            EXPECT_EQ(result[i].mean[0], alone.mean[0]) << members << " members, column " << c;
            EXPECT_EQ(result[i].variance[0], alone.variance[0]) << members << " members, column " << c;
          } else {
            EXPECT_NEAR(result[i].mean[0], alone.mean[0], 1e-13 * std::abs(alone.mean[0]));
            EXPECT_NEAR(result[i].variance[0], alone.variance[0], 1e-13 * alone.variance[0]);
          }
        }
      }
    }
}

/// The divergence counts in the moments' launch (ColumnMoments with NotOkMembers): for each status column,
/// count_status of not_positive_definite plus that of non_finite among the members whose truth is ok, in both forms
/// of the kernel, again with its kept buffers and device lists, and with other columns; the moments beside them
/// are the bits of the moments alone.
TYPED_TEST(EnsembleMomentsTest, DivergenceCountsInTheMomentsLaunchEqualTheStatusCounts) {
  using MemSpace = typename TypeParam::memory_space;
  const int members = 777;  // three blocks and a short one
  Kokkos::View<Status*, Kokkos::LayoutLeft, Kokkos::HostSpace> truth("truth", members), a("a", members),
      b("b", members);
  Kokkos::View<double*, Kokkos::HostSpace> values("values", members);
  for (int m = 0; m < members; ++m) {
    truth(m) = m % 50 == 3 ? Status::non_finite : Status::ok;
    a(m) = m % 7 == 0 ? Status::not_positive_definite : m % 11 == 0 ? Status::non_finite : Status::ok;
    b(m) = m % 3 == 0 ? Status::non_finite : Status::ok;
    values(m) = m % 13 == 0 ? std::numeric_limits<double>::quiet_NaN() : std::cos(0.1 * m);
  }
  const BankScalar<Status, MemSpace> truth_d = Kokkos::create_mirror_view_and_copy(MemSpace(), truth);
  const BankScalar<Status, MemSpace> a_d = Kokkos::create_mirror_view_and_copy(MemSpace(), a);
  const BankScalar<Status, MemSpace> b_d = Kokkos::create_mirror_view_and_copy(MemSpace(), b);
  const Kokkos::View<const double*, MemSpace> column = Kokkos::create_mirror_view_and_copy(MemSpace(), values);
  long expected_a = 0, expected_b = 0;
  for (int m = 0; m < members; ++m) {
    expected_a += truth(m) == Status::ok && a(m) != Status::ok;
    expected_b += truth(m) == Status::ok && b(m) != Status::ok;
  }
  EXPECT_EQ(expected_a, count_status(TypeParam(), a_d, Status::not_positive_definite, truth_d) +
                            count_status(TypeParam(), a_d, Status::non_finite, truth_d));
  for (const bool teams : {false, true}) {
    ColumnMoments<TypeParam> moments(teams);
    const EnsembleMoments alone = moments(TypeParam(), {column}).front();
    DivergedMembers<MemSpace> diverged;
    for (int repeat = 0; repeat < 2; ++repeat) {
      moments.start(TypeParam(), {column, column}, diverged(TypeParam(), {a_d, b_d, a_d}, truth_d));
      const MergedBlocks merged = moments.finish();
      EXPECT_EQ(merged.counts, (std::vector<long>{expected_a, expected_b, expected_a})) << "teams " << teams;
      ASSERT_EQ(merged.moments.size(), 2u);
      for (const auto& mo : merged.moments) {
        EXPECT_EQ(mo.mean, alone.mean) << "teams " << teams;
        EXPECT_EQ(mo.variance, alone.variance) << "teams " << teams;
        EXPECT_EQ(mo.non_finite, alone.non_finite) << "teams " << teams;
      }
    }
    moments.start(TypeParam(), {column}, diverged(TypeParam(), {b_d}, truth_d));
    EXPECT_EQ(moments.finish().counts, std::vector<long>{expected_b}) << "teams " << teams;
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
