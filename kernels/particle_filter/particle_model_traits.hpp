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

}  // namespace kushner
