#pragma once
// Every model type kushner runs, one line each: adding a model is its header, its #include below and one
// line in a list. The registry (models/registry.hpp) reads the lists for `--model NAME`, and CMake reads this
// file to compile the `filter`, `compare` and `control` commands for every model of the three lists
// (drivers/CMakeLists.txt), so neither keeps a copy. One entry per line, spelled
// `MODEL(Type)`, `DISCRETE_MODEL(Type)` or `FILE_MODEL(Type)`: CMake matches those words.
#include "models/benes_model.hpp"
#include "models/car_model.hpp"
#include "models/clark_linear_model.hpp"
#include "models/clark_quintic_model.hpp"
#include "models/cubic_oscillator_model.hpp"
#include "models/cubic_sensor_model.hpp"
#include "models/discrete_polynomial_model.hpp"
#include "models/linear_discrete_model.hpp"
#include "models/linear_model.hpp"
#include "models/ou_model.hpp"
#include "models/pendulum_model.hpp"
#include "models/polynomial_model.hpp"
#include "models/range_bearing_model.hpp"
#include "models/sine_model.hpp"
#include "models/terpolymer_model.hpp"

#include <tuple>
#include <utility>

/// Continuous-time models named by `--model` (a name may stand for several types told apart by `--set dim=N`).
#define KUSHNER_CONTINUOUS_MODELS(MODEL) \
  MODEL(OuModel)                         \
  MODEL(SineModel)                       \
  MODEL(CubicOscillatorModel)            \
  MODEL(LinearModel<1>)                  \
  MODEL(LinearModel<2>)                  \
  MODEL(LinearModel<3>)                  \
  MODEL(CarModel)                        \
  MODEL(CarTaylor3Model)                 \
  MODEL(TerpolymerModel)                 \
  MODEL(BenesModel)                      \
  MODEL(CubicSensorModel)                \
  MODEL(PendulumModel)                   \
  MODEL(RangeBearingModel)

/// Discrete-time models named by `--model`.
#define KUSHNER_DISCRETE_MODELS(DISCRETE_MODEL) \
  DISCRETE_MODEL(ClarkLinearModel)              \
  DISCRETE_MODEL(ClarkQuinticModel)             \
  DISCRETE_MODEL(LinearDiscreteModel)

/// The polynomial models of `--model-file`, one type per time and state dimension.
#define KUSHNER_FILE_MODELS(FILE_MODEL)  \
  FILE_MODEL(PolynomialModel<1>)         \
  FILE_MODEL(PolynomialModel<2>)         \
  FILE_MODEL(PolynomialModel<3>)         \
  FILE_MODEL(DiscretePolynomialModel<1>) \
  FILE_MODEL(DiscretePolynomialModel<2>) \
  FILE_MODEL(DiscretePolynomialModel<3>)

namespace kushner {

#define KUSHNER_MODEL_TUPLE(Type) std::declval<std::tuple<Type>>(),
/// Every model `--model` names, as a std::tuple of types (never instantiated).
using BuiltinModels = decltype(std::tuple_cat(KUSHNER_CONTINUOUS_MODELS(KUSHNER_MODEL_TUPLE)
                                                  KUSHNER_DISCRETE_MODELS(KUSHNER_MODEL_TUPLE) std::tuple<>{}));
#undef KUSHNER_MODEL_TUPLE

}  // namespace kushner
