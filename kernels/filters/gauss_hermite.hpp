#pragma once
// Gauss-Hermite quadrature for the standard normal: sum_q w_q g(xi_q) = E[g(Z)], Z ~ N(0, 1), exact for
// polynomials g of degree <= 2 K - 1 with K nodes. The rule is computed on the host once per run and copied
// into the kernels by value; tensor products of it integrate over N(0, I) in dimension <= 3.
#include "core/errors.hpp"

#include <cmath>

namespace kushner {

constexpr int max_gauss_hermite_nodes = 40;
constexpr int max_cubature_dim = 3;  // tensor products grow as K^n: beyond 3 a run would be dominated by them

struct GaussHermiteRule {
  int order = 0;
  double node[max_gauss_hermite_nodes];
  double weight[max_gauss_hermite_nodes];
};

/// The K-point rule for N(0, 1). Newton's method on the orthonormal Hermite recurrence from the asymptotic
/// starting values of Numerical Recipes' `gauher` (weight e^{-x^2}), then rescaled: xi = sqrt(2) x,
/// w = w_phys / sqrt(pi). Host only.
inline GaussHermiteRule make_gauss_hermite_rule(int order) {
  KUSHNER_REQUIRE(order >= 1 && order <= max_gauss_hermite_nodes, "order " << order);
  GaussHermiteRule rule;
  rule.order = order;
  const int n = order;
  const double pim4 = 0.7511255444649425;  // pi^{-1/4}
  double z = 0.0;
  for (int i = 0; i < (n + 1) / 2; ++i) {
    if (i == 0)
      z = std::sqrt(2.0 * n + 1.0) - 1.85575 * std::pow(2.0 * n + 1.0, -0.16667);
    else if (i == 1)
      z -= 1.14 * std::pow(static_cast<double>(n), 0.426) / z;
    else if (i == 2)
      z = 1.86 * z - 0.86 * rule.node[0];
    else if (i == 3)
      z = 1.91 * z - 0.91 * rule.node[1];
    else
      z = 2.0 * z - rule.node[i - 2];
    double pp = 0.0;
    for (int iteration = 0; iteration < 100; ++iteration) {
      double p1 = pim4, p2 = 0.0;
      for (int j = 0; j < n; ++j) {  // orthonormal Hermite polynomials for the weight e^{-x^2}
        const double p3 = p2;
        p2 = p1;
        p1 = z * std::sqrt(2.0 / (j + 1)) * p2 - std::sqrt(static_cast<double>(j) / (j + 1)) * p3;
      }
      pp = std::sqrt(2.0 * n) * p2;
      const double previous = z;
      z = previous - p1 / pp;
      if (std::fabs(z - previous) <= 1e-15 * std::fabs(z)) break;
    }
    rule.node[i] = z;  // stored in physicists' units until the rescaling below
    rule.node[n - 1 - i] = -z;
    rule.weight[i] = rule.weight[n - 1 - i] = 2.0 / (pp * pp);
  }
  const double root_pi = 1.7724538509055160273;
  for (int i = 0; i < n; ++i) {
    rule.node[i] *= 1.4142135623730950488;
    rule.weight[i] /= root_pi;
  }
  if (n % 2 == 1) rule.node[n / 2] = 0.0;
  return rule;
}

}  // namespace kushner
