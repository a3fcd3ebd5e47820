#pragma once
// Run-time settings of the filters that have any (host side; each filter copies what it needs into itself).
#include "kernels/filters/gauss_hermite.hpp"

#include <vector>

namespace kushner {

/// How QLF obtains its Gaussian expectations E_N[f], E_N[grad f], E_N[h], E_N[grad h].
enum class Expectations {
  automatic,  // closed form where the model has one, else cubature
  closed,     // the model's formulas (seed 000 (6.4)-(6.5), (6.14)) or exact moments of a polynomial drift
  cubature,   // tensor-product Gauss-Hermite, any model of state dimension <= 3
};

struct FilterConfig {
  Expectations qlf_expectations = Expectations::automatic;
  int gh_nodes = 8;              // per axis; exact for polynomials of degree <= 2 gh_nodes - 1 in each variable
  double asre_tolerance = 1e-6;  // on max over t of |m^[i](t) - m^[i-1](t)|_inf
  int asre_max_iterations = 30;
  /// Per member: the ASRE iterate to report. Empty: iterate to asre_max_iterations and record the changes
  /// (the convergence pass of drivers/filter_run.hpp).
  std::vector<int> asre_iterations;
};

}  // namespace kushner
