#pragma once
// General linear model, state dimension N (1 to 3 on the command line, `--set dim=N`):
//   dx = (a0 + A x) dt + b dw,   dy = (c0 + C x) dt + R dv,   w, v standard N-dimensional Brownian motions.
// Default: a damped rotation A = -0.5 I + J (J: +1 above, -1 below the diagonal), b = 0.5 I, C = I,
// R = 0.5 I, a0 = c0 = 0, x(0) ~ N(1, 0.1 I) for truths and prior alike. All matrices are settable.
// The observation has the state's dimension; a partial observation is a row of C set to zero. Controlled
// (`kushner control`): dx = (a0 + A x + B u) dt + b dw with one input, B = (0, ..., 0, 1) by default.
#include "core/small_matrix.hpp"
#include "models/drift_forms.hpp"
#include "models/initial_law.hpp"

namespace kushner {

template <int N>
struct LinearModel : InitialLaw<N> {
  static constexpr int state_dim = N, obs_dim = N, noise_dim = N, control_dim = 1;
  static constexpr bool discrete_time = false;
  static constexpr bool time_invariant = true;  // f, G, h, R: no function of t
  static constexpr const char* name = "linear";
  static constexpr const char* description = "linear: dx = (a0 + A x) dt + b dw, dy = (c0 + C x) dt + R dv (dim 1..3)";
  using Control = Vec<control_dim>;

  Vec<N> a0 = Vec<N>::zero();
  Mat<N, N> A = default_drift_matrix();
  Mat<N, N> b = Mat<N, N>::diagonal(0.5);
  Vec<N> c0 = Vec<N>::zero();
  Mat<N, N> C = Mat<N, N>::identity();
  Mat<N, N> R = Mat<N, N>::diagonal(0.5);
  Mat<N, 1> B = default_control_input();

  LinearModel() { this->set_initial_law(Vec<N>::constant(1.0), Mat<N, N>::diagonal(0.1)); }

  static Mat<N, N> default_drift_matrix() {
    Mat<N, N> a = Mat<N, N>::diagonal(-0.5);
    for (int i = 0; i + 1 < N; ++i) {
      a(i, i + 1) = 1.0;
      a(i + 1, i) = -1.0;
    }
    return a;
  }

  static Mat<N, 1> default_control_input() {
    Mat<N, 1> b = Mat<N, 1>::zero();
    b(N - 1, 0) = 1.0;
    return b;
  }

  template <class Visitor>
  void parameters(Visitor&& v) {
    v("a0", a0, "constant drift term");
    v("A", A, "drift matrix");
    v("b", b, "diffusion matrix (process noise intensity)");
    v("c0", c0, "constant observation term");
    v("C", C, "observation matrix");
    v("R", R, "observation noise intensity");
    v("B", B, "control input matrix (kushner control)");
    this->initial_law_parameters(v);
  }

  // Templates on the scalar: the particle filter's fp32 steps its particles in float (particle_model_traits.hpp).
  template <class T>
  KOKKOS_INLINE_FUNCTION Vec<N, T> drift(double, const Vec<N, T>& x, const Control& u) const {
    return convert<T>(a0) + convert<T>(A) * x + convert<T>(B * u);
  }
  KOKKOS_INLINE_FUNCTION Mat<N, 1> control_input(double) const { return B; }
  KOKKOS_INLINE_FUNCTION Mat<N, N> drift_jacobian(double, const Vec<N>&, const Control&) const { return A; }
  KOKKOS_INLINE_FUNCTION Mat<N, N> drift_hessian(double, const Vec<N>&, const Control&, int) const {
    return Mat<N, N>::zero();
  }
  template <class T>
  KOKKOS_INLINE_FUNCTION Mat<N, N, T> diffusion(double, const Vec<N, T>&) const {
    return convert<T>(b);
  }
  template <class T>
  KOKKOS_INLINE_FUNCTION Vec<N, T> observation(double, const Vec<N, T>& x) const {
    return convert<T>(c0) + convert<T>(C) * x;
  }
  KOKKOS_INLINE_FUNCTION Mat<N, N> observation_jacobian(double, const Vec<N>&) const { return C; }
  KOKKOS_INLINE_FUNCTION Mat<N, N> observation_hessian(double, const Vec<N>&, int) const { return Mat<N, N>::zero(); }
  KOKKOS_INLINE_FUNCTION Mat<N, N> observation_noise(double) const { return R; }

  /// The coefficients the Kalman-Bucy filter reads.
  KOKKOS_INLINE_FUNCTION LinearForm<N, N> linear_form(double) const { return {a0, A, c0, C}; }
};

}  // namespace kushner
