// Each continuous-time model's Jacobians and Hessians against central differences of its drift and observation.
#include "models/registry.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace kushner {
namespace {

template <class Model>
void expect_derivatives_match_central_differences(const Model& model, const Vec<Model::state_dim>& x) {
  constexpr int n = Model::state_dim, p = Model::obs_dim;
  const typename Model::Control u = Model::Control::zero();
  const double h = 1e-5, t = 0.3;
  const auto J = model.drift_jacobian(t, x, u);
  const auto H = model.observation_jacobian(t, x);
  for (int j = 0; j < n; ++j) {
    Vec<n> xp = x, xm = x;
    xp[j] += h;
    xm[j] -= h;
    const auto df = (model.drift(t, xp, u) - model.drift(t, xm, u)) * (0.5 / h);
    const auto dh = (model.observation(t, xp) - model.observation(t, xm)) * (0.5 / h);
    for (int i = 0; i < n; ++i)
      EXPECT_NEAR(J(i, j), df[i], 1e-6 * (1 + std::abs(df[i]))) << Model::name << " df" << i << "/dx" << j;
    for (int i = 0; i < p; ++i)
      EXPECT_NEAR(H(i, j), dh[i], 1e-6 * (1 + std::abs(dh[i]))) << Model::name << " dh" << i << "/dx" << j;
    for (int k = 0; k < n; ++k) {  // Hessian column j of drift component k from differences of the Jacobian
      const auto hess = model.drift_hessian(t, x, u, k);
      const auto dJ = (model.drift_jacobian(t, xp, u) - model.drift_jacobian(t, xm, u)) * (0.5 / h);
      for (int i = 0; i < n; ++i)
        EXPECT_NEAR(hess(i, j), dJ(k, i), 1e-5 * (1 + std::abs(dJ(k, i))))
            << Model::name << " d2f" << k << "/dx" << i << "dx" << j;
    }
    for (int k = 0; k < p; ++k) {
      const auto hess = model.observation_hessian(t, x, k);
      const auto dH = (model.observation_jacobian(t, xp) - model.observation_jacobian(t, xm)) * (0.5 / h);
      for (int i = 0; i < n; ++i)
        EXPECT_NEAR(hess(i, j), dH(k, i), 1e-5 * (1 + std::abs(dH(k, i))))
            << Model::name << " d2h" << k << "/dx" << i << "dx" << j;
    }
  }
}

TEST(ModelDerivatives, JacobiansAndHessiansMatchCentralDifferences) {
  int checked = 0;
  detail::for_each_model_type([&](auto* tag) {
    using Model = std::remove_pointer_t<decltype(tag)>;
    if constexpr (!Model::discrete_time) {
      Vec<Model::state_dim> x;
      for (int i = 0; i < Model::state_dim; ++i) x[i] = 0.7 - 0.45 * i;
      expect_derivatives_match_central_differences(Model{}, x);
      ++checked;
    }
  });
  EXPECT_EQ(checked, 13);  // ou, sine, cubic-oscillator, linear 1-3, car, car-taylor3, terpolymer, benes,
                           // cubic-sensor, pendulum, range-bearing
}

}  // namespace
}  // namespace kushner
