#pragma once
// One controller's closed loop over the bank: every member's truth driven by LAW applied to ESTIMATOR's estimate
// of that member (kernels/control/closed_loop_step.hpp), from the same initial states and with the same noise
// increments for every controller (the draws depend on seed, member and step only: common random numbers), so
// that two controllers' costs differ by their control alone and are compared member by member. The estimator is
// `state` (full information), a filter of the bank (its pre-pass, if any, runs inside the loop: ASRE iterates on
// controlled trajectories), or `PF`, the particle filter's posterior mean (certainty equivalence with the true
// conditional mean).
#include "core/errors.hpp"
#include "core/fields.hpp"
#include "core/options.hpp"
#include "engine/filter_bank.hpp"
#include "engine/particle_reference.hpp"
#include "engine/shared_instances.hpp"
#include "engine/time_grid.hpp"
#include "engine/truth_bank.hpp"
#include "kernels/control/closed_loop_step.hpp"
#include "kernels/ensemble_moments.hpp"
#include "kernels/host_copy.hpp"

#include <Kokkos_Core.hpp>

#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

namespace kushner {

inline constexpr const char* state_estimator_name = "state";

template <class ExecSpace, class Model>
class ControlLoop {
 public:
  using MemSpace = typename ExecSpace::memory_space;
  static constexpr int n = Model::state_dim, p = Model::obs_dim, m = Model::control_dim;

 private:
  template <class Tuple>
  struct Kernels;
  template <class... Filters>
  struct Kernels<std::tuple<Filters...>> {
    using Slots = FilterSlots<MemSpace, Filters...>;
    using Step = ClosedLoopStep<Model, MemSpace, Filters...>;
    using Prepared = std::tuple<std::optional<Filters>...>;
  };
  using K = Kernels<SupportedFilters<Model, MemSpace>>;

 public:
  using PreparedFilters = typename K::Prepared;

  /// `estimator`: state_estimator_name, a filter the model supports, or particle_filter_name.
  ControlLoop(const ExecSpace& space, const Model& model, long members, Seed seed, const std::string& estimator,
              const ControlLaw<n, m, MemSpace>& law, const QuadraticCost<n, m>& cost, const OptionValues& options = {},
              const ParticleSettings& particle = {}, const PreparedFilters& prepared = {});

  /// Step k over [k dt, (k + 1) dt]; `record`: (k + 1) dt is an output time.
  void step(long k, double dt, bool record);

  /// Each member's cost over the run (call after the last step): running plus terminal; NaN where the truth
  /// escaped to infinity.
  std::vector<double> member_costs() const;

  /// Each member's control energy, the integral of |u|^2 dt so far.
  std::vector<double> member_control_energy() const { return host_column(totals_, loop_control_energy); }

  /// Each member's sum over steps of |x - x_hat|^2 dt so far (x_hat: the estimate the law reads).
  std::vector<double> member_squared_error() const { return host_column(totals_, loop_squared_error); }

  /// Each member's running cost so far.
  std::vector<double> member_running_cost() const { return host_column(totals_, loop_running_cost); }

  /// The estimate the law reads, per member (the state itself for `state`).
  BankVector<MemSpace> estimate() const {
    if (pf_) return pf_->posterior_mean();
    BankVector<MemSpace> out = truths_.state();
    for_each_filter_slot(slots_, [&](const auto& slot) {
      if (slot.enabled) out = slot.m;
    });
    return out;
  }

  /// Per member: whether its truth and its estimator are still finite and well defined.
  std::vector<char> members_ok() const;

  /// Members whose truth escaped to infinity, and members whose estimator diverged (their truth did not).
  long truths_escaped() const { return count_status(space_, truth_status_, Status::non_finite); }
  long estimator_diverged() const;

  /// What the estimator adds to the summary (a bank filter's summary fields; the particle filter's settings).
  Fields estimator_fields() const {
    Fields fields;
    for_each_filter_slot(slots_, [&](const auto& slot) {
      if (slot.enabled) fields = filter_summary_fields(slot.filter);
    });
    if (pf_)
      fields = {{"particles", static_cast<long>(pf_->num_particles())},
                {"resampling", std::string(to_string(pf_->options().scheme))},
                {"precision", std::string(to_string(pf_->options().precision))}};
    return fields;
  }

  const TruthBank<ExecSpace, Model>& truths() const { return truths_; }
  const BankVector<MemSpace>& control() const { return control_; }
  const BankScalar<Status, MemSpace>& truth_status() const { return truth_status_; }
  const std::string& estimator() const { return estimator_; }

 private:
  /// Whether the estimator keeps a status per member (a filter, the particle filter; not the true state). Decided
  /// by the estimator, not by the status view's size: a rank may hold no members, and the counts are collective.
  bool estimator_has_status() const {
    bool has = static_cast<bool>(pf_);
    for_each_filter_slot(slots_, [&](const auto& slot) { has = has || slot.enabled; });
    return has;
  }
  BankScalar<Status, MemSpace> estimator_status() const {
    if (pf_) return pf_->status();
    BankScalar<Status, MemSpace> status;
    for_each_filter_slot(slots_, [&](const auto& slot) {
      if (slot.enabled) status = slot.status;
    });
    return status;
  }

  std::vector<double> host_column(const BankVector<MemSpace>& v, int column) const {
    space_.fence();
    const auto h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), v);
    std::vector<double> out(members_);
    for (long member = 0; member < members_; ++member) out[member] = h(member, column);
    return out;
  }

  ExecSpace space_;
  Model model_;
  long members_;
  Seed seed_;
  std::string estimator_;
  ControlLaw<n, m, MemSpace> law_;
  QuadraticCost<n, m> cost_;
  TruthBank<ExecSpace, Model> truths_;
  BankScalar<Status, MemSpace> truth_status_;
  BankVector<MemSpace> control_, totals_;
  typename K::Slots slots_;
  EstimateSource source_ = EstimateSource::state;
  std::unique_ptr<ParticleFilterBank<ExecSpace, Model>> pf_;
};

template <class ExecSpace, class Model>
ControlLoop<ExecSpace, Model>::ControlLoop(const ExecSpace& space, const Model& model, long members, Seed seed,
                                           const std::string& estimator, const ControlLaw<n, m, MemSpace>& law,
                                           const QuadraticCost<n, m>& cost, const OptionValues& options,
                                           const ParticleSettings& particle, const PreparedFilters& prepared)
    : space_(space),
      model_(model),
      members_(members),
      seed_(seed),
      estimator_(estimator),
      law_(law),
      cost_(cost),
      truths_(space, model, members, seed),
      truth_status_("kushner::loop_truth_status", members),
      control_("kushner::loop_control", members, m),
      totals_("kushner::loop_totals", members, num_loop_columns) {
  if (estimator == particle_filter_name) {
    if constexpr (particle_filter_unsupported<Model>() == nullptr) {
      pf_ = std::make_unique<ParticleFilterBank<ExecSpace, Model>>(space, model, static_cast<int>(members),
                                                                   particle.particles, seed, particle.options);
      source_ = EstimateSource::outside;
    }
    KUSHNER_REQUIRE(pf_ != nullptr, "ControlLoop: no particle filter for model " << Model::name);
  } else if (estimator != state_estimator_name) {
    KUSHNER_REQUIRE(enable_named_filter_slot(slots_, estimator, model, members, options, prepared, seed),
                    "ControlLoop: filter '" << estimator << "' is not supported by model " << Model::name);
    source_ = EstimateSource::bank_filter;
  }
}

template <class ExecSpace, class Model>
void ControlLoop<ExecSpace, Model>::step(long k, double dt, bool record) {
  typename K::Step kernel;
  kernel.truth = TruthStep<Model, MemSpace>{model_, truths_.state(), truths_.observations(),       k * dt,
                                            dt,     seed_,           static_cast<std::uint32_t>(k)};
  kernel.model = model_;
  kernel.truth_status = truth_status_;
  kernel.slots = slots_;
  kernel.source = source_;
  if (pf_) kernel.outside_estimate = pf_->posterior_mean();
  kernel.law = law_;
  kernel.cost = cost_;
  kernel.control = control_;
  kernel.totals = totals_;
  kernel.step = k;
  kernel.record = record;
  parallel_for_members("kushner::closed_loop_step", space_, members_, kernel);
  if (pf_) pf_->step(k, dt, truths_.observations(), control_);
}

template <class ExecSpace, class Model>
std::vector<double> ControlLoop<ExecSpace, Model>::member_costs() const {
  BankScalar<double, MemSpace> cost("kushner::loop_cost", members_);
  parallel_for_members("kushner::closed_loop_terminal", space_, members_,
                       ClosedLoopTerminal<Model, MemSpace>{truths_.state(), truth_status_, cost_, totals_, cost});
  space_.fence();
  const auto h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), cost);
  return std::vector<double>(h.data(), h.data() + members_);
}

template <class ExecSpace, class Model>
std::vector<char> ControlLoop<ExecSpace, Model>::members_ok() const {
  std::vector<char> ok(members_, 0);
  space_.fence();
  const auto truth = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), truth_status_);
  const bool has_status = estimator_has_status();
  const auto status = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), estimator_status());
  for (long member = 0; member < members_; ++member)
    ok[member] = truth(member) == Status::ok && (!has_status || status(member) == Status::ok);
  return ok;
}

template <class ExecSpace, class Model>
long ControlLoop<ExecSpace, Model>::estimator_diverged() const {
  if (!estimator_has_status()) return 0;
  const BankScalar<Status, MemSpace> status = estimator_status();
  return count_status(space_, status, Status::not_positive_definite, truth_status_) +
         count_status(space_, status, Status::non_finite, truth_status_);
}

/// The model type the shared instances compile ControlLoop for (SharedModel, engine/shared_instances.hpp): Model, or
/// NotShared<Model> for a model without a control input.
template <class Model>
using ControlLoopInstanceModel = SharedModel<Model, ModelTraits<Model>::controlled>;
template <class ExecSpace, class Model>
class ControlLoop<ExecSpace, NotShared<Model>> {};

#define KUSHNER_SHARED_INSTANCE(Space, Model) extern template class ControlLoop<Space, ControlLoopInstanceModel<Model>>;
KUSHNER_FOR_EACH_SHARED_INSTANCE
#undef KUSHNER_SHARED_INSTANCE

}  // namespace kushner
