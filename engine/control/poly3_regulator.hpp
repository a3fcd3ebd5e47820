#pragma once
// Basin's polynomial regulator (POLY3, issue 14 part 2; seed 002 regulator (14)-(17), (23); control paper
// (6)-(7), (11); SPEC section 5) for dx = (a0 + a1 x + a2 x^2 + a3 x^3 + B u) dt, x^k componentwise, B constant,
// and the cost of kernels/control/quadratic_cost.hpp. Basin's cost carries factors 1/2 (002 (15)); ours does not,
// so with Psi = F, L = Q (cost), the same R, our J is twice his, his Q(t) is our S(t) and the gains agree.
//
// DERIVED reading (the default; standard signs, V ~ x^T S x + 2 s^T x):
//   -dS/dt = A^T S + S A + Q - S B R^-1 B^T S,                    S(T) = F,
//   -ds/dt = (A - B R^-1 B^T S)^T s + S a - Q x*,                 s(T) = -F x*,
//   A(t) = a1 + 2 a2 diag(x) + 3 a3 diag(x o x + diag S),    a(t) = f(x) - A(t) x,   x = x(t) the state path,
//   u = -R^-1 B^T (S x + s).
// The S-equation is the transpose dual of the polynomial filter's variance equation (002 (10): dP = (J P + P J^T
// + b b^T - P A^T (B B^T)^-1 A P) dt with J = a1 + 2 a2 diag(m) + 3 a3 diag(m o m + diag P), the Gaussian mean of
// the Jacobian): P -> S, m -> x, J -> J^T, diag P -> diag S. Basin writes the dual with diag(.) on the other side of
// Q (a2^T Q * x^T = a2^T Q diag(x), not diag(x) a2^T Q); that is the PRINTED reading below. The s-equation is
// derived as in riccati.hpp: the affine model dx = (A x + a + B u) dt that touches the drift along the path
// (A x + a = f(x) on the path) has the value function x^T S x + 2 s^T x + c with exactly these S, s. Why this a:
// then p = S x + s satisfies -dp/dt = A^T p + Q (x - x*), p(T) = F (x(T) - x*), u = -R^-1 B^T p, which with
// diagonal_term = false (A = df/dx on the path) are Pontryagin's necessary conditions: the converged nominal path
// is a stationary point of the deterministic problem (to the discretization). Basin's diag(S) term (the dual of
// the filter's variances, kept by default as his regulator) moves A away from df/dx and the path away from it.
// Basin's own law u = R^-1 G^T Q x has no affine term: x1 (the target) does not enter his control at all.
//
// PRINTED readings (for `kushner reproduce`): Basin's signs, u = +R^-1 B^T Q x (no affine term), Q(T) = Psi = F,
//   printed_general   dQ/dt = -a1^T Q - Q a1 - 2 a2^T Q diag(x) - 2 diag(x) Q a2 - 3 a3^T Q diag(q) - 3 diag(q) Q a3
//                             - 3 a3^T Q diag(x^2) - 3 diag(x^2) Q a3 + L - Q B R^-1 B^T Q      (002 (17), ctl (7))
//   printed_car_eq23  002 (23), the car (phi, delta), v/l = a1(0, 1), T = 0.3:
//                     dq11 = -q12^2, dq12 = -3(v/l) q11^2 - q11 q12 - (v/l) q11 - 3(v/l) phi^2 q11,
//                     dq22 = -2(v/l) q12 - 2(v/l) q12 q22 - 2(v/l) delta^2 q12 - q22^2
//   printed_car_eq11  control paper (11), T = 0.1, v = 17, l = 2: as (23) but dq12 has -q12 q22 (for (23)'s
//                     -q11 q12) and dq22 has 6 v/l (for (23)'s 2 v/l) in its cubic terms.
// The car forms hold R = 1, B = (0, 1)^T, L = 0 only (checked). With Q(T) = +Psi, Basin's signs make the feedback
// positive (u grows with phi, delta), which steers towards a larger phi as his example wants; the derived reading
// reaches phi* through s.
//
// The two-point boundary problem: x forward from x0 under u (forward Euler, nominal_path.hpp's scheme, on the
// design polynomial), S, s backward from T along x (classical RK4 per step, the path at the step's midpoint taken
// as the mean of its ends, as riccati.hpp). Two solvers of its fixed point x = Phi(x) on the grid:
//   sweep  Basin's "direct and reverse passing" (002 L1543): guess, forward pass, backward pass, repeat (optionally
//          relaxed, x <- x + w (Phi(x) - x)). Basin passes endpoint values between the passes and integrates x
//          backwards too; here whole paths are passed (the usual forward-backward sweep): same fixed points.
//   exact  Newton on the discretized system R(x_1..x_N) = x - Phi(x) = 0 (x_0 = x0 fixed), central-difference
//          Jacobian, backtracking on |R|, to |R|_inf <= exact_tolerance.
// A model without a power polynomial (the car: tan) supplies `design_polynomial(t)` (models/car_model.hpp): the law
// is designed on it, as Basin does; `applied` is the schedule run on the model itself.
#include "core/eigen_dense.hpp"
#include "core/eigen_helpers.hpp"
#include "core/errors.hpp"
#include "engine/control/nominal_path.hpp"
#include "kernels/control/gain_schedule.hpp"
#include "kernels/control/quadratic_cost.hpp"
#include "models/model_traits.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace kushner {

namespace detail {
template <class Model, class = void>
struct has_design_polynomial : std::false_type {};
template <class Model>
struct has_design_polynomial<Model, std::void_t<decltype(std::declval<const Model&>().design_polynomial(0.0))>>
    : std::true_type {};
}  // namespace detail

/// The polynomial a controller is designed on: the model's design_polynomial(t) where it has one (the car's Taylor
/// model), else its drift as a power polynomial.
template <class Model>
auto design_power_polynomial(const Model& model, double t) {
  if constexpr (detail::has_design_polynomial<Model>::value)
    return model.design_polynomial(t);
  else
    return drift_power_polynomial(model, t);
}

enum class Poly3Reading { derived, printed_general, printed_car_eq23, printed_car_eq11 };

inline const char* poly3_reading_name(Poly3Reading r) {
  switch (r) {
    case Poly3Reading::derived: return "derived";
    case Poly3Reading::printed_general: return "printed-general";
    case Poly3Reading::printed_car_eq23: return "printed-car-eq23";
    case Poly3Reading::printed_car_eq11: return "printed-car-eq11";
  }
  return "?";
}

struct Poly3Options {
  Poly3Reading reading = Poly3Reading::derived;
  bool diagonal_term = true;       // derived reading: the 3 a3 diag(diag S) term (Basin's dual of the variances)
  int max_sweeps = 500;            // sweep
  double sweep_tolerance = 1e-12;  // sweep: max_k |x_new - x_old|_inf <= tol * max(1, max |x|)
  double relaxation = 1.0;         // sweep: x <- x + w (Phi(x) - x), 0 < w <= 1
  bool run_exact = true;
  int max_newton = 40;
  double exact_tolerance = 1e-12;  // exact: |x - Phi(x)|_inf <= tol * max(1, max |x|)
};

/// How one solver ended: converged, or why not, in one line.
struct TpbvpStatus {
  bool converged = false;
  int iterations = 0;
  double residual = std::numeric_limits<double>::quiet_NaN();  // last max_k |x - Phi(x)|_inf (scaled)
  std::string reason;                                          // "converged", or why it stopped
};

template <int N, int M>
struct Poly3Solution {
  GainSchedule<N, M> gains;   // of the exact solve (of the sweep when the exact solve did not converge)
  std::vector<Mat<N, N>> S;   // S (derived) or Basin's Q (printed) at the grid times
  std::vector<Vec<N>> s;      // s (0 in the printed readings)
  NominalPath<N, M> nominal;  // the converged path on the design polynomial and its J (empty when the passes escaped)
  NominalPath<N, M> applied;  // the same schedule run on the model itself (= nominal unless designed on a Taylor model)
  std::vector<Vec<N>> sweep_path;  // the sweep's last path
  std::vector<Vec<N>> exact_path;  // the exact solve's last path
  TpbvpStatus sweep, exact;
  bool converged() const { return exact.converged || sweep.converged; }
};

namespace detail {

template <int N>
struct Poly3Coefficients {
  Eigen::Matrix<double, N, 1> a0;
  Eigen::Matrix<double, N, N> a1, a2, a3;
};

template <int N, int D>
Poly3Coefficients<N> poly3_coefficients(const PowerPolynomial<N, D>& p) {
  static_assert(D >= 1 && D <= 3, "POLY3: the design polynomial must have degree 1, 2 or 3");
  Poly3Coefficients<N> c;
  c.a0 = Eigen::Map<const Eigen::Matrix<double, N, 1>>(p.a0.v);
  c.a1 = to_eigen(p.coefficient[1]);
  c.a2.setZero();
  c.a3.setZero();
  if constexpr (D >= 2) c.a2 = to_eigen(p.coefficient[2]);
  if constexpr (D >= 3) c.a3 = to_eigen(p.coefficient[3]);
  return c;
}

/// The backward pass and the forward pass of POLY3 for one model, cost and grid.
template <class Model>
struct Poly3Passes {
  static constexpr int n = Model::state_dim, m = Model::control_dim;
  using MatN = Eigen::Matrix<double, n, n>;
  using VecN = Eigen::Matrix<double, n, 1>;
  using Path = std::vector<Vec<n>>;

  const Model& model;
  const QuadraticCost<n, m>& cost;
  long steps;
  double dt;
  Poly3Options options;
  std::vector<Poly3Coefficients<n>> poly;  // at the grid times
  std::vector<Eigen::Matrix<double, n, m>> B;
  MatN Qc, F;
  Eigen::Matrix<double, m, m> Rinv;
  VecN target;

  Poly3Passes(const Model& model_, const QuadraticCost<n, m>& cost_, long steps_, double dt_, const Poly3Options& o)
      : model(model_), cost(cost_), steps(steps_), dt(dt_), options(o) {
    poly.resize(steps + 1);
    B.resize(steps + 1);
    for (long k = 0; k <= steps; ++k) {
      poly[k] = poly3_coefficients(design_power_polynomial(model, k * dt));
      B[k] = to_eigen(model.control_input(k * dt));
    }
    Qc = to_eigen(cost.Q);
    F = to_eigen(cost.F);
    Rinv = to_eigen(cost.R).inverse();
    target = Eigen::Map<const VecN>(cost.target.v);
    const bool car_form =
        options.reading == Poly3Reading::printed_car_eq23 || options.reading == Poly3Reading::printed_car_eq11;
    if (car_form) {
      // Decided at compile time: for other sizes the checks below would be unreachable (nvcc warned, #128-D).
      if constexpr (n != 2 || m != 1) {
        KUSHNER_INPUT_REQUIRE(false, "POLY3 " << poly3_reading_name(options.reading)
                                              << ": Basin's car equations need 2 states and 1 control");
      } else {
        KUSHNER_INPUT_REQUIRE(Qc.cwiseAbs().maxCoeff() == 0.0 && std::fabs(Rinv(0, 0) - 1.0) < 1e-15,
                              "POLY3 " << poly3_reading_name(options.reading) << ": Basin's car equations hold for "
                                       << "Q = 0 and R = 1 only");
        for (long k = 0; k <= steps; ++k)
          KUSHNER_INPUT_REQUIRE(std::fabs(B[k](0, 0)) == 0.0 && B[k](n - 1, 0) == 1.0,
                                "POLY3 " << poly3_reading_name(options.reading) << ": needs B = (0, 1)^T");
      }
    }
  }

  struct Coeff {
    Poly3Coefficients<n> p;
    Eigen::Matrix<double, n, m> B;
    VecN x;
  };
  struct State {
    MatN S;
    VecN s;
  };

  static VecN polynomial(const Poly3Coefficients<n>& p, const VecN& x) {
    const VecN x2 = x.cwiseProduct(x);
    return p.a0 + p.a1 * x + p.a2 * x2 + p.a3 * x2.cwiseProduct(x);
  }

  /// d/dt of (S, s) (derived) or (Q, 0) (printed) at one time.
  State rate(const Coeff& c, const State& st) const {
    const MatN BRB = c.B * Rinv * c.B.transpose();
    const MatN& S = st.S;
    const VecN x2 = c.x.cwiseProduct(c.x);
    State d;
    d.s.setZero();
    switch (options.reading) {
      case Poly3Reading::derived: {
        VecN shift = x2;
        if (options.diagonal_term) shift += S.diagonal();
        const MatN A = c.p.a1 + 2.0 * c.p.a2 * c.x.asDiagonal() + 3.0 * c.p.a3 * shift.asDiagonal();
        const VecN a = polynomial(c.p, c.x) - A * c.x;
        d.S = -(A.transpose() * S + S * A + Qc - S * BRB * S);
        d.s = -((A - BRB * S).transpose() * st.s + S * a - Qc * target);
        break;
      }
      case Poly3Reading::printed_general: {
        const MatN Dx = c.x.asDiagonal(), Dq = S.diagonal().asDiagonal(), Dx2 = x2.asDiagonal();
        const auto& p = c.p;
        d.S = -p.a1.transpose() * S - S * p.a1 - 2.0 * p.a2.transpose() * S * Dx - 2.0 * Dx * S * p.a2 -
              3.0 * p.a3.transpose() * S * Dq - 3.0 * Dq * S * p.a3 - 3.0 * p.a3.transpose() * S * Dx2 -
              3.0 * Dx2 * S * p.a3 + Qc - S * BRB * S;
        break;
      }
      case Poly3Reading::printed_car_eq23:
      case Poly3Reading::printed_car_eq11: {
        const double vl = c.p.a1(0, 1), q11 = S(0, 0), q12 = S(0, 1), q22 = S(1, 1);
        const double phi = c.x(0), delta = c.x(n - 1);
        const bool eq11 = options.reading == Poly3Reading::printed_car_eq11;
        const double dq11 = -q12 * q12;
        const double dq12 =
            -3.0 * vl * q11 * q11 - (eq11 ? q12 * q22 : q11 * q12) - vl * q11 - 3.0 * vl * phi * phi * q11;
        const double cubic = eq11 ? 6.0 : 2.0;
        const double dq22 = -2.0 * vl * q12 - cubic * vl * q12 * q22 - cubic * vl * delta * delta * q12 - q22 * q22;
        d.S.setZero();
        d.S(0, 0) = dq11;
        d.S(0, 1) = d.S(1, 0) = dq12;
        d.S(1, 1) = dq22;
        break;
      }
    }
    return d;
  }

  struct Backward {
    std::vector<Mat<n, n>> S;
    std::vector<Vec<n>> s;
    GainSchedule<n, m> gains;
    bool finite = true;
  };

  /// S, s backwards from T along the path x, and the gains u = -(K x + k).
  Backward backward(const Path& x) const {
    Backward out;
    out.S.resize(steps + 1);
    out.s.resize(steps + 1);
    out.gains.K.resize(steps + 1);
    out.gains.k.resize(steps + 1);
    const bool derived = options.reading == Poly3Reading::derived;
    State st{F, derived ? VecN(-F * target) : VecN(VecN::Zero())};
    auto coeff = [&](long k) { return Coeff{poly[k], B[k], Eigen::Map<const VecN>(x[k].v)}; };
    auto record = [&](long k, const State& v) {
      const MatN S = 0.5 * (v.S + v.S.transpose());
      out.S[k] = from_eigen<n, n>(S);
      for (int i = 0; i < n; ++i) out.s[k][i] = v.s(i);
      // derived: u = -R^-1 B^T (S x + s); printed: u = +R^-1 B^T Q x, i.e. K = -R^-1 B^T Q, k = 0.
      const Eigen::Matrix<double, m, n> K = (derived ? 1.0 : -1.0) * Rinv * B[k].transpose() * S;
      const Eigen::Matrix<double, m, 1> kk = Rinv * B[k].transpose() * v.s;
      out.gains.K[k] = from_eigen<m, n>(K);
      for (int i = 0; i < m; ++i) out.gains.k[k][i] = kk(i);
      out.finite = out.finite && S.allFinite() && v.s.allFinite();
    };
    auto axpy = [](const State& a, double h, const State& d) { return State{a.S + h * d.S, a.s + h * d.s}; };
    record(steps, st);
    Coeff upper = coeff(steps);
    for (long k = steps - 1; k >= 0 && out.finite; --k) {
      const Coeff lower = coeff(k);
      Coeff mid = lower;
      mid.x = 0.5 * (lower.x + upper.x);
      mid.B = 0.5 * (lower.B + upper.B);
      mid.p.a0 = 0.5 * (lower.p.a0 + upper.p.a0);
      mid.p.a1 = 0.5 * (lower.p.a1 + upper.p.a1);
      mid.p.a2 = 0.5 * (lower.p.a2 + upper.p.a2);
      mid.p.a3 = 0.5 * (lower.p.a3 + upper.p.a3);
      const double h = -dt;
      const State k1 = rate(upper, st);
      const State k2 = rate(mid, axpy(st, 0.5 * h, k1));
      const State k3 = rate(mid, axpy(st, 0.5 * h, k2));
      const State k4 = rate(lower, axpy(st, h, k3));
      st = State{st.S + (h / 6.0) * (k1.S + 2.0 * k2.S + 2.0 * k3.S + k4.S),
                 st.s + (h / 6.0) * (k1.s + 2.0 * k2.s + 2.0 * k3.s + k4.s)};
      record(k, st);
      upper = lower;
    }
    return out;
  }

  /// The path from x0 under the gains on the design polynomial (forward Euler), and its cost.
  NominalPath<n, m> forward(const GainSchedule<n, m>& gains, const Vec<n>& x0) const {
    NominalPath<n, m> out;
    out.x.resize(steps + 1);
    out.u.resize(steps);
    out.x[0] = x0;
    double J = 0.0;
    for (long k = 0; k < steps; ++k) {
      const Vec<m> u = -(gains.K[k] * out.x[k] + gains.k[k]);
      out.u[k] = u;
      J += cost.running(out.x[k], u) * dt;
      const VecN xk = Eigen::Map<const VecN>(out.x[k].v);
      Eigen::Matrix<double, m, 1> ue;
      for (int i = 0; i < m; ++i) ue(i) = u[i];
      const VecN next = xk + (polynomial(poly[k], xk) + B[k] * ue) * dt;
      for (int i = 0; i < n; ++i) out.x[k + 1][i] = next(i);
    }
    J += cost.terminal(out.x[steps]);
    out.J = J;
    out.finite = std::isfinite(J);
    return out;
  }

  /// Phi(x): one backward and one forward pass; `finite` false when either escaped.
  struct Map {
    Backward back;
    NominalPath<n, m> path;
    bool finite = false;
  };
  Map apply(const Path& x, const Vec<n>& x0) const {
    Map out;
    out.back = backward(x);
    if (!out.back.finite) return out;
    out.path = forward(out.back.gains, x0);
    out.finite = out.path.finite;
    return out;
  }

  static double scale_of(const Path& x) {
    double scale = 1.0;
    for (const auto& v : x)
      for (int i = 0; i < n; ++i) scale = std::max(scale, std::fabs(v[i]));
    return scale;
  }
  /// max_k |a_k - b_k|_inf / max(1, max |a|)
  static double difference(const Path& a, const Path& b) {
    double d = 0.0;
    for (size_t k = 0; k < a.size(); ++k)
      for (int i = 0; i < n; ++i) d = std::max(d, std::fabs(a[k][i] - b[k][i]));
    return std::isfinite(d) ? d / scale_of(a) : std::numeric_limits<double>::infinity();
  }
};

}  // namespace detail

/// Solves POLY3's two-point boundary problem from x0 over `steps` steps of `dt` by the sweep and by Newton.
template <class Model>
Poly3Solution<Model::state_dim, Model::control_dim> poly3_regulator(
    const Model& model, const QuadraticCost<Model::state_dim, Model::control_dim>& cost,
    const Vec<Model::state_dim>& x0, long steps, double dt, const Poly3Options& options = {}) {
  constexpr int n = Model::state_dim, m = Model::control_dim;
  KUSHNER_REQUIRE(steps >= 1 && dt > 0.0, "poly3_regulator: steps " << steps << ", dt " << dt);
  KUSHNER_INPUT_REQUIRE(options.relaxation > 0.0 && options.relaxation <= 1.0,
                        "POLY3: the sweep's relaxation must lie in (0, 1], not " << options.relaxation);
  using Passes = detail::Poly3Passes<Model>;
  using Path = typename Passes::Path;
  const Passes passes(model, cost, steps, dt, options);
  Poly3Solution<n, m> out;
  typename Passes::Map best;

  // (a) The sweep, from the path that stays at x0.
  {
    Path x(steps + 1, x0);
    double first = -1.0, last = 0.0;
    int growing = 0;
    TpbvpStatus& st = out.sweep;
    for (int i = 1; i <= options.max_sweeps; ++i) {
      typename Passes::Map next = passes.apply(x, x0);
      st.iterations = i;
      if (!next.back.finite) {
        st.reason = "the backward pass escaped to infinity (a finite escape time of the Q-equation) on sweep " +
                    std::to_string(i);
        break;
      }
      if (!next.finite) {
        st.reason = "the forward pass escaped to infinity on sweep " + std::to_string(i);
        break;
      }
      const double change = Passes::difference(next.path.x, x);
      st.residual = change;
      if (first < 0.0) first = change;
      growing = change > last ? growing + 1 : 0;
      last = change;
      if (change <= options.sweep_tolerance) {
        x = next.path.x;
        best = next;
        st.converged = true;
        st.reason = "converged";
        break;
      }
      if (growing >= 5 && change > 10.0 * first) {
        std::ostringstream why;
        why << "diverging: the path change grew from " << first << " to " << change << " over " << i << " sweeps";
        st.reason = why.str();
        break;
      }
      for (long k = 1; k <= steps; ++k) x[k] = x[k] + options.relaxation * (next.path.x[k] - x[k]);
      if (i == options.max_sweeps) {
        std::ostringstream why;
        why << "not converged in " << i << " sweeps: last path change " << change << " (first " << first << ")";
        st.reason = why.str();
      }
    }
    out.sweep_path = x;
  }

  // (b) Newton on x - Phi(x) = 0 over x_1..x_steps, from Phi(x0 held): independent of the sweep.
  if (options.run_exact) {
    TpbvpStatus& st = out.exact;
    const long unknowns = steps * n;
    using VecX = Eigen::VectorXd;
    auto pack = [&](const Path& x) {
      VecX v(unknowns);
      for (long k = 1; k <= steps; ++k)
        for (int i = 0; i < n; ++i) v((k - 1) * n + i) = x[k][i];
      return v;
    };
    auto unpack = [&](const VecX& v) {
      Path x(steps + 1);
      x[0] = x0;
      for (long k = 1; k <= steps; ++k)
        for (int i = 0; i < n; ++i) x[k][i] = v((k - 1) * n + i);
      return x;
    };
    auto residual = [&](const VecX& v, typename Passes::Map* keep) -> VecX {
      const Path x = unpack(v);
      typename Passes::Map map = passes.apply(x, x0);
      if (!map.finite) return VecX::Constant(unknowns, std::numeric_limits<double>::infinity());
      VecX r = v - pack(map.path.x);
      if (keep) *keep = std::move(map);
      return r;
    };
    typename Passes::Map start = passes.apply(Path(steps + 1, x0), x0);
    if (!start.finite) {
      st.reason = "the first pass from the path at x0 escaped to infinity";
    } else {
      VecX v = pack(start.path.x);
      typename Passes::Map current;
      VecX r = residual(v, &current);
      for (int it = 1; it <= options.max_newton; ++it) {
        const double scale = Passes::scale_of(unpack(v));
        st.iterations = it - 1;
        st.residual = r.cwiseAbs().maxCoeff() / scale;
        if (!std::isfinite(st.residual)) {
          st.reason = "the passes escaped to infinity";
          break;
        }
        if (st.residual <= options.exact_tolerance) {
          st.converged = true;
          st.reason = "converged";
          break;
        }
        Eigen::MatrixXd jac(unknowns, unknowns);
        for (long j = 0; j < unknowns; ++j) {
          const double h = 1e-6 * std::max(1.0, std::fabs(v(j)));
          VecX plus = v, minus = v;
          plus(j) += h;
          minus(j) -= h;
          jac.col(j) = (residual(plus, nullptr) - residual(minus, nullptr)) / (2.0 * h);
        }
        if (!jac.allFinite()) {
          st.reason = "the Jacobian is not finite (a pass escaped near the iterate)";
          break;
        }
        const VecX step = jac.partialPivLu().solve(-r);
        double lambda = 1.0;
        bool accepted = false;
        const double norm = r.cwiseAbs().maxCoeff();
        for (int back = 0; back < 30; ++back) {
          typename Passes::Map trial_map;
          const VecX trial = v + lambda * step;
          const VecX rt = residual(trial, &trial_map);
          if (rt.allFinite() && rt.cwiseAbs().maxCoeff() < norm) {
            v = trial;
            r = rt;
            current = std::move(trial_map);
            accepted = true;
            break;
          }
          lambda *= 0.5;
        }
        if (!accepted) {
          // At the level of rounding no step decreases |R| any more: accept that as converged when close.
          st.iterations = it;
          std::ostringstream why;
          why << "Newton stalled at residual " << st.residual << " (no step decreases it)";
          st.reason = why.str();
          break;
        }
        if (it == options.max_newton) {
          st.iterations = it;
          st.residual = r.cwiseAbs().maxCoeff() / Passes::scale_of(unpack(v));
          std::ostringstream why;
          why << "not converged in " << it << " Newton steps: residual " << st.residual;
          st.reason = why.str();
          st.converged = st.residual <= options.exact_tolerance;
          if (st.converged) st.reason = "converged";
        }
      }
      out.exact_path = unpack(v);
      if (st.converged) best = std::move(current);
    }
  }

  if (!best.finite) {  // neither converged: report the sweep's last state
    best = passes.apply(out.sweep_path, x0);
  }
  out.gains = best.back.gains;
  out.S = best.back.S;
  out.s = best.back.s;
  out.nominal = best.path;
  if (best.finite) out.applied = simulate_feedback(model, cost, out.gains, x0, steps, dt);
  return out;
}

}  // namespace kushner
