#pragma once
// The numbering of the monomials of degree 2..4 that a polynomial model (models/polynomial_model.hpp) keeps one
// coefficient each for (its drift up to degree 4, its observation up to degree 3): by degree, then
// lexicographically in the sorted variable indices (x1^2, x1 x2, x2^2, x1^3, ... for n = 2). Plain C++ without
// Kokkos, because the model-file parser (models/model_file.cpp) reads it too and is compiled by the host compiler
// alone in CUDA builds (toml++ does not get through nvcc). Device code
// calls these functions only where a constant is required, but nvcc wants them __host__ __device__ all the same.
#if defined(__CUDACC__)
#define KUSHNER_CONSTEXPR_FUNCTION __host__ __device__ constexpr
#else
#define KUSHNER_CONSTEXPR_FUNCTION constexpr
#endif

namespace kushner {

/// x_var[0] x_var[1] ... x_var[degree - 1], var sorted.
struct Monomial {
  int degree;
  int var[4];
};

/// The t-th monomial of degree 2..4 in n variables.
KUSHNER_CONSTEXPR_FUNCTION Monomial polynomial_monomial(int n, int t) {
  int index = 0;
  for (int degree = 2; degree <= 4; ++degree) {
    int v[4] = {0, 0, 0, 0};
    while (true) {
      if (index == t) {
        Monomial m{degree, {-1, -1, -1, -1}};
        for (int p = 0; p < degree; ++p) m.var[p] = v[p];
        return m;
      }
      ++index;
      int p = degree - 1;  // next sorted index tuple
      while (p >= 0 && v[p] == n - 1) --p;
      if (p < 0) break;
      ++v[p];
      for (int r = p + 1; r < degree; ++r) v[r] = v[p];
    }
  }
  return Monomial{0, {-1, -1, -1, -1}};
}

/// Number of monomials of degree 2..max_degree (max_degree <= 4) in n variables: the first ones in
/// polynomial_monomial() order, which numbers them by degree.
KUSHNER_CONSTEXPR_FUNCTION int polynomial_monomial_count(int n, int max_degree = 4) {
  return (max_degree >= 2 ? n * (n + 1) / 2 : 0) + (max_degree >= 3 ? n * (n + 1) * (n + 2) / 6 : 0) +
         (max_degree >= 4 ? n * (n + 1) * (n + 2) * (n + 3) / 24 : 0);
}

}  // namespace kushner
