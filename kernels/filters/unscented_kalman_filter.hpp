#pragma once
// UKF: the continuous-time unscented Kalman(-Bucy) filter of Sarkka (2007, IEEE TAC 52(9), "On unscented Kalman
// filtering for state estimation of continuous-time nonlinear systems"):
//   dm = f(X) w_m dt + X W h(X)^T V^{-1} (dy - h(X) w_m dt),
//   dP = (X W f(X)^T + f(X) W X^T + G G^T - X W h(X)^T V^{-1} h(X) W X^T) dt,
// i.e. seed 000's (5.27), (5.29) with the expectations of f, h and their cross-covariances with x taken over
// sigma points instead of a Gaussian integral. Sigma points: the unscented transform of Julier and Uhlmann
// with the scaling of Wan and van der Merwe, lambda = alpha^2 (n + kappa) - n, c = n + lambda,
//   X_0 = m, X_{+-j} = m +- sqrt(c) L_j (L L^T = P),
//   w_m0 = lambda / c, w_c0 = lambda / c + 1 - alpha^2 + beta, w_j = 1 / (2 c).
// Defaults alpha = 1, beta = 0, kappa = 0 give the third-degree spherical-radial rule (2n points of weight
// 1/(2n): the cubature Kalman filter of Arasaratnam and Haykin): positive weights, so P stays a covariance.
// One step of the bank's discretization (kernels/filters/filter_step.hpp):
//   1. update with dy at the sigma points of (m, P): h_bar = sum w_m h(X), C_xh, C_hh their (w_c) covariances,
//      S = V + dt C_hh, K = C_xh S^{-1}, m <- m + K (dy - h_bar dt), P <- P - dt K C_xh^T
//      (the discrete unscented update of the observation dy with noise V dt);
//   2. prediction: the sigma points of the updated (m, P) through the Euler map x + f(x) dt, their weighted
//      mean and covariance, plus G G^T dt.
// Both stages are Sarkka's equations to O(dt); on a linear model the unscented transform is exact and the
// step is the Kalman-Bucy step to rounding.
#include "core/linear_algebra.hpp"
#include "kernels/filters/filter_protocol.hpp"
#include "kernels/filters/filter_step.hpp"

#include <cmath>
#include <vector>

namespace kushner {

template <class Model, class MemSpace>
struct UnscentedKalmanFilter {
  static constexpr int n = Model::state_dim, p = Model::obs_dim;
  static constexpr const char* name = "UKF";
  static constexpr const char* description =
      "unscented Kalman-Bucy filter, Sarkka 2007 (sigma points: alpha, beta, kappa; default cubature rule)";
  static constexpr const char* unsupported = nullptr;  // needs only f, G and h

  double scale = 0.0;  // sqrt(c)
  double wm0 = 0.0, wc0 = 0.0, wj = 0.0;

  static std::vector<OptionSpec> options() {
    OptionSpec beta{"ukf_beta", OptionSpec::Kind::real, 0.0};
    beta.min = 0.0, beta.max = 10.0, beta.help = "UKF sigma-point beta (2 is optimal for a Gaussian prior)";
    OptionSpec kappa{"ukf_kappa", OptionSpec::Kind::real, 0.0};
    kappa.min = 0.0, kappa.max = 100.0, kappa.help = "UKF sigma-point kappa (3 - n: Julier-Uhlmann's choice)";
    return {OptionSpec::positive_real("ukf_alpha", 1.0, "UKF sigma-point spread alpha"), beta, kappa};
  }

  static UnscentedKalmanFilter create(const OptionValues& options, const Model&, long) {
    return with_parameters(options.real("ukf_alpha"), options.real("ukf_beta"), options.real("ukf_kappa"));
  }

  static UnscentedKalmanFilter with_parameters(double alpha, double beta, double kappa) {
    const double lambda = alpha * alpha * (n + kappa) - n, c = n + lambda;
    KUSHNER_REQUIRE(c > 0.0, "UKF: n + lambda must be positive (got " << c << ")");
    UnscentedKalmanFilter f;
    f.scale = std::sqrt(c);
    f.wm0 = lambda / c;
    f.wc0 = lambda / c + 1.0 - alpha * alpha + beta;
    f.wj = 0.5 / c;
    return f;
  }

  /// summary.json: the sigma-point weights in use.
  Fields summary_fields() const {
    return {{"sigma_points", static_cast<long>(2 * n + 1)}, {"w_m0", wm0}, {"w_c0", wc0}, {"w_j", wj}};
  }

  KOKKOS_INLINE_FUNCTION Status step(const Model& model, int, const StepInput<p>& in, Vec<n>& m, Mat<n, n>& P) const {
    Mat<n, n> L;
    if (semidefinite_cholesky(P, L, covariance_tolerance) == Definiteness::indefinite)
      return Status::not_positive_definite;
    // 1. Update.
    const Vec<p> h0 = model.observation(in.t, m);
    Vec<p> h_bar = h0 * wm0;
    for (int j = 0; j < n; ++j) {
      const Vec<n> d = column(L, j) * scale;
      h_bar += (model.observation(in.t, m + d) + model.observation(in.t, m - d)) * wj;
    }
    Mat<n, p> Cxh = Mat<n, p>::zero();
    Mat<p, p> Chh = outer(h0 - h_bar, h0 - h_bar) * wc0;
    for (int j = 0; j < n; ++j) {
      const Vec<n> d = column(L, j) * scale;
      const Vec<p> hp = model.observation(in.t, m + d) - h_bar, hm = model.observation(in.t, m - d) - h_bar;
      Cxh += outer(d, hp - hm) * wj;
      Chh += (outer(hp, hp) + outer(hm, hm)) * wj;
    }
    const Mat<p, p> S = in.V + Chh * in.dt;
    PositiveDefiniteSolver<p> solver;
    if (!solver.factor(S)) return Status::not_positive_definite;
    const Vec<p> innovation = in.dy - h_bar * in.dt;
    const Mat<n, p> K = solver.right_solve(Cxh);  // C_xh S^{-1}
    m += K * innovation;
    P = symmetrize(P - (K * transpose(Cxh)) * in.dt);
    // 2. Prediction through the Euler map.
    if (semidefinite_cholesky(P, L, covariance_tolerance) == Definiteness::indefinite)
      return Status::not_positive_definite;
    const auto u = Model::Control::zero();
    const Mat<n, n> W = noise_intensity(model.diffusion(in.t, m));
    const Vec<n> x0 = m + model.drift(in.t, m, u) * in.dt;
    Vec<n> xp[n], xm[n];
    Vec<n> mean = x0 * wm0;
    for (int j = 0; j < n; ++j) {
      const Vec<n> d = column(L, j) * scale;
      xp[j] = m + d + model.drift(in.t, m + d, u) * in.dt;
      xm[j] = m - d + model.drift(in.t, m - d, u) * in.dt;
      mean += (xp[j] + xm[j]) * wj;
    }
    Mat<n, n> cov = outer(x0 - mean, x0 - mean) * wc0;
    for (int j = 0; j < n; ++j) cov += (outer(xp[j] - mean, xp[j] - mean) + outer(xm[j] - mean, xm[j] - mean)) * wj;
    m = mean;
    P = symmetrize(cov + W * in.dt);
    return Status::ok;
  }

 private:
  KOKKOS_INLINE_FUNCTION static Vec<n> column(const Mat<n, n>& L, int j) {
    Vec<n> c;
    for (int i = 0; i < n; ++i) c[i] = L(i, j);
    return c;
  }
};

}  // namespace kushner
