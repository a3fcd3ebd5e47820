#pragma once
// What the particle filter asks of a model beyond the usual drift/diffusion/observation functions.
#include "core/small_matrix.hpp"

#include <type_traits>
#include <utility>

namespace kushner {

/// A model may provide an exact sampler of its transition over dt,
///   Vec<n> sample_exact_transition(double t, const Vec<n>& x, double dt, const Vec<noise_dim>& z, double u),
/// from noise_dim standard normals z and one uniform u in (0, 1). The particle filter then uses it instead of
/// Euler-Maruyama, so that its only error is Monte Carlo (e.g. the Benes model, whose transition density is
/// known in closed form).
template <class Model, class = void>
struct has_exact_transition : std::false_type {};
template <class Model>
struct has_exact_transition<Model, std::void_t<decltype(std::declval<const Model&>().sample_exact_transition(
                                       0.0, std::declval<const Vec<Model::state_dim>&>(), 0.0,
                                       std::declval<const Vec<Model::noise_dim>&>(), 0.0))>> : std::true_type {};

/// A model whose drift, diffusion and observation are templates on the scalar (sine_model.hpp) can be evaluated in
/// float: the particle filter's fp32 then steps its particles in float, which costs a GPU a fraction of the energy
/// of fp64 sin, exp and multiply-adds (perf/particle_filter.md).
template <class Model, class = void>
struct has_float_dynamics : std::false_type {};
template <class Model>
struct has_float_dynamics<
    Model, std::enable_if_t<std::is_same_v<decltype(std::declval<const Model&>().drift(
                                               0.0, std::declval<const Vec<Model::state_dim, float>&>(),
                                               std::declval<const typename Model::Control&>())),
                                           Vec<Model::state_dim, float>> &&
                            std::is_same_v<decltype(std::declval<const Model&>().diffusion(
                                               0.0, std::declval<const Vec<Model::state_dim, float>&>())),
                                           Mat<Model::state_dim, Model::noise_dim, float>> &&
                            std::is_same_v<decltype(std::declval<const Model&>().observation(
                                               0.0, std::declval<const Vec<Model::state_dim, float>&>())),
                                           Vec<Model::obs_dim, float>>>> : std::true_type {};

/// Whether a model's particles take Euler-Maruyama steps (not an exact or discrete-time transition) whose increments
/// can be computed in float: the fp32 precision's particles then step in float, the mixed precision's take float
/// increments of a double state.
template <class Model>
constexpr bool has_float_increments =
    !Model::discrete_time && !has_exact_transition<Model>::value && has_float_dynamics<Model>::value;

/// Whether particles stored as Real take the `mixed` precision's float increments of a double state: the kernels of
/// mixed's own (ParticleTeamStep/ParticleTeamPairStep's Mixed, particle_block_host's FloatIncrements) exist only then.
template <class Model, class Real>
constexpr bool has_mixed_increments = std::is_same_v<Real, double> ? has_float_increments<Model> : false;

/// The scalar a particle's Euler-Maruyama step is computed in, for particles stored as Real: float where they are
/// stored in float and the model has float increments, else double (as are exact and discrete-time transitions).
template <class Model, class Real>
using particle_step_scalar =
    std::conditional_t<std::is_same_v<Real, float> && has_float_increments<Model>, float, double>;

}  // namespace kushner
