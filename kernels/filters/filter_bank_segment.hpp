#pragma once
// Several steps of a host bank in one pass over its members (temporal blocking): each block of moment_block_size
// members takes every step of a segment while its columns stay in the core's cache, and after each output step it
// reduces its own snapshot values to the block statistics that the output's moments merge
// (kernels/ensemble_moments.hpp). A step at a time, a step streamed each member's ~420 bytes (truth, and per filter m,
// P, status, three score sums) from memory and back: sine with EKF, SOF, QLF, KBL ran 2.2e7 member-steps/s per thread
// at 1e6 members against 3.9e7 at 8192 members, whose columns fit in the caches. A member's step is the step kernel's
// own chunk function (run_member_chunk: the same machine code, in runs of host_lane_capacity members, whose vector
// bodies and remainders take the members that chunks of host_member_chunk give them) and a block's statistic is
// block_statistic of the same values in the same order, so the numbers are the same bits as those of steps taken one at
// a time.
#include "kernels/ensemble_moments.hpp"
#include "kernels/filters/filter_slot.hpp"
#include "kernels/for_each_member.hpp"
#include "kernels/streaming_store.hpp"

#include <Kokkos_Core.hpp>

#include <cstddef>
#include <cstdint>
#include <new>
#include <vector>

namespace kushner {

/// A column an output step reduces: a filter's snapshot values in the block's sink (`sink` >= 0: the sink's column)
/// or in the bank's snapshot column `column` (member-indexed).
struct SegmentColumn {
  double* column;
  int sink;
};

/// An element of a bank view (element_address of (member, column): a truth's, or a filter's m or P) that a segment
/// copies at each of its output steps: what an observer reads of a few members (drivers/trajectory_recorder.hpp).
struct WatchedElement {
  std::uintptr_t address;
  long member;
};

/// A segment's watched elements and where their values go: the block that holds element i's member copies it to
/// values(output, first_column + i) once it took that output step, the other blocks being at other steps then.
template <class MemSpace>
struct WatchedElements {
  Kokkos::View<const std::uintptr_t*, MemSpace> list;  // the count addresses, then their members' blocks
  int count = 0;
  Kokkos::View<double**, Kokkos::LayoutRight, MemSpace> values;
  int first_column = 0;

  /// The lists start_segment uploads: the addresses, then the blocks.
  static std::vector<std::uintptr_t> list_of(const std::vector<WatchedElement>& elements) {
    std::vector<std::uintptr_t> list;
    for (const WatchedElement& e : elements) list.push_back(e.address);
    for (const WatchedElement& e : elements) list.push_back(static_cast<std::uintptr_t>(e.member / moment_block_size));
    return list;
  }

  /// Block b's elements at output `output`, element i by `thread` (of `threads`) where i % threads == thread.
  KOKKOS_INLINE_FUNCTION void copy_block(const int b, const int output, const int thread, const int threads) const {
    for (int i = thread; i < count; i += threads)
      if (list(count + i) == static_cast<std::uintptr_t>(b))
        values(output, first_column + i) = *reinterpret_cast<const double*>(list(i));
  }
};

/// Members i of a block's contiguous values (block_statistic from 0: member begin + i is lane i % moment_lanes,
/// as when it runs from begin).
struct BlockValues {
  const double* x;
  KOKKOS_INLINE_FUNCTION double operator()(const int i) const { return x[i]; }
};

/// `Step`: a FilterBankStep; `Counted`: NotOkMembers (kernels/filters/filter_metrics.hpp), with count(s, begin, end).
/// operator()(b): block b takes steps first_step .. first_step + steps - 1. Output step s (output_of[s] >= 0) leaves
/// block b's row of output output_of[s] at rows + (output_of[s] num_blocks + b) width: per column its BlockStatistic
/// (BlockStatistics' layout), per counted column its count; and the values of the watched elements in block b.
template <class Step, class Counted>
struct FilterBankSegment {
  static constexpr int sink_doubles = 2 * Step::num_filters * moment_block_size;

  Step first;  // step first_step's kernel; each step's time, index and output flag are set from it
  long first_step;
  int steps;
  double dt;
  const int* output_of;  // per step of the segment: its output's index, or -1
  int last_output;       // the segment's last output step: its sink columns also go to the bank's snapshot columns
  const SegmentColumn* columns;
  int num_columns;
  Counted counted;
  double* rows;
  int num_blocks, width, members;
  WatchedElements<Kokkos::HostSpace> watched;

  void operator()(const int b) const {
    double sink[sink_doubles];
    const int begin = b * moment_block_size, end = block_end(b, members);
    Step step = first;
    step.snapshot_sink = sink;
    step.sink_first = begin;
    step.sink_stride = moment_block_size;
    for (int s = 0; s < steps; ++s) {
      const long k = first_step + s;
      step.truth.t = k * dt;  // run_step_kernel's time, bit for bit
      step.truth.step = static_cast<std::uint32_t>(k);
      step.record = output_of[s] >= 0;
      run_member_runs(step, begin, end);
      if (output_of[s] < 0) continue;
      double* const row = rows + (static_cast<std::size_t>(output_of[s]) * num_blocks + b) * width;
      for (int c = 0; c < num_columns; ++c) {
        const SegmentColumn& column = columns[c];
        const double* const x = column.sink >= 0 ? sink + column.sink * moment_block_size : column.column + begin;
        store_block_row(row, num_columns, c, block_statistic(BlockValues{x}, 0, end - begin));
      }
      for (int c = 0; c < counted.columns(); ++c) row[3 * num_columns + c] = counted.count(c, begin, end);
      watched.copy_block(b, output_of[s], 0, 1);
      if (s != last_output) continue;
      // What a step at a time leaves in the snapshot columns (a checkpoint saves them); only then read again.
      for (int c = 0; c < num_columns; ++c)
        if (columns[c].sink >= 0)
          store_streaming_run(columns[c].column + begin, sink + columns[c].sink * moment_block_size, end - begin);
      streaming_stores_done();
    }
  }
};

/// Most steps of a FilterBankTeamSegment launch (its output indices travel in the kernel's arguments).
constexpr int team_segment_max_steps = 32;

/// A segment on a GPU: one team per block of moment_block_size members (a CUDA block of up to 256 threads, a member per
/// thread), each block through every step, its columns in the SM's caches from step to step (a step at a time streamed
/// each member's ~420 bytes from device memory and back at every step). After an output step the team's warps reduce
/// the block's snapshot values (written by its own threads, read after a barrier) to its BlockStatistic rows and
/// divergence counts, as BlockColumnStatistics' warps do after a step at a time, and its threads copy the block's
/// watched elements; the rows of every output go to `rows` (output, block, width), merged where they are
/// (MergeBlockRows). On a GPU the columns in `sink_mask` (those of the filters whose slot has a team_sink: column c at
/// c moment_block_size in the block's sink) are written to and reduced from shared memory, and the launch's last output
/// step copies them to the snapshot columns, what a step at a time leaves there; 16 bytes per filter and member written
/// to device memory and read back at every output step made such a step 1.5x a step without outputs (1e6 members, four
/// filters, an H200). On the host (the tests' check of this form) a team is one thread, which steps its block chunk by
/// chunk (run_member_chunk) and reduces it with team_block_statistic: the numbers of FilterBankSegment.
template <class Step, class Counted, class MemSpace>
struct FilterBankTeamSegment {
  Step first;  // step first_step's kernel; each step's time, index and output flag are set from it
  long first_step;
  int steps;  // it takes steps first_step .. first_step + steps - 1
  double dt;
  int output_of[team_segment_max_steps];  // per step of the segment: its output's index, or -1
  int last_output;                        // the last output step, or -1
  ColumnAddresses<MemSpace> columns;
  int num_columns;
  std::uint64_t sink_mask;  // GPU: bit c, column c is in the block's sink (team_sink_values)
  Counted counted;
  Kokkos::View<double*, MemSpace> rows;
  int num_blocks, width, members;
  WatchedElements<MemSpace> watched;

  template <class Team>
  KOKKOS_INLINE_FUNCTION void operator()(const Team& team) const {
    const int b = team.league_rank();
    const int begin = b * moment_block_size, end = block_end(b, members);
#if KUSHNER_CUDA_DEVICE_PASS
    // Each thread passes a step's time, index and output flag to the step kernel, read where the launch put it
    // (constant memory): a copy per thread sat on each thread's stack (3240 bytes of local memory per thread for sine's
    // bank, by ptxas), and a copy per team in shared memory, its fields set by the team's first thread between two
    // barriers, made every view's pointer and stride a shared-memory load and every step two barriers. The team
    // meets only at output steps, where its warps reduce what its threads wrote.
    if (sink_mask != 0 && team.team_shmem().get_shmem(sink_bytes()) != team_sink_values())
      Kokkos::abort("FilterBankTeamSegment: the team's scratch is not where team_sink_values looks for it");
    for (int s = 0; s < steps; ++s) {
      const long k = first_step + s;
      const bool output = output_of[s] >= 0;
      for (int m = begin + team.team_rank(); m < end; m += team.team_size())
        first.step_at(m, k * dt, static_cast<std::uint32_t>(k), output);  // k * dt: run_step_kernel's time
      if (!output) continue;
      team.team_barrier();  // every member's snapshot values are written
      // The watched elements before the reduction: after it, the copy made the whole kernel spill more (ptxas: 96 ->
      // 128 bytes of spill stores), and a bank watching none ran at x0.96-0.97 of the bank before the copy instead of
      // x0.98-0.99 (an H200, 1e6 members; perf/filter_bank.md).
      watched.copy_block(b, output_of[s], team.team_rank(), team.team_size());
      reduce_block(team, output_row(s, b), begin, end, nullptr);
      if (s == last_output) sink_to_columns(team, begin, end);  // each thread its own members' values: no barrier
      team.team_barrier();  // and read, before a later output step writes them again
    }
#else
    // The host's team (one thread, the tests' check of this form) steps its block in the step kernel's own chunks,
    // which read the step's fields: one copy per team in its scratch, set before each step.
    const std::ptrdiff_t step_bytes = sizeof(Step);  // copies: get_shmem takes a reference
    Step* const step = static_cast<Step*>(team.team_shmem().get_shmem_aligned(step_bytes, step_alignment));
    const std::ptrdiff_t bytes = block_team_scratch_bytes;
    double* const scratch = static_cast<double*>(team.team_shmem().get_shmem(bytes));
    Kokkos::single(Kokkos::PerTeam(team), [&]() { new (step) Step(first); });
    for (int s = 0; s < steps; ++s) {
      Kokkos::single(Kokkos::PerTeam(team), [&]() {
        const long k = first_step + s;
        step->truth.t = k * dt;  // run_step_kernel's time, bit for bit
        step->truth.step = static_cast<std::uint32_t>(k);
        step->record = output_of[s] >= 0;
      });
      team.team_barrier();  // the step's fields are set
      step_block(*step, begin, end);
      team.team_barrier();  // every member took the step (its snapshot values are written) before the fields change
      if (output_of[s] < 0) continue;
      Kokkos::single(Kokkos::PerTeam(team), [&]() { watched.copy_block(b, output_of[s], 0, 1); });
      reduce_block(team, output_row(s, b), begin, end, scratch);
    }
    team.team_barrier();
    Kokkos::single(Kokkos::PerTeam(team), [&]() { step->~Step(); });
#endif
  }

  /// Team scratch of a host launch: the team's step kernel (with room to align it) and team_block_statistic's
  /// (sizeof(Step) is a multiple of its alignment, at least a double's: the doubles that follow it are aligned). A
  /// GPU's team: its block's sink.
  static constexpr std::ptrdiff_t step_alignment = alignof(Step) > 16 ? alignof(Step) : 16;
  static constexpr bool host_team = Kokkos::SpaceAccessibility<Kokkos::HostSpace, MemSpace>::accessible;
  std::size_t scratch_bytes() const {
    return host_team ? step_alignment + sizeof(Step) + block_team_scratch_bytes : sink_bytes();
  }

  /// The block's sink: room for every column up to the last one in it.
  KOKKOS_INLINE_FUNCTION std::ptrdiff_t sink_bytes() const {
    int columns_in_sink = 0;
    for (int c = 0; c < num_columns; ++c)
      if (in_sink(c)) columns_in_sink = c + 1;
    return static_cast<std::ptrdiff_t>(sizeof(double)) * columns_in_sink * moment_block_size;
  }

 private:
  /// The host's team (one thread: FilterBank launches host teams of one) steps its block in the step kernel's own
  /// chunks (its bits: lanes and vector math).
  KOKKOS_INLINE_FUNCTION void step_block(const Step& step, const int begin, const int end) const {
#if !KUSHNER_CUDA_DEVICE_PASS
    if constexpr (Kokkos::SpaceAccessibility<Kokkos::HostSpace, MemSpace>::accessible)
      run_member_runs(step, begin, end);
#endif
  }

  KOKKOS_INLINE_FUNCTION bool in_sink(const int c) const { return (sink_mask >> c) & 1u; }

#if KUSHNER_CUDA_DEVICE_PASS
  /// The sink's values of the members this thread steps to their snapshot columns.
  template <class Team>
  __device__ void sink_to_columns(const Team& team, const int begin, const int end) const {
    const double* const sink = team_sink_values();
    for (int c = 0; c < num_columns; ++c) {
      if (!in_sink(c)) continue;
      double* const column = reinterpret_cast<double*>(columns.addresses(c));
      for (int m = begin + team.team_rank(); m < end; m += team.team_size())
        column[m] = sink[c * moment_block_size + m - begin];
    }
  }
#endif

  /// Block b's row of output step s's output in `rows`.
  KOKKOS_INLINE_FUNCTION double* output_row(const int s, const int b) const {
    return rows.data() + (static_cast<std::size_t>(output_of[s]) * num_blocks + b) * width;
  }

  template <class Team>
  KOKKOS_INLINE_FUNCTION void reduce_block(const Team& team, double* row, const int begin, const int end,
                                           double* scratch) const {
#if KUSHNER_CUDA_DEVICE_PASS
    // A column per warp at a time; lane j of a warp adds block_statistic's lane j.
    const int warps = team.team_size() / moment_lanes, warp = team.team_rank() / moment_lanes;
    const int j = team.team_rank() % moment_lanes;
    for (int c = warp; c < num_columns + counted.columns(); c += warps) {
      if (c < num_columns) {
        const BlockStatistic s =
            in_sink(c)
                ? warp_block_statistic(j, ColumnValue{team_sink_values() + c * moment_block_size}, 0, end - begin)
                : warp_block_statistic(j, columns(c), begin, end);
        if (j == 0) store_block_row(row, num_columns, c, s);
      } else {
        const int counted_column = c - num_columns;
        const int count = counted.warp_count(j, counted_column, begin, end);
        if (j == 0) row[3 * num_columns + counted_column] = count;
      }
    }
#else
    for (int c = 0; c < num_columns; ++c) {
      const BlockStatistic s = team_block_statistic(team, columns(c), begin, end, scratch);
      Kokkos::single(Kokkos::PerTeam(team), [&]() { store_block_row(row, num_columns, c, s); });
    }
    for (int c = 0; c < counted.columns(); ++c) {
      const int count = team_block_count(
          team, [&](const int m) { return counted(c, m); }, begin, end);
      Kokkos::single(Kokkos::PerTeam(team), [&]() { row[3 * num_columns + c] = count; });
    }
#endif
  }
};

}  // namespace kushner
