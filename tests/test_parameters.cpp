// `--set key=value` parsing and application, and the registry's refusals.
#include "models/registry.hpp"

#include <gtest/gtest.h>

namespace kushner {
namespace {

TEST(ParameterValue, ParsesScalarsVectorsAndBothMatrixForms) {
  const auto s = parse_parameter_value("q", " 0.25 ");
  EXPECT_EQ(s.rows, 1);
  EXPECT_EQ(s.cols, 1);
  EXPECT_EQ(s.values[0], 0.25);
  const auto m1 = parse_parameter_value("A", "1, 2; 3, 4");
  const auto m2 = parse_parameter_value("A", "[[1, 2], [3, 4]]");
  EXPECT_EQ(m1.rows, 2);
  EXPECT_EQ(m1.cols, 2);
  EXPECT_EQ(m1.values, m2.values);
  EXPECT_EQ(m2.values, (std::vector<double>{1, 2, 3, 4}));
  const auto v = parse_parameter_value("x0_mean", "[1.5, -2]");
  EXPECT_EQ(v.rows, 1);
  EXPECT_EQ(v.cols, 2);
}

TEST(ParameterValue, RejectsMalformedValuesWithTheKeyInTheMessage) {
  for (const char* bad : {"", "abc", "1,,2", "[[1,2],[3]]", "[1,2", "1;2,3", "nan", "1e999"}) {
    try {
      parse_parameter_value("A", bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("--set A"), std::string::npos) << e.what();
    }
  }
}

TEST(Registry, AppliesSetsAndPassesTheConcreteModel) {
  bool called = false;
  with_model("linear", {"dim=3", "A=-1,0,0;0,-2,0;0,0,-3", "x0_mean=1,2,3"}, [&](const auto& model) {
    using Model = std::decay_t<decltype(model)>;
    if constexpr (std::is_same_v<Model, LinearModel<3>>) {
      called = true;
      EXPECT_EQ(model.A(2, 2), -3.0);
      EXPECT_EQ(model.x0_mean[1], 2.0);
    }
  });
  EXPECT_TRUE(called);
}

std::string error_of(const std::string& name, const std::vector<std::string>& sets) {
  try {
    with_model(name, sets, [](const auto&) {});
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Registry, RefusesBadInputWithOneClearMessage) {
  EXPECT_EQ(
      error_of("sin", {}),
      "--model: unknown model 'sin' (known: benes, car, car-taylor3, clark-linear, clark-quintic, cubic-oscillator, "
      "cubic-sensor, linear, linear-discrete, ou, pendulum, range-bearing, sine, terpolymer)");
  EXPECT_NE(error_of("sine", {"z=1"}).find("model 'sine' has no parameter 'z' (known: q, r,"), std::string::npos);
  EXPECT_NE(error_of("sine", {"q"}).find("expected key=value"), std::string::npos);
  EXPECT_NE(error_of("linear", {"dim=4"}).find("supports dim 1, 2, 3"), std::string::npos);
  EXPECT_NE(error_of("sine", {"dim=2"}).find("fixed dimension"), std::string::npos);
  EXPECT_NE(error_of("linear", {"A=1,2"}).find("expected a 2x2 matrix"), std::string::npos);
  EXPECT_NE(
      error_of("linear", {"prior_cov=1,2;2,1"}).find("prior_cov: not positive semidefinite (smallest eigenvalue -1"),
      std::string::npos);
  EXPECT_EQ(error_of("linear", {"x0_cov=1,2;3,4"}), "x0_cov: not symmetric");
  EXPECT_NE(error_of("sine", {"r=0"}).find("observation noise R R^T: not positive definite"), std::string::npos);
  EXPECT_NE(error_of("clark-linear", {"bound_w=-1"}).find("bound_w, bound_v: must be positive"), std::string::npos);
}

TEST(Registry, ListsEveryModelOnceWithItsParameters) {
  const auto models = describe_models();
  ASSERT_EQ(models.size(), model_names().size());
  for (const auto& m : models) EXPECT_FALSE(m["parameters"].empty()) << m["name"];
}

}  // namespace
}  // namespace kushner
