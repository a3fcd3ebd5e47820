#pragma once
// One filter's part of the bank: its estimates m, covariances P (packed symmetric: symmetric by
// construction), per-member status, and the per-member error accumulators the run's metrics come from.
// advance() is what the bank's fused step kernel does for one member and one filter.
#include "core/status.hpp"
#include "kernels/bank.hpp"
#include "kernels/filters/filter_protocol.hpp"
#include "kernels/filters/filter_step.hpp"

#include <Kokkos_Core.hpp>

namespace kushner {

/// Columns of FilterSlot::score: sums over the time points 0, dt, ..., t of one member's errors.
enum ScoreColumn : int {
  squared_error_sum = 0,            // |m - x|^2
  nees_sum = 1,                     // (m - x)^T P^{-1} (m - x), at points where P is positive definite
  nees_points = 2,                  // how many points nees_sum has
  reference_squared_error_sum = 3,  // |m - m_ref|^2, when the run has a reference mean
  num_score_columns = 4,
};

/// Columns of FilterSlot::snapshot: one member's errors at the latest output time; NaN = not scored (the
/// member diverged, its truth escaped, or NEES is undefined because P is singular).
enum SnapshotColumn : int {
  snapshot_squared_error = 0,
  snapshot_nees = 1,
  snapshot_reference_squared_error = 2,
  num_snapshot_columns = 3,
};

template <class Filter, class MemSpace>
struct FilterSlot {
  Filter filter;
  bool enabled = false;
  BankVector<MemSpace> m;               // (member, i)
  BankSymmetric<MemSpace> P;            // (member, packed k)
  BankScalar<Status, MemSpace> status;  // (member): ok until the member diverges; then m, P stay frozen
  BankVector<MemSpace> score;           // (member, ScoreColumn)
  BankVector<MemSpace> snapshot;        // (member, SnapshotColumn)
};

/// Scores a member's estimate m (covariance factor L, from semidefinite_cholesky) against the truth x.
template <int N, class Slot>
KOKKOS_INLINE_FUNCTION void score_member(const Slot& s, int member, const Vec<N>& x, const Vec<N>& m,
                                         const Mat<N, N>& L, Definiteness definiteness, bool record) {
  const Vec<N> e = m - x;
  const double squared_error = dot(e, e);
  const bool has_nees = definiteness == Definiteness::positive_definite;
  const double nees = has_nees ? cholesky_quadratic_form(L, e) : math::quiet_nan();
  s.score(member, squared_error_sum) += squared_error;
  if (has_nees) {
    s.score(member, nees_sum) += nees;
    s.score(member, nees_points) += 1.0;
  }
  if (record) {
    s.snapshot(member, snapshot_squared_error) = squared_error;
    s.snapshot(member, snapshot_nees) = nees;
  }
}

template <class Slot>
KOKKOS_INLINE_FUNCTION void mark_unscored(const Slot& s, int member) {
  if (!s.enabled) return;
  for (int c = 0; c < num_snapshot_columns; ++c) s.snapshot(member, c) = math::quiet_nan();
}

/// One step of one member for one filter: the filter's step, then the divergence checks (non-finite values;
/// P not positive semidefinite), then the scores against the new truth x. A diverged member keeps its last
/// good m, P and is not updated again. In a closed loop, `control_shift` = B(t) u dt, the known input's part of
/// the mean's Euler step: every filter's prediction is m + (a + B u) dt with P unchanged by a known additive
/// input (kernels/filters/filter_step.hpp), so adding it after the filter's own step is that step exactly. A
/// discrete-time filter predicts before it updates with z[k+1], so it takes B u[k] into its step's prediction.
template <class Model, class Filter, class MemSpace>
KOKKOS_INLINE_FUNCTION void advance(const FilterSlot<Filter, MemSpace>& s, const Model& model, int member,
                                    const StepInput<Model::obs_dim>& in, const Vec<Model::state_dim>& x, bool record,
                                    const Vec<Model::state_dim>& control_shift = Vec<Model::state_dim>::zero()) {
  constexpr int n = Model::state_dim;
  if (!s.enabled) return;
  if (s.status(member) != Status::ok) {
    if (record) mark_unscored(s, member);
    return;
  }
  Vec<n> m = load<n>(s.m, member);
  Mat<n, n> P = load_symmetric<n>(s.P, member);
  Status status;
  if constexpr (Model::discrete_time) {
    status = s.filter.step(model, member, in, m, P, control_shift);
  } else {
    status = s.filter.step(model, member, in, m, P);
    m += control_shift;
    if constexpr (detail::has_known_input<Filter, n>::value) s.filter.apply_known_input(member, control_shift);
  }
  if (status == Status::ok && !(all_finite(m) && all_finite(P))) status = Status::non_finite;
  Mat<n, n> L;
  Definiteness definiteness = Definiteness::indefinite;
  if (status == Status::ok) {
    definiteness = semidefinite_cholesky(P, L, covariance_tolerance);
    if (definiteness == Definiteness::indefinite) status = Status::not_positive_definite;
  }
  if (status != Status::ok) {
    s.status(member) = status;
    if (record) mark_unscored(s, member);
    return;
  }
  store(s.m, member, m);
  store_symmetric(s.P, member, P);
  score_member(s, member, x, m, L, definiteness, record);
}

/// Time 0: the prior against the initial truth.
template <int N, class Filter, class MemSpace>
KOKKOS_INLINE_FUNCTION void score_initial(const FilterSlot<Filter, MemSpace>& s, int member, const Vec<N>& x) {
  if (!s.enabled) return;
  const Mat<N, N> P = load_symmetric<N>(s.P, member);
  Mat<N, N> L;
  const Definiteness definiteness = semidefinite_cholesky(P, L, covariance_tolerance);
  score_member(s, member, x, load<N>(s.m, member), L, definiteness, true);
}

/// |m - m_ref|^2 against a reference mean (e.g. a particle filter's posterior mean) of the same member.
template <int N, class Filter, class MemSpace, class ReferenceView>
KOKKOS_INLINE_FUNCTION void score_reference(const FilterSlot<Filter, MemSpace>& s, int member,
                                            const ReferenceView& reference, bool scored, bool record) {
  if (!s.enabled) return;
  if (!scored || s.status(member) != Status::ok) {
    if (record) s.snapshot(member, snapshot_reference_squared_error) = math::quiet_nan();
    return;
  }
  const Vec<N> d = load<N>(s.m, member) - load<N>(reference, member);
  const double squared = dot(d, d);
  s.score(member, reference_squared_error_sum) += squared;
  if (record) s.snapshot(member, snapshot_reference_squared_error) = squared;
}

}  // namespace kushner
