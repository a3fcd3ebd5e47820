#pragma once
// `--filters EXACT`: the exact filter where the model has one (Kalman for linear models, Benes' closed form)
// or the grid (point-mass) filter for the other models of dimension 1 and 2 (kernels/reference/), as an
// estimator beside the bank. Like the particle filter it starts from the filters' prior.
#include "drivers/reference_estimator.hpp"
#include "kernels/reference/exact_reference.hpp"

#include <type_traits>

namespace kushner {

/// Whether `--filters EXACT` can run for Model (host space stands for every space: the trait does not
/// depend on it).
template <class Model>
constexpr bool has_exact_reference = !std::is_void_v<exact_reference_t<Kokkos::DefaultHostExecutionSpace, Model>>;

template <class ExecSpace, class Model>
class ExactReferenceEstimator final : public ReferenceEstimator<typename ExecSpace::memory_space> {
 public:
  using MemSpace = typename ExecSpace::memory_space;
  using Reference = exact_reference_t<ExecSpace, Model>;
  static_assert(!std::is_void_v<Reference>, "ExactReferenceEstimator: the model has no exact or grid reference");

  ExactReferenceEstimator(const ExecSpace& space, const Model& model, long members)
      : reference_(space, model, static_cast<int>(members)) {}

  std::string name() const override { return "EXACT"; }
  void advance(long k, double, double dt, const BankVector<MemSpace>& dy) override { reference_.step(k, dt, dy); }
  BankVector<MemSpace> mean() const override { return reference_.posterior_mean(); }
  BankSymmetric<MemSpace> covariance() const override { return reference_.posterior_covariance(); }
  BankScalar<Status, MemSpace> status() const override { return reference_.status(); }
  nlohmann::json describe() const override {
    if constexpr (std::is_same_v<Reference, BenesFilter<ExecSpace>>)
      return {{"kind", "benes"}, {"note", "Benes closed form (exact)"}};
    else if constexpr (std::is_same_v<Reference, GridFilter<ExecSpace, Model>>)
      return {{"kind", "grid"}, {"note", "point-mass grid filter (Fokker-Planck prediction, Bayes update)"}};
    else
      return {{"kind", "kalman"}, {"note", "Kalman filter of the Euler-Maruyama discretization (exact for it)"}};
  }

 private:
  Reference reference_;
};

}  // namespace kushner
