#pragma once
// Per member: merge the block partials of a step in block order (fixed, so the same bits on any number of
// threads), and turn them into the posterior mean and covariance, the effective sample size
// ESS = (sum w)^2 / sum w^2 (Kong, Liu & Wong 1994), the log-normalizer, and the decision to resample.
#include "core/status.hpp"
#include "kernels/bank.hpp"
#include "kernels/particle_filter/weighted_moments.hpp"

#include <Kokkos_Core.hpp>

namespace kushner {

template <int N, class MemSpace>
struct ParticlePosterior {
  static constexpr int packed = packed_size(N);
  Kokkos::View<const double***, Kokkos::LayoutLeft, MemSpace> partials;  // (block, member, k)
  int num_blocks;
  BankVector<MemSpace> reference;      // (member, i): in, the step's reference point; out, the new mean
  bool update_reference;               // false: leave the reference point (the first step of a fused pair)
  BankVector<MemSpace> mean;           // (member, i)
  BankSymmetric<MemSpace> covariance;  // (member, packed)
  BankScalar<double, MemSpace> ess, log_normalizer;
  BankScalar<int, MemSpace> resample, resample_count;
  BankScalar<Status, MemSpace> status;
  double resample_below;                           // resample when ESS < this (threshold * N)
  Kokkos::View<int*, MemSpace> resample_list;      // if allocated: the resampled members, [0, resample_list_size())
  Kokkos::View<int, MemSpace> resample_list_size;  // (in any order: each member's resampling is its own), zero before
  // If allocated: set to zero by this kernel, the size of the list the next posterior kernel appends to (the bank
  // alternates two lists, so that no kernel of its own clears them; every reader of that list has run before this).
  Kokkos::View<int, MemSpace> next_list_size;
  BankScalar<Status, MemSpace> status_copy;  // if allocated: each member's status after this step, as well

  KOKKOS_INLINE_FUNCTION void operator()(const int member) const {
    if (member == 0 && next_list_size.data() != nullptr) next_list_size() = 0;
    update(member);
    if (status_copy.data() != nullptr) status_copy(member) = status(member);
  }

 private:
  KOKKOS_INLINE_FUNCTION void update(const int member) const {
    resample(member) = 0;
    if (status(member) != Status::ok) {
      ess(member) = 0.0;
      return;
    }
    // Block order, as always; the loads of a batch of partials are issued before the merges (a GPU thread
    // otherwise waits for memory once per block).
    constexpr int batch = WeightedMoments<N>::size <= 8 ? 8 : (WeightedMoments<N>::size <= 16 ? 4 : 1);
    WeightedMoments<N> w = WeightedMoments<N>::load(partials, 0, member);
    for (int b0 = 1; b0 < num_blocks; b0 += batch) {
      WeightedMoments<N> p[batch];
      for (int k = 0; k < batch; ++k)
        if (b0 + k < num_blocks) p[k] = WeightedMoments<N>::load(partials, b0 + k, member);
      for (int k = 0; k < batch; ++k)
        if (b0 + k < num_blocks) w.merge(p[k]);
    }
    bool finite = w.sum_weight > 0.0 && math::is_finite(w.sum_weight) && math::is_finite(w.max_log_weight);
    const double inverse = 1.0 / w.sum_weight;
    Vec<N> mean_dx = w.sum_dx * inverse;
    Vec<packed> cov;
    for (int i = 0; i < N; ++i)
      for (int j = i; j < N; ++j) {
        const int k = packed_index(N, i, j);
        cov[k] = w.sum_dxdx[k] * inverse - mean_dx[i] * mean_dx[j];
      }
    for (int i = 0; i < N; ++i) finite = finite && math::is_finite(mean_dx[i]);
    for (int k = 0; k < packed; ++k) finite = finite && math::is_finite(cov[k]);
    if (!finite) {  // every particle left the finite numbers, or the weights did: a result, not a crash
      status(member) = Status::non_finite;
      ess(member) = 0.0;
      return;
    }
    for (int i = 0; i < N; ++i) {
      const double m = reference(member, i) + mean_dx[i];
      mean(member, i) = m;
      if (update_reference) reference(member, i) = m;
    }
    for (int k = 0; k < packed; ++k) covariance(member, k) = cov[k];
    ess(member) = w.sum_weight * w.sum_weight / w.sum_weight_sq;
    log_normalizer(member) = w.max_log_weight + math::log(w.sum_weight);
    if (ess(member) < resample_below) {
      resample(member) = 1;
      resample_count(member) += 1;
      if (resample_list.extent(0) > 0) resample_list(Kokkos::atomic_fetch_add(&resample_list_size(), 1)) = member;
    }
  }
};

template <int N, class MemSpace>
struct MonteCarloStandardError {
  BankSymmetric<MemSpace> covariance;
  BankScalar<double, MemSpace> ess;
  BankVector<MemSpace> se;
  KOKKOS_INLINE_FUNCTION void operator()(const int member) const {
    for (int i = 0; i < N; ++i)
      se(member, i) = ess(member) > 0.0 ? math::sqrt(covariance(member, packed_index(N, i, i)) / ess(member))
                                        : math::infinity() - math::infinity();  // NaN: member diverged
  }
};

}  // namespace kushner
