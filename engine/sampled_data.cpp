#include "engine/sampled_data.hpp"

#include "core/errors.hpp"
#include "engine/dense_checks.hpp"

#include <unsupported/Eigen/MatrixFunctions>

#include <cmath>

namespace kushner {

namespace {

void check_update(const GaussianEstimate& predicted, const Eigen::MatrixXd& H, const Eigen::VectorXd& z,
                  const Eigen::MatrixXd& R) {
  const long n = predicted.x.size(), m = z.size();
  check_dense_shape("update: P", predicted.P, n, n);
  check_dense_shape("update: H", H, m, n);
  check_dense_positive_definite("update: R", R);
  check_dense_shape("update: R", R, m, m);
}

Eigen::MatrixXd symmetric(const Eigen::MatrixXd& m) { return 0.5 * (m + m.transpose()); }

}  // namespace

DiscreteTransition discretize(const Eigen::MatrixXd& A, const Eigen::MatrixXd& G, double dt) {
  KUSHNER_INPUT_REQUIRE(std::isfinite(dt) && dt > 0.0, "discretize: dt must be positive (got " << dt << ")");
  const long n = A.rows();
  check_dense_shape("discretize: A", A, n, n);
  check_dense_shape("discretize: G", G, n, -1);
  // The block exponential holds exp(-A h): over a long interval of a stable A it grows like the inverse of Phi and
  // Qd = Phi F12 cancels. So it runs on h = dt / 2^s with |A| h <= 1/2 and the interval is doubled s times,
  // Phi(2h) = Phi(h)^2, Qd(2h) = Phi(h) Qd(h) Phi(h)^T + Qd(h), each step a sum of positive semidefinite terms.
  const double norm = A.cwiseAbs().rowwise().sum().maxCoeff() * dt;
  const int doublings = norm > 0.5 ? static_cast<int>(std::ceil(std::log2(norm / 0.5))) : 0;
  const double h = std::ldexp(dt, -doublings);
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  C.topLeftCorner(n, n) = -A * h;
  C.topRightCorner(n, n) = G * G.transpose() * h;
  C.bottomRightCorner(n, n) = A.transpose() * h;
  const Eigen::MatrixXd F = C.exp();  // Pade approximant
  DiscreteTransition d;
  d.Phi = F.bottomRightCorner(n, n).transpose();
  d.Qd = symmetric(d.Phi * F.topRightCorner(n, n));
  for (int i = 0; i < doublings; ++i) {
    d.Qd = symmetric(d.Phi * d.Qd * d.Phi.transpose() + d.Qd);
    d.Phi = d.Phi * d.Phi;
  }
  return d;
}

Eigen::MatrixXd averaged_observation_noise(const Eigen::MatrixXd& R, double dt) {
  KUSHNER_INPUT_REQUIRE(std::isfinite(dt) && dt > 0.0,
                        "averaged_observation_noise: dt must be positive (got " << dt << ")");
  check_dense_positive_definite("averaged_observation_noise: R", R);
  return R / dt;
}

GaussianEstimate predict(const GaussianEstimate& estimate, const DiscreteTransition& transition) {
  const long n = estimate.x.size();
  check_dense_shape("predict: P", estimate.P, n, n);
  check_dense_shape("predict: Phi", transition.Phi, n, n);
  check_dense_shape("predict: Qd", transition.Qd, n, n);
  return {transition.Phi * estimate.x,
          symmetric(transition.Phi * estimate.P * transition.Phi.transpose() + transition.Qd)};
}

GaussianEstimate update_gain_form(const GaussianEstimate& predicted, const Eigen::MatrixXd& H, const Eigen::VectorXd& z,
                                  const Eigen::MatrixXd& R) {
  check_update(predicted, H, z, R);
  const Eigen::MatrixXd PHt = predicted.P * H.transpose();
  const Eigen::MatrixXd S = symmetric(H * PHt + R);
  const Eigen::LLT<Eigen::MatrixXd> llt(S);
  KUSHNER_INPUT_REQUIRE(llt.info() == Eigen::Success, "update: H P H^T + R not positive definite");
  const Eigen::MatrixXd K = llt.solve(PHt.transpose()).transpose();
  const long n = predicted.x.size();
  const Eigen::MatrixXd I_KH = Eigen::MatrixXd::Identity(n, n) - K * H;
  return {predicted.x + K * (z - H * predicted.x),
          symmetric(I_KH * predicted.P * I_KH.transpose() + K * R * K.transpose())};
}

GaussianEstimate update_information_form(const GaussianEstimate& predicted, const Eigen::MatrixXd& H,
                                         const Eigen::VectorXd& z, const Eigen::MatrixXd& R) {
  check_update(predicted, H, z, R);
  check_dense_positive_definite("update: P", predicted.P);
  const long n = predicted.x.size();
  const Eigen::LLT<Eigen::MatrixXd> r_llt(R);
  const Eigen::MatrixXd Rinv_H = r_llt.solve(H);
  const Eigen::MatrixXd Y =
      predicted.P.llt().solve(Eigen::MatrixXd::Identity(n, n)) + H.transpose() * Rinv_H;  // P[k|k]^-1
  const Eigen::MatrixXd P = symmetric(Y.llt().solve(Eigen::MatrixXd::Identity(n, n)));
  const Eigen::MatrixXd K = P * Rinv_H.transpose();
  return {predicted.x + K * (z - H * predicted.x), P};
}

}  // namespace kushner
