#pragma once
// The particle filter's settings, as the command line reads them and the particle-filter bank takes them: no Kokkos
// header, so that the option parsers compile on the host alone (cmake/host_only.cmake).
#include "kernels/particle_filter/particle_precision.hpp"
#include "kernels/particle_filter/resampling_scheme.hpp"

namespace kushner {

/// Which step kernel runs: the host's SIMD block kernel, or the team kernel written for GPUs (which also
/// runs on host spaces, for testing it where there is no GPU).
enum class ParticleKernel { automatic, host_block, team };

/// Where the particles start: the filters' prior N(prior_mean, prior_cov) (default: the reference then
/// answers "what is the optimal estimate given what the filters assume"), or the truths' law
/// N(x0_mean, x0_cov).
enum class ParticleInitialLaw { prior, truth };

struct ParticleFilterOptions {
  ResamplingScheme scheme = ResamplingScheme::systematic;
  double ess_threshold = 0.5;  // resample a member when ESS < ess_threshold * N
  ParticleInitialLaw initial_law = ParticleInitialLaw::prior;
  ParticleKernel kernel = ParticleKernel::automatic;
  int team_size = 0;             // team kernel and resampling: 0 = the backend's default
  int particles_per_thread = 0;  // team kernel: 0 = device_particles_per_thread<stored>
  ParticlePrecision precision = ParticlePrecision::fp64;
};

/// When the particle filter takes two steps per call (ParticleFilterBank::step_pair) and the bank scores one
/// step behind for it: where its kernel fuses the two steps into one pass over the particles (the GPU's), always
/// (the two steps one after the other where it does not fuse them: the same numbers as `never`, which tests
/// check), or never.
enum class StepPairs { automatic, always, never };

/// Whether the particle filter takes step pairs under `step_pairs`, given whether its kernel fuses them.
inline bool takes_step_pairs(StepPairs step_pairs, bool fuses) {
  return step_pairs == StepPairs::always || (step_pairs == StepPairs::automatic && fuses);
}

/// Particle-filter settings of `kushner filter` and `kushner compare`.
struct ParticleSettings {
  int particles = 1024;
  ParticleFilterOptions options;
  StepPairs step_pairs = StepPairs::automatic;
};

}  // namespace kushner
