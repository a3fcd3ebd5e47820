#pragma once
// Host-side validation of a configured model, before any output is opened.
#include "core/eigen_helpers.hpp"

#include <type_traits>

namespace kushner {

template <class Model, class = void>
struct has_validate : std::false_type {};
template <class Model>
struct has_validate<Model, std::void_t<decltype(std::declval<const Model&>().validate())>> : std::true_type {};

/// Everything a run needs of a model, checked before outputs are opened: the initial laws, the observation
/// noise (continuous time: R R^T positive definite) and the model's own checks (`void validate() const`).
template <class Model>
void validate_model(const Model& model) {
  check_covariance("x0_cov", model.x0_cov, /*allow_singular=*/true);
  // Singular priors are allowed (seed 002's car starts its filters from P(0) = [[100, 10], [10, 1]]): no
  // filter inverts P (kernels/filters/filter_step.hpp).
  check_covariance("prior_cov", model.prior_cov, /*allow_singular=*/true);
  if constexpr (!Model::discrete_time) {
    const auto r = model.observation_noise(0.0);
    check_covariance("observation noise R R^T", r * transpose(r), /*allow_singular=*/false);
  }
  if constexpr (has_validate<Model>::value) model.validate();
}

}  // namespace kushner
