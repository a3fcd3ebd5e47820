#pragma once
// MOM: Clark's Bayes-law moment filter of order M (seed 003 (2.13)-(2.17), Appendix I), for a scalar linear
// transition x[k+1] = a x + c + w and z = x + v with bounded noises. Per member it carries the posterior's
// support [l, f] (kernels/filters/clark_bounds.hpp) and its moments mu_1..mu_M. A step:
//   1. moments of x[k+1] | Z_k exactly from mu_j and w's moments (binomial expansions of (a x + c + w)^i, (2.19));
//   2. its density as the polynomial of degree M on the predicted support with those moments 0..M (2.13): in
//      Legendre form on s = (x - centre) / half-width, the coefficient of P_i is (2i + 1)/2 E[P_i(s)] (the
//      polynomial's moments are exactly the given ones, and this form needs no linear solve);
//   3. Bayes' rule with z (2.9)-(2.10): the polynomial times v's density on the posterior support, its
//      moments by Gauss-Legendre quadrature (exact for uniform v: degree <= 2M; the interval is split at z
//      so that |z - x|^rho_v is smooth on each piece). m = mu_1, P = mu_2 - mu_1^2 ((2.14), (2.17)).
// M = 4 is Clark's "fourth-order nonlinear filter". The moment-matched polynomial dips below zero where the true
// predicted density is near zero (Clark's rho = 10 plant noise is zero at 0): those dips are cut to zero in Bayes'
// rule (unclipped, most members of clark-linear met a negative normalizer or variance within a few steps; the
// thesis does not say how it met them). A member whose normalizer or variance is still not positive diverges.
#include "kernels/filters/clark_bounds.hpp"
#include "kernels/filters/filter_protocol.hpp"
#include "kernels/filters/filter_step.hpp"

#include <Kokkos_Core.hpp>

#include <cmath>
#include <vector>

namespace kushner {

template <class Model, class MemSpace>
struct MomentFilter {
  static constexpr int n = Model::state_dim, p = Model::obs_dim;
  static constexpr int max_order = 14;
  static constexpr int nodes = 16;  // Gauss-Legendre: exact to degree 31 >= 2 max_order + 1
  static constexpr const char* name = "MOM";
  static constexpr const char* description =
      "Clark's Bayes-law moment filter of order M, bounded noises (Clark 1971 (2.13)-(2.17))";
  static constexpr const char* unsupported = clark_filter_unsupported<Model>();

  int order = 4;
  double node[nodes], weight[nodes];                           // on [-1, 1]
  Kokkos::View<double**, Kokkos::LayoutLeft, MemSpace> state;  // (member, 0: l, 1: f, 1 + j: mu_j)

  template <class Archive>
  void visit_state(Archive& archive) {
    archive.view("bounds_and_moments", state);
  }
  static double own_bytes_per_member(const OptionValues& options) {
    return sizeof(double) * (2.0 + static_cast<double>(options.integer("mom_order")));
  }

  static std::vector<OptionSpec> options() {
    return {OptionSpec::integer("mom_order", 4, 1, max_order,
                                "MOM: degree M of the polynomial predicted density (Clark's fourth-order filter: 4)")};
  }

  static MomentFilter create(const OptionValues& options, const Model& model, long members) {
    MomentFilter f;
    f.order = static_cast<int>(options.integer("mom_order"));
    gauss_legendre(f.node, f.weight);
    f.state = decltype(f.state)("kushner::mom_state", members, 2 + f.order);
    const Interval prior = clark_prior_bounds(model);
    auto host = Kokkos::create_mirror_view(f.state);
    for (long member = 0; member < members; ++member) {
      host(member, 0) = prior.lower;
      host(member, 1) = prior.upper;
      for (int j = 1; j <= f.order; ++j)  // the uniform law on [l, f], or the point l = f
        host(member, 1 + j) = prior.upper > prior.lower
                                  ? (std::pow(prior.upper, j + 1) - std::pow(prior.lower, j + 1)) /
                                        ((j + 1) * (prior.upper - prior.lower))
                                  : std::pow(prior.lower, j);
    }
    Kokkos::deep_copy(f.state, host);
    return f;
  }

  Fields summary_fields() const { return {{"order", static_cast<long>(order)}}; }

  /// `known_input`: a closed loop's B u[k], part of the transition's constant term c.
  KOKKOS_INLINE_FUNCTION Status step(const Model& model, int member, const StepInput<p>& in, Vec<n>& m, Mat<n, n>& P,
                                     const Vec<n>& known_input) const {
    const double a = model.transition_jacobian(in.t, m)(0, 0);
    const double c = model.transition(in.t, Vec<1>::zero(), Model::Control::zero())[0] + known_input[0];
    return step_linear(model, member, in, a, c, m, P);
  }

  /// The step for the transition x[k+1] = a x + c + w, whatever gives a and c (the model's own linear
  /// transition, or a nonlinear one linearized along a nominal path: MOM-NOM).
  KOKKOS_INLINE_FUNCTION Status step_linear(const Model& model, int member, const StepInput<p>& in, double a, double c,
                                            Vec<n>& m, Mat<n, n>& P) const {
    const int M = order;
    // 1. Moments of a x + c, then of a x + c + w (odd moments of w vanish: symmetric noise).
    double mu[max_order + 1], shifted[max_order + 1], predicted[max_order + 1];
    mu[0] = 1.0;
    for (int j = 1; j <= M; ++j) mu[j] = state(member, 1 + j);
    for (int i = 0; i <= M; ++i) {
      double sum = 0.0, binomial = 1.0;
      for (int j = 0; j <= i; ++j) {  // C(i, j) a^j mu_j c^(i - j)
        sum += binomial * math::pow(a, j) * mu[j] * math::pow(c, i - j);
        binomial = binomial * (i - j) / (j + 1);
      }
      shifted[i] = sum;
    }
    for (int i = 0; i <= M; ++i) {
      double sum = 0.0, binomial = 1.0;
      for (int j = 0; j <= i; ++j) {
        sum += binomial * shifted[i - j] * model.w.moment(j);
        binomial = binomial * (i - j) / (j + 1);
      }
      predicted[i] = sum;
    }
    const Interval support = clark_predicted_bounds({state(member, 0), state(member, 1)}, a, c, model.w.bound);
    // 2. Legendre coefficients of the predicted density of s = (x - centre) / half on [-1, 1].
    const double centre = 0.5 * (support.lower + support.upper), half = 0.5 * (support.upper - support.lower);
    double s_moment[max_order + 1];
    for (int i = 0; i <= M; ++i) {
      double sum = 0.0, binomial = 1.0;
      for (int j = 0; j <= i; ++j) {  // E[(x - centre)^i] = sum C(i, j) E[x^(i - j)] (-centre)^j
        sum += binomial * predicted[i - j] * math::pow(-centre, j);
        binomial = binomial * (i - j) / (j + 1);
      }
      s_moment[i] = sum / math::pow(half, i);
    }
    double coefficient[max_order + 1];  // b_i = (2i + 1)/2 E[P_i(s)], P_i in monomials by the recurrence
    double previous[max_order + 1], current[max_order + 1], next[max_order + 1];
    for (int j = 0; j <= M; ++j) previous[j] = current[j] = 0.0;
    previous[0] = 1.0;             // P_0
    if (M >= 1) current[1] = 1.0;  // P_1
    coefficient[0] = 0.5;
    for (int i = 1; i <= M; ++i) {
      double expectation = 0.0;
      for (int j = 0; j <= i; ++j) expectation += current[j] * s_moment[j];
      coefficient[i] = 0.5 * (2 * i + 1) * expectation;
      // P_{i+1} = ((2i + 1) s P_i - i P_{i-1}) / (i + 1)
      for (int j = 0; j <= M; ++j) next[j] = ((j > 0 ? (2 * i + 1) * current[j - 1] : 0.0) - i * previous[j]) / (i + 1);
      for (int j = 0; j <= M; ++j) {
        previous[j] = current[j];
        current[j] = next[j];
      }
    }
    // 3. Bayes' rule with z on the posterior support.
    const double z = in.dy[0];
    const Interval posterior = clark_posterior_bounds(support, z, model.v.bound);
    if (!(posterior.lower < posterior.upper)) return Status::not_positive_definite;
    double moment[max_order + 1];
    for (int j = 0; j <= M; ++j) moment[j] = 0.0;
    const bool split = model.v.rho != 0.0 && posterior.lower < z && z < posterior.upper;
    const double cuts[3] = {posterior.lower, split ? z : posterior.upper, posterior.upper};
    for (int piece = 0; piece < (split ? 2 : 1); ++piece) {
      const double mid = 0.5 * (cuts[piece] + cuts[piece + 1]), radius = 0.5 * (cuts[piece + 1] - cuts[piece]);
      for (int q = 0; q < nodes; ++q) {
        const double x = mid + radius * node[q], s = (x - centre) / half;
        double density = coefficient[0], p_prev = 1.0, p_cur = s;  // sum b_i P_i(s)
        for (int i = 1; i <= M; ++i) {
          density += coefficient[i] * p_cur;
          const double p_next = ((2 * i + 1) * s * p_cur - i * p_prev) / (i + 1);
          p_prev = p_cur;
          p_cur = p_next;
        }
        density = density > 0.0 ? density : 0.0;  // the polynomial's dips below zero are no probability
        double mass = radius * weight[q] * density * model.v.density(z - x), power = 1.0;
        for (int j = 0; j <= M; ++j) {
          moment[j] += mass * power;
          power *= x;
        }
      }
    }
    if (!(moment[0] > 0.0)) return Status::not_positive_definite;
    for (int j = 1; j <= M; ++j) moment[j] /= moment[0];
    const double mean = moment[1], variance = M >= 2 ? moment[2] - mean * mean : 0.0;
    if (M >= 2 && !(variance > 0.0)) return Status::not_positive_definite;
    state(member, 0) = posterior.lower;
    state(member, 1) = posterior.upper;
    for (int j = 1; j <= M; ++j) state(member, 1 + j) = moment[j];
    m[0] = mean;
    P(0, 0) = M >= 2 ? variance : (posterior.upper - posterior.lower) * (posterior.upper - posterior.lower) / 12.0;
    return Status::ok;
  }

  /// Gauss-Legendre nodes and weights on [-1, 1] (Newton on P_nodes from the Chebyshev guesses).
  static void gauss_legendre(double* x, double* w) {
    for (int i = 0; i < nodes; ++i) {
      double t = std::cos(M_PI * (i + 0.75) / (nodes + 0.5)), derivative = 0.0;
      for (int iteration = 0; iteration < 100; ++iteration) {
        double p0 = 1.0, p1 = t;
        for (int k = 2; k <= nodes; ++k) {
          const double p2 = ((2 * k - 1) * t * p1 - (k - 1) * p0) / k;
          p0 = p1;
          p1 = p2;
        }
        derivative = nodes * (t * p1 - p0) / (t * t - 1.0);
        const double delta = p1 / derivative;
        t -= delta;
        if (std::fabs(delta) < 1e-16) break;
      }
      x[i] = t;
      w[i] = 2.0 / ((1.0 - t * t) * derivative * derivative);
    }
  }
};

}  // namespace kushner
