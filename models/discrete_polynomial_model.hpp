#pragma once
// A discrete-time polynomial model defined at run time (`--model-file FILE` with `time = "discrete"`,
// drivers/model_file.hpp), state dimension N = 1..3:
//   x[k+1] = F(x[k]) + B u[k] + G e[k],   z[k] = h(x[k]) + R d[k],   e, d standard normal,
// F of degree <= 4 and h of degree <= 3. F is PolynomialModel's drift polynomial and G its diffusion matrix b:
// the coefficients, their monomial order, values and derivatives are PolynomialModel's (one piece of code for
// both times); this type only names them as a discrete-time model does (models/clark_noises.hpp lists what
// the discrete filters and references ask of one). Gaussian noises only: Clark's bounded laws are built-in
// models' (clark-linear, clark-quintic).
#include "core/linear_algebra.hpp"
#include "models/polynomial_model.hpp"

namespace kushner {

template <int N>
struct DiscretePolynomialModel : PolynomialModel<N> {
  static constexpr bool discrete_time = true;
  static constexpr const char* name = "polynomial-discrete";
  static constexpr const char* description =
      "discrete-time polynomial model from a file (--model-file, time = \"discrete\"): x[k+1] = F(x) + B u + G e, "
      "F of degree <= 4, z = h(x) + R d, h of degree <= 3";
  using Control = typename PolynomialModel<N>::Control;

  KOKKOS_INLINE_FUNCTION Vec<N> transition(double k, const Vec<N>& x, const Control& u) const {
    return this->drift(k, x, u);
  }
  KOKKOS_INLINE_FUNCTION Mat<N, N> transition_jacobian(double k, const Vec<N>& x) const {
    return this->drift_jacobian(k, x, Control::zero());
  }
  KOKKOS_INLINE_FUNCTION Vec<N> process_noise(const Vec<N>& normals, double) const { return this->b * normals; }
  KOKKOS_INLINE_FUNCTION Mat<N, N> process_noise_covariance(double) const { return this->b * transpose(this->b); }

  KOKKOS_INLINE_FUNCTION Vec<N> observation_noise_sample(const Vec<N>& normals, double) const {
    return this->R * normals;
  }
  KOKKOS_INLINE_FUNCTION double observation_log_density(const Vec<N>& r) const {
    return gaussian_log_density(this->R, r);
  }
  KOKKOS_INLINE_FUNCTION double observation_max_log_density() const { return observation_log_density(Vec<N>::zero()); }
};

template <int N>
struct is_polynomial_model<DiscretePolynomialModel<N>> : std::true_type {};

}  // namespace kushner
