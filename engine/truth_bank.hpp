#pragma once
// Simulates the bank of truths over a time grid and records ensemble moments at the grid's output steps.
// Shared by `kushner simulate`, the tests and the benchmarks.
#include "core/eigen_helpers.hpp"
#include "engine/member_share.hpp"
#include "engine/progress_callback.hpp"
#include "engine/time_grid.hpp"
#include "kernels/ensemble_moments.hpp"
#include "kernels/simulate_truth.hpp"

#include <chrono>
#include <cstdint>
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
  void step(long k, double dt) {
    simulate_truth_step(space_, model_, x_, observations_, k * dt, dt, seed_, static_cast<std::uint32_t>(k));
  }

  /// step(k, dt), then ensemble_moments(state()) (a collective call); in one pass on the host from
  /// truth_block_min_members members (simulate_truth_step_and_moments).
  EnsembleMoments step_and_moments(long k, double dt) {
    return simulate_truth_step_and_moments(space_, model_, x_, observations_, k * dt, dt, seed_,
                                           static_cast<std::uint32_t>(k), moment_rows_);
  }

  /// ensemble_moments(state()) with step_and_moments' rows (a collective call).
  EnsembleMoments moments() { return ensemble_moments(space_, x_, moment_rows_); }

  const BankVector<MemSpace>& state() const { return x_; }
  const BankVector<MemSpace>& observations() const { return observations_; }

 private:
  ExecSpace space_;
  Model model_;
  Seed seed_;
  BankVector<MemSpace> x_, observations_;
  MomentRows<MemSpace> moment_rows_;  // the moments' block rows, from output step to output step
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
  for (long k = 0; k < grid.steps; ++k) {
    if (output_at(k + 1))  // the moments of the state step k leaves
      series.moments.push_back(bank.step_and_moments(k, grid.dt));
    else
      bank.step(k, grid.dt);
    if (progress) progress(k + 1);
  }
  space.fence();
  series.step_loop_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - loop_start).count();
  return series;
}

}  // namespace kushner
