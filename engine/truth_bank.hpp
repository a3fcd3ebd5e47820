#pragma once
// Simulates the bank of truths over a time grid and records ensemble moments at the grid's output steps.
// Shared by `kushner simulate`, the tests and the benchmarks.
#include "core/eigen_helpers.hpp"
#include "core/errors.hpp"
#include "engine/member_share.hpp"
#include "engine/progress_callback.hpp"
#include "engine/time_grid.hpp"
#include "kernels/ensemble_moments.hpp"
#include "kernels/simulate_truth.hpp"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <type_traits>
#include <utility>
#include <vector>

namespace kushner {

struct MomentSeries {
  std::vector<double> times;
  std::vector<EnsembleMoments> moments;  // one per time
  double step_loop_seconds = 0.0;        // wall time of the steps and moments (this rank; fenced)
};

template <class ExecSpace, class Model>
class TruthBank {
 public:
  using MemSpace = typename ExecSpace::memory_space;

  TruthBank(const ExecSpace& space, const Model& model, long members, Seed seed)
      : space_(space),
        model_(model),
        seed_(seed),
        x_("kushner::truth", members, Model::state_dim),
        observations_("kushner::observations", members, Model::obs_dim) {
    initialize_gaussian<ExecSpace, Model::state_dim, MemSpace>(
        space_, x_, model.x0_mean, covariance_square_root(model.x0_cov), RngKey{seed, Stream::truth_initial});
  }

  /// Step k: [k dt, (k+1) dt].
  void step(long k, double dt) { simulate_truth_step(space_, model_, x_, observations_, k, dt, seed_); }

  /// step(k, dt), then ensemble_moments(state()) (a collective call, the same bits); on the host from
  /// truth_block_min_members members a segment of one step, whose blocks leave their statistics while in their core's
  /// cache (a reduction of its own read the whole state back from memory: as much as a tenth of the cubic
  /// oscillator's step at 1e6 members, perf/filter_bank.md).
  EnsembleMoments step_and_moments(long k, double dt) {
    if (steps_in_segments()) return std::move(step_segment(k, dt, {1}).front());
    step(k, dt);
    return moments();
  }

  /// Whether step_segment may run: a host bank of truth_block_min_members members or more.
  bool steps_in_segments() const {
    if constexpr (std::is_same<MemSpace, Kokkos::HostSpace>::value)
      return truth_step_by_blocks(x_);
    else
      return false;
  }

  /// Steps k .. k + outputs.size() - 1 (at most truth_segment_steps) by blocks, each block through all of them while
  /// it is in its core's cache (TruthSegmentBlocks): the states, observations and moments of step() and
  /// step_and_moments() one step at a time, bit for bit. outputs[s] != 0: the moments of the state step k + s leaves,
  /// returned in order (a collective call per output). Needs steps_in_segments().
  std::vector<EnsembleMoments> step_segment(long k, double dt, const std::vector<char>& outputs) {
    KUSHNER_REQUIRE(steps_in_segments(),
                    "step_segment: " << x_.extent(0) << " members on this backend step one at a time");
    KUSHNER_REQUIRE(!outputs.empty() && outputs.size() <= static_cast<std::size_t>(truth_segment_steps),
                    "step_segment: " << outputs.size() << " steps, a segment takes 1 to " << truth_segment_steps);
    std::vector<int> output_of(outputs.size(), -1);
    int num_outputs = 0;
    for (std::size_t s = 0; s < outputs.size(); ++s)
      if (outputs[s] != 0) output_of[s] = num_outputs++;
    const long members = static_cast<long>(x_.extent(0));
    const std::size_t rows_per_output = static_cast<std::size_t>(moment_blocks(members)) * 3 * Model::state_dim;
    segment_rows_.resize(rows_per_output * num_outputs);
    if constexpr (std::is_same<MemSpace, Kokkos::HostSpace>::value)
      step_truth_segment(space_, model_, x_, observations_, k, output_of, dt, seed_, segment_rows_.data());
    space_.fence();
    std::vector<EnsembleMoments> moments;
    for (int o = 0; o < num_outputs; ++o)
      moments.push_back(moments_of_block_rows(segment_rows_.data() + o * rows_per_output, rows_per_output,
                                              Model::state_dim, members));
    return moments;
  }

  /// ensemble_moments(state()) (a collective call), its block rows kept from call to call (moment_rows_).
  EnsembleMoments moments() { return ensemble_moments(space_, x_, moment_rows_); }

  const BankVector<MemSpace>& state() const { return x_; }
  const BankVector<MemSpace>& observations() const { return observations_; }

 private:
  ExecSpace space_;
  Model model_;
  Seed seed_;
  BankVector<MemSpace> x_, observations_;
  MomentRows<MemSpace> moment_rows_;  // the moments' block rows, from output step to output step
  std::vector<double> segment_rows_;  // step_segment's, (output, block, 3 state_dim), kept from segment to segment
};

template <class ExecSpace, class Model>
MomentSeries simulate_ensemble(const ExecSpace& space, const Model& model, long members, std::uint32_t seed,
                               const TimeGrid& grid, const ProgressCallback& progress = {}) {
  const MemberShare share = member_share(members);  // this rank's members; the moments cover every rank's
  TruthBank<ExecSpace, Model> bank(space, model, share.count, share.seed(seed));
  MomentSeries series;
  std::size_t next_output = 0;
  const auto output_at = [&](const long k) {
    const bool output = next_output < grid.output_steps.size() && grid.output_steps[next_output] == k;
    if (output) {
      series.times.push_back(k * grid.dt);
      ++next_output;
    }
    return output;
  };
  space.fence();
  const auto loop_start = std::chrono::steady_clock::now();
  if (output_at(0)) series.moments.push_back(bank.moments());
  for (long k = 0; k < grid.steps;) {
    if (bank.steps_in_segments()) {
      std::vector<char> outputs;
      for (long s = k; s < std::min<long>(k + truth_segment_steps, grid.steps); ++s)
        outputs.push_back(output_at(s + 1));
      for (EnsembleMoments& m : bank.step_segment(k, grid.dt, outputs)) series.moments.push_back(std::move(m));
      k += static_cast<long>(outputs.size());
    } else {
      if (output_at(k + 1))  // the moments of the state step k leaves
        series.moments.push_back(bank.step_and_moments(k, grid.dt));
      else
        bank.step(k, grid.dt);
      ++k;
    }
    if (progress) progress(k);
  }
  space.fence();
  series.step_loop_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - loop_start).count();
  return series;
}

}  // namespace kushner
