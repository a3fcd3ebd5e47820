#pragma once
// The discrete-time Kalman filters (seed 004 (2.3)-(2.4), (4.9)-(4.17); seed 003 ch. II's comparison filter):
// step k -> k + 1 predicts with the transition, then updates with z[k+1] (StepInput::dy):
//   m- = F(k, m, 0),  P- = A P A^T + Q,                      A = dF/dx at m, Q = Cov w
//   S = H P- H^T + V,  K = P- H^T S^-1,  m = m- + K (z - h(k+1, m-)),  P = (I - K H) P- (I - K H)^T + K V K^T
// (Joseph form: P stays symmetric positive semidefinite); a closed loop's known input B u[k] is added to m-. On a
// linear Gaussian model this is the exact filter; on Clark's bounded noises it is the best linear one (it uses only the
// noises' covariances).
//   KF      covariance form, linear models
//   KF-INF  information form of the same update, Y = P^-1:  Y = Y- + H^T V^-1 H,  y = Y- m- + H^T V^-1 (z - h(0)),
//           the recursive least-squares recursion (004 (4.9)-(4.17)); equal to KF to rounding
//   EKF-D   extended Kalman filter: A and H linearized at the estimate (KF's equations on a linear model)
#include "kernels/filters/filter_protocol.hpp"
#include "kernels/filters/filter_step.hpp"

namespace kushner {

namespace detail {

/// A model known only at run time (a model file) is checked by discrete_kalman_unsupported_by instead.
template <class Model>
constexpr const char* discrete_kalman_unsupported() {
  if (!Model::discrete_time) return "continuous-time model (discrete-time filter)";
  if (ModelTraits<Model>::runtime_checked) return nullptr;
  if (!DiscreteModelTraits<Model>::linear) return "transition is not linear";
  if (!DiscreteModelTraits<Model>::linear_observation) return "observation is not linear";
  return nullptr;
}

inline const char* discrete_kalman_unsupported_by(const ModelFacts& f) {
  if (f.drift_degree > 1) return "transition is not linear (the file has terms of degree 2 or more)";
  return observation_unsupported_by(f);
}

/// The prediction k -> k + 1 at (m, P) with the known input B u[k] (zero in open loop).
template <class Model>
KOKKOS_INLINE_FUNCTION void discrete_predict(const Model& model, double k, const Vec<Model::state_dim>& known_input,
                                             Vec<Model::state_dim>& m, Mat<Model::state_dim, Model::state_dim>& P) {
  const auto A = model.transition_jacobian(k, m);
  m = model.transition(k, m, Model::Control::zero()) + known_input;
  P = symmetrize(A * P * transpose(A) + model.process_noise_covariance(k));
}

/// The Kalman update with z in covariance (Joseph) form; false when S is not positive definite.
template <class Model>
KOKKOS_INLINE_FUNCTION bool discrete_covariance_update(const Model& model, const StepInput<Model::obs_dim>& in,
                                                       Vec<Model::state_dim>& m,
                                                       Mat<Model::state_dim, Model::state_dim>& P) {
  constexpr int n = Model::state_dim, p = Model::obs_dim;
  const double k1 = in.t + 1.0;
  const Mat<p, n> H = model.observation_jacobian(k1, m);
  const Mat<n, p> PHt = P * transpose(H);
  PositiveDefiniteSolver<p> solver;
  if (!solver.factor(in.V + H * PHt)) return false;
  const Mat<n, p> K = solver.right_solve(PHt);  // P H^T S^-1
  m += K * (in.dy - model.observation(k1, m));
  const Mat<n, n> I_KH = Mat<n, n>::identity() - K * H;
  P = symmetrize(I_KH * P * transpose(I_KH) + K * in.V * transpose(K));
  return true;
}

}  // namespace detail

/// The covariance-form step KF and EKF-D share (they differ in the models they accept).
template <class Model>
struct DiscreteKalmanStep {
  static constexpr int n = Model::state_dim, p = Model::obs_dim;
  KOKKOS_INLINE_FUNCTION Status step(const Model& model, int, const StepInput<p>& in, Vec<n>& m, Mat<n, n>& P,
                                     const Vec<n>& known_input) const {
    detail::discrete_predict(model, in.t, known_input, m, P);
    return detail::discrete_covariance_update(model, in, m, P) ? Status::ok : Status::not_positive_definite;
  }
};

template <class Model, class MemSpace>
struct KalmanFilter : DiscreteKalmanStep<Model> {
  static constexpr const char* name = "KF";
  static constexpr const char* description =
      "discrete Kalman filter, covariance form (Tarushkin 1972; Clark 1971 ch. II)";
  static constexpr const char* unsupported = detail::discrete_kalman_unsupported<Model>();
  static const char* unsupported_by(const ModelFacts& f) { return detail::discrete_kalman_unsupported_by(f); }

  static KalmanFilter create(const OptionValues&, const Model&, long) { return {}; }
};

template <class Model, class MemSpace>
struct InformationFilter {
  static constexpr int n = Model::state_dim, p = Model::obs_dim;
  static constexpr const char* name = "KF-INF";
  static constexpr const char* description =
      "discrete Kalman filter, information form = recursive least squares (Tarushkin 1972 (4.9)-(4.17))";
  static constexpr const char* unsupported = detail::discrete_kalman_unsupported<Model>();
  static const char* unsupported_by(const ModelFacts& f) { return detail::discrete_kalman_unsupported_by(f); }

  static InformationFilter create(const OptionValues&, const Model&, long) { return {}; }

  /// Needs P- and V positive definite (their inverses are the information); else the member diverges.
  KOKKOS_INLINE_FUNCTION Status step(const Model& model, int, const StepInput<p>& in, Vec<n>& m, Mat<n, n>& P,
                                     const Vec<n>& known_input) const {
    detail::discrete_predict(model, in.t, known_input, m, P);
    Mat<n, n> Lp;
    Mat<p, p> Lv;
    if (!cholesky(P, Lp) || !cholesky(in.V, Lv)) return Status::not_positive_definite;
    const double k1 = in.t + 1.0;
    const Mat<p, n> H = model.observation_jacobian(k1, m);
    const Vec<p> z = in.dy - model.observation(k1, Vec<n>::zero());  // h(x) = h(0) + H x
    Mat<n, n> Y = cholesky_inverse(Lp);
    Vec<n> y = Y * m;
    Mat<p, p> Vinv = cholesky_inverse(Lv);
    Y = symmetrize(Y + transpose(H) * Vinv * H);
    y += transpose(H) * (Vinv * z);
    Mat<n, n> Ly;
    if (!cholesky(Y, Ly)) return Status::not_positive_definite;
    P = cholesky_inverse(Ly);
    m = cholesky_solve(Ly, y);
    return Status::ok;
  }
};

template <class Model, class MemSpace>
struct ExtendedKalmanFilterD : DiscreteKalmanStep<Model> {
  static constexpr const char* name = "EKF-D";
  static constexpr const char* description = "discrete extended Kalman filter (linearized at the estimate)";
  static constexpr const char* unsupported =
      Model::discrete_time ? nullptr : "continuous-time model (discrete-time filter)";

  static ExtendedKalmanFilterD create(const OptionValues&, const Model&, long) { return {}; }
};

}  // namespace kushner
