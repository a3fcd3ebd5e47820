#pragma once
// Gaussian initial laws shared by every continuous-time model: the truths start from N(x0_mean, x0_cov), the
// filters from their prior N(prior_mean, prior_cov). They coincide unless a model (e.g. Sunahara's Example 2,
// whose truth starts at a fixed point far from the filters' prior) or the user sets them apart.
#include "core/small_matrix.hpp"

namespace kushner {

template <int N>
struct InitialLaw {
  Vec<N> x0_mean = Vec<N>::zero();
  Mat<N, N> x0_cov = Mat<N, N>::identity();
  Vec<N> prior_mean = Vec<N>::zero();
  Mat<N, N> prior_cov = Mat<N, N>::identity();

  /// Sets truth law and prior to the same Gaussian.
  void set_initial_law(const Vec<N>& mean, const Mat<N, N>& cov) {
    x0_mean = prior_mean = mean;
    x0_cov = prior_cov = cov;
  }

  template <class Visitor>
  void initial_law_parameters(Visitor&& v) {
    v("x0_mean", x0_mean, "mean of the truths' initial state");
    v("x0_cov", x0_cov, "covariance of the truths' initial state (positive semidefinite; 0 = fixed start)");
    v("prior_mean", prior_mean, "filters' initial estimate");
    v("prior_cov", prior_cov, "filters' initial covariance (positive semidefinite)");
  }
};

}  // namespace kushner
