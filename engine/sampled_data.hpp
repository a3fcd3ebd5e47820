#pragma once
// Sampled data (seed 004 §2): the continuous linear model (2.1)-(2.2),
//   dx = A x dt + G dw,   dy = H x dt + dv  (E dv dv^T = R dt),
// observed every dt, as the discrete system (2.11), (2.14) and its Kalman filter (2.18)-(2.19). The
// discretization of the state is exact: x[k+1] = Phi x[k] + w[k] with Phi = exp(A dt) and
// Qd = E w w^T = int_0^dt exp(A s) G G^T exp(A^T s) ds (Van Loan's block exponential), whatever dt.
// Host code (Eigen), for set-ups, references and tests.
#include "core/eigen_dense.hpp"

namespace kushner {

/// x[k+1] = Phi x[k] + w[k], w[k] ~ N(0, Qd): seed 004 (2.11)-(2.12).
struct DiscreteTransition {
  Eigen::MatrixXd Phi, Qd;
};

/// The exact transition over `dt` of dx = A x dt + G dw (A: n x n, G: n x p). Van Loan (1978): the exponential
/// of [[-A, G G^T], [0, A^T]] h is [[., F12], [0, Phi(h)^T]] and Qd(h) = Phi(h) F12, taken on a short h = dt / 2^s
/// and doubled up to dt (accurate for long intervals too). InputError for shapes, non-finite entries, dt <= 0.
DiscreteTransition discretize(const Eigen::MatrixXd& A, const Eigen::MatrixXd& G, double dt);

/// The observation noise of the averaged increment z_k = (y[k+1] - y[k]) / dt, seed 004 (2.15)-(2.17):
/// R_k = (1 / dt^2) int R dtau = R / dt. InputError unless R is positive definite and dt > 0.
Eigen::MatrixXd averaged_observation_noise(const Eigen::MatrixXd& R, double dt);

/// A Gaussian estimate: mean x and covariance P.
struct GaussianEstimate {
  Eigen::VectorXd x;
  Eigen::MatrixXd P;
};

/// x[k|k-1] = Phi x[k-1|k-1], P[k|k-1] = Phi P Phi^T + Qd (seed 004 L345: the prediction (2.18)-(2.19) start from).
GaussianEstimate predict(const GaussianEstimate& estimate, const DiscreteTransition& transition);

/// The update with z_k = H_k x_k + v_k, v_k ~ N(0, R_k), in the gain form (2.18):
/// K = P H^T (H P H^T + R)^-1, x += K (z - H x), P -= K H P (Joseph's form, which is the same matrix in exact
/// arithmetic and stays symmetric positive semidefinite in rounding). InputError for shapes or a R_k that is
/// not positive definite.
GaussianEstimate update_gain_form(const GaussianEstimate& predicted, const Eigen::MatrixXd& H, const Eigen::VectorXd& z,
                                  const Eigen::MatrixXd& R);

/// The same update in the information form (2.19): P[k|k]^-1 = P[k|k-1]^-1 + H^T R^-1 H, K = P[k|k] H^T R^-1.
/// Needs P[k|k-1] positive definite (InputError otherwise).
GaussianEstimate update_information_form(const GaussianEstimate& predicted, const Eigen::MatrixXd& H,
                                         const Eigen::VectorXd& z, const Eigen::MatrixXd& R);

}  // namespace kushner
