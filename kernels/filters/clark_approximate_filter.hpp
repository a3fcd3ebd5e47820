#pragma once
// Clark's cheap approximations to the moment filter's estimate (seed 003 ch. II "Approximations to the
// Suboptimal Filter", ch. IV (4.7)). Each carries only the posterior's support [l, f] (clark_bounds.hpp):
//   MOM-MID   x = (l + f) / 2, the first two terms of (2.20); ch. IV's nonoptimal estimate (4.7)
//   MOM-LS    x = z - 0.119 z^3                     least-squares cubic (2.28)
//   MOM-LINE  x = 0.525 z                           straight line (2.29)
//   MOM-HYP   x = (sinh z + tanh z) / 2             hyperbolic (2.30); (2.31) is its series
// The last three are Clark's fits to Example 1 (a = 0.1, unit bounds, E u = 0): maps of z alone, as printed; on
// another model they are what they are. P = (f - l)^2 / 12, the variance of the uniform law on the support.
#include "kernels/filters/clark_bounds.hpp"
#include "kernels/filters/filter_protocol.hpp"
#include "kernels/filters/filter_step.hpp"

#include <Kokkos_Core.hpp>

namespace kushner {

enum class ClarkEstimate { midpoint, least_squares, straight_line, hyperbolic };

template <class Model, class MemSpace, ClarkEstimate Estimate>
struct ClarkApproximateFilter {
  static constexpr int n = Model::state_dim, p = Model::obs_dim;
  static constexpr const char* name = Estimate == ClarkEstimate::midpoint        ? "MOM-MID"
                                      : Estimate == ClarkEstimate::least_squares ? "MOM-LS"
                                      : Estimate == ClarkEstimate::straight_line ? "MOM-LINE"
                                                                                 : "MOM-HYP";
  static constexpr const char* description =
      Estimate == ClarkEstimate::midpoint ? "Clark's midpoint of the posterior bounds (Clark 1971 (2.20), (4.7))"
      : Estimate == ClarkEstimate::least_squares
          ? "Clark's least-squares cubic z - 0.119 z^3 (Clark 1971 (2.28), Ex. 1)"
      : Estimate == ClarkEstimate::straight_line ? "Clark's straight line 0.525 z (Clark 1971 (2.29), Ex. 1)"
                                                 : "Clark's (sinh z + tanh z)/2 (Clark 1971 (2.30), Ex. 1)";
  static constexpr const char* unsupported = clark_filter_unsupported<Model>();

  Kokkos::View<double**, Kokkos::LayoutLeft, MemSpace> bounds;  // (member, 0: l, 1: f)

  template <class Archive>
  void visit_state(Archive& archive) {
    archive.view("bounds", bounds);
  }
  static double own_bytes_per_member(const OptionValues&) { return 2.0 * sizeof(double); }

  static ClarkApproximateFilter create(const OptionValues&, const Model& model, long members) {
    ClarkApproximateFilter f;
    f.bounds = decltype(f.bounds)("kushner::clark_bounds", members, 2);
    const Interval prior = clark_prior_bounds(model);
    auto host = Kokkos::create_mirror_view(f.bounds);
    for (long member = 0; member < members; ++member) {
      host(member, 0) = prior.lower;
      host(member, 1) = prior.upper;
    }
    Kokkos::deep_copy(f.bounds, host);
    return f;
  }

  KOKKOS_INLINE_FUNCTION Status step(const Model& model, int member, const StepInput<p>& in, Vec<n>& m, Mat<n, n>& P,
                                     const Vec<n>& known_input) const {
    const double a = model.transition_jacobian(in.t, m)(0, 0);
    const double c = model.transition(in.t, Vec<1>::zero(), Model::Control::zero())[0] + known_input[0];
    const double z = in.dy[0];
    const Interval posterior = clark_posterior_bounds(
        clark_predicted_bounds({bounds(member, 0), bounds(member, 1)}, a, c, model.w.bound), z, model.v.bound);
    if (!(posterior.lower < posterior.upper)) return Status::not_positive_definite;
    bounds(member, 0) = posterior.lower;
    bounds(member, 1) = posterior.upper;
    if constexpr (Estimate == ClarkEstimate::midpoint)
      m[0] = 0.5 * (posterior.lower + posterior.upper);
    else if constexpr (Estimate == ClarkEstimate::least_squares)
      m[0] = z - 0.119 * z * z * z;
    else if constexpr (Estimate == ClarkEstimate::straight_line)
      m[0] = 0.525 * z;
    else
      m[0] = 0.5 * (math::sinh(z) + math::tanh(z));
    const double width = posterior.upper - posterior.lower;
    P(0, 0) = width * width / 12.0;
    return Status::ok;
  }
};

template <class Model, class MemSpace>
using ClarkMidpointFilter = ClarkApproximateFilter<Model, MemSpace, ClarkEstimate::midpoint>;
template <class Model, class MemSpace>
using ClarkLeastSquaresFilter = ClarkApproximateFilter<Model, MemSpace, ClarkEstimate::least_squares>;
template <class Model, class MemSpace>
using ClarkStraightLineFilter = ClarkApproximateFilter<Model, MemSpace, ClarkEstimate::straight_line>;
template <class Model, class MemSpace>
using ClarkHyperbolicFilter = ClarkApproximateFilter<Model, MemSpace, ClarkEstimate::hyperbolic>;

}  // namespace kushner
