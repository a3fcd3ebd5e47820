// `--model-file`: a file the reader accepts describes a model of the sizes it states, every coefficient finite, the
// observation's polynomial of degree <= 3.
#include "core/errors.hpp"
#include "models/polynomial_monomials.hpp"
#include "models/polynomial_spec.hpp"
#include "tests/fuzz/fuzz_check.hpp"
#include "tests/fuzz/fuzz_targets.hpp"

#include <cmath>
#include <string>
#include <vector>

namespace kushner::fuzz {

namespace {

void check_block(const std::vector<double>& values, std::size_t size, const char* what) {
  FUZZ_CHECK(values.size() == size, what);
  for (double v : values) FUZZ_CHECK(std::isfinite(v), what);
}

}  // namespace

int model_file(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const PolynomialModelSpec spec = parse_polynomial_model(text, "fuzz.toml");
    const std::size_t n = spec.n, p = spec.p, q = spec.q;
    FUZZ_CHECK(n >= 1 && n <= 3, "state_dim outside 1 .. 3");
    FUZZ_CHECK(p >= 1 && p <= n, "observation rows outside 1 .. state_dim");
    FUZZ_CHECK(q >= 1 && q <= n, "noise columns outside 1 .. state_dim");
    check_block(spec.a0, n, "drift.a0");
    check_block(spec.a1, n * n, "drift.a1");
    check_block(spec.monomial, n * polynomial_monomial_count(spec.n), "drift monomials");
    check_block(spec.b, n * q, "diffusion.b");
    check_block(spec.C, p * n, "observation.C");
    check_block(spec.observation_monomial, p * polynomial_monomial_count(spec.n), "observation monomials");
    for (std::size_t k = 0; k < p; ++k)
      for (int t = polynomial_monomial_count(spec.n, 3); t < polynomial_monomial_count(spec.n); ++t)
        FUZZ_CHECK(spec.observation_monomial[k * polynomial_monomial_count(spec.n) + t] == 0.0,
                   "an observation term of degree 4");
    FUZZ_CHECK(spec.B.empty() || spec.B.size() == n, "control.B not n entries");
    check_block(spec.B, spec.B.size(), "control.B");
    check_block(spec.R, p * p, "observation.R");
    check_block(spec.c0, p, "observation.c0");
    check_block(spec.x0_mean, n, "initial.x0_mean");
    check_block(spec.x0_cov, n * n, "initial.x0_cov");
    check_block(spec.prior_mean, n, "initial.prior_mean");
    check_block(spec.prior_cov, n * n, "initial.prior_cov");
  } catch (const InputError&) {
  }
  return 0;
}

}  // namespace kushner::fuzz
