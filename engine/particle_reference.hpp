#pragma once
// The particle filter as the bank's reference estimator: N particles per member driven by the same dy as the
// filters, started from the filters' prior (so it answers "what is the optimal estimate under the filters'
// assumptions"). Also keeps, per member, sums over steps of the effective sample size and of trace(P) / ESS,
// the squared Monte Carlo error of the particle mean (Kong, Liu & Wong 1994): rmse_ref cannot tell apart
// filters closer to the particle mean than its root mean, the reference's noise floor. Reduced on the host
// in member order, so the figures are the same on any number of threads.
#include "core/collectives.hpp"
#include "engine/particle_filter_bank.hpp"
#include "engine/reference_estimator.hpp"
#include "kernels/for_each_member.hpp"

#include <Kokkos_Core.hpp>

#include <cmath>
#include <cstdint>
#include <memory>
#include <type_traits>
#include <vector>

namespace kushner {

/// Adds a step's ESS and trace(P) / ESS to each member's sums; a step pair's two steps in one launch, in order.
template <int N, class MemSpace>
struct AccumulateEss {
  BankScalar<double, MemSpace> ess, ess_next;  // ess_next: the second step of a pair (empty after one step)
  BankSymmetric<MemSpace> covariance, covariance_next;
  BankVector<MemSpace> sums;  // (member, 0): sum of ESS; (member, 1): sum of trace(P) / ESS
  KOKKOS_INLINE_FUNCTION void add(const int member, const BankScalar<double, MemSpace>& e,
                                  const BankSymmetric<MemSpace>& p) const {
    double trace = 0.0;
    for (int i = 0; i < N; ++i) trace += p(member, packed_index(N, i, i));
    sums(member, 0) += e(member);
    sums(member, 1) += trace / e(member);
  }
  KOKKOS_INLINE_FUNCTION void operator()(const int member) const {
    add(member, ess, covariance);
    if (ess_next.extent(0) > 0) add(member, ess_next, covariance_next);
  }
};

/// Real: the particle filter's storage (ParticleFilterBank), float for the fp32 precision: make_particle_reference
/// picks it from the settings.
template <class ExecSpace, class Model, class Real = double>
class ParticleReference final : public ReferenceEstimator<typename ExecSpace::memory_space> {
 public:
  using MemSpace = typename ExecSpace::memory_space;

  ParticleReference(const ExecSpace& space, const Model& model, long members, Seed seed,
                    const ParticleSettings& settings)
      : space_(space),
        pf_(space, model, static_cast<int>(members), settings.particles, seed, settings.options),
        sums_("kushner::particle_reference_sums", members, 2),
        in_pairs_(takes_step_pairs(settings.step_pairs, pf_.fuses_step_pairs())) {}

  std::string name() const override { return particle_filter_name; }
  void advance(long k, double, double dt, const BankVector<MemSpace>& dy) override;
  bool advances_in_pairs() const override { return in_pairs_; }
  void advance_pair(long k, double, double dt, const BankVector<MemSpace>& dy,
                    const BankVector<MemSpace>& dy_next) override;
  EstimateViews<MemSpace> first_of_pair() const override {
    return {pf_.first_step().mean, pf_.first_step().covariance, pf_.first_step().status};
  }
  BankVector<MemSpace> mean() const override { return pf_.posterior_mean(); }
  BankSymmetric<MemSpace> covariance() const override { return pf_.posterior_covariance(); }
  BankScalar<Status, MemSpace> status() const override { return pf_.status(); }

  Fields describe() const override;

  std::optional<ParticleSnapshot> particle_snapshot(const std::vector<int>& members) const override;

  void visit_state(StateArchive& archive) override;

  const ParticleFilterBank<ExecSpace, Model, Real>& bank() const { return pf_; }

 private:
  /// The steps just taken: one, or a pair's two (`pair`).
  void accumulate_ess(const bool pair) {
    using Accumulate = AccumulateEss<Model::state_dim, MemSpace>;
    const Accumulate accumulate =
        pair ? Accumulate{pf_.first_step().ess, pf_.effective_sample_size(), pf_.first_step().covariance,
                          pf_.posterior_covariance(), sums_}
             : Accumulate{pf_.effective_sample_size(), {}, pf_.posterior_covariance(), {}, sums_};
    parallel_for_members("kushner::accumulate_ess", space_, pf_.num_members(), accumulate);
    steps_ += pair ? 2 : 1;
  }

  ExecSpace space_;
  ParticleFilterBank<ExecSpace, Model, Real> pf_;
  BankVector<MemSpace> sums_;
  bool in_pairs_;
  long steps_ = 0;
};

template <class ExecSpace, class Model, class Real>
void ParticleReference<ExecSpace, Model, Real>::advance(long k, double, double dt, const BankVector<MemSpace>& dy) {
  pf_.step(k, dt, dy);
  accumulate_ess(false);
}

template <class ExecSpace, class Model, class Real>
void ParticleReference<ExecSpace, Model, Real>::advance_pair(long k, double, double dt, const BankVector<MemSpace>& dy,
                                                             const BankVector<MemSpace>& dy_next) {
  pf_.step_pair(k, dt, dy, dy_next);
  accumulate_ess(true);
}

template <class ExecSpace, class Model, class Real>
Fields ParticleReference<ExecSpace, Model, Real>::describe() const {
  space_.fence();
  const auto sums = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), sums_);
  const auto resamples = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), pf_.resample_count());
  // Every rank's members in member order (collective::gather), summed in that order: the same bits for any
  // number of ranks. Resample counts are exact in a double.
  std::vector<double> local;
  for (int m = 0; m < pf_.num_members(); ++m)
    local.insert(local.end(), {sums(m, 0), sums(m, 1), static_cast<double>(resamples(m))});
  const std::vector<double> all = collective::gather(local);
  double ess_total = 0.0, squared_error_total = 0.0;
  long resample_total = 0;
  const long members = static_cast<long>(all.size()) / 3;
  for (long m = 0; m < members; ++m) {
    const double* row = all.data() + 3 * m;
    if (!std::isfinite(row[0]) || !std::isfinite(row[1])) continue;  // a member that left the numbers
    ess_total += row[0], squared_error_total += row[1], resample_total += static_cast<long>(row[2]);
  }
  const double member_steps = static_cast<double>(members) * steps_;
  return {{"kind", std::string("particle filter")},
          {"particles", static_cast<long>(pf_.num_particles())},
          {"resampling", std::string(to_string(pf_.options().scheme))},
          {"ess_threshold", pf_.options().ess_threshold},
          {"precision", std::string(to_string(pf_.options().precision))},
          {"step_pairs", in_pairs_ ? std::string(pf_.fuses_step_pairs() ? "fused" : "unfused") : std::string("off")},
          {"mean_ess", steps_ > 0 ? ess_total / member_steps : std::nan("")},
          {"noise_floor", steps_ > 0 ? std::sqrt(squared_error_total / member_steps) : std::nan("")},
          {"resamples", resample_total},
          {"resamples_per_member_step", steps_ > 0 ? resample_total / member_steps : std::nan("")}};
}

template <class ExecSpace, class Model, class Real>
std::optional<ParticleSnapshot> ParticleReference<ExecSpace, Model, Real>::particle_snapshot(
    const std::vector<int>& members) const {
  return ParticleSnapshot(pf_, members);
}

template <class ExecSpace, class Model, class Real>
void ParticleReference<ExecSpace, Model, Real>::visit_state(StateArchive& archive) {
  pf_.visit_state(archive);
  archive.view("ess_sums", sums_);
  archive.value("steps", steps_);
}

/// A model the particle filter does not run has no shared ParticleReference (ParticleInstanceModel).
template <class ExecSpace, class Model, class Real>
class ParticleReference<ExecSpace, NotShared<Model>, Real> {};

/// The particle filter of `settings` as a reference estimator, stored in float for the fp32 precision.
template <class ExecSpace, class Model>
std::unique_ptr<ReferenceEstimator<typename ExecSpace::memory_space>> make_particle_reference(
    const ExecSpace& space, const Model& model, long members, Seed seed, const ParticleSettings& settings) {
  return with_particle_storage(settings.options.precision, [&](auto* stored) {
    using Real = std::remove_pointer_t<decltype(stored)>;
    return std::unique_ptr<ReferenceEstimator<typename ExecSpace::memory_space>>(
        std::make_unique<ParticleReference<ExecSpace, Model, Real>>(space, model, members, seed, settings));
  });
}

#define KUSHNER_SHARED_INSTANCE(Space, Model)                                   \
  extern template class ParticleReference<Space, ParticleInstanceModel<Model>>; \
  extern template class ParticleReference<Space, ParticleInstanceModel<Model>, float>;
KUSHNER_FOR_EACH_SHARED_INSTANCE
#undef KUSHNER_SHARED_INSTANCE

}  // namespace kushner
