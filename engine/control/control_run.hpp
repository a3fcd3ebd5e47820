#pragma once
// A whole `kushner control` experiment: every controller LAW@ESTIMATOR run in closed loop over the grid, one
// after the other on the same members, initial states and noise (engine/control/closed_loop.hpp), with the
// per-member costs kept so that controllers are compared by paired differences. A bank filter with a pre-pass
// (ASRE) gets it inside its own loop, with the law it serves.
#include "core/collectives.hpp"
#include "core/fields.hpp"
#include "core/options.hpp"
#include "engine/control/closed_loop.hpp"
#include "engine/control/control_laws.hpp"
#include "engine/member_share.hpp"
#include "engine/progress_callback.hpp"
#include "engine/time_grid.hpp"
#include "kernels/host_copy.hpp"

#include <Kokkos_Core.hpp>

#include <chrono>
#include <string>
#include <type_traits>
#include <vector>

namespace kushner {

struct ControllerSpec {
  std::string name;       // as reported: LAW@ESTIMATOR, or the alias it was given by
  std::string law;        // law_list()
  std::string estimator;  // state_estimator_name, a bank filter, or particle_filter_name
};

/// One controller over the run.
struct ControllerRun {
  ControllerSpec spec;
  std::vector<double> cost;            // per member: J (NaN where the truth escaped)
  std::vector<double> control_energy;  // per member: integral of |u|^2 dt
  std::vector<double> squared_error;   // per member: integral of |x - x_hat|^2 dt (x_hat: the law's estimate)
  std::vector<double> terminal_mean;   // mean x(T) over members whose truth did not escape
  long truths_escaped = 0, estimator_diverged = 0;
  Fields law_fields, estimator_fields;
  // At the output times: ensemble means, and one member's path (the traced member).
  std::vector<std::vector<double>> state_mean, control_mean;  // [time][component]
  std::vector<double> running_cost_mean;                      // mean running cost accrued up to the time
  std::vector<std::vector<double>> member_state, member_estimate, member_control;  // [time][component]
  double step_loop_seconds = 0.0;  // wall time of the closed loop's steps (this rank; fenced)
};

struct ControlReport {
  std::vector<double> times;
  std::vector<ControllerRun> controllers;
  long traced_member = 0;
};

/// Steps a control run reports to its progress callback: each controller's loop, and its estimator's pre-pass.
template <class Model>
long control_progress_steps(const std::vector<ControllerSpec>& specs, const TimeGrid& grid) {
  long passes = 0;
  for (const auto& spec : specs) {
    passes += 1;
    for_each_filter_type<Model, Kokkos::HostSpace>([&](auto* tag) {
      using Filter = std::remove_pointer_t<decltype(tag)>;
      if (spec.estimator == Filter::name) passes += filter_prepass_passes<Filter>();
    });
  }
  return passes * grid.steps;
}

namespace detail {

/// Global member `member`'s row of a (member, column) view of this rank's share, on every rank: the rank that
/// holds it copies it to the host (host_copy: the row is strided) and sends it to the others.
template <class ExecSpace, class View>
std::vector<double> host_row(const ExecSpace& space, const View& v, const MemberShare& share, long member) {
  std::vector<double> row;
  if (share.holds(member)) {
    space.fence();
    const auto h = host_copy(Kokkos::subview(v, member - share.first, Kokkos::ALL));
    row.resize(h.extent(0));
    for (std::size_t i = 0; i < row.size(); ++i) row[i] = h(i);
  }
  return collective::broadcast(row, member_owner(member, share.total));
}

}  // namespace detail

template <class ExecSpace, class Model>
ControllerRun run_controller(const ExecSpace& space, const Model& model, long members, std::uint32_t seed,
                             const TimeGrid& grid, const ControllerSpec& spec,
                             const QuadraticCost<Model::state_dim, Model::control_dim>& cost,
                             const OptionValues& options, const ParticleSettings& particle, long traced_member,
                             std::vector<double>* times, const ProgressCallback& progress, long& progress_base) {
  using MemSpace = typename ExecSpace::memory_space;
  using Loop = ControlLoop<ExecSpace, Model>;
  // This rank's members; what the run reports covers every rank's, gathered in member order.
  const MemberShare share = member_share(members);
  const Seed rank_seed = share.seed(seed);
  members = share.count;
  ControllerRun run;
  run.spec = spec;
  const MadeLaw<Model, MemSpace> law = make_law<Model, MemSpace>(spec.law, model, cost, grid);
  run.law_fields = law.fields;

  typename Loop::PreparedFilters prepared;
  for_each_filter_type<Model, MemSpace>([&](auto* tag) {
    using Filter = std::remove_pointer_t<decltype(tag)>;
    if constexpr (Filter::unsupported == nullptr && filter_prepass_passes<Filter>() > 0) {
      if (spec.estimator != Filter::name) return;
      const long start = progress_base;
      const auto run_alone = [&](const Filter& filter) {
        typename Loop::PreparedFilters only;
        std::get<std::optional<Filter>>(only) = filter;
        Loop loop(space, model, members, rank_seed, spec.estimator, law.law, cost, options, particle, only);
        for (long k = 0; k < grid.steps; ++k) {
          loop.step(k, grid.dt, false);
          if (progress) progress(progress_base + k + 1);
        }
        progress_base += grid.steps;
        return loop.members_ok();
      };
      std::get<std::optional<Filter>>(prepared) =
          Filter::prepare(options.with_defaults(filter_options<Filter>()), model, members, run_alone);
      progress_base = start + filter_prepass_passes<Filter>() * grid.steps;
    }
    if constexpr (Filter::unsupported == nullptr && detail::follows_nominal<Filter, Model::control_dim>::value) {
      if (spec.estimator != Filter::name || law.nominal_control.empty()) return;
      Filter filter = create_filter<Filter>(options.with_defaults(filter_options<Filter>()), model, members, rank_seed);
      filter.follow_nominal(law.nominal_control);  // the filter's linearization follows the law's path
      std::get<std::optional<Filter>>(prepared) = filter;
    }
  });

  Loop loop(space, model, members, rank_seed, spec.estimator, law.law, cost, options, particle, prepared);
  MomentRows<MemSpace> state_rows, control_rows;  // from output step to output step
  auto record = [&](double t) {
    if (times) times->push_back(t);
    run.state_mean.push_back(ensemble_moments(space, loop.truths().state(), state_rows).mean);
    run.control_mean.push_back(ensemble_moments(space, loop.control(), control_rows).mean);
    const std::vector<double> running = collective::gather(loop.member_running_cost());
    double sum = 0.0;
    long count = 0;
    for (double c : running)
      if (std::isfinite(c)) sum += c, ++count;
    run.running_cost_mean.push_back(count > 0 ? sum / count : std::nan(""));
    run.member_state.push_back(detail::host_row(space, loop.truths().state(), share, traced_member));
    run.member_estimate.push_back(detail::host_row(space, loop.estimate(), share, traced_member));
    run.member_control.push_back(detail::host_row(space, loop.control(), share, traced_member));
  };
  record(0.0);
  std::size_t next_output = 1;
  space.fence();
  const auto loop_start = std::chrono::steady_clock::now();
  for (long k = 0; k < grid.steps; ++k) {
    const bool output = next_output < grid.output_steps.size() && grid.output_steps[next_output] == k + 1;
    loop.step(k, grid.dt, output);
    if (output) {
      record((k + 1) * grid.dt);
      ++next_output;
    }
    if (progress) progress(progress_base + k + 1);
  }
  progress_base += grid.steps;
  space.fence();
  run.step_loop_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - loop_start).count();
  run.cost = collective::gather(loop.member_costs());
  run.control_energy = collective::gather(loop.member_control_energy());
  run.squared_error = collective::gather(loop.member_squared_error());
  run.terminal_mean = ensemble_moments(space, loop.truths().state(), state_rows).mean;
  run.truths_escaped = loop.truths_escaped();
  run.estimator_diverged = loop.estimator_diverged();
  run.estimator_fields = loop.estimator_fields();
  return run;
}

/// Runs every controller of `specs` (laws and estimators the model supports: the command line checks them).
template <class ExecSpace, class Model>
ControlReport run_control(const ExecSpace& space, const Model& model, long members, std::uint32_t seed,
                          const TimeGrid& grid, const std::vector<ControllerSpec>& specs,
                          const QuadraticCost<Model::state_dim, Model::control_dim>& cost,
                          const OptionValues& options = {}, const ParticleSettings& particle = {},
                          const ProgressCallback& progress = {}, long traced_member = 0) {
  KUSHNER_REQUIRE(traced_member >= 0 && traced_member < members, "traced member " << traced_member);
  ControlReport report;
  report.traced_member = traced_member;
  long progress_base = 0;
  for (std::size_t c = 0; c < specs.size(); ++c)
    report.controllers.push_back(run_controller(space, model, members, seed, grid, specs[c], cost, options, particle,
                                                traced_member, c == 0 ? &report.times : nullptr, progress,
                                                progress_base));
  return report;
}

}  // namespace kushner
