#pragma once
// Helpers for the statistical tests that compare the particle filter with exact and grid references: record
// one bank of observation increments, replay it into any estimator with step(k, dt, dy) and
// posterior_mean(), and summarize the differences.
#include "engine/truth_bank.hpp"

#include <Kokkos_Core.hpp>

#include <cmath>
#include <vector>

namespace kushner::test {

using Space = Kokkos::DefaultExecutionSpace;
using Mem = Space::memory_space;

/// dy of `steps` steps of a bank of truths (seed `seed`), one device view per step.
template <class Model>
std::vector<BankVector<Mem>> record_observations(const Model& model, int members, int steps, double dt,
                                                 std::uint32_t seed) {
  TruthBank<Space, Model> truth(Space(), model, members, seed);
  std::vector<BankVector<Mem>> dys;
  for (int k = 0; k < steps; ++k) {
    truth.step(k, dt);
    BankVector<Mem> dy("dy", members, Model::obs_dim);
    Kokkos::deep_copy(Space(), dy, truth.observations());
    dys.push_back(dy);
  }
  Space().fence();
  return dys;
}

/// Posterior means after every step: value(step, member, i).
struct Trajectory {
  int steps = 0, members = 0, dim = 0;
  std::vector<double> data;
  double operator()(int k, int m, int i) const { return data[(static_cast<std::size_t>(k) * members + m) * dim + i]; }
};

template <class Estimator>
Trajectory replay(Estimator& estimator, const std::vector<BankVector<Mem>>& dys, double dt) {
  Trajectory tr;
  tr.steps = static_cast<int>(dys.size());
  tr.members = dys.front().extent_int(0);
  tr.dim = estimator.posterior_mean().extent_int(1);
  for (int k = 0; k < tr.steps; ++k) {
    estimator.step(k, dt, dys[k]);
    const auto mean = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), estimator.posterior_mean());
    for (int m = 0; m < tr.members; ++m)
      for (int i = 0; i < tr.dim; ++i) tr.data.push_back(mean(m, i));
  }
  return tr;
}

/// Root mean square of a - b over steps, members and components.
inline double rms_distance(const Trajectory& a, const Trajectory& b) {
  double s = 0.0;
  for (std::size_t j = 0; j < a.data.size(); ++j) s += (a.data[j] - b.data[j]) * (a.data[j] - b.data[j]);
  return std::sqrt(s / a.data.size());
}

/// Mean over members of the time-averaged difference a - b in component i, and its standard error from the
/// spread over members (independent truths).
struct Bias {
  double mean, standard_error;
};
inline Bias member_bias(const Trajectory& a, const Trajectory& b, int i) {
  std::vector<double> d(a.members, 0.0);
  for (int m = 0; m < a.members; ++m) {
    for (int k = 0; k < a.steps; ++k) d[m] += a(k, m, i) - b(k, m, i);
    d[m] /= a.steps;
  }
  double mean = 0.0, var = 0.0;
  for (double v : d) mean += v / a.members;
  for (double v : d) var += (v - mean) * (v - mean) / (a.members - 1);
  return {mean, std::sqrt(var / a.members)};
}

/// Least-squares slope of log(y) against log(x).
inline double log_log_slope(const std::vector<double>& x, const std::vector<double>& y) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const double n = static_cast<double>(x.size());
  for (std::size_t j = 0; j < x.size(); ++j) {
    const double lx = std::log(x[j]), ly = std::log(y[j]);
    sx += lx, sy += ly, sxx += lx * lx, sxy += lx * ly;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

}  // namespace kushner::test
