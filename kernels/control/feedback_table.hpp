#pragma once
// A feedback law given as a table u*(t, x) on a box grid (the HJB solver's output,
// engine/control/hjb_markov_chain.hpp): device-callable, applied to an estimate like any law of the closed loop
// (`HJB@state` on the true state). Rows are times r * row_dt, r = 0, ..., rows - 1; nodes are the grid points lower + i
// h, index i_0 slowest (row-major). The law interpolates linearly in time between rows and multilinearly in x between
// nodes; x outside the box is clamped to it, t beyond the last row uses the last row. step is the closed loop's step: t
// = step * loop_dt.
#include "core/small_matrix.hpp"

#include <Kokkos_Core.hpp>

#include <vector>

namespace kushner {

/// The host's table: values[(row * nodes + node) * M + i].
template <int N, int M>
struct FeedbackTable {
  double lower[N] = {}, spacing[N] = {};
  int points[N] = {};
  long rows = 0;
  double row_dt = 0.0;
  std::vector<double> values;

  long nodes() const {
    long n = 1;
    for (int d = 0; d < N; ++d) n *= points[d];
    return n;
  }
};

template <int N, int M, class MemSpace>
struct TabulatedFeedback {
  Kokkos::View<double**, Kokkos::LayoutRight, MemSpace> table;  // (row, node * M + i)
  double lower[N], spacing[N];
  int points[N];
  long rows;
  double rows_per_step;  // loop_dt / row_dt

  KOKKOS_INLINE_FUNCTION Vec<M> operator()(long step, const Vec<N>& x) const {
    double r = step * rows_per_step;
    if (r < 0.0) r = 0.0;
    if (r > rows - 1) r = rows - 1;
    long r0 = static_cast<long>(r);
    if (r0 > rows - 2) r0 = rows > 1 ? rows - 2 : 0;
    const double wr = rows > 1 ? r - r0 : 0.0;
    // The cell and the weights in each dimension, clamped to the box.
    int base[N];
    double w[N];
    for (int d = 0; d < N; ++d) {
      double s = (x[d] - lower[d]) / spacing[d];
      if (s < 0.0) s = 0.0;
      if (s > points[d] - 1) s = points[d] - 1;
      int i = static_cast<int>(s);
      if (i > points[d] - 2) i = points[d] - 2;
      base[d] = i;
      w[d] = s - i;
    }
    Vec<M> u = Vec<M>::zero();
    for (int corner = 0; corner < (1 << N); ++corner) {
      double weight = 1.0;
      long node = 0;
      for (int d = 0; d < N; ++d) {
        const int bit = (corner >> d) & 1;
        weight *= bit ? w[d] : 1.0 - w[d];
        node = node * points[d] + base[d] + bit;
      }
      if (weight == 0.0) continue;
      for (int i = 0; i < M; ++i) {
        const double a = table(r0, node * M + i);
        const double b = rows > 1 ? table(r0 + 1, node * M + i) : a;
        u[i] += weight * ((1.0 - wr) * a + wr * b);
      }
    }
    return u;
  }
};

/// The table on the device for a closed loop of step loop_dt.
template <class MemSpace, int N, int M>
TabulatedFeedback<N, M, MemSpace> to_device(const FeedbackTable<N, M>& host, double loop_dt) {
  TabulatedFeedback<N, M, MemSpace> f;
  const long columns = host.nodes() * M;
  f.table = Kokkos::View<double**, Kokkos::LayoutRight, MemSpace>("kushner::feedback_table", host.rows, columns);
  const auto h = Kokkos::create_mirror_view(f.table);
  for (long r = 0; r < host.rows; ++r)
    for (long c = 0; c < columns; ++c) h(r, c) = host.values[r * columns + c];
  Kokkos::deep_copy(f.table, h);
  for (int d = 0; d < N; ++d) {
    f.lower[d] = host.lower[d];
    f.spacing[d] = host.spacing[d];
    f.points[d] = host.points[d];
  }
  f.rows = host.rows;
  f.rows_per_step = loop_dt / host.row_dt;
  return f;
}

}  // namespace kushner
