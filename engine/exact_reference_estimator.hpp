#pragma once
// `--filters EXACT`: the exact filter where the model has one (Kalman for linear models, Benes' closed form)
// or the grid (point-mass) filter for the other models of dimension 1 and 2 (kernels/reference/), as an
// estimator beside the bank. Like the particle filter it starts from the filters' prior.
#include "engine/reference_estimator.hpp"
#include "kernels/reference/exact_reference.hpp"

#include <type_traits>

namespace kushner {

/// Whether `--filters EXACT` can run for Model (host space stands for every space: the trait does not
/// depend on it).
template <class Model>
constexpr bool has_exact_reference = !std::is_void_v<exact_reference_t<Kokkos::DefaultHostExecutionSpace, Model>>;

/// Why the exact filter cannot run `model`, or nullptr: no exact or grid filter for its type, or noise (or, in
/// discrete time, a prior) its grid filter cannot take.
template <class Model>
const char* exact_filter_unsupported(const Model& model) {
  if constexpr (!has_exact_reference<Model>)
    return "no exact filter, and no grid filter above dimension 2";
  else
    return exact_reference_t<Kokkos::DefaultHostExecutionSpace, Model>::unsupported(model);
}

template <class ExecSpace, class Model>
class ExactReferenceEstimator final : public ReferenceEstimator<typename ExecSpace::memory_space> {
 public:
  using MemSpace = typename ExecSpace::memory_space;
  using Reference = exact_reference_t<ExecSpace, Model>;
  static_assert(!std::is_void_v<Reference>, "ExactReferenceEstimator: the model has no exact or grid reference");

  /// Bytes it allocates per member (a 2-D grid filter's masses: 256 KiB).
  static double bytes_per_member() { return Reference::bytes_per_member(); }

  ExactReferenceEstimator(const ExecSpace& space, const Model& model, long members)
      : reference_(space, model, static_cast<int>(members)) {}

  std::string name() const override { return exact_filter_name; }
  void advance(long k, double, double dt, const BankVector<MemSpace>& dy) override { reference_.step(k, dt, dy); }
  BankVector<MemSpace> mean() const override { return reference_.posterior_mean(); }
  BankSymmetric<MemSpace> covariance() const override { return reference_.posterior_covariance(); }
  BankScalar<Status, MemSpace> status() const override { return reference_.status(); }
  void visit_state(StateArchive& archive) override { reference_.visit_state(archive); }
  Fields describe() const override {
    const auto fields = [](const char* kind, const char* note) {
      return Fields{{"kind", std::string(kind)}, {"note", std::string(note)}};
    };
    if constexpr (std::is_same_v<Reference, BenesFilter<ExecSpace>>)
      return fields("benes", "Benes closed form (exact)");
    else if constexpr (std::is_same_v<Reference, GridFilter<ExecSpace, Model>>)
      return fields("grid", "point-mass grid filter (Fokker-Planck prediction, Bayes update)");
    else if constexpr (std::is_same_v<Reference, DiscreteGridFilter<ExecSpace, Model>>)
      return {{"kind", std::string("grid")},
              {"note", std::string("point-mass Bayes filter with exact cell masses (noise CDFs)")},
              {"cells", static_cast<long>(reference_.cells())}};
    else if constexpr (std::is_same_v<Reference, DiscreteGaussianGridFilter<ExecSpace, Model>>)
      return {{"kind", std::string("grid")},
              {"note", std::string("point-mass Bayes filter: trapezoidal rule on a grid that follows the posterior "
                                   "(Gaussian noises)")},
              {"points", static_cast<long>(reference_.cells())}};
    else
      return fields("kalman", "Kalman filter of the Euler-Maruyama discretization (exact for it)");
  }

 private:
  Reference reference_;
};

}  // namespace kushner
