#pragma once
// The particle filter's tuning constants, in one place. None of them changes a result except where its line
// says so (host_particle_block, the team size and its particles per thread fix the order of the weight sums, so they
// fix the last bits); the rest only change speed. How each value was chosen, with the measurements, is in
// perf/particle_filter.md ("Tuning constants").

#include <type_traits>

namespace kushner {

// --- Propagate + weight + block moments (particle_block_step.hpp, particle_team_step.hpp) -------------------

/// Host kernel: particles per block. A block's arrays (draws, log-weights, deviations) stay in L1, and the
/// (block, member) pairs are the units of parallel work. Fixes the order of the host's sums.
constexpr int host_particle_block = 256;

/// GPU team kernel: threads per team. Fixes the order of the GPU's sums.
constexpr int device_particle_team = 256;
/// GPU team kernel: particles per thread (particles stored as Real), so a team's chunk is device_particle_team * this
/// many particles. Fixes the order of the GPU's sums. fp32 takes 32: its team sums and barriers cost half as much per
/// particle (fp32's fused pass x1.04 on an H100); fp64 x1.02 and mixed x0.98 with 32: both keep 16, and their bits.
template <class Real>
constexpr int device_particles_per_thread = std::is_same_v<Real, float> ? 32 : 16;
/// GPU team kernel: particles a thread loads before it computes (one Philox block draws for a pair), so a warp
/// keeps a batch of loads in flight while the draws are computed. Larger batches need more registers than the
/// launch bound below leaves.
constexpr int device_particle_batch = 2;
/// GPU team kernel: teams resident per multiprocessor, as the launch bound (4 x 256 threads caps the kernel
/// at 64 registers; more occupancy beat fewer spills).
constexpr int device_particle_teams_per_sm = 4;

// --- Resampling (particle_resample_step.hpp, chunked_systematic_resample.hpp, blocked_scan.hpp) -------------

/// GPU threads per team of the one-team-per-member resampling (schemes other than systematic): a resampled
/// member's loops are latency-bound, so one member gets a whole block of threads.
constexpr int device_resample_team = 1024;
/// Particles a thread of that kernel loads before it stores (latency hiding).
constexpr int resample_step_batch = 8;
/// Entries a thread loads at once in the blocked scan's sequential loops.
constexpr int scan_batch = 16;

/// Chunked systematic resampling (the GPU's systematic path): threads per team, and the fixed league that
/// loops over the (listed member, chunk) work items (how many members resample stays on the device).
constexpr int device_chunked_resample_team = 256;
constexpr int chunked_resample_league = 1024;
/// Its chunks: at most this many particles (whole scan blocks; their weights live in team scratch).
constexpr int resample_chunk_particles = 2048;
/// Its threads load this many particles at once: a chunk of 2048 is 8 per thread of a 256-thread team.
constexpr int resample_batch = 8;

// --- Kernels over the listed members (ParticleFilterBank::step_pair's redo) ---------------------------------

/// Fixed league of the team kernel over the listed members' chunks.
constexpr int listed_team_league = 1024;

}  // namespace kushner
