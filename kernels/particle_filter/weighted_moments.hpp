#pragma once
// Weighted sums over a set of particles, kept relative to the largest log-weight of the set so that exp()
// never overflows (the streaming log-sum-exp of Milakov & Gimelshein 2018, "Online normalizer calculation
// for softmax"). Two sets merge exactly; merging block partials in a fixed order gives the same bits on any
// number of threads. Positions are kept relative to a reference point (the previous posterior mean), so the
// covariance does not lose digits when the mean is large compared to the spread.
#include "core/math.hpp"
#include "kernels/bank.hpp"

#include <Kokkos_Core.hpp>

namespace kushner {

template <int N>
struct WeightedMoments {
  static constexpr int packed = packed_size(N);  // entries of a packed N x N symmetric matrix
  static constexpr int size = 3 + N + packed;    // doubles in a stored partial

  double max_log_weight;  // m: the largest log-weight of the set, or any shift near it (the GPU team kernel
                          // uses one per member and step); -inf for an empty set (or one whose weights are all zero)
  double sum_weight;      // sum e^{l - m}
  double sum_weight_sq;   // sum e^{2 (l - m)}
  Vec<N> sum_dx;          // sum e^{l - m} (x - ref)
  Vec<packed> sum_dxdx;   // sum e^{l - m} (x - ref)(x - ref)^T, packed upper triangle

  KOKKOS_INLINE_FUNCTION static WeightedMoments empty() {
    WeightedMoments w;
    w.max_log_weight = -math::infinity();
    w.sum_weight = w.sum_weight_sq = 0.0;
    w.sum_dx = Vec<N>::zero();
    w.sum_dxdx = Vec<packed>::zero();
    return w;
  }

  /// Adds one particle with log-weight l at offset dx from the reference; l = -inf adds nothing.
  KOKKOS_INLINE_FUNCTION void add(double l, const Vec<N>& dx) {
    if (!(l > max_log_weight)) {
      if (!(l > -math::infinity())) return;
      accumulate(math::exp(l - max_log_weight), dx);
      return;
    }
    scale(math::exp(max_log_weight - l));  // exp(-inf) = 0 when the set was empty
    max_log_weight = l;
    accumulate(1.0, dx);
  }

  /// This set followed by `other`; the order matters in the last bits only.
  KOKKOS_INLINE_FUNCTION void merge(const WeightedMoments& other) {
    if (!(other.max_log_weight > -math::infinity())) return;
    if (other.max_log_weight == max_log_weight) {  // the GPU's blocks share one shift: no exp (exp(0) = 1 exactly)
      add_scaled(other, 1.0);
    } else if (other.max_log_weight > max_log_weight) {
      scale(math::exp(max_log_weight - other.max_log_weight));
      max_log_weight = other.max_log_weight;
      add_scaled(other, 1.0);
    } else {
      add_scaled(other, math::exp(other.max_log_weight - max_log_weight));
    }
  }

  /// Adds one particle of weight e = exp(l - max_log_weight) > 0 (the caller took the exp with a fixed shift).
  KOKKOS_INLINE_FUNCTION void add_weight(double e, const Vec<N>& dx) { accumulate(e, dx); }

  KOKKOS_INLINE_FUNCTION void store(double* out) const {
    out[0] = max_log_weight;
    out[1] = sum_weight;
    out[2] = sum_weight_sq;
    for (int i = 0; i < N; ++i) out[3 + i] = sum_dx[i];
    for (int k = 0; k < packed; ++k) out[3 + N + k] = sum_dxdx[k];
  }
  KOKKOS_INLINE_FUNCTION static WeightedMoments load(const double* in) {
    WeightedMoments w;
    w.max_log_weight = in[0];
    w.sum_weight = in[1];
    w.sum_weight_sq = in[2];
    for (int i = 0; i < N; ++i) w.sum_dx[i] = in[3 + i];
    for (int k = 0; k < packed; ++k) w.sum_dxdx[k] = in[3 + N + k];
    return w;
  }
  template <class View>
  KOKKOS_INLINE_FUNCTION void store(const View& partials, int block, int member) const {
    partials(block, member, 0) = max_log_weight;
    partials(block, member, 1) = sum_weight;
    partials(block, member, 2) = sum_weight_sq;
    for (int i = 0; i < N; ++i) partials(block, member, 3 + i) = sum_dx[i];
    for (int k = 0; k < packed; ++k) partials(block, member, 3 + N + k) = sum_dxdx[k];
  }
  template <class View>
  KOKKOS_INLINE_FUNCTION static WeightedMoments load(const View& partials, int block, int member) {
    WeightedMoments w;
    w.max_log_weight = partials(block, member, 0);
    w.sum_weight = partials(block, member, 1);
    w.sum_weight_sq = partials(block, member, 2);
    for (int i = 0; i < N; ++i) w.sum_dx[i] = partials(block, member, 3 + i);
    for (int k = 0; k < packed; ++k) w.sum_dxdx[k] = partials(block, member, 3 + N + k);
    return w;
  }

 private:
  KOKKOS_INLINE_FUNCTION void accumulate(double e, const Vec<N>& dx) {
    sum_weight += e;
    sum_weight_sq += e * e;
    for (int i = 0; i < N; ++i) {
      sum_dx[i] += e * dx[i];
      for (int j = i; j < N; ++j) sum_dxdx[packed_index(N, i, j)] += e * dx[i] * dx[j];
    }
  }
  KOKKOS_INLINE_FUNCTION void scale(double f) {
    sum_weight *= f;
    sum_weight_sq *= f * f;
    for (int i = 0; i < N; ++i) sum_dx[i] *= f;
    for (int k = 0; k < packed; ++k) sum_dxdx[k] *= f;
  }
  KOKKOS_INLINE_FUNCTION void add_scaled(const WeightedMoments& o, double f) {
    sum_weight += f * o.sum_weight;
    sum_weight_sq += f * f * o.sum_weight_sq;
    for (int i = 0; i < N; ++i) sum_dx[i] += f * o.sum_dx[i];
    for (int k = 0; k < packed; ++k) sum_dxdx[k] += f * o.sum_dxdx[k];
  }
};

}  // namespace kushner
