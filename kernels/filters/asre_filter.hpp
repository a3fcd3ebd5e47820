#pragma once
// ASRE: the Cimen-Banks filter (seed 001 Theorem 2, (11)-(12)) for a factorization f = A(x) x + b (the
// known input b of Theorem 3 (ii), needed when f(0) != 0) and a linear observation h = c0 + C x:
//   iterate i = 0, 1, ...: A_i(t) = A(m^[i-1](t)), G_i(t) = G(m^[i-1](t)), m^[-1](t) = m(0) for all t,
//   dm^[i] = (A_i m^[i] + b) dt + P^[i] C^T V^{-1} (dy - (c0 + C m^[i]) dt),
//   dP^[i] = (A_i P^[i] + P^[i] A_i^T + G_i G_i^T - P^[i] C^T V^{-1} C P^[i]) dt,
// each a Kalman-Bucy run over the whole horizon with the same dy, until the estimate trajectory changes less
// than a tolerance. Iterate i at step k needs iterate i-1 only at step k, so the iterates run as a cascade in
// one forward pass, filter i reading filter i-1's current estimate: the same numbers as sweeping the horizon
// once per iteration, with no stored trajectories. (With this explicit step, iterate i equals the causal
// state-dependent-coefficient filter on the first i + 1 steps; /work/notes/filters.md, ASRE.)
// One bank pass with `max_iterations` iterates records, per member and iterate, the largest change
// max_t |m^[i](t) - m^[i-1](t)|_inf (`change`); drivers/filter_run.hpp picks each member's first iterate
// below the tolerance and runs the bank again reporting that iterate.
#include "kernels/bank.hpp"
#include "kernels/errors.hpp"
#include "kernels/filters/filter_config.hpp"
#include "kernels/filters/jacobian_linearization.hpp"
#include "kernels/filters/model_traits.hpp"

#include <Kokkos_Core.hpp>

#include <algorithm>

namespace kushner {

template <class Model>
constexpr const char* asre_unsupported() {
  if (!ModelTraits<Model>::sdc) return "model has no factorization f = A(x) x + b";
  if (!ModelTraits<Model>::linear_observation) return "observation is not linear";
  return nullptr;
}

template <class Model, class MemSpace>
struct AsreFilter {
  static constexpr int n = Model::state_dim, p = Model::obs_dim;
  static constexpr const char* name = "ASRE";
  static constexpr const char* description =
      "approximating sequence of Riccati equations, Cimen-Banks (iterated over the horizon)";
  static constexpr const char* unsupported = asre_unsupported<Model>();

  Vec<n> prior_mean;
  Kokkos::View<int*, MemSpace> iterations;                      // (member): the iterate reported
  Kokkos::View<double***, Kokkos::LayoutLeft, MemSpace> m;      // (member, i, iterate)
  Kokkos::View<double***, Kokkos::LayoutLeft, MemSpace> P;      // (member, packed k, iterate)
  Kokkos::View<double**, Kokkos::LayoutLeft, MemSpace> change;  // (member, iterate): max_t |m^[i] - m^[i-1]|_inf

  static AsreFilter create(const FilterConfig& config, const Model& model, long members) {
    KUSHNER_INPUT_REQUIRE(config.asre_max_iterations >= 1 && config.asre_max_iterations <= 1000,
                          "--asre-max-iterations: must be in 1 .. 1000 (got " << config.asre_max_iterations << ")");
    KUSHNER_REQUIRE(
        config.asre_iterations.empty() || static_cast<long>(config.asre_iterations.size()) == members,
        "asre_iterations has " << config.asre_iterations.size() << " entries for " << members << " members");
    AsreFilter f;
    f.prior_mean = model.prior_mean;
    f.iterations = Kokkos::View<int*, MemSpace>("kushner::asre_iterations", members);
    auto iterations_host = Kokkos::create_mirror_view(f.iterations);
    for (long member = 0; member < members; ++member)
      iterations_host(member) =
          config.asre_iterations.empty() ? config.asre_max_iterations : config.asre_iterations[member];
    Kokkos::deep_copy(f.iterations, iterations_host);
    const int iterates = 1 + (config.asre_iterations.empty()
                                  ? config.asre_max_iterations
                                  : *std::max_element(config.asre_iterations.begin(), config.asre_iterations.end()));
    f.m = decltype(f.m)(Kokkos::view_alloc(Kokkos::WithoutInitializing, "kushner::asre_m"), members, n, iterates);
    f.P = decltype(f.P)(Kokkos::view_alloc(Kokkos::WithoutInitializing, "kushner::asre_P"), members, packed_size(n),
                        iterates);
    f.change = decltype(f.change)("kushner::asre_change", members, iterates);
    auto m_host = Kokkos::create_mirror_view(f.m);
    auto P_host = Kokkos::create_mirror_view(f.P);
    for (long member = 0; member < members; ++member)
      for (int it = 0; it < iterates; ++it) {
        for (int i = 0; i < n; ++i) m_host(member, i, it) = model.prior_mean[i];
        for (int i = 0; i < n; ++i)
          for (int j = i; j < n; ++j) P_host(member, packed_index(n, i, j), it) = model.prior_cov(i, j);
      }
    Kokkos::deep_copy(f.m, m_host);
    Kokkos::deep_copy(f.P, P_host);
    return f;
  }

  KOKKOS_INLINE_FUNCTION Status step(const Model& model, int member, const StepInput<p>& in, Vec<n>& m_out,
                                     Mat<n, n>& P_out) const {
    static_assert(unsupported == nullptr,
                  "AsreFilter: Model must define sdc_drift(t, x) (or linear_form) and a linear observation");
    const auto mi = Kokkos::subview(m, member, Kokkos::ALL, Kokkos::ALL);
    const auto Pi = Kokkos::subview(P, member, Kokkos::ALL, Kokkos::ALL);
    Vec<n> linearization_point = prior_mean, previous_updated = prior_mean;
    const int last = iterations(member);
    for (int it = 0; it <= last; ++it) {
      Vec<n> mk;
      Mat<n, n> Pk;
      for (int i = 0; i < n; ++i) mk[i] = mi(i, it);
      for (int i = 0; i < n; ++i)
        for (int j = i; j < n; ++j) Pk(i, j) = Pk(j, i) = Pi(packed_index(n, i, j), it);
      const Vec<n> next_linearization_point = mk;  // m^[it](t): iterate it + 1 linearizes here
      Vec<p> weighted_innovation;
      if (!kalman_update(observation_linearization(model, in.t, mk), in, mk, Pk, weighted_innovation))
        return Status::not_positive_definite;
      const SdcDrift<n> sdc = drift_sdc(model, in.t, linearization_point);
      euler_predict(
          DriftLinearization<n>{sdc.A * mk + sdc.b, sdc.A, noise_intensity(model.diffusion(in.t, linearization_point))},
          in.dt, mk, Pk);
      for (int i = 0; i < n; ++i) mi(i, it) = mk[i];
      for (int i = 0; i < n; ++i)
        for (int j = i; j < n; ++j) Pi(packed_index(n, i, j), it) = Pk(i, j);
      if (it > 0) {
        double largest = change(member, it);
        for (int i = 0; i < n; ++i)
          largest =
              math::fabs(mk[i] - previous_updated[i]) > largest ? math::fabs(mk[i] - previous_updated[i]) : largest;
        change(member, it) = largest;
      }
      previous_updated = mk;
      linearization_point = next_linearization_point;
      if (it == last) {
        m_out = mk;
        P_out = Pk;
      }
    }
    return Status::ok;
  }
};

}  // namespace kushner
