#pragma once
// Facts about a model whose structure is known only at run time (a --model-file polynomial): a model with
// `ModelFacts model_facts() const` states them, and each filter decides from them whether it can run the model
// (`unsupported_by`, kernels/filters/filter_protocol.hpp). Models state facts, never filter names.
namespace kushner {

struct ModelFacts {
  int drift_degree = 0;            // highest degree of the drift with a nonzero coefficient (0: constant drift)
  bool cross_terms = false;        // a drift monomial of degree >= 2 in two or more variables (x1 x2, x1^2 x3, ...)
  bool axis_aligned_noise = true;  // b b^T is diagonal
  int observation_degree = 1;      // highest degree of h with a nonzero coefficient (<= 1: a linear observation)
};

}  // namespace kushner
