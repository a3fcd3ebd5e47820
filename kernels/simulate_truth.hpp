#pragma once
// The bank of truths: initial states, and one step of every member in one kernel. Continuous-time models
// take an Euler-Maruyama step and produce the observation increment dy over the step; discrete-time models
// take x[k+1] = F(k, x[k], u) + w[k] and produce z[k+1] = H x[k+1] + v[k+1] in the same bank.
#include "core/errors.hpp"
#include "kernels/bank.hpp"
#include "kernels/for_each_member.hpp"
#include "kernels/rng.hpp"

#include <Kokkos_Core.hpp>

#include <cstdint>
#include <type_traits>
#include <utility>

namespace kushner {

namespace detail {
template <class Model, class = void>
struct has_observation_noise_increment : std::false_type {};
template <class Model>
struct has_observation_noise_increment<
    Model, std::void_t<decltype(std::declval<const Model&>().observation_noise_increment(0.0, 0.0))>> : std::true_type {
};
}  // namespace detail

/// Whether Model's observation noise is a given deterministic path (models/sine_observation_noise.hpp): the
/// truths then take dv = model.observation_noise_increment(t, dt) instead of a Brownian increment.
template <class Model>
constexpr bool has_deterministic_observation_noise = detail::has_observation_noise_increment<Model>::value;

/// x(member) = mean + root z, z standard normal from Stream::truth_initial (root: any square root of the
/// initial covariance, computed on the host, so that a singular covariance (fixed start) is allowed).
template <int N, class MemSpace>
struct GaussianInitialize {
  BankVector<MemSpace> x;
  Vec<N> mean;
  Mat<N, N> root;
  RngKey key;
  KOKKOS_INLINE_FUNCTION void operator()(const int member) const {
    const Vec<N> z = normal_vector<N>(key, member, 0, 0);
    store(x, member, mean + root * z);
  }
};

template <class ExecSpace, int N, class MemSpace>
void initialize_gaussian(const ExecSpace& space, const BankVector<MemSpace>& x, const Vec<N>& mean,
                         const Mat<N, N>& root, RngKey key) {
  KUSHNER_REQUIRE(x.extent_int(1) == N, "x has " << x.extent(1) << " columns, expected " << N);
  parallel_for_members("kushner::initialize_gaussian", space, x.extent(0),
                       GaussianInitialize<N, MemSpace>{x, mean, root, key});
}

/// One Euler-Maruyama step of every member over [t, t + dt]:
///   dy = h(t, x) dt + R dv,   x <- x + f(t, x, u) dt + G(t, x) dw,   dw, dv ~ N(0, dt I),
/// with u = 0 (open loop) or, in a closed loop, the member's control (step_member). The draws depend on seed,
/// member and step only, so every controller's loop sees the same noise (common random numbers).
/// or dv = model.observation_noise_increment(t, dt) where the model's observation noise is a deterministic path.
template <class Model, class MemSpace>
struct EulerMaruyamaTruthStep {
  Model model;
  BankVector<MemSpace> x, dy;
  double t, dt;
  Seed seed;
  std::uint32_t step;

  KOKKOS_INLINE_FUNCTION void operator()(const int member) const { step_member(member, Model::Control::zero()); }

  /// The step of one member driven by the control u over it (a closed loop's, kernels/control/).
  KOKKOS_INLINE_FUNCTION void step_member(const int member, const typename Model::Control& u) const {
    constexpr int n = Model::state_dim, p = Model::obs_dim, q = Model::noise_dim;
    const Vec<n> xm = load<n>(x, member);
    const double sqrt_dt = math::sqrt(dt);
    const Vec<q> dw = normal_vector<q>(RngKey{seed, Stream::process_noise}, member, 0, step) * sqrt_dt;
    Vec<p> dv;
    if constexpr (has_deterministic_observation_noise<Model>)
      dv = model.observation_noise_increment(t, dt);
    else
      dv = normal_vector<p>(RngKey{seed, Stream::observation_noise}, member, 0, step) * sqrt_dt;
    store(dy, member, model.observation(t, xm) * dt + model.observation_noise(t) * dv);
    store(x, member, xm + model.drift(t, xm, u) * dt + model.diffusion(t, xm) * dw);
  }
};

/// One step of a discrete-time model: x <- F(k, x, u) + w, z = H(k+1, x) + v, noises sampled by the model
/// from uniforms (inverse CDF), so bounded non-Gaussian laws are exact.
template <class Model, class MemSpace>
struct DiscreteTruthStep {
  Model model;
  BankVector<MemSpace> x, z;
  Seed seed;
  std::uint32_t step;

  KOKKOS_INLINE_FUNCTION void operator()(const int member) const {
    constexpr int n = Model::state_dim, p = Model::obs_dim;
    const typename Model::Control u = Model::Control::zero();
    const Vec<n> w = model.process_noise(uniform_vector<n>(RngKey{seed, Stream::process_noise}, member, 0, step));
    const Vec<n> next = model.transition(static_cast<int>(step), load<n>(x, member), u) + w;
    const Vec<p> v =
        model.observation_noise_sample(uniform_vector<p>(RngKey{seed, Stream::observation_noise}, member, 0, step));
    store(x, member, next);
    store(z, member, model.observation(static_cast<int>(step) + 1, next) + v);
  }
};

/// Advances every member of the bank by one step; `observations` receives dy (continuous time) or z[k+1]
/// (discrete time). No fence: the caller fences before reading results on the host.
template <class ExecSpace, class Model, class MemSpace>
void simulate_truth_step(const ExecSpace& space, const Model& model, const BankVector<MemSpace>& x,
                         const BankVector<MemSpace>& observations, double t, double dt, Seed seed, std::uint32_t step) {
  static_assert(Kokkos::SpaceAccessibility<ExecSpace, MemSpace>::accessible, "bank not accessible from ExecSpace");
  KUSHNER_REQUIRE(x.extent_int(1) == Model::state_dim,
                  "x has " << x.extent(1) << " columns, " << Model::name << " has state_dim " << Model::state_dim);
  KUSHNER_REQUIRE(observations.extent_int(1) == Model::obs_dim && observations.extent(0) == x.extent(0),
                  "observation bank has shape (" << observations.extent(0) << ", " << observations.extent(1) << ")");
  if constexpr (Model::discrete_time) {
    parallel_for_members("kushner::discrete_truth_step", space, x.extent(0),
                         DiscreteTruthStep<Model, MemSpace>{model, x, observations, seed, step});
  } else {
    parallel_for_members("kushner::euler_maruyama_truth_step", space, x.extent(0),
                         EulerMaruyamaTruthStep<Model, MemSpace>{model, x, observations, t, dt, seed, step});
  }
}

}  // namespace kushner
