#pragma once
// A polynomial model defined at run time (`--model-file FILE`, drivers/model_file.hpp), state dimension N = 1..3:
//   dx = (f(x) + B u) dt + b dw,   dy = h(x) dt + R dv,
//   f_k(x) = a0_k + sum_i a1_ki x_i + sum over the monomials x^alpha of degree 2..4 of c_k,alpha x^alpha,
//   h_k(x) = c0_k + sum_i C_ki x_i + sum over the monomials x^alpha of degree 2..3 of d_k,alpha x^alpha.
// The monomials are stored once each (x1 x2 is one term, not a2_k12 and a2_k21), in a fixed order: by degree,
// then lexicographically in their sorted variable indices (polynomial_monomial). Every sum is taken in that order,
// so a file equal to a built-in model gives the built-in's numbers wherever the formulas are the same. A file
// with no terms of degree >= 2 in h (`observation_degree` <= 1) skips them at run time: the linear observation
// costs what it did before h could be a polynomial, and gives the same bits. One control input, B = 0 unless the
// file has a [control] table (`kushner control` refuses a model with B = 0).
// The file's observation may have p <= N rows and its diffusion q <= N columns: the model runs with N of each,
// the extra observation rows zero with unit noise (channels that carry no information: the posterior is the
// same) and the extra diffusion columns zero (the same G G^T, and the first q noise draws are the ones a
// q-column model takes). Which filters apply depends on the coefficients, so the model says why a filter
// cannot run (from `model_facts()`, checked when filters are selected) instead of the compile-time traits.
#include "core/small_matrix.hpp"
#include "models/drift_forms.hpp"
#include "models/initial_law.hpp"
#include "models/model_facts.hpp"
#include "models/polynomial_monomials.hpp"

#include <type_traits>
#include <utility>

namespace kushner {

namespace detail {

/// f(std::integral_constant<int, 0>{}), ..., f(std::integral_constant<int, Count - 1>{}), in order: the monomial
/// loops are unrolled at compile time, so every index is a constant (registers on a GPU, SIMD on the host).
template <class F, int... I>
KOKKOS_FORCEINLINE_FUNCTION void static_for(F&& f, std::integer_sequence<int, I...>) {
  (f(std::integral_constant<int, I>{}), ...);
}
template <int Count, class F>
KOKKOS_FORCEINLINE_FUNCTION void static_for(F&& f) {
  static_for(f, std::make_integer_sequence<int, Count>{});
}

/// Number of monomials of degree 2..Degree in N variables (the first ones in polynomial_monomial order).
template <int N, int Degree>
inline constexpr int monomial_count = polynomial_monomial_count(N, Degree);

/// start times the variables of monomial T, leaving out positions S1 and S2, multiplied in left to right.
template <int N, int T, int S1 = -1, int S2 = -1>
KOKKOS_FORCEINLINE_FUNCTION double monomial_product(const Vec<N>& x, double start = 1.0) {
  constexpr Monomial m = polynomial_monomial(N, T);
  double v = start;
  if constexpr (0 < m.degree && S1 != 0 && S2 != 0) v *= x[m.var[0]];
  if constexpr (1 < m.degree && S1 != 1 && S2 != 1) v *= x[m.var[1]];
  if constexpr (2 < m.degree && S1 != 2 && S2 != 2) v *= x[m.var[2]];
  if constexpr (3 < m.degree && S1 != 3 && S2 != 3) v *= x[m.var[3]];
  return v;
}

/// How often variable var[P] occurs in monomial T, and whether position P is its first occurrence.
template <int N, int T, int P>
KOKKOS_INLINE_FUNCTION constexpr int monomial_multiplicity() {
  constexpr Monomial m = polynomial_monomial(N, T);
  int count = 0;
  for (int p = 0; p < m.degree; ++p) count += m.var[p] == m.var[P] ? 1 : 0;
  return count;
}
template <int N, int T, int P>
KOKKOS_INLINE_FUNCTION constexpr bool first_occurrence() {
  constexpr Monomial m = polynomial_monomial(N, T);
  return P < m.degree && (P == 0 || m.var[P] != m.var[P - 1]);
}

/// Whether positions P < Q of monomial T stand for a pair of its variables {var[P], var[Q]} counted once:
/// var[P] at its first occurrence, var[Q] at a different variable's first occurrence or var[P]'s second.
template <int N, int T, int P, int Q>
KOKKOS_INLINE_FUNCTION constexpr bool hessian_pair() {
  constexpr Monomial m = polynomial_monomial(N, T);
  return first_occurrence<N, T, P>() && P < Q && Q < m.degree &&
         (first_occurrence<N, T, Q>() || (Q == P + 1 && m.var[Q] == m.var[P]));
}
/// d^2 x^alpha / d x_u d x_w over the product of the remaining variables: m_u (m_u - 1) or m_u m_w.
template <int N, int T, int P, int Q>
KOKKOS_INLINE_FUNCTION constexpr double hessian_factor() {
  constexpr Monomial m = polynomial_monomial(N, T);
  constexpr int mp = monomial_multiplicity<N, T, P>(), mq = monomial_multiplicity<N, T, Q>();
  return m.var[P] == m.var[Q] ? mp * (mp - 1) : mp * mq;
}

/// E[x_v[0] ... x_v[d-1]] for x ~ N(m, P), d = 0..4 (Isserlis: sum over the pairings).
template <int N>
KOKKOS_INLINE_FUNCTION double gaussian_monomial_moment(int d, const int* v, const Vec<N>& m, const Mat<N, N>& P) {
  if (d == 0) return 1.0;
  if (d == 1) return m[v[0]];
  const int a = v[0], b = v[1];
  if (d == 2) return m[a] * m[b] + P(a, b);
  const int c = v[2];
  if (d == 3) return m[a] * m[b] * m[c] + m[a] * P(b, c) + m[b] * P(a, c) + m[c] * P(a, b);
  const int e = v[3];
  return m[a] * m[b] * m[c] * m[e] + m[a] * m[b] * P(c, e) + m[a] * m[c] * P(b, e) + m[a] * m[e] * P(b, c) +
         m[b] * m[c] * P(a, e) + m[b] * m[e] * P(a, c) + m[c] * m[e] * P(a, b) + P(a, b) * P(c, e) + P(a, c) * P(b, e) +
         P(a, e) * P(b, c);
}

}  // namespace detail

/// Host-side record of where a model came from (file path, the file's name and description); never read
/// in kernels.
struct PolynomialModelSource {
  const char* path = "";
  const char* label = "";
  const char* description = "";
};

template <int N>
struct PolynomialModel : InitialLaw<N> {
  static_assert(N >= 1 && N <= 3, "PolynomialModel: state dimension 1, 2 or 3");
  static constexpr int state_dim = N, obs_dim = N, noise_dim = N, control_dim = 1;
  static constexpr bool discrete_time = false;
  static constexpr bool time_invariant = true;  // f, G, h, R: no function of t
  static constexpr bool linear_observation = true;
  static constexpr const char* name = "polynomial";
  static constexpr const char* description =
      "polynomial model from a file (--model-file): dx = (f(x) + B u) dt + b dw, f of degree <= 4, "
      "dy = h(x) dt + R dv, h of degree <= 3";
  static constexpr int num_monomials = detail::monomial_count<N, 4>;
  static constexpr int num_observation_monomials = detail::monomial_count<N, 3>;
  using Control = Vec<control_dim>;

  Vec<N> a0 = Vec<N>::zero();
  Mat<N, N> a1 = Mat<N, N>::zero();
  double coefficient[N][num_monomials] = {};  // (component k, monomial t), polynomial_monomial order
  Mat<N, N> b = Mat<N, N>::zero();            // diffusion; columns q.. zero
  Vec<N> c0 = Vec<N>::zero();                 // rows p.. zero
  Mat<N, N> C = Mat<N, N>::zero();            // rows p.. zero
  double observation_coefficient[N][num_observation_monomials] = {};  // (row k, monomial t); rows p.. zero
  int observation_degree = 1;           // observed_degree(), set with the coefficients: <= 1 skips the terms
  Mat<N, N> R = Mat<N, N>::identity();  // p x p block, identity below
  Mat<N, 1> B = Mat<N, 1>::zero();      // control input; zero: the file has no [control]
  int obs_rows = N, noise_columns = N;  // the file's p and q
  const PolynomialModelSource* source = nullptr;

  template <class Visitor>
  void parameters(Visitor&& v) {
    this->initial_law_parameters(v);
  }

  KOKKOS_INLINE_FUNCTION Vec<N> drift(double, const Vec<N>& x, const Control& u) const {
    Vec<N> f = a0 + a1 * x;
    add_values<num_monomials>(coefficient, x, f);
    return f + B * u;
  }
  KOKKOS_INLINE_FUNCTION Mat<N, 1> control_input(double) const { return B; }

  /// d f_k / d x_u: a1 plus, per monomial and variable u in it, (c * multiplicity) times the other variables.
  KOKKOS_INLINE_FUNCTION Mat<N, N> drift_jacobian(double, const Vec<N>& x, const Control&) const {
    Mat<N, N> J = a1;
    detail::static_for<num_monomials>([&](auto t) { add_jacobian_terms<decltype(t)::value>(coefficient, x, J); });
    return J;
  }

  /// Hessian of f_k: per monomial and pair of its variables {u, w}, c * (multiplicities) times the others.
  KOKKOS_INLINE_FUNCTION Mat<N, N> drift_hessian(double, const Vec<N>& x, const Control&, int k) const {
    Mat<N, N> H = Mat<N, N>::zero();
    detail::static_for<num_monomials>([&](auto t) { add_hessian_terms<decltype(t)::value>(coefficient, x, k, H); });
    return H;
  }

  KOKKOS_INLINE_FUNCTION Mat<N, N> diffusion(double, const Vec<N>&) const { return b; }
  /// The columns of b that are the file's (q): a truth draws normals for these only (kernels/simulate_truth.hpp's
  /// truth_normal_count), so that the file draws the numbers of the built-in model it writes out.
  KOKKOS_INLINE_FUNCTION int process_noise_columns() const { return noise_columns; }
  KOKKOS_INLINE_FUNCTION Mat<N, N> observation_noise(double) const { return R; }

  // ---- the observation h, its derivatives and forms: the drift's formulas on the observation's coefficients --
  KOKKOS_INLINE_FUNCTION Vec<N> observation(double, const Vec<N>& x) const {
    Vec<N> h = c0 + C * x;
    if (observation_degree > 1) add_values<num_observation_monomials>(observation_coefficient, x, h);
    return h;
  }
  KOKKOS_INLINE_FUNCTION Mat<N, N> observation_jacobian(double, const Vec<N>& x) const {
    Mat<N, N> J = C;
    if (observation_degree > 1)
      detail::static_for<num_observation_monomials>(
          [&](auto t) { add_jacobian_terms<decltype(t)::value>(observation_coefficient, x, J); });
    return J;
  }
  KOKKOS_INLINE_FUNCTION Mat<N, N> observation_hessian(double, const Vec<N>& x, int k) const {
    Mat<N, N> H = Mat<N, N>::zero();
    if (observation_degree > 1)
      detail::static_for<num_observation_monomials>(
          [&](auto t) { add_hessian_terms<decltype(t)::value>(observation_coefficient, x, k, H); });
    return H;
  }
  /// E_N[h], E_N[grad h] for x ~ N(m, P), exactly (QLF; seed 000 (5.9)-(5.10)).
  KOKKOS_INLINE_FUNCTION GaussianObservation<N, N> gaussian_observation(double, const Vec<N>& m,
                                                                        const Mat<N, N>& P) const {
    GaussianDrift<N> g{c0 + C * m, C};
    if (observation_degree > 1)
      detail::static_for<num_observation_monomials>(
          [&](auto t) { add_gaussian_terms<decltype(t)::value>(observation_coefficient, m, P, g); });
    return {g.mean, g.jacobian};
  }
  /// h = C(x) x + c0, each monomial factored at its first variable as in sdc_drift (ASRE, seed 001 (5)).
  KOKKOS_INLINE_FUNCTION SdcObservation<N, N> sdc_observation(double, const Vec<N>& x) const {
    SdcDrift<N> s{C, c0};
    if (observation_degree > 1)
      detail::static_for<num_observation_monomials>(
          [&](auto t) { add_factored_terms<decltype(t)::value>(observation_coefficient, x, s); });
    return {s.A, s.b};
  }

  /// E_N[f], E_N[grad f] for x ~ N(m, P), exactly (Isserlis; d x^alpha / d x_u has the moment of degree - 1).
  KOKKOS_INLINE_FUNCTION GaussianDrift<N> gaussian_drift(double, const Vec<N>& m, const Mat<N, N>& P) const {
    GaussianDrift<N> g{a0 + a1 * m, a1};
    detail::static_for<num_monomials>([&](auto t) { add_gaussian_terms<decltype(t)::value>(coefficient, m, P, g); });
    return g;
  }

  /// The componentwise-power part a0 + a1 x + sum_k a_k x^k (POLY3, POLY4): the whole drift when the model
  /// has no cross terms of degree >= 2, which the filters check in model_facts() before they run.
  KOKKOS_INLINE_FUNCTION PowerPolynomial<N, 4> drift_power_polynomial(double) const {
    auto poly = PowerPolynomial<N, 4>::zero();
    poly.a0 = a0;
    poly.coefficient[1] = a1;
    detail::static_for<num_monomials>([&](auto t) {
      constexpr int T = decltype(t)::value;
      constexpr Monomial mono = polynomial_monomial(N, T);
      if constexpr (mono.var[0] == mono.var[mono.degree - 1])
        for (int k = 0; k < N; ++k) poly.coefficient[mono.degree](k, mono.var[0]) = coefficient[k][T];
    });
    return poly;
  }

  static constexpr int num_quadratic_terms = N * N * (N + 1) / 2;
  /// The part of degree <= 2 (BILIN): the whole drift when the degree is at most 2 (model_facts).
  KOKKOS_INLINE_FUNCTION QuadraticPolynomial<N, num_quadratic_terms> drift_quadratic_polynomial(double) const {
    QuadraticPolynomial<N, num_quadratic_terms> poly;
    poly.a0 = a0;
    poly.a1 = a1;
    detail::static_for<num_monomials>([&](auto t) {
      constexpr int T = decltype(t)::value;
      constexpr Monomial mono = polynomial_monomial(N, T);
      if constexpr (mono.degree == 2)
        for (int k = 0; k < N; ++k) poly.add(k, mono.var[0], mono.var[1], coefficient[k][T]);
    });
    return poly;
  }

  /// f = A(x) x + a0 with every monomial factored at its first (lowest-index) variable:
  /// A_k,var[0](x) += c * (the product of the other variables) (the ASRE factorization; not unique).
  KOKKOS_INLINE_FUNCTION SdcDrift<N> sdc_drift(double, const Vec<N>& x) const {
    SdcDrift<N> s{a1, a0};
    detail::static_for<num_monomials>([&](auto t) { add_factored_terms<decltype(t)::value>(coefficient, x, s); });
    return s;
  }

  /// The linear part (Kalman-Bucy): the whole model when the drift and the observation have degree <= 1
  /// (model_facts).
  KOKKOS_INLINE_FUNCTION LinearForm<N, N> linear_form(double) const { return {a0, a1, c0, C}; }

  // ---- one monomial's terms, for the drift's coefficients (Terms = num_monomials) or the observation's
  // (num_observation_monomials); member templates, so that nested compile-time loops see only template
  // parameters: nvcc does not take a constexpr local of an enclosing lambda as a constant -----------------------
  template <int Terms>
  KOKKOS_INLINE_FUNCTION static void add_values(const double (&c)[N][Terms], const Vec<N>& x, Vec<N>& f) {
    detail::static_for<Terms>([&](auto t) {
      constexpr int T = decltype(t)::value;
      const double v = detail::monomial_product<N, T>(x);
      for (int k = 0; k < N; ++k) f[k] += c[k][T] * v;
    });
  }

  template <int T, int Terms>
  KOKKOS_INLINE_FUNCTION static void add_factored_terms(const double (&c)[N][Terms], const Vec<N>& x, SdcDrift<N>& s) {
    constexpr Monomial mono = polynomial_monomial(N, T);
    const double rest = detail::monomial_product<N, T, 0>(x);
    for (int k = 0; k < N; ++k) s.A(k, mono.var[0]) += c[k][T] * rest;
  }

  template <int T, int Terms>
  KOKKOS_INLINE_FUNCTION static void add_jacobian_terms(const double (&coefficient)[N][Terms], const Vec<N>& x,
                                                        Mat<N, N>& J) {
    detail::static_for<4>([&](auto position) {
      constexpr int p = decltype(position)::value;
      if constexpr (detail::first_occurrence<N, T, p>()) {
        constexpr Monomial m = polynomial_monomial(N, T);
        constexpr double multiplicity = detail::monomial_multiplicity<N, T, p>();
        for (int k = 0; k < N; ++k)
          J(k, m.var[p]) += detail::monomial_product<N, T, p>(x, coefficient[k][T] * multiplicity);
      }
    });
  }

  template <int T, int Terms>
  KOKKOS_INLINE_FUNCTION static void add_hessian_terms(const double (&coefficient)[N][Terms], const Vec<N>& x, int k,
                                                       Mat<N, N>& H) {
    detail::static_for<16>([&](auto pair) {
      constexpr int p = decltype(pair)::value / 4, q = decltype(pair)::value % 4;
      if constexpr (detail::hessian_pair<N, T, p, q>()) {
        constexpr Monomial m = polynomial_monomial(N, T);
        constexpr double factor = detail::hessian_factor<N, T, p, q>();
        const double value = detail::monomial_product<N, T, p, q>(x, coefficient[k][T] * factor);
        H(m.var[p], m.var[q]) += value;
        if constexpr (m.var[p] != m.var[q]) H(m.var[q], m.var[p]) += value;
      }
    });
  }

  template <int T, int Terms>
  KOKKOS_INLINE_FUNCTION static void add_gaussian_terms(const double (&coefficient)[N][Terms], const Vec<N>& mean,
                                                        const Mat<N, N>& P, GaussianDrift<N>& g) {
    constexpr Monomial m = polynomial_monomial(N, T);
    const double moment = detail::gaussian_monomial_moment<N>(m.degree, m.var, mean, P);
    for (int k = 0; k < N; ++k) g.mean[k] += coefficient[k][T] * moment;
    detail::static_for<4>([&](auto position) {
      constexpr int p = decltype(position)::value;
      if constexpr (detail::first_occurrence<N, T, p>()) {
        constexpr Monomial mono = polynomial_monomial(N, T);
        constexpr double multiplicity = detail::monomial_multiplicity<N, T, p>();
        int rest[4] = {-1, -1, -1, -1};
        for (int r = 0, s = 0; r < mono.degree; ++r)
          if (r != p) rest[s++] = mono.var[r];
        const double rest_moment = detail::gaussian_monomial_moment<N>(mono.degree - 1, rest, mean, P);
        for (int k = 0; k < N; ++k) g.jacobian(k, mono.var[p]) += (coefficient[k][T] * multiplicity) * rest_moment;
      }
    });
  }

  // ---- host: what the coefficients are (filters decide from these facts whether they can run them) ------
  /// The highest degree of h with a nonzero coefficient (0: constant); `observation_degree` holds it.
  int observed_degree() const {
    int degree = 0;
    for (int i = 0; i < N; ++i)
      for (int j = 0; j < N; ++j)
        if (C(i, j) != 0.0) degree = 1;
    for (int t = 0; t < num_observation_monomials; ++t)
      for (int k = 0; k < N; ++k)
        if (observation_coefficient[k][t] != 0.0 && polynomial_monomial(N, t).degree > degree)
          degree = polynomial_monomial(N, t).degree;
    return degree;
  }

  ModelFacts model_facts() const {
    ModelFacts f;
    f.observation_degree = observed_degree();
    for (int i = 0; i < N; ++i)
      for (int j = 0; j < N; ++j)
        if (a1(i, j) != 0.0) f.drift_degree = 1;
    for (int t = 0; t < num_monomials; ++t) {
      const Monomial m = polynomial_monomial(N, t);
      for (int k = 0; k < N; ++k) {
        if (coefficient[k][t] == 0.0) continue;
        f.drift_degree = m.degree > f.drift_degree ? m.degree : f.drift_degree;
        f.cross_terms = f.cross_terms || m.var[0] != m.var[m.degree - 1];
      }
    }
    const Mat<N, N> q = b * transpose(b);
    for (int i = 0; i < N; ++i)
      for (int j = 0; j < N; ++j)
        if (i != j && q(i, j) != 0.0) f.axis_aligned_noise = false;
    return f;
  }
};

template <class Model>
struct is_polynomial_model : std::false_type {};
template <int N>
struct is_polynomial_model<PolynomialModel<N>> : std::true_type {};

}  // namespace kushner
