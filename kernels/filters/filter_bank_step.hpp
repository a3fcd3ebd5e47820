#pragma once
// The bank's kernels. One step is one pass over the members: each member's truth takes its Euler-Maruyama
// step (producing dy; a discrete-time model: its transition, producing z[k+1]), then every selected filter
// takes its step with that same observation and is scored against the new truth. The filters are a compile-time list
// (no virtual calls); unselected ones are skipped by a flag that is the same for every member.
#include "kernels/filters/filter_slot.hpp"
#include "kernels/simulate_truth.hpp"
#include "kernels/streaming_store.hpp"

#include <Kokkos_Core.hpp>

#include <cstdint>
#include <type_traits>

namespace kushner {

/// The slots of a list of filters, one base class each, so that a fold expression visits all of them.
template <class MemSpace, class... Filters>
struct FilterSlots : FilterSlot<Filters, MemSpace>... {};

/// `TruthModel`: the truths' model, Model or one of the same dimensions (e.g. the system a Taylor model of it
/// approximates, or Model with a deterministic observation noise); `model`: the filters' model.
template <class Model, class TruthModel, class MemSpace, class... Filters>
struct FilterBankStep {
  static_assert(TruthModel::state_dim == Model::state_dim && TruthModel::obs_dim == Model::obs_dim,
                "FilterBankStep: the truths' model and the filters' model must have the same dimensions");
  static constexpr int num_filters = sizeof...(Filters);
  TruthStep<TruthModel, MemSpace> truth;
  Model model;
  BankScalar<Status, MemSpace> truth_status;  // non_finite once a truth escaped: not filtered, not scored
  FilterSlots<MemSpace, Filters...> slots;
  bool record;  // the step ends at an output time: fill the snapshots
  // Host segments (kernels/filters/filter_bank_segment.hpp): where the filters that fills_sink() put a chunk's
  // snapshot values instead of their snapshot columns: filter slot_index<Filter>()'s column c of member m at
  // snapshot_sink[(2 slot_index + c) * sink_stride + m - sink_first]. Null: the columns.
  double* snapshot_sink = nullptr;
  int sink_first = 0, sink_stride = 0;

  /// Filter's place among Filters... (the sink's order).
  template <class Filter>
  static constexpr int slot_index() {
    int index = 0, found = -1;
    ((found = found < 0 && std::is_same<Filter, Filters>::value ? index : found, ++index), ...);
    return found;
  }
  /// Whether run_chunk gives Filter's snapshot values to the sink (its lanes: filter_lanes); the others write their
  /// snapshot columns member by member (advance).
  template <class Filter>
  static constexpr bool fills_sink() {
    return !(Model::discrete_time || TruthModel::discrete_time) && filter_step_is_pure<Filter, Model::state_dim>;
  }

  KOKKOS_INLINE_FUNCTION void operator()(const int member) const { step_at(member, truth.t, truth.step, record); }

  /// operator() as step k at time `at`, an output step where `at_output` (a step at a time: the fields truth.t,
  /// truth.step and record). A GPU's segment passes each of its steps' here and reads the kernel where it is, in
  /// constant memory: a copy whose fields it set per step sat in shared memory, and every view's pointer and stride
  /// was then a load of its own.
  KOKKOS_INLINE_FUNCTION void step_at(const int member, const double at, const std::uint32_t k,
                                      const bool at_output) const {
    constexpr int n = Model::state_dim, p = Model::obs_dim;
    const Status truth_was = truth_status(member);
    const Vec<n> x0 = load<n>(truth.x, member);  // read with the status: one wait for memory, not two
    if (truth_was != Status::ok) {
      if (at_output) (mark_unscored(static_cast<const FilterSlot<Filters, MemSpace>&>(slots), member), ...);
      return;
    }
    Vec<n> x;
    Vec<p> dy;
    truth.step_from(member, at, k, TruthModel::Control::zero(), x0, x, dy);
    if (!(all_finite(x) && all_finite(dy))) {
      truth_status(member) = Status::non_finite;
      if (at_output) (mark_unscored(static_cast<const FilterSlot<Filters, MemSpace>&>(slots), member), ...);
      return;
    }
    const Mat<p, p> R = model.observation_noise(at);
    const StepInput<p> in{at, truth.dt, k, dy, R * transpose(R)};
    (advance(static_cast<const FilterSlot<Filters, MemSpace>&>(slots), model, member, in, x, at_output), ...);
  }

  /// Host: operator() for the members [begin, end) of one chunk (kernels/for_each_member.hpp), with the members
  /// in SIMD lanes: the truths' step first (EulerMaruyamaTruthStep::step_lane), then each filter over the chunk
  /// (advance_lane; members are independent, so the order changes nothing). A filter whose step is not pure (own
  /// state, random numbers) takes its step member by member as in operator(). Discrete time: operator().
  void run_chunk(const int begin, const int end) const {
    if constexpr (Model::discrete_time || TruthModel::discrete_time) {
      for (int member = begin; member < end; ++member) (*this)(member);
    } else {
      std::int64_t live[host_lane_capacity];  // 64-bit: see advance_lane
      truth_lanes(begin, end, live);
      const Mat<Model::obs_dim, Model::obs_dim> R = model.observation_noise(truth.t);
      (filter_chunk(static_cast<const FilterSlot<Filters, MemSpace>&>(slots), begin, end, live, R * transpose(R)), ...);
      // Once per chunk, not per filter: a fence per filter made an output step 15% slower (2 threads, 1e6 members).
      if (record) streaming_stores_done();
    }
  }

 private:
  /// The truths of the chunk in SIMD lanes, as operator() steps them (a truth not ok is left as it is, one that
  /// becomes non-finite is marked); live[member - begin]: the member's truth is ok after the step.
  KUSHNER_FLATTEN void truth_lanes(const int begin, const int end, std::int64_t* live) const {
    double z[TruthStep<TruthModel, MemSpace>::lane_draws * host_lane_capacity];
    truth.draw_lanes(begin, end, z);
    double* const xs = truth.x.data();  // raw pointers: GCC does not vectorize a loop that reloads a View's pointer
    double* const dys = truth.dy.data();
    const std::size_t x_stride = truth.x.stride(1), dy_stride = truth.dy.stride(1);
    // 64-bit flags: a one-byte Status in the loop would make GCC take 64 lanes at a time, more than a chunk.
    for (int member = begin; member < end; ++member) live[member - begin] = truth_status(member) == Status::ok;
    KUSHNER_SIMD
    for (int member = begin; member < end; ++member) {
      const bool ok = live[member - begin] != 0;
      live[member - begin] = truth.step_lane(member, xs, x_stride, dys, dy_stride, ok, z + (member - begin)) && ok;
    }
    for (int member = begin; member < end; ++member)
      if (truth_status(member) == Status::ok && !live[member - begin]) truth_status(member) = Status::non_finite;
  }

  template <class Filter>
  void filter_chunk(const FilterSlot<Filter, MemSpace>& slot, const int begin, const int end, const std::int64_t* live,
                    const Mat<Model::obs_dim, Model::obs_dim>& V) const {
    constexpr int n = Model::state_dim, p = Model::obs_dim;
    if (!slot.enabled) return;
    if constexpr (filter_step_is_pure<Filter, n>) {
      const auto lanes = [&](const auto& filter) {
        if (record)
          filter_lanes<true>(slot, filter, begin, end, live, V);
        else
          filter_lanes<false>(slot, filter, begin, end, live, V);
      };
      if constexpr (detail::has_fixed_method<Filter>::value)
        slot.filter.with_fixed_method(lanes);
      else
        lanes(slot.filter);
    } else {
      for (int member = begin; member < end; ++member) {
        if (!live[member - begin]) {
          if (record) mark_unscored(slot, member);
          continue;
        }
        const StepInput<p> in{truth.t, truth.dt, truth.step, load<p>(truth.dy, member), V};
        advance(slot, model, member, in, load<n>(truth.x, member), record);
      }
    }
  }

  /// The lanes of slot's filter over the chunk; `stepper`: the filter, or its FixedMethod (has_fixed_method).
  template <bool Record, class Filter, class Stepper>
  KUSHNER_FLATTEN void filter_lanes(const FilterSlot<Filter, MemSpace>& slot, const Stepper& stepper, const int begin,
                                    const int end, const std::int64_t* live,
                                    const Mat<Model::obs_dim, Model::obs_dim>& V) const {
    // Raw columns, and copies of what the lanes read through references: a copy is not reloaded after a store.
    const Stepper filter = stepper;
    const Model lane_model = model;
    const Mat<Model::obs_dim, Model::obs_dim> lane_V = V;
    double* const m = slot.m.data();
    double* const P = slot.P.data();
    double* const score = slot.score.data();
    const std::size_t m_stride = slot.m.stride(1), P_stride = slot.P.stride(1), score_stride = slot.score.stride(1);
    const double* const xs = truth.x.data();
    const double* const dys = truth.dy.data();
    const std::size_t x_stride = truth.x.stride(1), dy_stride = truth.dy.stride(1);
    const double t = truth.t, dt = truth.dt;
    std::int64_t status[host_lane_capacity];  // 64-bit: see advance_lane
    // The lanes' snapshot values: straight into the block's sink where there is one (an output step of a segment),
    // else into `chunk`, from where an output step stores them in the snapshot columns.
    double chunk[2 * host_lane_capacity];
    const bool to_sink = Record && snapshot_sink != nullptr;
    double* const error = to_sink ? snapshot_sink + 2 * slot_index<Filter>() * sink_stride + begin - sink_first : chunk;
    double* const nees = to_sink ? error + sink_stride : chunk + host_lane_capacity;
    for (int member = begin; member < end; ++member)
      status[member - begin] = static_cast<std::int64_t>(slot.status(member));
    KUSHNER_SIMD
    for (int member = begin; member < end; ++member)
      status[member - begin] =
          advance_lane(filter, lane_model, m, m_stride, P, P_stride, score, score_stride, error + (member - begin),
                       nees + (member - begin), status[member - begin], member, live[member - begin] != 0, t, dt,
                       truth.step, lane_V, xs, x_stride, dys, dy_stride);
    for (int member = begin; member < end; ++member) slot.status(member) = static_cast<Status>(status[member - begin]);
    if constexpr (Record) {
      // The reference column is not touched: with a reference, its score (FilterBankReferenceScore, after the step
      // at every output time) writes it for every member; without one nothing reads it.
      if (to_sink) return;
      // Streaming stores (fenced at the chunk's end, run_chunk): only the output step's reductions read these
      // columns, after the step.
      double* const snapshot = slot.snapshot.data();
      const std::size_t snapshot_stride = slot.snapshot.stride(1);
      store_streaming_run(snapshot + begin + snapshot_squared_error * snapshot_stride, error, end - begin);
      store_streaming_run(snapshot + begin + snapshot_nees * snapshot_stride, nees, end - begin);
    }
  }
};

/// Time 0: every filter at its prior, scored against the initial truths.
template <class Model, class MemSpace, class... Filters>
struct FilterBankInitialScore {
  BankVector<MemSpace> x;
  FilterSlots<MemSpace, Filters...> slots;

  KOKKOS_INLINE_FUNCTION void operator()(const int member) const {
    const Vec<Model::state_dim> xm = load<Model::state_dim>(x, member);
    (score_initial<Model::state_dim>(static_cast<const FilterSlot<Filters, MemSpace>&>(slots), member, xm), ...);
  }
};

/// A step pair's copy of its first step's truths, increments and truth statuses (FilterBank::keep_step), in one
/// launch rather than three copies.
template <class MemSpace>
struct KeepTruthStep {
  BankVector<MemSpace> truth, dy;
  BankScalar<Status, MemSpace> truth_status;
  BankVector<MemSpace> kept_truth, kept_dy;
  BankScalar<Status, MemSpace> kept_truth_status;

  KOKKOS_INLINE_FUNCTION void operator()(const int member) const {
    for (int i = 0; i < static_cast<int>(truth.extent(1)); ++i) kept_truth(member, i) = truth(member, i);
    for (int i = 0; i < static_cast<int>(dy.extent(1)); ++i) kept_dy(member, i) = dy(member, i);
    kept_truth_status(member) = truth_status(member);
  }
};

/// After a reference (e.g. a particle filter) has taken the same step: |m - m_ref|^2 for every filter, on the
/// members whose truth and reference are both still ok (a diverged reference's frozen mean is no reference).
template <class Model, class MemSpace, class ReferenceView, class... Filters>
struct FilterBankReferenceScore {
  ReferenceView reference;
  BankScalar<Status, MemSpace> reference_status;
  BankScalar<Status, MemSpace> truth_status;
  FilterSlots<MemSpace, Filters...> slots;
  bool record;

  KOKKOS_INLINE_FUNCTION void operator()(const int member) const {
    const bool scored = truth_status(member) == Status::ok && reference_status(member) == Status::ok;
    (score_reference<Model::state_dim>(static_cast<const FilterSlot<Filters, MemSpace>&>(slots), member, reference,
                                       scored, record),
     ...);
  }
};

/// Stands in for the filter type of a slot that scores an estimator outside the bank (a particle filter, an
/// exact filter): its m, P and status are the estimator's own views.
struct ExternalEstimator {};

/// After an outside estimator has taken the same step: it is scored like a filter against the truth, and
/// against the reference mean when it is not the reference itself (`reference` empty then).
template <int N, class MemSpace>
struct EstimatorScore {
  FilterSlot<ExternalEstimator, MemSpace> slot;
  BankVector<MemSpace> truth, reference;
  BankScalar<Status, MemSpace> reference_status;  // the reference's (empty with `reference`)
  BankScalar<Status, MemSpace> truth_status;
  bool record;

  KOKKOS_INLINE_FUNCTION void operator()(const int member) const {
    if (truth_status(member) != Status::ok || slot.status(member) != Status::ok) {
      if (record) mark_unscored(slot, member);
      return;
    }
    const Mat<N, N> P = load_symmetric<N>(slot.P, member);
    Mat<N, N> L;
    const Definiteness definiteness = semidefinite_cholesky(P, L, covariance_tolerance);
    score_member(slot, member, load<N>(truth, member), load<N>(slot.m, member), P, L, definiteness, record);
    if (reference.extent(0) > 0)
      score_reference<N>(slot, member, reference, reference_status(member) == Status::ok, record);
  }
};

}  // namespace kushner
