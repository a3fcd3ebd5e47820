#pragma once
// The exact conditional law for deterministic dynamics (no process noise) and a rank-1 Gaussian prior, as an
// estimator beside the bank: the reference of `kushner reproduce basin-car-filter`, where a particle filter
// cannot serve (without process noise its resampled particles never spread again, and the posterior, a point
// on the flow of the prior's line, is 1/100 of the prior's width by T = 20: a bootstrap filter keeps ~1% of its
// particles and then copies of them).
//
// The prior N(m0, v v^T) puts x(0) = m0 + s v on a line, s ~ N(0, 1). With dx = f(t, x) dt the state is a
// function x(t; s) of s, and the conditional law of s given the observations y(0..t) has the density
//   p(s | y) ~ N(s; 0, 1) exp( sum_k h(x_k(s))^T V^{-1} dy_k - 1/2 h(x_k(s))^T V^{-1} h(x_k(s)) dt )
// (Girsanov; the same Euler steps as the truths, the same dy). It is exact for the Euler-discretized model up
// to the quadrature in s: here the trapezoidal rule on `nodes` equally spaced points of [-8, 8] (prior mass
// outside: 1e-15), spectrally accurate for a smooth integrand once the spacing is below the posterior's width.
// Its quadrature error is estimated at each step as |mean - mean on every second node| (the rule with twice
// the spacing), whose largest value over the run describe() reports: it bounds the error of the mean used.
#include "core/eigen_dense.hpp"
#include "core/eigen_helpers.hpp"
#include "core/errors.hpp"
#include "core/linear_algebra.hpp"
#include "core/math.hpp"
#include "engine/reference_estimator.hpp"
#include "kernels/bank.hpp"
#include "kernels/for_each_member.hpp"

#include <Kokkos_Core.hpp>

#include <cmath>
#include <string>

namespace kushner {

namespace detail {

/// One step of every member: weights by the likelihood of dy, nodes by one Euler step, posterior moments.
template <class Model, class MemSpace>
struct PriorLineStep {
  Model model;
  ParticleBank<MemSpace> x;                                         // (node, member, i)
  Kokkos::View<double**, Kokkos::LayoutLeft, MemSpace> log_weight;  // (node, member)
  BankVector<MemSpace> dy, mean;
  BankSymmetric<MemSpace> covariance;
  BankScalar<double, MemSpace> quadrature_error;  // largest |mean(h) - mean(2h)| so far, per member
  BankScalar<Status, MemSpace> status;
  double t, dt;

  /// exp(d) for d <= 0, and 0 where it would underflow: most nodes lie far out in the tails, and exp's
  /// underflow path is slow.
  KOKKOS_INLINE_FUNCTION static double relative_weight(double d) { return d < -745.0 ? 0.0 : math::exp(d); }

  KOKKOS_INLINE_FUNCTION void operator()(const int member) const {
    constexpr int n = Model::state_dim, p = Model::obs_dim;
    if (status(member) != Status::ok) return;
    const int nodes = static_cast<int>(x.extent(0));
    const Vec<p> dym = load<p>(dy, member);
    const Mat<p, p> V = model.observation_noise(t) * transpose(model.observation_noise(t));
    PositiveDefiniteSolver<p> V_solver;
    if (!V_solver.factor(V)) {
      status(member) = Status::not_positive_definite;
      return;
    }
    const typename Model::Control u = Model::Control::zero();
    double largest = -1e300;
    for (int j = 0; j < nodes; ++j) {
      Vec<n> xj;
      for (int i = 0; i < n; ++i) xj[i] = x(j, member, i);
      const Vec<p> h = model.observation(t, xj);
      const Vec<p> Vinv_h = V_solver.solve(h);
      const double lw = log_weight(j, member) + dot(Vinv_h, dym) - 0.5 * dot(Vinv_h, h) * dt;
      log_weight(j, member) = lw;
      largest = lw > largest ? lw : largest;
      const Vec<n> next = xj + model.drift(t, xj, u) * dt;
      for (int i = 0; i < n; ++i) x(j, member, i) = next[i];
    }
    double total = 0.0, total_even = 0.0;
    Vec<n> sum = Vec<n>::zero(), sum_even = Vec<n>::zero();
    for (int j = 0; j < nodes; ++j) {
      const double w = relative_weight(log_weight(j, member) - largest);
      Vec<n> xj;
      for (int i = 0; i < n; ++i) xj[i] = x(j, member, i);
      total += w;
      sum += xj * w;
      if (j % 2 == 0) total_even += w, sum_even += xj * w;
    }
    const Vec<n> m = sum * (1.0 / total);
    const Vec<n> m_even = sum_even * (1.0 / total_even);
    Mat<n, n> P = Mat<n, n>::zero();
    for (int j = 0; j < nodes; ++j) {
      const double w = relative_weight(log_weight(j, member) - largest) / total;
      Vec<n> d;
      for (int i = 0; i < n; ++i) d[i] = x(j, member, i) - m[i];
      for (int a = 0; a < n; ++a)
        for (int b = 0; b < n; ++b) P(a, b) += w * d[a] * d[b];
    }
    double error = quadrature_error(member);
    for (int i = 0; i < n; ++i) error = math::fabs(m[i] - m_even[i]) > error ? math::fabs(m[i] - m_even[i]) : error;
    if (!(all_finite(m) && all_finite(P) && total > 0.0)) {
      status(member) = Status::non_finite;
      return;
    }
    quadrature_error(member) = error;
    store(mean, member, m);
    store_symmetric(covariance, member, P);
  }
};

}  // namespace detail

template <class ExecSpace, class Model>
class PriorLineReference final : public ReferenceEstimator<typename ExecSpace::memory_space> {
 public:
  using MemSpace = typename ExecSpace::memory_space;
  static constexpr int n = Model::state_dim;
  static constexpr double half_width = 8.0;  // in prior standard deviations

  /// InputError unless the model's process noise is zero at the prior mean and its prior covariance has rank 1.
  PriorLineReference(const ExecSpace& space, const Model& model, long members, int nodes = 4097)
      : space_(space),
        model_(model),
        nodes_(nodes),
        x_("kushner::prior_line_x", nodes, members, n),
        log_weight_("kushner::prior_line_log_weight", nodes, members),
        mean_("kushner::prior_line_mean", members, n),
        covariance_("kushner::prior_line_covariance", members, packed_size(n)),
        error_("kushner::prior_line_quadrature_error", members),
        status_("kushner::prior_line_status", members) {
    KUSHNER_REQUIRE(nodes >= 3 && nodes % 2 == 1, "PriorLineReference: nodes must be odd and at least 3");
    const auto G = to_eigen(model.diffusion(0.0, model.prior_mean));
    KUSHNER_INPUT_REQUIRE(G.cwiseAbs().maxCoeff() == 0.0,
                          "prior-line reference: the model has process noise (it needs deterministic dynamics)");
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, n, n>> eigen(to_eigen(model.prior_cov));
    const double largest = eigen.eigenvalues()(n - 1);
    for (int i = 0; i + 1 < n; ++i)
      KUSHNER_INPUT_REQUIRE(
          std::abs(eigen.eigenvalues()(i)) <= 1e-12 * largest,
          "prior-line reference: prior_cov must have rank 1 (eigenvalue " << eigen.eigenvalues()(i) << ")");
    const Eigen::Matrix<double, n, 1> v = eigen.eigenvectors().col(n - 1) * std::sqrt(largest);
    const auto x = Kokkos::create_mirror_view(x_);
    const auto lw = Kokkos::create_mirror_view(log_weight_);
    const auto m = Kokkos::create_mirror_view(mean_);
    const auto P = Kokkos::create_mirror_view(covariance_);
    const double spacing = 2.0 * half_width / (nodes - 1);
    for (long member = 0; member < members; ++member) {
      for (int j = 0; j < nodes; ++j) {
        const double s = -half_width + j * spacing;
        for (int i = 0; i < n; ++i) x(j, member, i) = model.prior_mean[i] + s * v(i);
        lw(j, member) = -0.5 * s * s;
      }
      for (int i = 0; i < n; ++i) m(member, i) = model.prior_mean[i];
      for (int i = 0; i < n; ++i)
        for (int k = i; k < n; ++k) P(member, packed_index(n, i, k)) = model.prior_cov(i, k);
    }
    Kokkos::deep_copy(x_, x);
    Kokkos::deep_copy(log_weight_, lw);
    Kokkos::deep_copy(mean_, m);
    Kokkos::deep_copy(covariance_, P);
  }

  std::string name() const override { return "EXACT"; }
  void advance(long, double t, double dt, const BankVector<MemSpace>& dy) override {
    parallel_for_members("kushner::prior_line_step", space_, mean_.extent(0),
                         detail::PriorLineStep<Model, MemSpace>{model_, x_, log_weight_, dy, mean_, covariance_, error_,
                                                                status_, t, dt});
  }
  BankVector<MemSpace> mean() const override { return mean_; }
  BankSymmetric<MemSpace> covariance() const override { return covariance_; }
  BankScalar<Status, MemSpace> status() const override { return status_; }
  Fields describe() const override {
    space_.fence();
    const auto error = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), error_);
    double largest = 0.0;
    for (std::size_t member = 0; member < error.extent(0); ++member) largest = std::max(largest, error(member));
    return {{"kind", std::string("prior-line quadrature")},
            {"note", std::string("exact conditional law of the filters' model for deterministic dynamics and a rank-1 "
                                 "prior: likelihood-weighted points of the prior's line, trapezoidal rule")},
            {"nodes", static_cast<long>(nodes_)},
            {"half_width_sd", half_width},
            {"quadrature_error", largest}};
  }

 private:
  ExecSpace space_;
  Model model_;
  int nodes_;
  ParticleBank<MemSpace> x_;
  Kokkos::View<double**, Kokkos::LayoutLeft, MemSpace> log_weight_;
  BankVector<MemSpace> mean_;
  BankSymmetric<MemSpace> covariance_;
  BankScalar<double, MemSpace> error_;
  BankScalar<Status, MemSpace> status_;
};

}  // namespace kushner
