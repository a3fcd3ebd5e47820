#pragma once
// The filters of Clark's perturbation loop (seed 003 ch. III, (3.4)-(3.14)): a nonlinear discrete-time plant
// x[k+1] = f(k, x, u) + w linearized along a nominal path x_bar,
//   x[k+1] ~ f(k, x_bar[k], 0) + A_k (x - x_bar[k]) + B u + w,   A_k = df/dx(k, x_bar[k]),
// and a linear filter of the deviations run on it: the estimate of dx = x - x_bar from dz = z - x_bar (3.13)-(3.14)
// plus x_bar is the estimate of x from z under that linear model, which is what these filters compute.
//   KF-NOM    the Kalman filter of the linearized plant (Clark's "Kalman filter in the perturbation loop"; the
//             linearized Kalman filter)
//   MOM-NOM   Clark's moment filter of the linearized plant (his "fourth-order filter in the perturbation loop")
// The nominal path: in `kushner control` under LQR-NOM, the law's (the noise-free optimum, engine/control/
// perturbation_loop.hpp), whose nominal control u_bar the loop hands over; elsewhere the plant's noise-free
// uncontrolled path from the prior mean. Each member carries x_bar (the same in every member) and advances it with
// f(k, x_bar, u_bar[k]). Unlike EKF-D, the linearization does not follow the estimate: where the truth strays far
// from the nominal, the linear model is wrong (Clark's Table 3.1 at large plant noise). On a linear transition
// they are KF and MOM, and are not offered there.
#include "kernels/bank.hpp"
#include "kernels/filters/discrete_kalman_filter.hpp"
#include "kernels/filters/moment_filter.hpp"

#include <Kokkos_Core.hpp>

#include <string>
#include <vector>

namespace kushner {

namespace detail {
template <class Model>
constexpr const char* nominal_filter_unsupported() {
  if (!Model::discrete_time) return "continuous-time model (discrete-time filter)";
  if (DiscreteModelTraits<Model>::linear) return "transition is linear (the nominal path changes nothing: use KF, MOM)";
  if (!DiscreteModelTraits<Model>::linear_observation) return "observation is not linear";
  return nullptr;
}
}  // namespace detail

/// The nominal path every member of a perturbation-loop filter follows.
template <class Model, class MemSpace>
struct NominalPathState {
  static constexpr int n = Model::state_dim, m = Model::control_dim;
  BankVector<MemSpace> x;                                   // (member, i): x_bar at the current step
  Kokkos::View<double**, Kokkos::LayoutRight, MemSpace> u;  // (k, j): u_bar[k]; no rows: u_bar = 0
  bool follows_law = false;

  static NominalPathState create(const Model& model, long members) {
    NominalPathState s;
    s.x = BankVector<MemSpace>("kushner::nominal_x", members, n);
    const auto h = Kokkos::create_mirror_view(s.x);
    for (long member = 0; member < members; ++member)
      for (int i = 0; i < n; ++i) h(member, i) = model.prior_mean[i];
    Kokkos::deep_copy(s.x, h);
    return s;
  }

  /// The nominal control of a closed loop's law (LQR-NOM): x_bar then follows that law's nominal path.
  void follow(const std::vector<Vec<m>>& controls) {
    u = decltype(u)("kushner::nominal_u", controls.size(), m);
    const auto h = Kokkos::create_mirror_view(u);
    for (std::size_t k = 0; k < controls.size(); ++k)
      for (int j = 0; j < m; ++j) h(k, j) = controls[k][j];
    Kokkos::deep_copy(u, h);
    follows_law = true;
  }

  /// The linearization at step k: A_k and c_k = f(k, x_bar, 0) - A_k x_bar; then x_bar moves to step k + 1.
  KOKKOS_INLINE_FUNCTION void take(const Model& model, int member, double k, Mat<n, n>& A, Vec<n>& c) const {
    const Vec<n> at = load<n>(x, member);
    A = model.transition_jacobian(k, at);
    const Vec<n> free = model.transition(k, at, Vec<m>::zero());
    c = free - A * at;
    Vec<m> control = Vec<m>::zero();
    const long row = static_cast<long>(k);
    if (row < static_cast<long>(u.extent(0)))
      for (int j = 0; j < m; ++j) control[j] = u(row, j);
    store(x, member, free + model.control_input(k) * control);
  }

  Fields summary_fields() const {
    return {{"nominal", std::string(follows_law ? "the law's nominal path (LQR-NOM)"
                                                : "noise-free uncontrolled path from the prior mean")}};
  }
};

template <class Model, class MemSpace>
struct NominalKalmanFilter {
  static constexpr int n = Model::state_dim, p = Model::obs_dim;
  static constexpr const char* name = "KF-NOM";
  static constexpr const char* description =
      "Kalman filter of the plant linearized along a nominal path (Clark 1971 ch. III perturbation loop)";
  static constexpr const char* unsupported = detail::nominal_filter_unsupported<Model>();
  /// A model file's coefficients (its type declares a nonlinear transition and a linear observation).
  static const char* unsupported_by(const ModelFacts& f) {
    if (f.drift_degree <= 1) return "transition is linear (the nominal path changes nothing: use KF)";
    return observation_unsupported_by(f);
  }

  NominalPathState<Model, MemSpace> nominal;

  static NominalKalmanFilter create(const OptionValues&, const Model& model, long members) {
    return {NominalPathState<Model, MemSpace>::create(model, members)};
  }
  template <class Archive>
  void visit_state(Archive& archive) {
    archive.view("nominal", nominal.x);
  }
  static double own_bytes_per_member(const OptionValues&) { return sizeof(double) * n; }
  Fields summary_fields() const { return nominal.summary_fields(); }
  void follow_nominal(const std::vector<Vec<Model::control_dim>>& controls) { nominal.follow(controls); }

  KOKKOS_INLINE_FUNCTION Status step(const Model& model, int member, const StepInput<p>& in, Vec<n>& m, Mat<n, n>& P,
                                     const Vec<n>& known_input) const {
    Mat<n, n> A;
    Vec<n> c;
    nominal.take(model, member, in.t, A, c);
    m = A * m + c + known_input;
    P = symmetrize(A * P * transpose(A) + model.process_noise_covariance(in.t));
    return detail::discrete_covariance_update(model, in, m, P) ? Status::ok : Status::not_positive_definite;
  }
};

template <class Model, class MemSpace>
struct NominalMomentFilter {
  static constexpr int n = Model::state_dim, p = Model::obs_dim;
  static constexpr const char* name = "MOM-NOM";
  static constexpr const char* description =
      "Clark's moment filter of the plant linearized along a nominal path (Clark 1971 ch. III perturbation loop)";
  static constexpr const char* unsupported =
      detail::nominal_filter_unsupported<Model>() != nullptr ? detail::nominal_filter_unsupported<Model>()
      : Model::state_dim != 1 || Model::obs_dim != 1         ? "state or observation is not scalar"
      : !DiscreteModelTraits<Model>::bounded_noises          ? "noises are not bounded (Clark's family)"
                                                             : nullptr;

  MomentFilter<Model, MemSpace> moments;
  NominalPathState<Model, MemSpace> nominal;

  static std::vector<OptionSpec> options() { return MomentFilter<Model, MemSpace>::options(); }
  static NominalMomentFilter create(const OptionValues& options, const Model& model, long members) {
    return {MomentFilter<Model, MemSpace>::create(options, model, members),
            NominalPathState<Model, MemSpace>::create(model, members)};
  }
  template <class Archive>
  void visit_state(Archive& archive) {
    moments.visit_state(archive);
    archive.view("nominal", nominal.x);
  }
  static double own_bytes_per_member(const OptionValues& options) {
    return MomentFilter<Model, MemSpace>::own_bytes_per_member(options) + sizeof(double) * n;
  }
  void follow_nominal(const std::vector<Vec<Model::control_dim>>& controls) { nominal.follow(controls); }
  Fields summary_fields() const {
    Fields fields = moments.summary_fields();
    for (const auto& field : nominal.summary_fields()) fields.push_back(field);
    return fields;
  }

  KOKKOS_INLINE_FUNCTION Status step(const Model& model, int member, const StepInput<p>& in, Vec<n>& m, Mat<n, n>& P,
                                     const Vec<n>& known_input) const {
    Mat<n, n> A;
    Vec<n> c;
    nominal.take(model, member, in.t, A, c);
    return moments.step_linear(model, member, in, A(0, 0), c[0] + known_input[0], m, P);
  }
};

}  // namespace kushner
