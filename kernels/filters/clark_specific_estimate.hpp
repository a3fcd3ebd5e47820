#pragma once
// MOM-SPEC: the estimate of Clark's specific optimal controller (seed 003 ch. IV, (4.7)-(4.13)). A fixed, nonoptimal
// estimator sees the measurements: the midpoint x_mid = (l + f)/2 of the posterior bounds (4.7) (MOM-MID). The
// controller does not see z; it corrects x_mid by the terms the moment filter's mean adds to the midpoint of its
// support ((4.9)'s expansion beyond 0.5 (f + l)), with that support and density obtained from the pseudo-measurement
// z = x_mid (4.12):
//   x' = x_mid + (mean - (l' + f')/2),  mean, [l', f'] the moment filter's (order M) Bayes update with z = x_mid,
// and the moment filter's own recursion runs on those pseudo-updates (it never sees z). With the Riccati controller
// (LQR@MOM-SPEC) this is Clark's specific optimal controller (his Fig. 4.3: the new estimate feeds the Riccati
// controller). P is the pseudo-update's variance. Clark reports the average estimation error 40% below the
// midpoint's, and above the moment filter's on the real measurements (Fig. 4.4, no numbers).
#include "kernels/filters/clark_approximate_filter.hpp"
#include "kernels/filters/moment_filter.hpp"

#include <Kokkos_Core.hpp>

#include <vector>

namespace kushner {

template <class Model, class MemSpace>
struct ClarkSpecificEstimate {
  static constexpr int n = Model::state_dim, p = Model::obs_dim;
  static constexpr const char* name = "MOM-SPEC";
  static constexpr const char* description =
      "Clark's specific optimal estimate: the midpoint corrected by the moment filter at z = midpoint (Clark 1971 "
      "(4.7)-(4.13))";
  static constexpr const char* unsupported = clark_filter_unsupported<Model>();

  ClarkApproximateFilter<Model, MemSpace, ClarkEstimate::midpoint> midpoint;
  MomentFilter<Model, MemSpace> moments;

  static std::vector<OptionSpec> options() { return MomentFilter<Model, MemSpace>::options(); }
  static ClarkSpecificEstimate create(const OptionValues& options, const Model& model, long members) {
    return {ClarkApproximateFilter<Model, MemSpace, ClarkEstimate::midpoint>::create(options, model, members),
            MomentFilter<Model, MemSpace>::create(options, model, members)};
  }
  template <class Archive>
  void visit_state(Archive& archive) {
    midpoint.visit_state(archive);
    moments.visit_state(archive);
  }
  static double own_bytes_per_member(const OptionValues& options) {
    return 2.0 * sizeof(double) + MomentFilter<Model, MemSpace>::own_bytes_per_member(options);
  }
  Fields summary_fields() const { return moments.summary_fields(); }

  KOKKOS_INLINE_FUNCTION Status step(const Model& model, int member, const StepInput<p>& in, Vec<n>& m, Mat<n, n>& P,
                                     const Vec<n>& known_input) const {
    Vec<n> x_mid = m;
    Mat<n, n> P_mid = P;
    const Status seen = midpoint.step(model, member, in, x_mid, P_mid, known_input);
    if (seen != Status::ok) return seen;
    StepInput<p> pseudo = in;
    pseudo.dy[0] = x_mid[0];  // (4.12): z = the nonoptimal estimate
    const double a = model.transition_jacobian(in.t, m)(0, 0);
    const double c = model.transition(in.t, Vec<1>::zero(), Model::Control::zero())[0] + known_input[0];
    const Status corrected = moments.step_linear(model, member, pseudo, a, c, m, P);
    if (corrected != Status::ok) return corrected;
    m[0] = x_mid[0] + m[0] - 0.5 * (moments.state(member, 0) + moments.state(member, 1));
    return Status::ok;
  }
};

}  // namespace kushner
