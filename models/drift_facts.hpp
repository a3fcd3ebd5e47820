#pragma once
// Facts about a drift whose structure is known only at run time (a --model-file polynomial): a model with
// `DriftFacts drift_facts() const` states them, and each filter decides from them whether it can run the model
// (`unsupported_by`, kernels/filters/filter_protocol.hpp). Models state facts, never filter names.
namespace kushner {

struct DriftFacts {
  int degree = 0;                  // highest degree with a nonzero coefficient (0: constant drift)
  bool cross_terms = false;        // a monomial of degree >= 2 in two or more variables (x1 x2, x1^2 x3, ...)
  bool axis_aligned_noise = true;  // b b^T is diagonal
};

}  // namespace kushner
