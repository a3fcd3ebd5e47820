#include "drivers/filter_options.hpp"
#include "kernels/errors.hpp"

#include <cmath>

namespace kushner {

void add_filter_options(CLI::App& app, FilterOptions& o) {
  add_run_options(app, o.run);
  app.add_option("--filters", o.filters, "comma-separated filters, or all (see `kushner filters`)")
      ->capture_default_str();
  app.add_option("--qlf-expectations", o.qlf_expectations,
                 "QLF's Gaussian expectations: closed (the model's formulas), cubature (Gauss-Hermite), or auto "
                 "(closed where the model has them)")
      ->check(CLI::IsMember({"auto", "closed", "cubature"}))
      ->capture_default_str();
  app.add_option("--gh-nodes", o.gh_nodes, "Gauss-Hermite nodes per axis for QLF cubature")->capture_default_str();
  app.add_option("--asre-tolerance", o.asre_tolerance,
                 "ASRE stops iterating when max_t |m^[i](t) - m^[i-1](t)| is below this")
      ->capture_default_str();
  app.add_option("--asre-max-iterations", o.asre_max_iterations, "ASRE iterations at most")->capture_default_str();
  app.add_option("--particles", o.particles, "particles per member of the particle filter (PF)")
      ->capture_default_str();
  app.add_option("--resample", o.resample, "PF resampling scheme: systematic, stratified, multinomial, residual")
      ->capture_default_str();
  app.add_option("--ess-threshold", o.ess_threshold,
                 "PF resamples a member when its effective sample size falls below this fraction of --particles")
      ->capture_default_str();
}

void add_compare_options(CLI::App& app, CompareOptions& o) {
  add_filter_options(app, o);
  app.add_option("--trajectory-members", o.trajectory_members,
                 "members whose truth, estimates and bands go to trajectories.csv (comma-separated)")
      ->delimiter(',')
      ->capture_default_str();
  app.add_option("--density-times", o.density_times,
                 "1-D models: times of the density snapshots (comma-separated; default T/10, T/2, T)")
      ->delimiter(',');
  app.add_flag("!--no-plots", o.plots, "write the CSV and JSON files only (no plots, no report.md)");
}

ParticleSettings particle_settings(const FilterOptions& o) {
  KUSHNER_INPUT_REQUIRE(o.particles >= 1, "--particles: must be at least 1 (got " << o.particles << ")");
  KUSHNER_INPUT_REQUIRE(o.ess_threshold >= 0.0 && o.ess_threshold <= 1.0,
                        "--ess-threshold: must be in [0, 1] (got " << o.ess_threshold << ")");
  ParticleSettings settings;
  settings.particles = o.particles;
  settings.options.scheme = parse_resampling_scheme(o.resample);
  settings.options.ess_threshold = o.ess_threshold;
  return settings;
}

FilterConfig filter_config(const FilterOptions& o) {
  FilterConfig config;
  config.qlf_expectations = o.qlf_expectations == "closed"     ? Expectations::closed
                            : o.qlf_expectations == "cubature" ? Expectations::cubature
                                                               : Expectations::automatic;
  KUSHNER_INPUT_REQUIRE(o.gh_nodes >= 1 && o.gh_nodes <= max_gauss_hermite_nodes,
                        "--gh-nodes: must be in 1 .. " << max_gauss_hermite_nodes << " (got " << o.gh_nodes << ")");
  KUSHNER_INPUT_REQUIRE(std::isfinite(o.asre_tolerance) && o.asre_tolerance > 0.0,
                        "--asre-tolerance: must be positive (got " << o.asre_tolerance << ")");
  KUSHNER_INPUT_REQUIRE(o.asre_max_iterations >= 1 && o.asre_max_iterations <= 1000,
                        "--asre-max-iterations: must be in 1 .. 1000 (got " << o.asre_max_iterations << ")");
  config.gh_nodes = o.gh_nodes;
  config.asre_tolerance = o.asre_tolerance;
  config.asre_max_iterations = o.asre_max_iterations;
  return config;
}

}  // namespace kushner
