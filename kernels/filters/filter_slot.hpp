#pragma once
// One filter's part of the bank: its estimates m, covariances P (packed symmetric: symmetric by
// construction), per-member status, and the per-member error accumulators the run's metrics come from.
// advance() is what the bank's fused step kernel does for one member and one filter.
#include "core/status.hpp"
#include "kernels/bank.hpp"
#include "kernels/ensemble_moments.hpp"
#include "kernels/filters/filter_protocol.hpp"
#include "kernels/filters/filter_step.hpp"

#include <Kokkos_Core.hpp>

#include <cstdint>
#include <type_traits>
#include <utility>

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
  // A GPU segment's team (FilterBankTeamSegment): where this filter's squared error and NEES columns start in its
  // block's sink in shared memory (team_sink_values); -1: its snapshot columns. Set in the team kernel's copy only.
  int team_sink = -1;
};

#if KUSHNER_CUDA_DEVICE_PASS
/// A GPU segment's block sink: the snapshot values of the team's block of moment_block_size members, member m of the
/// block at m % moment_block_size of each column, in the launch's dynamic shared memory where Kokkos puts a team's
/// scratch (after its own team_size + 2 doubles; FilterBankTeamSegment checks that its scratch is there). Found
/// from the block's dimensions, so no thread carries its address through the filters' steps: a sink passed to each
/// step as an argument kept a pointer and the block's start live in every filter's step, and at 80 registers with
/// spills that cost more than the sink saved (perf/filter_bank.md).
__device__ inline double* team_sink_values() {
  extern __shared__ double kushner_dynamic_shared[];
  return kushner_dynamic_shared + blockDim.y + 2;
}
#endif

/// A member's snapshot values at an output time: to its slot's snapshot columns, or its team's sink (team_sink).
template <class Slot>
KOKKOS_INLINE_FUNCTION void store_snapshot(const Slot& s, int member, double squared_error, double nees) {
#if KUSHNER_CUDA_DEVICE_PASS
  if (s.team_sink >= 0) {
    static_assert((moment_block_size & (moment_block_size - 1)) == 0, "a block's members by a mask");
    double* const values = team_sink_values() + s.team_sink + (member & (moment_block_size - 1));
    values[0] = squared_error;
    values[moment_block_size] = nees;
    return;
  }
#endif
  s.snapshot(member, snapshot_squared_error) = squared_error;
  s.snapshot(member, snapshot_nees) = nees;
}

/// A member's three score sums (ScoreColumn), read together: each read-add-write of one after the other was a round
/// trip to memory of its own (the compiler cannot move a read above a write it cannot prove apart), three per filter
/// and step, on a GPU each a wait of some hundred cycles.
struct ScoreSums {
  double squared_error, nees, nees_points;
};

template <class Slot>
KOKKOS_INLINE_FUNCTION ScoreSums load_score_sums(const Slot& s, int member) {
  return {s.score(member, squared_error_sum), s.score(member, nees_sum), s.score(member, nees_points)};
}

/// Scores a member's estimate m (covariance factor L, from semidefinite_cholesky) against the truth x; `sums`: the
/// member's score sums before this point (load_score_sums).
template <int N, class Slot>
KOKKOS_INLINE_FUNCTION void score_member(const Slot& s, int member, const Vec<N>& x, const Vec<N>& m,
                                         const Mat<N, N>& P, const Mat<N, N>& L, Definiteness definiteness, bool record,
                                         const ScoreSums& sums) {
  const Vec<N> e = m - x;
  const double squared_error = dot(e, e);
  const bool has_nees = definiteness == Definiteness::positive_definite;
  // The form whatever P is (selected away where P is not positive definite): a branch around its division was a
  // convergence barrier per filter and member-step on a GPU.
  const double form = inverse_quadratic_form(P, L, e);
  const double nees = has_nees ? form : math::quiet_nan();
  s.score(member, squared_error_sum) = sums.squared_error + squared_error;
  if (has_nees) {
    s.score(member, nees_sum) = sums.nees + nees;
    s.score(member, nees_points) = sums.nees_points + 1.0;
  }
  if (record) store_snapshot(s, member, squared_error, nees);
}

template <int N, class Slot>
KOKKOS_INLINE_FUNCTION void score_member(const Slot& s, int member, const Vec<N>& x, const Vec<N>& m,
                                         const Mat<N, N>& P, const Mat<N, N>& L, Definiteness definiteness,
                                         bool record) {
  score_member(s, member, x, m, P, L, definiteness, record, load_score_sums(s, member));
}

template <class Slot>
KOKKOS_INLINE_FUNCTION void mark_unscored(const Slot& s, int member) {
  if (!s.enabled) return;
  static_assert(num_snapshot_columns == 3, "mark_unscored: every snapshot column");
  store_snapshot(s, member, math::quiet_nan(), math::quiet_nan());
  s.snapshot(member, snapshot_reference_squared_error) = math::quiet_nan();
}

namespace detail {
/// Whether Filter offers with_fixed_method(f): f called with a filter whose step is Filter's with its run-time
/// choices fixed at compile time (QLF's method), for loops over members in SIMD lanes.
template <class Filter, class = void>
struct has_fixed_method : std::false_type {};
template <class Filter>
struct has_fixed_method<Filter, std::void_t<decltype(std::declval<const Filter&>().with_fixed_method(
                                    std::declval<void (*)(const typename Filter::template FixedMethod<0>&)>()))>>
    : std::true_type {};
}  // namespace detail

/// Whether advance_lane may run Filter: its step changes nothing but the m and P it is given (no state of its
/// own, no random numbers, no known input), so a step computed for a member and discarded is no step.
/// (A variable, not a function: nvcc will not call a host constexpr function from device code.)
template <class Filter, int N>
constexpr bool filter_step_is_pure = !detail::is_randomized<Filter>::value && !detail::has_prepass<Filter>::value &&
                                     !detail::has_known_input<Filter, N>::value;

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
  // A pure continuous-time filter steps before its member's status is looked at, a frozen member's step then thrown
  // away: so the status, m, P and the score sums are read together, one wait for memory where reading m and P behind
  // the status' branch and the sums behind the stores made three (a GPU's segment stalled most on those).
  constexpr bool speculative = !Model::discrete_time && filter_step_is_pure<Filter, n>;
  const Status old_status = s.status(member);
  if (!speculative && old_status != Status::ok) {
    if (record) mark_unscored(s, member);
    return;
  }
  Vec<n> m = load<n>(s.m, member);
  Mat<n, n> P = load_symmetric<n>(s.P, member);
  const ScoreSums sums = speculative ? load_score_sums(s, member) : ScoreSums{};
  Status status;
  if constexpr (Model::discrete_time) {
    status = s.filter.step(model, member, in, m, P, control_shift);
  } else {
    status = s.filter.step(model, member, in, m, P);
    m += control_shift;
    if constexpr (detail::has_known_input<Filter, n>::value) s.filter.apply_known_input(member, control_shift);
  }
  // Both tests taken (no && between them, whose branch was a convergence barrier per filter and member-step on a
  // GPU; advance_lane keeps the && form: without it GCC did not vectorize the lanes' loop).
  const bool finite = all_finite(m) & all_finite(P);
  if (status == Status::ok && !finite) status = Status::non_finite;
  // Factored whatever the status (a failed step's factor is not used): a branch around it was a convergence barrier
  // per filter and member-step on a GPU.
  Mat<n, n> L;
  const Definiteness definiteness = semidefinite_cholesky(P, L, covariance_tolerance);
  if (status == Status::ok && definiteness == Definiteness::indefinite) status = Status::not_positive_definite;
  if (speculative && old_status != Status::ok) {  // frozen: the step above is not taken
    if (record) mark_unscored(s, member);
    return;
  }
  if (status != Status::ok) {
    s.status(member) = status;
    if (record) mark_unscored(s, member);
    return;
  }
  store(s.m, member, m);
  store_symmetric(s.P, member, P);
  if constexpr (speculative)
    score_member(s, member, x, m, P, L, definiteness, record, sums);
  else
    score_member(s, member, x, m, P, L, definiteness, record);
}

/// advance() of one member as one lane of a host loop over members in SIMD lanes (FilterBankStep::run_chunk): the
/// step, the checks and the scores are computed whatever the member's state, and what advance() would store is
/// selected, so the lanes need no branches; a frozen member (status not ok), or one whose truth is not `live`,
/// keeps its m, P and sums. *lane_error, *lane_nees receive the member's snapshot values (NaN: not scored), which
/// the caller stores at an output time. Returns the member's new status (`old_status`: its status before), which
/// the caller stores too, as a 64-bit integer: a one-byte value in the loop would make GCC take 64 lanes at a time,
/// and a store of a one-byte Status may alias anything, so GCC would reload every pointer after it. Continuous time,
/// open loop, a filter_step_is_pure filter. The views come as raw columns and member strides (GCC does not
/// vectorize a loop that reloads a View's pointer), and the loop body is this one call: a local of the body whose
/// address is taken becomes an `omp simd` array, which GCC does not vectorize well. The lanes call glibc's vector sin,
/// cos, exp, log (within 4 ulp of the scalar ones), so the last bits are those of this code, the same on every host
/// backend and thread count.
template <class Model, class Filter>
KOKKOS_INLINE_FUNCTION std::int64_t advance_lane(const Filter& filter, const Model& model, double* const m_column,
                                                 const std::size_t m_stride, double* const P_column,
                                                 const std::size_t P_stride, double* const score,
                                                 const std::size_t score_stride, double* const lane_error,
                                                 double* const lane_nees, const std::int64_t old_status, int member,
                                                 bool live, double t, double dt, std::uint32_t step,
                                                 const Mat<Model::obs_dim, Model::obs_dim>& V, const double* x,
                                                 std::size_t x_stride, const double* dy, std::size_t dy_stride) {
  constexpr int n = Model::state_dim, p = Model::obs_dim;
  static_assert(!Model::discrete_time && filter_step_is_pure<Filter, n>, "advance_lane: see filter_step_is_pure");
  const bool stepped = live && old_status == static_cast<std::int64_t>(Status::ok);
  Vec<n> m, xm;
  Mat<n, n> P;
  Vec<p> dyv;
  for (int i = 0; i < n; ++i) m[i] = m_column[member + i * m_stride];
  for (int i = 0; i < n; ++i)
    for (int j = i; j < n; ++j) P(i, j) = P(j, i) = P_column[member + packed_index(n, i, j) * P_stride];
  for (int i = 0; i < n; ++i) xm[i] = x[member + i * x_stride];
  for (int l = 0; l < p; ++l) dyv[l] = dy[member + l * dy_stride];
  // The status as a 64-bit integer: a one-byte value in the loop would make GCC take 64 lanes at a time.
  std::int64_t status = static_cast<std::int64_t>(filter.step(model, member, StepInput<p>{t, dt, step, dyv, V}, m, P));
  constexpr auto ok = static_cast<std::int64_t>(Status::ok);
  m += Vec<n>::zero();  // advance()'s control shift in an open loop
  if (status == ok && !(all_finite(m) && all_finite(P))) status = static_cast<std::int64_t>(Status::non_finite);
  Mat<n, n> L;
  const Definiteness definiteness = semidefinite_cholesky(P, L, covariance_tolerance);
  if (status == ok && definiteness == Definiteness::indefinite)
    status = static_cast<std::int64_t>(Status::not_positive_definite);
  const bool good = stepped && status == ok;
  for (int i = 0; i < n; ++i) {
    double& mi = m_column[member + i * m_stride];
    mi = good ? m[i] : mi;
  }
  for (int i = 0; i < n; ++i) {  // store_symmetric's values
    double& Pii = P_column[member + packed_index(n, i, i) * P_stride];
    Pii = good ? P(i, i) : Pii;
    for (int j = i + 1; j < n; ++j) {
      double& Pij = P_column[member + packed_index(n, i, j) * P_stride];
      Pij = good ? 0.5 * (P(i, j) + P(j, i)) : Pij;
    }
  }
  const Vec<n> e = m - xm;
  const double squared_error = dot(e, e);
  const bool has_nees = good && definiteness == Definiteness::positive_definite;
  const double nan = math::quiet_nan();
  const double nees = has_nees ? inverse_quadratic_form(P, L, e) : nan;
  double& sum = score[member + squared_error_sum * score_stride];
  double& nees_total = score[member + nees_sum * score_stride];
  double& points = score[member + nees_points * score_stride];
  sum = good ? sum + squared_error : sum;
  nees_total = has_nees ? nees_total + nees : nees_total;
  points = has_nees ? points + 1.0 : points;
  *lane_error = good ? squared_error : nan;  // what the snapshot records at an output time
  *lane_nees = nees;
  return stepped ? status : old_status;
}

/// Time 0: the prior against the initial truth.
template <int N, class Filter, class MemSpace>
KOKKOS_INLINE_FUNCTION void score_initial(const FilterSlot<Filter, MemSpace>& s, int member, const Vec<N>& x) {
  if (!s.enabled) return;
  const Mat<N, N> P = load_symmetric<N>(s.P, member);
  Mat<N, N> L;
  const Definiteness definiteness = semidefinite_cholesky(P, L, covariance_tolerance);
  score_member(s, member, x, load<N>(s.m, member), P, L, definiteness, true);
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
