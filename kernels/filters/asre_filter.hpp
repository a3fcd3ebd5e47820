#pragma once
// ASRE: the Cimen-Banks filter (seed 001 Theorem 2, (11)-(12)) for a factorization f = A(x) x + b (the
// known input b of Theorem 3 (ii), needed when f(0) != 0) and an observation h = C(x) x + c0 (linear, or
// factored by the model's sdc_observation, seed 001 (5); C below stands for C(m^[i-1](t))):
//   iterate i = 0, 1, ...: A_i(t) = A(m^[i-1](t)), G_i(t) = G(m^[i-1](t)), m^[-1](t) = m(0) for all t,
//   dm^[i] = (A_i m^[i] + b) dt + P^[i] C^T V^{-1} (dy - (c0 + C m^[i]) dt),
//   dP^[i] = (A_i P^[i] + P^[i] A_i^T + G_i G_i^T - P^[i] C^T V^{-1} C P^[i]) dt,
// each a Kalman-Bucy run over the whole horizon with the same dy, until the estimate trajectory changes less
// than a tolerance. Iterate i at step k needs iterate i-1 only at step k, so the iterates run as a cascade in
// one forward pass, filter i reading filter i-1's current estimate: the same numbers as sweeping the horizon
// once per iteration, with no stored trajectories. (With this explicit step iterate i linearizes at iterate
// i - 1's estimate of the same step, so on the first i + 1 steps it equals the causal state-dependent-coefficient
// filter that linearizes at its own estimate: tests/test_asre_filter.cpp checks it.)
// The pre-pass (prepare) runs the truths with ASRE alone, recording per member and iterate the largest change
// max_t |m^[i](t) - m^[i-1](t)|_inf (`change`), and picks each member's first iterate below the tolerance;
// the run then reports that iterate.
#include "core/collectives.hpp"
#include "core/errors.hpp"
#include "kernels/bank.hpp"
#include "kernels/filters/filter_protocol.hpp"
#include "kernels/filters/jacobian_linearization.hpp"
#include "models/model_traits.hpp"

#include <Kokkos_Core.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

namespace kushner {

template <class Model>
constexpr const char* asre_unsupported() {
  if (!ModelTraits<Model>::sdc) return "model has no factorization f = A(x) x + b";
  if (!ModelTraits<Model>::sdc_observation) return "observation has no factorization h = C(x) x + c0";
  return nullptr;
}

template <class Model, class MemSpace>
struct AsreFilter {
  static constexpr int n = Model::state_dim, p = Model::obs_dim;
  static constexpr const char* name = "ASRE";
  static constexpr const char* description =
      "approximating sequence of Riccati equations, Cimen-Banks (iterated over the horizon)";
  static constexpr const char* unsupported = asre_unsupported<Model>();

  /// What the pre-pass found, for summary.json (host only; `prepared` is false without a pre-pass).
  struct Iterations {
    bool prepared = false;
    double mean = 0.0;
    int min = 0, max = 0;
    long not_converged = 0;  // members that reached max_iterations without meeting the tolerance
    long diverged = 0;       // members whose iterates (or truth) did not stay finite: left out above
    double tolerance = 0.0;
    int max_iterations = 0;
  };

  Vec<n> prior_mean;
  Kokkos::View<int*, MemSpace> iterations;                      // (member): the iterate reported
  Kokkos::View<double***, Kokkos::LayoutLeft, MemSpace> m;      // (member, i, iterate)
  Kokkos::View<double***, Kokkos::LayoutLeft, MemSpace> P;      // (member, packed k, iterate)
  Kokkos::View<double**, Kokkos::LayoutLeft, MemSpace> change;  // (member, iterate): max_t |m^[i] - m^[i-1]|_inf
  Iterations summary;

  /// The pre-pass makes the same iterates again on resuming; they are saved anyway, so that a checkpoint
  /// holds everything the main pass reads.
  template <class Archive>
  void visit_state(Archive& archive) {
    archive.view("iterations", iterations);
    archive.view("m", m);
    archive.view("P", P);
    archive.view("change", change);
  }
  /// At most: every member iterated asre_max_iterations times.
  static double own_bytes_per_member(const OptionValues& options) {
    const double iterates = 1.0 + static_cast<double>(options.integer("asre_max_iterations"));
    return sizeof(int) + sizeof(double) * iterates * (n + packed_size(n) + 1);
  }

  static std::vector<OptionSpec> options() {
    return {OptionSpec::positive_real("asre_tolerance", 1e-6,
                                      "ASRE stops iterating when max_t |m^[i](t) - m^[i-1](t)| is below this"),
            OptionSpec::integer("asre_max_iterations", 30, 1, 1000, "ASRE iterations at most")};
  }

  /// Every member iterated asre_max_iterations times (a run without the pre-pass: tests, benchmarks).
  static AsreFilter create(const OptionValues& options, const Model& model, long members) {
    return with_iterations(model, std::vector<int>(members, static_cast<int>(options.integer("asre_max_iterations"))));
  }

  /// Member i iterated iterations[i] times.
  static AsreFilter with_iterations(const Model& model, const std::vector<int>& per_member) {
    const long members = static_cast<long>(per_member.size());
    AsreFilter f;
    f.prior_mean = model.prior_mean;
    f.iterations = Kokkos::View<int*, MemSpace>("kushner::asre_iterations", members);
    auto iterations_host = Kokkos::create_mirror_view(f.iterations);
    for (long member = 0; member < members; ++member) iterations_host(member) = per_member[member];
    Kokkos::deep_copy(f.iterations, iterations_host);
    const int iterates = 1 + (members > 0 ? *std::max_element(per_member.begin(), per_member.end()) : 0);
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

  /// The pre-pass: per member, the first iterate i >= 1 with max_t |m^[i] - m^[i-1]| < tolerance (else
  /// asre_max_iterations). Iterates do not depend on how many follow them, so it runs the truths with ASRE
  /// alone twice: every member iterated `first_round` times, then only the members still unconverged up to the
  /// maximum (the others iterate 0 times there). run_alone(filter) runs that pass and returns, per member,
  /// whether its filter and truth stayed finite.
  static constexpr int prepass_passes = 2;
  template <class RunAlone>
  static AsreFilter prepare(const OptionValues& options, const Model& model, long members, RunAlone&& run_alone) {
    constexpr int first_round = 10;  // most members of the seed models converge within it at tolerance 1e-6
    const double tolerance = options.real("asre_tolerance");
    const int max_iterations = static_cast<int>(options.integer("asre_max_iterations"));
    std::vector<int> first(members, 0);
    std::vector<char> diverged(members, 0);
    const auto pass = [&](const std::vector<int>& iterations) {
      const AsreFilter f = with_iterations(model, iterations);
      const std::vector<char> ok = run_alone(f);
      const auto change_host = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), f.change);
      for (long member = 0; member < members; ++member) {
        if (!ok[member]) diverged[member] = 1;
        for (int i = 1; i <= iterations[member] && !diverged[member]; ++i)
          if (change_host(member, i) < tolerance) {
            first[member] = i;
            break;
          }
      }
    };
    pass(std::vector<int>(members, std::min(first_round, max_iterations)));
    std::vector<int> rest(members, 0);
    bool any = false;
    for (long member = 0; member < members; ++member)
      if (first[member] == 0 && !diverged[member] && max_iterations > first_round)
        rest[member] = max_iterations, any = true;
    // `members` is this rank's share: every rank runs the second pass when any member anywhere needs it.
    if (collective::any(any)) pass(rest);

    std::vector<int> per_member(members);
    Iterations s;
    s.prepared = true;
    s.tolerance = tolerance;
    s.max_iterations = max_iterations;
    s.min = max_iterations;
    long sum = 0;  // an integer, so that its total over ranks does not depend on their order
    for (long member = 0; member < members; ++member) {
      per_member[member] = first[member] > 0 ? first[member] : max_iterations;
      if (diverged[member]) {
        ++s.diverged;
        continue;
      }
      if (first[member] == 0) ++s.not_converged;
      s.min = std::min(s.min, per_member[member]);
      s.max = std::max(s.max, per_member[member]);
      sum += per_member[member];
    }
    s.diverged = collective::sum(s.diverged);
    s.not_converged = collective::sum(s.not_converged);
    s.min = static_cast<int>(collective::min(s.min));
    s.max = static_cast<int>(collective::max(s.max));
    sum = collective::sum(sum);
    const long all_members = collective::sum(members);
    s.mean = all_members > s.diverged ? static_cast<double>(sum) / (all_members - s.diverged) : std::nan("");
    AsreFilter f = with_iterations(model, per_member);
    f.summary = s;
    return f;
  }

  /// summary.json: "iterations" {mean, min, max, not_converged, diverged, tolerance, max_iterations}.
  Fields summary_fields() const {
    if (!summary.prepared) return {};
    return {{"iterations.mean", summary.mean},
            {"iterations.min", static_cast<long>(summary.min)},
            {"iterations.max", static_cast<long>(summary.max)},
            {"iterations.not_converged", summary.not_converged},
            {"iterations.diverged", summary.diverged},
            {"iterations.tolerance", summary.tolerance},
            {"iterations.max_iterations", static_cast<long>(summary.max_iterations)}};
  }

  /// A closed loop's known input B u dt enters every iterate's mean equation alike (seed 001 Theorem 3 (ii)).
  KOKKOS_INLINE_FUNCTION void apply_known_input(int member, const Vec<n>& shift) const {
    const int last = iterations(member);
    for (int it = 0; it <= last; ++it)
      for (int i = 0; i < n; ++i) m(member, i, it) += shift[i];
  }

  KOKKOS_INLINE_FUNCTION Status step(const Model& model, int member, const StepInput<p>& in, Vec<n>& m_out,
                                     Mat<n, n>& P_out) const {
    static_assert(unsupported == nullptr,
                  "AsreFilter: Model must define sdc_drift(t, x) (or linear_form) and sdc_observation(t, x) (or a "
                  "linear observation)");
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
      ObservationLinearization<n, p> obs;
      // A run-time polynomial's h may have terms of degree 2 and 3: its C(x) x form.
      if constexpr (ModelTraits<Model>::linear_observation && !ModelTraits<Model>::runtime_checked) {
        obs = observation_linearization(model, in.t, mk);
      } else {  // (11)-(12): C(m^[i-1]) in the gain and in the innovation C(m^[i-1]) m^[i]
        const SdcObservation<n, p> c = observation_sdc(model, in.t, linearization_point);
        obs = ObservationLinearization<n, p>{c.C * mk + c.c0, c.C};
      }
      Vec<p> weighted_innovation;
      if (!kalman_update(obs, in, mk, Pk, weighted_innovation)) return Status::not_positive_definite;
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
