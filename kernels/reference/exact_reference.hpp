#pragma once
// Which exact (or grid) reference a model has, for `--filters EXACT`: the Kalman filter of the particle
// filter's discretization for linear models, the Benes closed form for the Benes model, the grid filter for
// the other models of state dimension 1 or 2 with axis-aligned noise (sine, cubic oscillator, OU), the discrete
// grid filter for scalar discrete-time models with bounded noises (Clark's) and its Gaussian twin for the other
// discrete-time models of dimension 1 or 2. `void` where there is none (dimension 3).
#include "kernels/reference/benes_filter.hpp"
#include "kernels/reference/discrete_gaussian_grid_filter.hpp"
#include "kernels/reference/discrete_grid_filter.hpp"
#include "kernels/reference/grid_filter.hpp"
#include "kernels/reference/kalman_bucy_reference.hpp"
#include "models/benes_model.hpp"
#include "models/linear_model.hpp"
#include "models/model_traits.hpp"

#include <type_traits>

namespace kushner {

template <class ExecSpace, class Model, class = void>
struct exact_reference {
  using type = std::conditional_t<!Model::discrete_time && (Model::state_dim == 1 || Model::state_dim == 2),
                                  GridFilter<ExecSpace, Model>, void>;
};
template <class ExecSpace, class Model>
struct exact_reference<ExecSpace, Model, std::enable_if_t<Model::discrete_time>> {
  using type =
      std::conditional_t<DiscreteModelTraits<Model>::bounded_noises,
                         std::conditional_t<Model::state_dim == 1, DiscreteGridFilter<ExecSpace, Model>, void>,
                         std::conditional_t<Model::state_dim <= 2, DiscreteGaussianGridFilter<ExecSpace, Model>, void>>;
};
template <class ExecSpace, int N>
struct exact_reference<ExecSpace, LinearModel<N>> {
  using type = KalmanBucyReference<ExecSpace, N>;
};
template <class ExecSpace>
struct exact_reference<ExecSpace, BenesModel> {
  using type = BenesFilter<ExecSpace>;
};

/// The reference type for Model, or void; every one has step(k, dt, dy), posterior_mean() (member, i),
/// posterior_covariance() (member, packed), status(), and a static unsupported(model): why it cannot run that
/// model's values (nullptr: it can).
template <class ExecSpace, class Model>
using exact_reference_t = typename exact_reference<ExecSpace, Model>::type;

}  // namespace kushner
