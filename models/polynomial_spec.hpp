#pragma once
// `--model-file FILE`: what a polynomial model file (models/polynomial_model.hpp, drivers/model_file.hpp) holds,
// read from TOML by models/model_file.cpp (toml++). Plain C++ without Kokkos: in CUDA builds that parser is
// compiled by the host compiler alone (toml++ does not get through nvcc). The format, with n = state_dim (1..3):
//   state_dim = 2                    # required
//   time = "continuous"              # optional; "discrete": x[k+1] = F(x) + B u + G e, z = h(x) + R d
//                                    # (models/discrete_polynomial_model.hpp), with [transition] (F, the keys of
//                                    # [drift]) and [process_noise] G = [[...]] (n x q) in place of [drift],
//                                    [diffusion]
//   name = "..."                     # optional, for reports; description = "..." likewise
//   [drift]                          # f_k = a0[k] + sum_i a1[k][i] x_i + sum_ij a2[k][i][j] x_i x_j + ... + a4
//   a0 = [...]                       # n            all optional (absent: zero)
//   a1 = [[...], ...]                # n x n
//   a2, a3, a4                       # n x n x n, n x n x n x n, n x n x n x n x n (nested arrays)
//   [[drift.terms]]                  # optional, repeatable: coefficient * prod_i x_i^powers[i] added to f_component
//   component = 2                    #   1-based
//   powers = [3, 0]                  #   n exponents, total degree <= 4
//   coefficient = 0.125
//   [diffusion]
//   b = [[...], ...]                 # required, n x q (q <= n): dx = f dt + b dw
//   [observation]                    # dy = h(x) dt + R dv, h_k = c0[k] + sum_i C[k][i] x_i + ... + c3 (degree <= 3)
//   C = [[...], ...]                 # p x n (p <= n); also spelled c1
//   c2, c3                           # optional, p x n x n, p x n x n x n; one of C (c1), c2, c3 is required
//   [[observation.terms]]            # optional, repeatable, as [[drift.terms]] (component 1..p, degree <= 3)
//   R = [[...], ...]                 # required, p x p, R R^T positive definite
//   c0 = [...]                       # optional, p (absent: zero)
//   [control]                        # optional: dx = (f(x) + B u) dt + b dw, one input (`kushner control`)
//   B = [...]                        # n entries (or an n x 1 matrix)
//   [initial]
//   x0_mean = [...]                  # required, n: the truths' initial law
//   x0_cov = [[...], ...]            # required, n x n, positive semidefinite
//   prior_mean, prior_cov            # optional: the filters' initial law (absent: the truths')
// Every error is one InputError line "FILE: KEY: what is wrong"; unknown keys are errors too (a typo would
// otherwise silently leave a coefficient zero).
#include <string>
#include <vector>

namespace kushner {

/// A model file's content, checked: sizes n (state), p (observation rows), q (diffusion columns); matrices
/// row-major; `monomial` (n x polynomial_monomial_count(n)) holds the drift's coefficients of degree 2..4 in the
/// order of polynomial_monomial(), `observation_monomial` (p x the same count) the observation's (degree 2..3;
/// the degree-4 entries zero); `B` the control input's column (empty: no [control]).
struct PolynomialModelSpec {
  std::string path, label, description;
  bool discrete = false;  // time = "discrete": `a0`.. hold F, `b` holds G
  int n = 0, p = 0, q = 0;
  std::vector<double> a0, a1, monomial, b, c0, C, observation_monomial, R, B, x0_mean, x0_cov, prior_mean, prior_cov;
};

/// Reads and checks `path`; InputError "path: key: ..." for a file that cannot be read, is not TOML, lacks a
/// required key, has an unknown key or a value of the wrong type or shape (make_polynomial_model checks the
/// covariances).
PolynomialModelSpec read_polynomial_model_file(const std::string& path);

/// The same from TOML text; `path` only names the source in messages.
PolynomialModelSpec parse_polynomial_model(const std::string& text, const std::string& path);

}  // namespace kushner
