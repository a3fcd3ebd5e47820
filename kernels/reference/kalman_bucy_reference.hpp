#pragma once
// Exact reference for the linear model: the Kalman filter of the model the particle filter targets, i.e.
// the Kalman-Bucy filter (seed 002 section 2; seed 004 (2.3)-(2.4)) discretized on the observation grid
// exactly as the particle filter discretizes it:
//   x' = x + (a0 + A x) dt + b dw,        dw ~ N(0, dt I)            (Euler-Maruyama transition)
//   dy = (c0 + C x') dt + R dv,           dv ~ N(0, dt I)            (likelihood at the propagated state)
// Predict: m- = m + (a0 + A m) dt, P- = F P F^T + b b^T dt with F = I + A dt. Update with H = C dt and
// observation covariance V dt (V = R R^T): K = P- H^T (H P- H^T + V dt)^{-1}, Joseph form for P.
// Its posterior is exactly the particle filter's target for any dt, so the two differ by Monte Carlo error
// only; as dt -> 0 it converges to the continuous Kalman-Bucy filter with error O(dt). One member per
// work item; the filter bank (KB there) has its own continuous-time implementation.
#include "core/errors.hpp"
#include "core/linear_algebra.hpp"
#include "core/status.hpp"
#include "kernels/bank.hpp"
#include "kernels/for_each_member.hpp"
#include "models/linear_model.hpp"

#include <Kokkos_Core.hpp>

namespace kushner {

template <int N, class MemSpace>
struct KalmanReferenceStep {
  LinearModel<N> model;
  BankVector<MemSpace> mean, dy;
  BankSymmetric<MemSpace> covariance;
  BankScalar<Status, MemSpace> status;
  double dt;

  KOKKOS_INLINE_FUNCTION void operator()(const int member) const {
    if (status(member) != Status::ok) return;
    const Mat<N, N>& A = model.A;
    const Mat<N, N> F = Mat<N, N>::identity() + A * dt;
    const Vec<N> m = load<N>(mean, member);
    const Mat<N, N> P = load_symmetric<N>(covariance, member);
    const Vec<N> m_pred = m + (model.a0 + A * m) * dt;
    const Mat<N, N> P_pred = F * P * transpose(F) + model.b * transpose(model.b) * dt;
    const Mat<N, N> H = model.C * dt;
    const Mat<N, N> V_dt = model.R * transpose(model.R) * dt;
    const Mat<N, N> S = H * P_pred * transpose(H) + V_dt;
    Mat<N, N> L;
    if (!cholesky(S, L)) {
      status(member) = Status::not_positive_definite;
      return;
    }
    const Mat<N, N> K = P_pred * transpose(H) * cholesky_inverse(L);
    const Vec<N> innovation = load<N>(dy, member) - (model.c0 + model.C * m_pred) * dt;
    const Mat<N, N> I_KH = Mat<N, N>::identity() - K * H;
    const Vec<N> m_new = m_pred + K * innovation;
    const Mat<N, N> P_new = I_KH * P_pred * transpose(I_KH) + K * V_dt * transpose(K);
    if (!all_finite(m_new) || !all_finite(P_new)) {
      status(member) = Status::non_finite;
      return;
    }
    store(mean, member, m_new);
    store_symmetric(covariance, member, P_new);
  }
};

/// Exact posterior mean (member, i) and covariance (member, packed) of every member of a linear-model bank.
template <class ExecSpace, int N>
class KalmanBucyReference {
 public:
  using MemSpace = typename ExecSpace::memory_space;

  static double bytes_per_member() { return sizeof(double) * (N + packed_size(N)) + sizeof(Status); }
  /// Why it cannot run `model` (every reference answers this, kernels/reference/exact_reference.hpp): it runs
  /// every linear model.
  static const char* unsupported(const LinearModel<N>&) { return nullptr; }

  /// Starts every member at N(prior_mean, prior_cov) (or the truths' law when `truth_law`).
  KalmanBucyReference(const ExecSpace& space, const LinearModel<N>& model, int num_members, bool truth_law = false)
      : space_(space),
        model_(model),
        mean_("kushner::kb_reference_mean", num_members, N),
        covariance_("kushner::kb_reference_covariance", num_members, packed_size(N)),
        status_("kushner::kb_reference_status", num_members) {
    auto m = Kokkos::create_mirror_view(mean_);
    auto P = Kokkos::create_mirror_view(covariance_);
    for (int k = 0; k < num_members; ++k) {
      store(m, k, truth_law ? model.x0_mean : model.prior_mean);
      store_symmetric(P, k, truth_law ? model.x0_cov : model.prior_cov);
    }
    Kokkos::deep_copy(space_, mean_, m);
    Kokkos::deep_copy(space_, covariance_, P);
  }

  /// Step k: [k dt, (k + 1) dt] with increments dy (member, i).
  void step(long, double dt, const BankVector<MemSpace>& dy) {
    KUSHNER_REQUIRE(dy.extent(0) == mean_.extent(0) && dy.extent_int(1) == N, "dy has the wrong shape");
    parallel_for_members("kushner::kalman_reference_step", space_, mean_.extent(0),
                         KalmanReferenceStep<N, MemSpace>{model_, mean_, dy, covariance_, status_, dt});
  }

  const BankVector<MemSpace>& posterior_mean() const { return mean_; }
  const BankSymmetric<MemSpace>& posterior_covariance() const { return covariance_; }
  const BankScalar<Status, MemSpace>& status() const { return status_; }

  /// What a checkpoint holds (engine/state_archive.hpp).
  template <class Archive>
  void visit_state(Archive& archive) {
    archive.view("mean", mean_);
    archive.view("covariance", covariance_);
    archive.view("status", status_);
  }

 private:
  ExecSpace space_;
  LinearModel<N> model_;
  BankVector<MemSpace> mean_;
  BankSymmetric<MemSpace> covariance_;
  BankScalar<Status, MemSpace> status_;
};

}  // namespace kushner
