#pragma once
// The particle filter's arithmetic precision, and its names.
#include <optional>
#include <string>

namespace kushner {

/// fp64: every number in double. mixed: particles, log-weights and every sum in double; the normals of the particles'
/// noise and initial states drawn in float from the same Philox blocks (kernels/rng.hpp), cut at 5.77 standard
/// deviations of the radius (probability 2^-24 beyond) and equal to fp64's to about 1e-7; and where the model's
/// dynamics take float (has_float_increments: sine, linear, ou) each Euler-Maruyama increment f dt + G sqrt(dt) z
/// computed in float and added to the double state (the increment is rounded, not the state: a step moves by about
/// 6e-8 of the increment and of |x f'(x)| dt, the drift taken at x rounded to float, as much as the float normal's
/// rounding moves it), and the GPU kernels' weights exp(l - shift) for the moments in float (math::weight_exp). A GPU's
/// float log, sine, Box-Muller and exp cost a fraction of the fp64 ones in a step bound by the card's power cap
/// (H200, sine, `step_pair`: 1.50e11 particle-steps/s against fp64's 8.3e10; perf/particle_filter.md). fp32: the
/// particles and their log-weights (and, while resampling, cumulative weights) stored in float: half the bytes moved
/// per particle-step, and about half the memory per particle (the ancestor index stays an int). Its normals are float
/// ones as mixed's, but two steps take theirs from one Philox block's four words (fp32_pair_normals: the even step's
/// are mixed's, the odd step's its own), half the blocks per particle-step; its initial particles are mixed's. A
/// particle's Euler-Maruyama step is computed in float where the model's dynamics take float (particle_step_scalar),
/// otherwise in double from the stored values, and rounded once where it is stored (the GPU kernels hold such
/// particles in float from load to store); the GPU kernels take the weights' exp in float (math::weight_exp); the
/// normalizers, moments and every sum are taken in double (a float step subtracts its member's normalizer rounded to
/// float: one shift for all of the member's particles, which the normalization takes back).
/// tests/test_particle_filter_references.cpp checks every precision for bias against exact filters.
enum class ParticlePrecision { fp64, mixed, fp32 };

inline const char* to_string(ParticlePrecision p) {
  switch (p) {
    case ParticlePrecision::fp64: return "fp64";
    case ParticlePrecision::mixed: return "mixed";
    case ParticlePrecision::fp32: return "fp32";
  }
  return "unknown";
}

/// f(static_cast<Real*>(nullptr)), with Real the type `precision` stores particles in: float for fp32, double
/// otherwise. Picks ParticleFilterBank's storage type from a run-time precision (f's two results must agree).
template <class F>
decltype(auto) with_particle_storage(ParticlePrecision precision, F&& f) {
  if (precision == ParticlePrecision::fp32) return f(static_cast<float*>(nullptr));
  return f(static_cast<double*>(nullptr));
}

/// The precision called `name`, if there is one.
inline std::optional<ParticlePrecision> particle_precision_named(const std::string& name) {
  for (auto p : {ParticlePrecision::fp64, ParticlePrecision::mixed, ParticlePrecision::fp32})
    if (name == to_string(p)) return p;
  return std::nullopt;
}

}  // namespace kushner
