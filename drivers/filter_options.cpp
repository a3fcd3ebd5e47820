#include "drivers/filter_options.hpp"

#include "core/errors.hpp"
#include "drivers/whole_number_notation.hpp"
#include "kernels/filters/filter_list.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>
#include <variant>

namespace kushner {

namespace {

std::string value_text(long v) { return std::to_string(v); }
std::string value_text(double v) {
  std::ostringstream text;
  text << v;
  return text.str();
}
std::string value_text(const std::string& v) { return v; }

/// `text` as a value of an option of `kind`: the whole text must be the number.
std::optional<Value> parse_value(const std::string& text, OptionSpec::Kind kind) {
  if (kind == OptionSpec::Kind::choice) return Value(text);
  std::size_t used = 0;
  try {
    if (kind == OptionSpec::Kind::integer) {
      const long v = std::stol(text, &used);
      if (used == text.size()) return Value(v);
    } else {
      const double v = std::stod(text, &used);
      if (used == text.size()) return Value(v);
    }
  } catch (const std::exception&) {
  }
  return std::nullopt;
}

}  // namespace

void add_filter_options(CLI::App& app, FilterOptions& o) {
  add_run_options(app, o.run);
  app.add_option("--filters", o.filters, "comma-separated filters, or all (see `kushner filters`)")
      ->capture_default_str();
  for (const OptionSpec& spec : all_filter_options()) {
    auto* option = app.add_option_function<std::string>(
        option_flag(spec.name), [&o, name = spec.name](const std::string& v) { o.filter_settings[name] = v; },
        spec.help);
    option->default_str(std::visit([](const auto& v) { return value_text(v); }, spec.default_value));
    if (spec.kind == OptionSpec::Kind::choice) option->check(CLI::IsMember(spec.choices));
    if (spec.kind == OptionSpec::Kind::integer) option->transform(whole_number_notation());
  }
  app.add_option("--particles", o.particles, "particles per member of the particle filter (PF)")
      ->capture_default_str()
      ->transform(whole_number_notation());
  app.add_option("--resample", o.resample, "PF resampling scheme: systematic, stratified, multinomial, residual")
      ->capture_default_str();
  app.add_option("--ess-threshold", o.ess_threshold,
                 "PF resamples a member when its effective sample size falls below this fraction of --particles")
      ->capture_default_str();
  app.add_option(
         "--precision", o.precision,
         "PF arithmetic: fp64; mixed (normals drawn in fp32, each step's increment computed in fp32 where the "
         "model's dynamics take it (sine, linear, ou); particles, weights and sums in fp64; faster on GPUs); or fp32 "
         "(normals in fp32, two steps' from one random block; particles and log-weights stored in fp32: about half "
         "the memory per particle; each step computed in fp32 where the model's dynamics take it (sine, linear, ou), "
         "else in fp64; sums in fp64)")
      ->capture_default_str();
  app.add_option("--step-pairs", o.step_pairs,
                 "PF takes two steps per pass over its particles, the bank scoring one step behind: auto (where its "
                 "kernel fuses them, i.e. on GPUs with systematic resampling, and the second particle bank fits in "
                 "memory), never, or always (elsewhere the two steps one after the other: the same numbers as never)")
      ->capture_default_str();
  app.add_option_function<double>(
      "--checkpoint-every",
      [&o](double seconds) {
        o.checkpoint_every = seconds;
        o.checkpoint_every_given = true;
      },
      "save the run's state into --out every SECONDS (0: after every step); `kushner resume DIR` continues it. "
      "SIGINT and SIGTERM save it too");
}

void add_compare_options(CLI::App& app, CompareOptions& o) {
  add_filter_options(app, o);
  app.add_option("--trajectory-members", o.trajectory_members,
                 "members whose truth, estimates and bands go to trajectories.csv (comma-separated)")
      ->delimiter(',')
      ->capture_default_str()
      ->transform(whole_number_notation());
  app.add_option("--density-times", o.density_times,
                 "times of the density snapshots of x1 (comma-separated; default T/10, T/2, T)")
      ->delimiter(',');
  app.add_flag("!--no-plots", o.plots, "write the CSV and JSON files only (no plots, no report.md)");
}

ParticleSettings particle_settings(const FilterOptions& o) {
  KUSHNER_INPUT_REQUIRE(o.particles >= 1, "--particles: must be at least 1 (got " << o.particles << ")");
  KUSHNER_INPUT_REQUIRE(o.ess_threshold >= 0.0 && o.ess_threshold <= 1.0,
                        "--ess-threshold: must be in [0, 1] (got " << o.ess_threshold << ")");
  ParticleSettings settings;
  settings.particles = o.particles;
  const std::optional<ResamplingScheme> scheme = resampling_scheme_named(o.resample);
  KUSHNER_INPUT_REQUIRE(scheme.has_value(), "--resample: unknown scheme '"
                                                << o.resample
                                                << "' (known: multinomial, residual, stratified, systematic)");
  settings.options.scheme = *scheme;
  settings.options.ess_threshold = o.ess_threshold;
  const std::optional<ParticlePrecision> precision = particle_precision_named(o.precision);
  KUSHNER_INPUT_REQUIRE(precision.has_value(),
                        "--precision: unknown precision '" << o.precision << "' (known: fp64, mixed, fp32)");
  settings.options.precision = *precision;
  KUSHNER_INPUT_REQUIRE(o.step_pairs == "auto" || o.step_pairs == "always" || o.step_pairs == "never",
                        "--step-pairs: unknown value '" << o.step_pairs << "' (known: auto, always, never)");
  settings.step_pairs = o.step_pairs == "auto"     ? StepPairs::automatic
                        : o.step_pairs == "always" ? StepPairs::always
                                                   : StepPairs::never;
  return settings;
}

std::string option_flag(const std::string& name) {
  std::string flag = "--" + name;
  std::replace(flag.begin(), flag.end(), '_', '-');
  return flag;
}

OptionValues filter_option_values(const FilterOptions& o) {
  OptionValues values;
  for (const OptionSpec& spec : all_filter_options()) {
    const auto given = o.filter_settings.find(spec.name);
    if (given == o.filter_settings.end()) {
      values.set(spec.name, spec.default_value);
      continue;
    }
    const std::string& text = given->second;
    const std::optional<Value> value = parse_value(text, spec.kind);
    KUSHNER_INPUT_REQUIRE(value.has_value(), option_flag(spec.name)
                                                 << ": expected "
                                                 << (spec.kind == OptionSpec::Kind::integer ? "an integer" : "a number")
                                                 << " (got '" << text << "')");
    const std::string problem = option_value_problem(spec, *value);
    KUSHNER_INPUT_REQUIRE(problem.empty(), option_flag(spec.name) << ": " << problem);
    values.set(spec.name, *value);
  }
  for (const auto& given : o.filter_settings)
    KUSHNER_REQUIRE(values.has(given.first), "no filter declares the option '" << given.first << "'");
  return values;
}

}  // namespace kushner
