#pragma once
// Options of `kushner reproduce NAME --out DIR`. Sizes not given take the example's defaults
// (drivers/reproduce/reproduce_command.cpp); --members, --particles and --seed apply to the stochastic
// examples only.
#include "drivers/cli_app.hpp"

#include <optional>
#include <string>

namespace kushner {

struct ReproduceOptions {
  std::string example;
  std::string out;
  bool quiet = false;
  bool plots = true;
  std::optional<long> members;  // unset: the example's default
  std::optional<int> particles;
  std::optional<long long> seed;
  std::optional<double> dt;
};

/// NAME (positional), --out (required), --quiet, --no-plots, --members, --particles, --seed, --dt.
void add_reproduce_options(CLI::App& app, ReproduceOptions& options);

}  // namespace kushner
