// Prints the particle filter's per-member outputs (posterior mean, covariance, ESS, resampling count) as
// exact hexadecimal floats, for the reproducibility test (cli/test_particle_filter_reproducibility.sh) to
// compare byte for byte across thread counts and backends. The backend comes from KUSHNER_BACKEND, the
// threads from OMP_NUM_THREADS, as for the kushner command. `particle_filter_dump car` prints Basin's car
// instead (no process noise: tan drift, deterministic particles between resamplings), for looking at how a
// GPU run departs from a host one.
#include "engine/backend.hpp"
#include "engine/particle_filter_bank.hpp"
#include "engine/truth_bank.hpp"
#include "models/car_model.hpp"
#include "models/cubic_oscillator_model.hpp"
#include "models/linear_model.hpp"
#include "models/sine_model.hpp"

#include <cstdio>
#include <string>

namespace kushner {
namespace {

template <class Space, class Model>
void dump(const char* label, Model model, int members, int particles, int steps, double dt, ResamplingScheme scheme) {
  const Space space;
  TruthBank<Space, Model> truth(space, model, members, 11);
  ParticleFilterBank<Space, Model> pf(space, model, members, particles, 12, scheme, 0.5);
  for (int k = 0; k < steps; ++k) {
    truth.step(k, dt);
    pf.step(k, dt, truth.observations());
  }
  space.fence();
  const auto mean = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), pf.posterior_mean());
  const auto cov = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), pf.posterior_covariance());
  const auto ess = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), pf.effective_sample_size());
  const auto count = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), pf.resample_count());
  for (int m = 0; m < members; ++m) {
    std::printf("%s %d", label, m);
    for (int i = 0; i < mean.extent_int(1); ++i) std::printf(" %a", mean(m, i));
    for (int k = 0; k < cov.extent_int(1); ++k) std::printf(" %a", cov(m, k));
    std::printf(" %a %d\n", ess(m), count(m));
  }
}

}  // namespace
}  // namespace kushner

int main(int argc, char** argv) {
  const std::string backend = kushner::selected_backend();
  kushner::KokkosSession session(backend);
  const bool car = argc > 1 && std::string(argv[1]) == "car";
  kushner::with_backend(backend, [car](const auto& space) {
    using Space = std::decay_t<decltype(space)>;
    if (car) {
      kushner::dump<Space>("car", kushner::CarModel{}, 500, 1024, 100, 5e-3, kushner::ResamplingScheme::systematic);
      return;
    }
    kushner::dump<Space>("sine", kushner::SineModel{}, 24, 3000, 300, 1e-2, kushner::ResamplingScheme::systematic);
    kushner::dump<Space>("linear2", kushner::LinearModel<2>{}, 10, 1500, 200, 1e-2,
                         kushner::ResamplingScheme::stratified);
    kushner::CubicOscillatorModel cubic;
    cubic.set_initial_law(kushner::Vec<2>{{1.0, 0.5}}, kushner::Mat<2, 2>::diagonal(0.1));
    kushner::dump<Space>("cubic", cubic, 7, 2000, 200, 1e-2, kushner::ResamplingScheme::residual);
  });
  return 0;
}
