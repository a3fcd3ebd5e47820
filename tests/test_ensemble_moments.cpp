// Fixed-order ensemble moments: equal to a direct two-pass computation, blind to non-finite members (counted),
// and bitwise the same on every backend.
#include "engine/member_share.hpp"
#include "kernels/ensemble_moments.hpp"
#include "kernels/filters/filter_metrics.hpp"
#include "tests/test_spaces.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

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

/// NotOkMembers' count of eight members from two 64-bit words (a GPU warp's count of a whole block) against its
/// member-by-member rule: every one of the 3^8 runs of eight statuses, each beside 16 runs of truths with 16 different
/// ok / not-ok patterns (every one of the 256 patterns beside ~410 runs of statuses), in 8 of them non_finite and
/// not_positive_definite mixed.
TEST(DivergenceCounts, EightMembersFromTwoWordsAreCountedAsOneAtATime) {
  constexpr int runs = 6561 * 16, members = 8 * runs;
  Kokkos::View<Status*, Kokkos::LayoutLeft, Kokkos::HostSpace> truth("truth", members), status("status", members);
  for (int r = 0; r < runs; ++r)
    for (int k = 0; k < 8; ++k) {
      int digits = r / 16;
      for (int d = 0; d < k; ++d) digits /= 3;
      status(8 * r + k) = static_cast<Status>(digits % 3);
      const int pattern = (r * 37 + r / 16) % 256;
      const bool mixed = r % 16 >= 8, not_ok = (pattern >> k) & 1;
      truth(8 * r + k) = !not_ok ? Status::ok : mixed && k % 2 ? Status::not_positive_definite : Status::non_finite;
    }
  DivergedMembers<Kokkos::HostSpace> diverged;
  const NotOkMembers<Kokkos::HostSpace> counted = diverged(Kokkos::DefaultHostExecutionSpace(), {status}, truth);
  ASSERT_EQ(reinterpret_cast<std::uintptr_t>(status.data()) % 8, 0u);
  ASSERT_EQ(reinterpret_cast<std::uintptr_t>(truth.data()) % 8, 0u);
  int mismatches = 0, counted_somewhere = 0;
  for (int r = 0; r < runs; ++r) {
    int one_at_a_time = 0;
    for (int m = 8 * r; m < 8 * r + 8; ++m) one_at_a_time += counted(0, m) ? 1 : 0;
    mismatches += counted.count_eight(0, 8 * r) != one_at_a_time;
    counted_somewhere += one_at_a_time > 0;
  }
  EXPECT_EQ(mismatches, 0);
  EXPECT_GT(counted_somewhere, runs / 2);  // the runs are not all empty
  for (const std::uint64_t byte : {0ull, 1ull, 2ull, 0x7full, 0x80ull, 0xffull})
    for (int k = 0; k < 8; ++k)
      EXPECT_EQ(NotOkMembers<Kokkos::HostSpace>::nonzero_bytes(byte << (8 * k)), byte == 0 ? 0 : 0x80ull << (8 * k));
}

/// Block rows (BlockStatistics' layout) of `outputs` outputs of `blocks` blocks, `columns` columns, `counted` counts:
/// full, short and empty blocks, means around 1e3 (pooling must not lose their digits).
std::vector<double> sample_block_rows(int outputs, int blocks, int columns, int counted) {
  const int width = 3 * columns + counted;
  std::vector<double> rows(static_cast<std::size_t>(outputs) * blocks * width);
  for (int o = 0; o < outputs; ++o)
    for (int b = 0; b < blocks; ++b) {
      double* row = rows.data() + (static_cast<std::size_t>(o) * blocks + b) * width;
      for (int c = 0; c < columns; ++c) {
        const int n = (b + c) % 97 == 5 ? 0 : (b * 7 + c + o) % 61 == 2 ? 1 : (b + o) % 53 == 0 ? 100 : 256;
        row[c] = n;
        row[columns + c] = n == 0 ? 0.0 : 1e3 + std::sin(0.3 * b + c + o);  // an empty block's mean is 0
        row[2 * columns + c] = n <= 1 ? 0.0 : (n - 1) * (1.0 + 0.5 * std::cos(0.7 * b - c));
      }
      for (int s = 0; s < counted; ++s) row[3 * columns + s] = (b * 3 + o) % 5 * (s + 1);
    }
  return rows;
}

/// The merge of block rows (merge_block_statistics: the host's, of every rank's rows; 1000 blocks: 31 rounds of the 32
/// lanes and 8 more; 13 columns: merged in groups of 8, 4 and 1): the pooled count, mean and m2 of each column (the
/// pooled formulas in long double, 1e-13), the counts exactly, and the same bits for a column merged alone.
/// MergeBlockRows (a segment's merge where its rows are, two outputs at once: a warp per pair on a GPU) gives the same
/// bits on the host and agrees to 1e-13 on a GPU.
TYPED_TEST(EnsembleMomentsTest, MergedBlockRowsArePooledMoments) {
  using MemSpace = typename TypeParam::memory_space;
  const int outputs = 2, blocks = 1000, columns = 13, counted = 2, width = 3 * columns + counted;
  const std::vector<double> rows = sample_block_rows(outputs, blocks, columns, counted);
  const std::size_t output_size = static_cast<std::size_t>(blocks) * width;
  const long members = 256L * blocks;
  std::vector<MergedBlocks> host;
  for (int o = 0; o < outputs; ++o) {
    const double* r = rows.data() + o * output_size;
    host.push_back(merge_block_statistics(r, output_size, columns, counted, members));
    const MergedBlocks& merged = host.back();
    std::vector<double> alone(width);
    for (int c = 0; c < columns; ++c) {
      BlockStatistic s;
      merge_block_columns<1>(r, blocks, width, columns, c, &s);
      store_block_row(alone.data(), columns, c, s);
      long double n = 0, weighted = 0;
      for (int b = 0; b < blocks; ++b) {
        n += r[b * width + c];
        weighted += static_cast<long double>(r[b * width + c]) * r[b * width + columns + c];
      }
      const long double mean = weighted / n;
      long double m2 = 0;
      for (int b = 0; b < blocks; ++b) {
        const long double delta = r[b * width + columns + c] - mean;
        if (r[b * width + c] > 0) m2 += r[b * width + 2 * columns + c] + r[b * width + c] * delta * delta;
      }
      const EnsembleMoments& mo = merged.moments[c];
      EXPECT_EQ(mo.members - mo.non_finite, static_cast<long>(n)) << "column " << c;
      EXPECT_NEAR(mo.mean[0], static_cast<double>(mean), 1e-13 * 1e3) << "column " << c;
      EXPECT_NEAR(mo.variance[0], static_cast<double>(m2 / (n - 1)), 1e-13 * static_cast<double>(m2 / (n - 1)))
          << "column " << c;
    }
    for (int s = 0; s < counted; ++s) {
      long expected = 0;
      for (int b = 0; b < blocks; ++b) expected += static_cast<long>(r[b * width + 3 * columns + s]);
      EXPECT_EQ(merged.counts[s], expected) << "count " << s;
      alone[3 * columns + s] = merge_block_count(r, blocks, width, columns, s);
    }
    const MergedBlocks one_at_a_time = merged_blocks(alone.data(), columns, counted, members);
    for (int c = 0; c < columns; ++c) {
      EXPECT_EQ(one_at_a_time.moments[c].mean, merged.moments[c].mean) << "column " << c;
      EXPECT_EQ(one_at_a_time.moments[c].variance, merged.moments[c].variance) << "column " << c;
    }
  }

  Kokkos::View<double*, MemSpace> rows_d("rows", rows.size());
  Kokkos::deep_copy(rows_d, Kokkos::View<const double*, Kokkos::HostSpace, Kokkos::MemoryTraits<Kokkos::Unmanaged>>(
                                rows.data(), rows.size()));
  Kokkos::View<double**, Kokkos::LayoutRight, MemSpace> sums("sums", outputs, width);
  merge_block_rows(TypeParam(), MergeBlockRows<MemSpace>{rows_d, blocks, columns, counted, sums}, outputs);
  const auto sums_h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), sums);
  const bool on_host = Kokkos::SpaceAccessibility<Kokkos::HostSpace, MemSpace>::accessible;
  for (int o = 0; o < outputs; ++o) {
    const MergedBlocks where = merged_blocks(&sums_h(o, 0), columns, counted, members);
    EXPECT_EQ(where.counts, host[o].counts) << "output " << o;
    for (int c = 0; c < columns; ++c) {
      const EnsembleMoments &a = where.moments[c], &b = host[o].moments[c];
      EXPECT_EQ(a.non_finite, b.non_finite) << "output " << o << " column " << c;
      if (on_host) {
        EXPECT_EQ(a.mean, b.mean) << "output " << o << " column " << c;
        EXPECT_EQ(a.variance, b.variance) << "output " << o << " column " << c;
      } else {
        EXPECT_NEAR(a.mean[0], b.mean[0], 1e-13 * std::abs(b.mean[0])) << "output " << o << " column " << c;
        EXPECT_NEAR(a.variance[0], b.variance[0], 1e-13 * b.variance[0]) << "output " << o << " column " << c;
      }
    }
  }
}

/// block_statistic of a block whose values are all finite (its unmasked passes) is, bit for bit, what its masked
/// passes give: the same block with a NaN after its last value (in the lane after the last one, where it adds
/// nothing) takes those. For every length of a block, with a large mean and a -0 among the values.
TEST(BlockStatistic, AllFiniteBlockGivesTheMaskedPassesBits) {
  std::vector<double> v(moment_block_size + 1);
  for (int n = 1; n <= moment_block_size; ++n) {
    for (int m = 0; m < n; ++m) v[m] = 1e3 + std::sin(0.37 * m + n);
    v[n / 2] = -0.0;
    v[n] = std::numeric_limits<double>::quiet_NaN();
    const ColumnValue value{v.data()};  // not a lambda: nvcc warns of a host lambda called from block_statistic
    const BlockStatistic unmasked = block_statistic(value, 0, n), masked = block_statistic(value, 0, n + 1);
    EXPECT_EQ(unmasked.count, n);
    EXPECT_EQ(masked.count, n);
    EXPECT_EQ(std::memcmp(&unmasked.mean, &masked.mean, sizeof(double)), 0) << n << " members";
    EXPECT_EQ(std::memcmp(&unmasked.m2, &masked.m2, sizeof(double)), 0) << n << " members";
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
