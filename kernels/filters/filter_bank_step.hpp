#pragma once
// The bank's kernels. One step is one pass over the members: each member's truth takes its Euler-Maruyama
// step (producing dy; a discrete-time model: its transition, producing z[k+1]), then every selected filter
// takes its step with that same observation and is scored against the new truth. The filters are a compile-time list
// (no virtual calls); unselected ones are skipped by a flag that is the same for every member.
#include "kernels/filters/filter_slot.hpp"
#include "kernels/simulate_truth.hpp"

#include <Kokkos_Core.hpp>

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
  TruthStep<TruthModel, MemSpace> truth;
  Model model;
  BankScalar<Status, MemSpace> truth_status;  // non_finite once a truth escaped: not filtered, not scored
  FilterSlots<MemSpace, Filters...> slots;
  bool record;  // the step ends at an output time: fill the snapshots

  KOKKOS_INLINE_FUNCTION void operator()(const int member) const {
    constexpr int n = Model::state_dim, p = Model::obs_dim;
    if (truth_status(member) != Status::ok) {
      if (record) (mark_unscored(static_cast<const FilterSlot<Filters, MemSpace>&>(slots), member), ...);
      return;
    }
    truth(member);
    const Vec<n> x = load<n>(truth.x, member);
    const Vec<p> dy = load<p>(truth.dy, member);
    if (!(all_finite(x) && all_finite(dy))) {
      truth_status(member) = Status::non_finite;
      if (record) (mark_unscored(static_cast<const FilterSlot<Filters, MemSpace>&>(slots), member), ...);
      return;
    }
    const Mat<p, p> R = model.observation_noise(truth.t);
    const StepInput<p> in{truth.t, truth.dt, dy, R * transpose(R)};
    (advance(static_cast<const FilterSlot<Filters, MemSpace>&>(slots), model, member, in, x, record), ...);
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
    score_member(slot, member, load<N>(truth, member), load<N>(slot.m, member), L, definiteness, record);
    if (reference.extent(0) > 0)
      score_reference<N>(slot, member, reference, reference_status(member) == Status::ok, record);
  }
};

}  // namespace kushner
