#pragma once
// `--model-file FILE`: the polynomial model (models/polynomial_model.hpp, models/discrete_polynomial_model.hpp) a
// model file describes (models/polynomial_spec.hpp: the format), its record in summary.json, and the dispatch on
// its time and dimension.
#include "core/errors.hpp"
#include "models/discrete_polynomial_model.hpp"
#include "models/parameters.hpp"
#include "models/polynomial_model.hpp"
#include "models/polynomial_spec.hpp"
#include "models/registry.hpp"

#include <nlohmann/json.hpp>

#include <string>
#include <utility>
#include <vector>

namespace kushner {

/// check_covariance for a matrix of the file: InputError "path: key: ...".
template <int N>
void check_file_covariance(const PolynomialModelSpec& spec, const std::string& key, const Mat<N, N>& m,
                           bool allow_singular) {
  try {
    check_covariance(key, m, allow_singular);
  } catch (const InputError& e) {
    throw InputError(spec.path + ": " + e.what());
  }
}

/// The model of a checked file (Model: PolynomialModel<N>, or DiscretePolynomialModel<N> for time = "discrete",
/// whose F and G fill the drift's and the diffusion's fields); InputError "path: key: ..." unless R R^T is positive
/// definite and x0_cov, prior_cov are covariances.
template <int N, class Model = PolynomialModel<N>>
Model make_polynomial_model(const PolynomialModelSpec& spec, const PolynomialModelSource* source) {
  KUSHNER_REQUIRE(spec.n == N, "model file has state_dim " << spec.n << ", not " << N);
  KUSHNER_REQUIRE(spec.discrete == Model::discrete_time, "model file's time is not the model type's");
  Model model;
  model.source = source;
  model.obs_rows = spec.p;
  model.noise_columns = spec.q;
  for (int i = 0; i < N; ++i) {
    model.a0[i] = spec.a0[i];
    model.x0_mean[i] = spec.x0_mean[i];
    model.prior_mean[i] = spec.prior_mean[i];
    for (int j = 0; j < N; ++j) {
      model.a1(i, j) = spec.a1[i * N + j];
      model.x0_cov(i, j) = spec.x0_cov[i * N + j];
      model.prior_cov(i, j) = spec.prior_cov[i * N + j];
    }
    for (int t = 0; t < PolynomialModel<N>::num_monomials; ++t)
      model.coefficient[i][t] = spec.monomial[i * PolynomialModel<N>::num_monomials + t];
    for (int j = 0; j < spec.q; ++j) model.b(i, j) = spec.b[i * spec.q + j];
  }
  for (int i = 0; i < spec.p; ++i) {
    model.c0[i] = spec.c0[i];
    for (int j = 0; j < N; ++j) model.C(i, j) = spec.C[i * N + j];
    for (int t = 0; t < PolynomialModel<N>::num_observation_monomials; ++t)
      model.observation_coefficient[i][t] = spec.observation_monomial[i * PolynomialModel<N>::num_monomials + t];
    for (int j = 0; j < spec.p; ++j) model.R(i, j) = spec.R[i * spec.p + j];
  }
  model.observation_degree = model.observed_degree();
  if (!spec.B.empty())
    for (int i = 0; i < N; ++i) model.B(i, 0) = spec.B[i];
  // R is the file's p x p block with the identity below it: R R^T is positive definite when the block's is,
  // and the pivot numbers are the block's.
  check_file_covariance(spec, "observation.R: R R^T", model.R * transpose(model.R), /*allow_singular=*/false);
  check_file_covariance(spec, "initial.x0_cov", model.x0_cov, /*allow_singular=*/true);
  check_file_covariance(spec, "initial.prior_cov", model.prior_cov, /*allow_singular=*/true);
  return model;
}

/// What summary.json records of a polynomial model: its file, and the coefficients as they run (drift, or a
/// discrete model's transition, as a0, a1 and the nonzero terms of degree 2..4 in the file's [[drift.terms]]
/// form; b (G), C, R in the file's shapes).
template <class Model>
nlohmann::json polynomial_model_json(const Model& model) {
  constexpr int N = Model::state_dim;
  const int p = model.obs_rows, q = model.noise_columns;
  auto matrix = [](const auto& m, int rows, int cols) {
    std::vector<std::vector<double>> r(rows, std::vector<double>(cols));
    for (int i = 0; i < rows; ++i)
      for (int j = 0; j < cols; ++j) r[i][j] = m(i, j);
    return r;
  };
  // The nonzero monomial coefficients of `rows` components in the file's [[...terms]] form.
  auto terms = [](const auto& coefficient, int rows) {
    nlohmann::json list = nlohmann::json::array();
    constexpr int count = std::extent_v<std::remove_reference_t<decltype(coefficient)>, 1>;
    for (int t = 0; t < count; ++t) {
      const Monomial mono = polynomial_monomial(N, t);
      std::vector<int> powers(N, 0);
      for (int r = 0; r < mono.degree; ++r) ++powers[mono.var[r]];
      for (int k = 0; k < rows; ++k)
        if (coefficient[k][t] != 0.0)
          list.push_back({{"component", k + 1}, {"powers", powers}, {"coefficient", coefficient[k][t]}});
    }
    return list;
  };
  nlohmann::json j = {{"state_dim", N},
                      {"time", Model::discrete_time ? "discrete" : "continuous"},
                      {"obs_dim", p},
                      {"noise_dim", q},
                      {Model::discrete_time ? "transition" : "drift",
                       {{"a0", std::vector<double>(model.a0.v, model.a0.v + N)},
                        {"a1", matrix(model.a1, N, N)},
                        {"terms", terms(model.coefficient, N)},
                        {"degree", model.model_facts().drift_degree}}},
                      {Model::discrete_time ? "process_noise" : "diffusion",
                       {{Model::discrete_time ? "G" : "b", matrix(model.b, N, q)}}},
                      {"observation",
                       {{"c0", std::vector<double>(model.c0.v, model.c0.v + p)},
                        {"C", matrix(model.C, p, N)},
                        {"terms", terms(model.observation_coefficient, p)},
                        {"degree", model.observed_degree()},
                        {"R", matrix(model.R, p, p)}}},
                      {"control", {{"B", matrix(model.B, N, 1)}}}};
  if (model.source != nullptr) {
    j["file"] = model.source->path;
    if (*model.source->label) j["label"] = model.source->label;
    if (*model.source->description) j["description"] = model.source->description;
  }
  return j;
}

namespace detail {

/// Calls run(Family<n>*) for a model file's state dimension n (1 to 3, checked where the file is read).
template <template <int> class Family, class Run>
void with_state_dim(int n, Run& run) {
  switch (n) {
    case 1: run(static_cast<Family<1>*>(nullptr)); break;
    case 2: run(static_cast<Family<2>*>(nullptr)); break;
    case 3: run(static_cast<Family<3>*>(nullptr)); break;
    default: KUSHNER_REQUIRE(false, "read_polynomial_model_file let state_dim " << n << " through");
  }
}

}  // namespace detail

/// Reads the model file `path`, applies `sets` ("key=value": the initial law, x0_mean, x0_cov, prior_mean,
/// prior_cov; the rest is edited in the file), validates the model and calls f(model) with a
/// PolynomialModel<state_dim> (DiscretePolynomialModel<state_dim> for time = "discrete"). InputError for a bad
/// file or assignment.
template <class F>
void with_model_file(const std::string& path, const std::vector<std::string>& sets, F&& f) {
  const PolynomialModelSpec spec = read_polynomial_model_file(path);
  const PolynomialModelSource source{spec.path.c_str(), spec.label.c_str(), spec.description.c_str()};
  std::vector<std::pair<std::string, std::string>> assignments;
  for (const auto& s : sets) {
    auto kv = split_assignment(s);
    KUSHNER_INPUT_REQUIRE(kv.first != "dim",
                          "--set dim: a --model-file model has the file's state_dim (" << spec.n << ")");
    assignments.push_back(std::move(kv));
  }
  auto run = [&](auto* tag) {
    using Model = std::remove_pointer_t<decltype(tag)>;
    Model from_file = make_polynomial_model<Model::state_dim, Model>(spec, &source);
    ParameterRecorder settable;
    from_file.parameters(settable);
    std::string names;
    for (const auto& e : settable.entries()) names += (names.empty() ? "" : ", ") + e.name;
    for (const auto& assignment : assignments) {
      bool known = false;
      for (const auto& e : settable.entries()) known = known || e.name == assignment.first;
      KUSHNER_INPUT_REQUIRE(known, "--set " << assignment.first << ": a --model-file model takes " << names
                                            << " (the other coefficients are edited in " << path << ")");
    }
    const Model model = configured_model(std::move(from_file), assignments);
    f(model);
  };
  if (spec.discrete)
    detail::with_state_dim<DiscretePolynomialModel>(spec.n, run);
  else
    detail::with_state_dim<PolynomialModel>(spec.n, run);
}

}  // namespace kushner
