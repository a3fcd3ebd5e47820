#pragma once
// Time-varying affine feedback u_k = -(K_k m + k_k) applied to an estimate m: the form every gain law of the
// closed loop takes (LQR, ASRE, POLY3: the gains are computed on the host, engine/control/, and shared by all
// members; only the estimate differs). Step k uses the gains of time k dt.
#include "core/small_matrix.hpp"
#include "kernels/bank.hpp"

#include <Kokkos_Core.hpp>

#include <vector>

namespace kushner {

/// The host's gains: K[k] (M x N) and k[k] (M) for k = 0, ..., steps (the last is never applied).
template <int N, int M>
struct GainSchedule {
  std::vector<Mat<M, N>> K;
  std::vector<Vec<M>> k;

  long size() const { return static_cast<long>(K.size()); }
};

/// The same gains on the device: (step, column), columns K row-major then k.
template <int N, int M, class MemSpace>
struct AffineFeedback {
  static constexpr int columns = M * N + M;
  Kokkos::View<double**, Kokkos::LayoutRight, MemSpace> gains;

  KOKKOS_INLINE_FUNCTION Vec<M> operator()(long step, const Vec<N>& m) const {
    Vec<M> u;
    for (int i = 0; i < M; ++i) {
      double s = gains(step, M * N + i);
      for (int j = 0; j < N; ++j) s += gains(step, i * N + j) * m[j];
      u[i] = -s;
    }
    return u;
  }
};

template <int N, int M, class MemSpace>
AffineFeedback<N, M, MemSpace> to_device(const GainSchedule<N, M>& schedule) {
  using F = AffineFeedback<N, M, MemSpace>;
  Kokkos::View<double**, Kokkos::LayoutRight, MemSpace> gains("kushner::gains", schedule.size(), F::columns);
  const auto h = Kokkos::create_mirror_view(gains);
  for (long s = 0; s < schedule.size(); ++s) {
    for (int i = 0; i < M; ++i) {
      for (int j = 0; j < N; ++j) h(s, i * N + j) = schedule.K[s](i, j);
      h(s, M * N + i) = schedule.k[s][i];
    }
  }
  Kokkos::deep_copy(gains, h);
  return F{gains};
}

}  // namespace kushner
