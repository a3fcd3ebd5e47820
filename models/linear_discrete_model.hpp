#pragma once
// The Gaussian linear discrete-time model, state dimension 2:
//   x[k+1] = F x[k] + B u[k] + G e[k],   z[k+1] = H x[k+1] + R d[k+1],   e, d standard normal.
// The Kalman filter is its exact filter: the model on which the discrete filters are checked against an
// independent computation (tests/filters/test_discrete_filters.cpp). Default: a damped rotation F, G = 0.5 I,
// H = I, R = 0.5 I, x[0] ~ N(1, 0.1 I) for truths and prior alike; B = (0, 1).
#include "core/errors.hpp"
#include "core/linear_algebra.hpp"
#include "core/math.hpp"
#include "core/small_matrix.hpp"
#include "models/initial_law.hpp"

namespace kushner {

struct LinearDiscreteModel : InitialLaw<2> {
  static constexpr int N = 2;
  static constexpr int state_dim = N, obs_dim = N, noise_dim = N, control_dim = 1;
  static constexpr bool discrete_time = true;
  static constexpr bool linear_transition = true;
  static constexpr bool linear_observation = true;
  static constexpr const char* name = "linear-discrete";
  static constexpr const char* description =
      "Gaussian linear, discrete time: x[k+1] = F x + B u + G e, z = H x + R d (dim 2)";
  using Control = Vec<control_dim>;

  Mat<N, N> F{{{0.9, 0.2}, {-0.2, 0.9}}};
  Mat<N, N> G = Mat<N, N>::diagonal(0.5);
  Mat<N, N> H = Mat<N, N>::identity();
  Mat<N, N> R = Mat<N, N>::diagonal(0.5);
  Mat<N, 1> B{{{0.0}, {1.0}}};

  LinearDiscreteModel() { set_initial_law(Vec<N>::constant(1.0), Mat<N, N>::diagonal(0.1)); }

  template <class Visitor>
  void parameters(Visitor&& visit) {
    visit("F", F, "transition matrix");
    visit("G", G, "process noise matrix (Cov w = G G^T)");
    visit("H", H, "observation matrix");
    visit("R", R, "measurement noise matrix (Cov v = R R^T, positive definite)");
    visit("B", B, "control input matrix");
    initial_law_parameters(visit);
  }

  void validate() const {
    Mat<N, N> L;
    KUSHNER_INPUT_REQUIRE(cholesky(R * transpose(R), L), "R: R R^T must be positive definite");
  }

  KOKKOS_INLINE_FUNCTION Vec<N> transition(double, const Vec<N>& x, const Control& u) const { return F * x + B * u; }
  KOKKOS_INLINE_FUNCTION Mat<N, N> transition_jacobian(double, const Vec<N>&) const { return F; }
  KOKKOS_INLINE_FUNCTION Mat<N, 1> control_input(double) const { return B; }
  KOKKOS_INLINE_FUNCTION Vec<N> process_noise(const Vec<N>& normals, double) const { return G * normals; }
  KOKKOS_INLINE_FUNCTION Mat<N, N> process_noise_covariance(double) const { return G * transpose(G); }

  KOKKOS_INLINE_FUNCTION Vec<N> observation(double, const Vec<N>& x) const { return H * x; }
  KOKKOS_INLINE_FUNCTION Mat<N, N> observation_jacobian(double, const Vec<N>&) const { return H; }
  KOKKOS_INLINE_FUNCTION Mat<N, N> observation_noise(double) const { return R; }
  KOKKOS_INLINE_FUNCTION Vec<N> observation_noise_sample(const Vec<N>& normals, double) const { return R * normals; }
  KOKKOS_INLINE_FUNCTION double observation_log_density(const Vec<N>& r) const { return gaussian_log_density(R, r); }
  KOKKOS_INLINE_FUNCTION double observation_max_log_density() const { return observation_log_density(Vec<N>::zero()); }
};

}  // namespace kushner
