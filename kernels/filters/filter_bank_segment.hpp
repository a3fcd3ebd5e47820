#pragma once
// Several steps of a host bank in one pass over its members (temporal blocking): each block of moment_block_size
// members takes every step of a segment while its columns stay in the core's cache, and after each output step it
// reduces its own snapshot values to the block statistics that the output's moments merge
// (kernels/ensemble_moments.hpp). A step at a time, a step streamed each member's ~420 bytes (truth, and per filter m,
// P, status, three score sums) from memory and back: sine with EKF, SOF, QLF, KBL ran 2.2e7 member-steps/s per thread
// at 1e6 members against 3.9e7 at 8192 members, whose columns fit in the caches. A member's step is the step kernel's
// own chunk function (run_member_chunk: the same machine code, on the same chunks) and a block's statistic is
// block_statistic of the same values in the same order, so the numbers are the same bits as those of steps taken one at
// a time.
#include "kernels/ensemble_moments.hpp"
#include "kernels/for_each_member.hpp"
#include "kernels/streaming_store.hpp"

#include <cstddef>
#include <cstdint>

namespace kushner {

/// A column an output step reduces: a filter's snapshot values in the block's sink (`sink` >= 0: the sink's column)
/// or in the bank's snapshot column `column` (member-indexed).
struct SegmentColumn {
  double* column;
  int sink;
};

/// Members i of a block's contiguous values (block_statistic from 0: member begin + i is lane i % moment_lanes,
/// as when it runs from begin).
struct BlockValues {
  const double* x;
  KOKKOS_INLINE_FUNCTION double operator()(const int i) const { return x[i]; }
};

/// `Step`: a FilterBankStep; `Counted`: NotOkMembers (kernels/filters/filter_metrics.hpp), with count(s, begin, end).
/// operator()(b): block b takes steps first_step .. first_step + steps - 1 (unless it is among `skipped`, which the
/// caller steps itself with run_block). Output step s (output_of[s] >= 0) leaves block b's row of output output_of[s]
/// at rows + (output_of[s] num_blocks + b) width: per column its BlockStatistic (BlockStatistics' layout), per counted
/// column its count.
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
  const int* skipped;  // blocks operator() leaves alone, in increasing order
  int num_skipped;

  void operator()(const int b) const {
    for (int i = 0; i < num_skipped; ++i)
      if (skipped[i] == b) return;
    run_block(b, 0, steps);
  }

  /// Block b's steps [first_step + s0, first_step + s1).
  KUSHNER_SAME_CODE_FOR_ALL_CALLERS void run_block(const int b, const int s0, const int s1) const {
    double sink[sink_doubles];
    const int begin = b * moment_block_size, end = block_end(b, members);
    Step step = first;
    step.snapshot_sink = sink;
    step.sink_first = begin;
    step.sink_stride = moment_block_size;
    for (int s = s0; s < s1; ++s) {
      const long k = first_step + s;
      step.truth.t = k * dt;  // run_step_kernel's time, bit for bit
      step.truth.step = static_cast<std::uint32_t>(k);
      step.record = output_of[s] >= 0;
      for (int chunk = begin; chunk < end; chunk += host_member_chunk)
        run_member_chunk(step, chunk, end - chunk < host_member_chunk ? end : chunk + host_member_chunk);
      if (output_of[s] < 0) continue;
      double* const row = rows + (static_cast<std::size_t>(output_of[s]) * num_blocks + b) * width;
      for (int c = 0; c < num_columns; ++c) {
        const SegmentColumn& column = columns[c];
        const double* const x = column.sink >= 0 ? sink + column.sink * moment_block_size : column.column + begin;
        const BlockStatistic statistic = block_statistic(BlockValues{x}, 0, end - begin);
        row[c] = statistic.count;
        row[num_columns + c] = statistic.mean;
        row[2 * num_columns + c] = statistic.m2;
      }
      for (int c = 0; c < counted.columns(); ++c) row[3 * num_columns + c] = counted.count(c, begin, end);
      if (s != last_output) continue;
      // What a step at a time leaves in the snapshot columns (a checkpoint saves them); only then read again.
      for (int c = 0; c < num_columns; ++c)
        if (columns[c].sink >= 0)
          for (int m = begin; m < end; ++m)
            store_streaming(columns[c].column + m, sink[columns[c].sink * moment_block_size + m - begin]);
      streaming_stores_done();
    }
  }
};

}  // namespace kushner
