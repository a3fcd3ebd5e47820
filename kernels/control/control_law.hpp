#pragma once
// A controller's law on the device: a map (step, estimate) -> control, the same for every member. The gain laws
// (LQR, ASRE, POLY3) are time-varying affine feedback (gain_schedule.hpp), HJB's a table u*(t, x) interpolated
// (feedback_table.hpp); `none` applies no control (the
// open-loop plant, a baseline every controller should beat). One type for all laws, chosen by a flag that is
// the same for every member, so that a model's closed-loop kernel is compiled once.
#include "kernels/control/feedback_table.hpp"
#include "kernels/control/gain_schedule.hpp"

namespace kushner {

enum class ControlLawKind { none, affine, table };

template <int N, int M, class MemSpace>
struct ControlLaw {
  ControlLawKind kind = ControlLawKind::none;
  AffineFeedback<N, M, MemSpace> affine;
  TabulatedFeedback<N, M, MemSpace> table;

  KOKKOS_INLINE_FUNCTION Vec<M> operator()(long step, const Vec<N>& estimate) const {
    if (kind == ControlLawKind::affine) return affine(step, estimate);
    if (kind == ControlLawKind::table) return table(step, estimate);
    return Vec<M>::zero();
  }
};

template <int N, int M, class MemSpace>
ControlLaw<N, M, MemSpace> affine_law(const GainSchedule<N, M>& gains) {
  ControlLaw<N, M, MemSpace> law;
  law.kind = ControlLawKind::affine;
  law.affine = to_device<N, M, MemSpace>(gains);
  return law;
}

template <int N, int M, class MemSpace>
ControlLaw<N, M, MemSpace> table_law(const FeedbackTable<N, M>& table, double loop_dt) {
  ControlLaw<N, M, MemSpace> law;
  law.kind = ControlLawKind::table;
  law.table = to_device<MemSpace>(table, loop_dt);
  return law;
}

}  // namespace kushner
