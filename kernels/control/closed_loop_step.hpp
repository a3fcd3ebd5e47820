#pragma once
// One step of one controller's closed loop, for every member in one kernel: the law reads the member's
// estimate at t, the cost accrues over [t, t + dt] at the left end (the rule the reference solvers use too),
// the truth takes its Euler-Maruyama step (a discrete-time model: its transition) driven by that control, and
// the estimator (a filter of the bank, or none: the state itself, or an estimator outside the kernel such as the
// particle filter, which then steps on the `control` this kernel stores) takes its step with the truth's dy (or
// z[k+1]) and the known input B u. Clark's estimation-error term accrues with the running cost. The filters are
// the model's compile-time list with at most one enabled, so each model's closed loop is one kernel whatever
// the estimator.
#include "kernels/control/control_law.hpp"
#include "kernels/control/quadratic_cost.hpp"
#include "kernels/filters/filter_bank_step.hpp"
#include "kernels/filters/filter_slot.hpp"
#include "kernels/simulate_truth.hpp"

#include <Kokkos_Core.hpp>

namespace kushner {

/// Columns of the per-member totals of a closed loop.
enum LoopColumn : int {
  loop_running_cost = 0,    // sum over steps of running(x, u) dt
  loop_control_energy = 1,  // sum over steps of |u|^2 dt
  loop_squared_error = 2,   // sum over steps of |x - x_hat|^2 dt, x_hat the estimate the law reads
  num_loop_columns = 3,
};

/// Where the law's estimate comes from.
enum class EstimateSource { state, bank_filter, outside };

template <class Model, class MemSpace, class... Filters>
struct ClosedLoopStep {
  static constexpr int n = Model::state_dim, p = Model::obs_dim, m = Model::control_dim;
  TruthStep<Model, MemSpace> truth;
  Model model;
  BankScalar<Status, MemSpace> truth_status;
  FilterSlots<MemSpace, Filters...> slots;  // at most one enabled: the estimator when source == bank_filter
  EstimateSource source = EstimateSource::state;
  BankVector<MemSpace> outside_estimate;  // (member, i) when source == outside (e.g. the particle filter's mean)
  ControlLaw<n, m, MemSpace> law;
  QuadraticCost<n, m> cost;
  BankVector<MemSpace> control;  // (member, j): the control over this step, written here
  BankVector<MemSpace> totals;   // (member, LoopColumn)
  long step = 0;
  bool record = false;

  KOKKOS_INLINE_FUNCTION void operator()(const int member) const {
    if (truth_status(member) != Status::ok) {
      if (record) (mark_unscored(static_cast<const FilterSlot<Filters, MemSpace>&>(slots), member), ...);
      return;
    }
    const Vec<n> x = load<n>(truth.x, member);
    Vec<n> estimate = x;
    if (source == EstimateSource::outside) estimate = load<n>(outside_estimate, member);
    if (source == EstimateSource::bank_filter)
      (read_estimate(static_cast<const FilterSlot<Filters, MemSpace>&>(slots), member, estimate), ...);
    const Vec<m> u = law(step, estimate);
    totals(member, loop_running_cost) += (cost.running(x, u) + cost.estimation_penalty(x, estimate)) * truth.dt;
    totals(member, loop_control_energy) += cost.control_energy(u) * truth.dt;
    totals(member, loop_squared_error) += dot(x - estimate, x - estimate) * truth.dt;
    store(control, member, u);
    truth.step_member(member, u);
    const Vec<n> next = load<n>(truth.x, member);
    const Vec<p> dy = load<p>(truth.dy, member);
    if (!(all_finite(next) && all_finite(dy))) {
      truth_status(member) = Status::non_finite;
      if (record) (mark_unscored(static_cast<const FilterSlot<Filters, MemSpace>&>(slots), member), ...);
      return;
    }
    if (source != EstimateSource::bank_filter) return;
    const Mat<p, p> R = model.observation_noise(truth.t);
    const StepInput<p> in{truth.t, truth.dt, truth.step, dy, R * transpose(R)};
    // The known input: B u dt of the Euler step, or a discrete step's B u (kernels/filters/filter_slot.hpp).
    const Vec<n> shift = model.control_input(truth.t) * u * (Model::discrete_time ? 1.0 : truth.dt);
    (advance(static_cast<const FilterSlot<Filters, MemSpace>&>(slots), model, member, in, next, record, shift), ...);
  }

 private:
  template <class Filter>
  KOKKOS_INLINE_FUNCTION static void read_estimate(const FilterSlot<Filter, MemSpace>& s, int member, Vec<n>& m_out) {
    if (s.enabled) m_out = load<n>(s.m, member);
  }
};

/// At T: each member's total cost, running plus terminal, into `cost_out` (NaN for a member whose truth escaped).
template <class Model, class MemSpace>
struct ClosedLoopTerminal {
  static constexpr int n = Model::state_dim, m = Model::control_dim;
  BankVector<MemSpace> x;
  BankScalar<Status, MemSpace> truth_status;
  QuadraticCost<n, m> cost;
  BankVector<MemSpace> totals;
  BankScalar<double, MemSpace> cost_out;

  KOKKOS_INLINE_FUNCTION void operator()(const int member) const {
    cost_out(member) = truth_status(member) == Status::ok
                           ? totals(member, loop_running_cost) + cost.terminal(load<n>(x, member))
                           : math::quiet_nan();
  }
};

}  // namespace kushner
