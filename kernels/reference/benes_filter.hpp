#pragma once
// The Benes filter in closed form for a Gaussian initial law x0 ~ N(m0, s0^2), on the observation grid the
// particle filter uses (exact for any dt):
//   x_{k+1} | x_k ~ cosh(x') N(x'; x, dt) / (e^{dt/2} cosh x)      (models/benes_model.hpp)
//   dy_k | x_{k+1} ~ N(x_{k+1} dt, r^2 dt).
// The transition densities telescope: prod_k p(x_{k+1} | x_k) = cosh(x_K) / cosh(x_0) e^{-K dt/2} prod_k
// N(x_{k+1}; x_k, dt), so the joint posterior of (x_K, x_0) is
//   p(x_K, x_0 | y) ∝ cosh(x_K) / cosh(x_0) N((x_K, x_0); M, S),
// where (M, S) is the Kalman filter of the random walk dx = dw with the same observations, run on the
// augmented state (x_K, x_0) (Benes 1981; Bain & Crisan 2009, section 6.1; the augmentation handles a
// Gaussian prior, which is not itself of the form cosh(x) N(x; a, b)). Given x_0 = z the posterior of x_K
// is cosh(x) N(x; c(z), s) with c(z) = M_x + S_xz / S_zz (z - M_z), s = S_xx - S_xz^2 / S_zz, whose mean
// and variance are c + s tanh c and s + s^2 sech^2 c; x_0 has posterior ∝ N(z; M_z, S_zz) cosh(c(z)) /
// cosh(z), integrated by Gauss-Hermite quadrature. tests/test_particle_filter_references.cpp checks it against
// the particle filter.
#include "core/eigen_dense.hpp"
#include "core/errors.hpp"
#include "core/math.hpp"
#include "core/status.hpp"
#include "kernels/bank.hpp"
#include "kernels/for_each_member.hpp"
#include "models/benes_model.hpp"

#include <Kokkos_Core.hpp>

#include <cmath>

namespace kushner {

/// Gauss-Hermite nodes and log-weights for the weight e^{-u^2/2} (probabilists'), by Golub-Welsch.
constexpr int benes_quadrature_nodes = 64;
struct HermiteRule {
  double node[benes_quadrature_nodes];
  double log_weight[benes_quadrature_nodes];
};

inline HermiteRule probabilists_hermite_rule() {
  constexpr int n = benes_quadrature_nodes;
  Eigen::MatrixXd jacobi = Eigen::MatrixXd::Zero(n, n);  // He_{k+1} = u He_k - k He_{k-1}
  for (int k = 1; k < n; ++k) jacobi(k, k - 1) = jacobi(k - 1, k) = std::sqrt(static_cast<double>(k));
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(jacobi);
  HermiteRule rule;
  for (int i = 0; i < n; ++i) {
    rule.node[i] = solver.eigenvalues()(i);
    const double v = solver.eigenvectors()(0, i);
    rule.log_weight[i] = std::log(v * v) + 0.5 * std::log(2.0 * 3.14159265358979323846);
  }
  return rule;
}

template <class MemSpace>
struct BenesFilterStep {
  BankVector<MemSpace> augmented_mean;    // (member, 2): (x_K, x_0)
  BankSymmetric<MemSpace> augmented_cov;  // (member, 3): S_xx, S_xz, S_zz
  BankVector<MemSpace> dy, mean;          // mean (member, 0)
  BankSymmetric<MemSpace> variance;       // (member, 0)
  BankScalar<Status, MemSpace> status;
  HermiteRule rule;
  double r, dt;
  bool update;  // false: moments of the current state only

  KOKKOS_INLINE_FUNCTION void operator()(const int member) const {
    if (status(member) != Status::ok) return;
    Vec<2> M = load<2>(augmented_mean, member);
    Mat<2, 2> S = load_symmetric<2>(augmented_cov, member);
    if (update) {
      S(0, 0) += dt;  // random walk: x_{k+1} = x_k + dw
      // dy = x dt + r dv: gain K = S H^T / (H S H^T + r^2 dt), H = (dt, 0).
      const double innovation_var = S(0, 0) * dt * dt + r * r * dt;
      const Vec<2> K = Vec<2>{{S(0, 0) * dt, S(1, 0) * dt}} * (1.0 / innovation_var);
      const double innovation = dy(member, 0) - M[0] * dt;
      M = M + K * innovation;
      Mat<2, 2> P;
      for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j) P(i, j) = S(i, j) - K[i] * K[j] * innovation_var;
      S = P;
      store(augmented_mean, member, M);
      store_symmetric(augmented_cov, member, S);
    }
    // Posterior moments of x_K by quadrature over x_0.
    const double s_zz = S(1, 1), slope = s_zz > 0.0 ? S(0, 1) / s_zz : 0.0;
    const double s = S(0, 0) - slope * S(0, 1);
    double log_w[benes_quadrature_nodes], c[benes_quadrature_nodes];
    double top = -1e300;
    for (int i = 0; i < benes_quadrature_nodes; ++i) {
      const double z = M[1] + math::sqrt(s_zz) * rule.node[i];
      c[i] = M[0] + slope * (z - M[1]);
      log_w[i] = rule.log_weight[i] + math::log_cosh(c[i]) - math::log_cosh(z);
      top = log_w[i] > top ? log_w[i] : top;
    }
    double total = 0.0, first = 0.0;
    for (int i = 0; i < benes_quadrature_nodes; ++i) {
      log_w[i] = math::exp(log_w[i] - top);
      total += log_w[i];
      first += log_w[i] * (c[i] + s * math::tanh(c[i]));
    }
    const double m = first / total;
    double second = 0.0;  // total variance: E[Var(x | z)] + Var(E[x | z])
    for (int i = 0; i < benes_quadrature_nodes; ++i) {
      const double t = math::tanh(c[i]);
      const double conditional_mean = c[i] + s * t;
      second += log_w[i] * (s + s * s * (1.0 - t * t) + (conditional_mean - m) * (conditional_mean - m));
    }
    const double v = second / total;
    if (!math::is_finite(m) || !math::is_finite(v)) {
      status(member) = Status::non_finite;
      return;
    }
    mean(member, 0) = m;
    variance(member, 0) = v;
  }
};

/// Exact posterior mean (member, 0) and variance (member, 0) of the Benes model, every member of a bank.
template <class ExecSpace>
class BenesFilter {
 public:
  using MemSpace = typename ExecSpace::memory_space;

  static double bytes_per_member() { return sizeof(double) * (2 + 3 + 1 + 1) + sizeof(Status); }
  /// Why it cannot run `model` (kernels/reference/exact_reference.hpp): nullptr; a degenerate prior variance is
  /// refused where the filter is made, with its value.
  static const char* unsupported(const BenesModel&) { return nullptr; }

  BenesFilter(const ExecSpace& space, const BenesModel& model, int num_members, bool truth_law = false)
      : space_(space),
        r_(model.r),
        rule_(probabilists_hermite_rule()),
        augmented_mean_("kushner::benes_augmented_mean", num_members, 2),
        augmented_cov_("kushner::benes_augmented_cov", num_members, 3),
        mean_("kushner::benes_mean", num_members, 1),
        variance_("kushner::benes_variance", num_members, 1),
        status_("kushner::benes_status", num_members) {
    const double m0 = truth_law ? model.x0_mean[0] : model.prior_mean[0];
    const double v0 = truth_law ? model.x0_cov(0, 0) : model.prior_cov(0, 0);
    KUSHNER_INPUT_REQUIRE(v0 > 0.0, "benes: the exact filter needs a positive initial variance (got " << v0 << ")");
    auto M = Kokkos::create_mirror_view(augmented_mean_);
    auto S = Kokkos::create_mirror_view(augmented_cov_);
    for (int k = 0; k < num_members; ++k) {  // x_K = x_0 at time 0: fully correlated
      M(k, 0) = M(k, 1) = m0;
      S(k, 0) = S(k, 1) = S(k, 2) = v0;
    }
    Kokkos::deep_copy(space_, augmented_mean_, M);
    Kokkos::deep_copy(space_, augmented_cov_, S);
    launch(BankVector<MemSpace>(), 0.0, false);
  }

  void step(long, double dt, const BankVector<MemSpace>& dy) {
    KUSHNER_REQUIRE(dy.extent(0) == mean_.extent(0) && dy.extent_int(1) == 1, "dy has the wrong shape");
    launch(dy, dt, true);
  }

  const BankVector<MemSpace>& posterior_mean() const { return mean_; }
  /// (member, 0): posterior variance (a 1x1 packed covariance).
  const BankSymmetric<MemSpace>& posterior_covariance() const { return variance_; }
  const BankScalar<Status, MemSpace>& status() const { return status_; }

  /// What a checkpoint holds (engine/state_archive.hpp).
  template <class Archive>
  void visit_state(Archive& archive) {
    archive.view("augmented_mean", augmented_mean_);
    archive.view("augmented_cov", augmented_cov_);
    archive.view("mean", mean_);
    archive.view("variance", variance_);
    archive.view("status", status_);
  }

 private:
  void launch(const BankVector<MemSpace>& dy, double dt, bool update) {
    parallel_for_members("kushner::benes_filter_step", space_, mean_.extent(0),
                         BenesFilterStep<MemSpace>{augmented_mean_, augmented_cov_, dy, mean_, variance_, status_,
                                                   rule_, r_, dt, update});
  }

  ExecSpace space_;
  double r_;
  HermiteRule rule_;
  BankVector<MemSpace> augmented_mean_;
  BankSymmetric<MemSpace> augmented_cov_;
  BankVector<MemSpace> mean_;
  BankSymmetric<MemSpace> variance_;
  BankScalar<Status, MemSpace> status_;
};

}  // namespace kushner
