#pragma once
// The particle-filter reference: N particles for each of M members in one structure-of-arrays bank, advanced
// one observation step at a time. It is the approximation of the true conditional density that every
// finite-dimensional filter is measured against (SPEC section 4): per member and step it gives the
// posterior mean and covariance, the effective sample size and the number of resamplings so far.
//
//   ParticleFilterBank<Kokkos::DefaultExecutionSpace, SineModel> pf(space, model, M, N, seed);
//   for (long k = 0; k < steps; ++k) { truth.step(k, dt); pf.step(k, dt, truth.observations()); }
//   pf.posterior_mean();   // (member, i)
//
// A step is three stages: propagate + weight + block moments (particle_block_step.hpp on the host,
// particle_team_step.hpp on GPUs; particle_update.hpp is the per-particle step both share), per-member posterior
// (particle_posterior.hpp), and resampling of the members whose ESS fell below threshold * N: a team per
// member (particle_resample_step.hpp), or, with the team kernel and systematic resampling (the GPU's
// default), many teams per member (chunked_systematic_resample.hpp; the same indices). Every sum that
// reaches an output is taken in a fixed order, so a seed gives the same bits on 1 or 2 threads and on Serial
// or OpenMP; the GPU differs in the last bits of its math library only.
//
// step_pair takes two steps with one pass over the particles where the team kernel and the chunked
// resampling run (the GPU's default): see step_pair.
#include "core/eigen_helpers.hpp"
#include "core/errors.hpp"
#include "core/linear_algebra.hpp"
#include "engine/particle_settings.hpp"
#include "engine/shared_instances.hpp"
#include "kernels/bank.hpp"
#include "kernels/for_each_member.hpp"
#include "kernels/particle_filter/chunked_systematic_resample.hpp"
#include "kernels/particle_filter/particle_block_step.hpp"
#include "kernels/particle_filter/particle_posterior.hpp"
#include "kernels/particle_filter/particle_resample_step.hpp"
#include "kernels/particle_filter/particle_team_pair_step.hpp"
#include "kernels/particle_filter/particle_team_step.hpp"
#include "kernels/particle_filter/resampling.hpp"
#include "kernels/particle_filter/tuning.hpp"

#include <Kokkos_Core.hpp>

#include <cmath>
#include <cstdint>
#include <type_traits>
#include <utility>

namespace kushner {

/// Largest state dimension of the particle filter: its GPU kernel keeps each thread's weighted moments
/// (3 + n + n(n+1)/2 doubles) in shared memory, which a 10-state model would overflow.
constexpr int max_particle_filter_dim = 4;

/// Why the particle filter cannot run Model, or nullptr.
template <class Model>
constexpr const char* particle_filter_unsupported() {
  if (Model::state_dim > max_particle_filter_dim) return "state dimension above 4";
  return nullptr;
}

/// Real: how the particles and log-weights are stored, double, or float for the fp32 precision (the constructor
/// requires options.precision to match; particle_reference.hpp picks the class).
template <class ExecSpace, class Model, class Real = double>
class ParticleFilterBank {
 public:
  using MemSpace = typename ExecSpace::memory_space;
  static constexpr int state_dim = Model::state_dim;

  ParticleFilterBank(const ExecSpace& space, const Model& model, int num_members, int num_particles, Seed seed,
                     ResamplingScheme scheme = ResamplingScheme::systematic, double ess_threshold = 0.5)
      : ParticleFilterBank(space, model, num_members, num_particles, seed,
                           ParticleFilterOptions{scheme, ess_threshold}) {}

  /// Samples the initial particles and computes the time-0 posterior. Requires members >= 0 (an MPI rank may hold
  /// none: engine/member_share.hpp), particles >= 1 and a threshold in [0, 1] (std::logic_error otherwise: user
  /// input is checked where it is read, drivers/filter_options.cpp).
  ParticleFilterBank(const ExecSpace& space, const Model& model, int num_members, int num_particles, Seed seed,
                     const ParticleFilterOptions& options);

  /// Step k: [k dt, (k + 1) dt] with the members' observation increments dy (member, j) over it, and in a closed
  /// loop the control (member, j) each member's truth was driven by over it (empty: none).
  void step(long k, double dt, const BankVector<MemSpace>& dy, const BankVector<MemSpace>& control = {});

  /// Bytes the bank allocates for `members` members of `particles` particles: per particle its state and the
  /// resampling scratch copy, its log-weight and ancestor index (and offspring count for residual resampling);
  /// per member the block partials (at the smallest block, the host's), the scan's block sums, the posterior, and
  /// the chunked resampling's two list entries. step_pair's second bank is step_pair_bytes_needed.
  static double bytes_needed(long members, long particles, const ParticleFilterOptions& options) {
    return static_cast<double>(members) *
           (bytes_per_particle(options) * static_cast<double>(particles) + bytes_per_member(particles));
  }
  static double bytes_per_particle(const ParticleFilterOptions& options) {
    return (2.0 * state_dim + 1.0) * stored_bytes(options) + sizeof(int) +
           (options.scheme == ResamplingScheme::residual ? sizeof(int) : 0);
  }
  /// Bytes of one stored particle coordinate or log-weight under `options`' precision.
  static double stored_bytes(const ParticleFilterOptions& options) {
    return options.precision == ParticlePrecision::fp32 ? sizeof(float) : sizeof(double);
  }
  static double bytes_per_member(long particles) {
    const double blocks = static_cast<double>((particles + host_particle_block - 1) / host_particle_block);
    return sizeof(double) * (blocks * WeightedMoments<state_dim>::size + scan_num_blocks(static_cast<int>(particles)) +
                             2.0 + 2.0 * state_dim + packed_size(state_dim)) +
           4.0 * sizeof(int) + sizeof(Status);
  }

  /// Bytes step_pair allocates besides bytes_needed when it fuses its steps: a second bank of states and
  /// log-weights, the second step's block partials (at the host's block, an upper bound) and step k's posterior.
  static double step_pair_bytes_needed(long members, long particles, const ParticleFilterOptions& options) {
    const double blocks = static_cast<double>((particles + host_particle_block - 1) / host_particle_block);
    return static_cast<double>(members) *
           (step_pair_bytes_per_particle(options) * static_cast<double>(particles) +
            sizeof(double) * (blocks * WeightedMoments<state_dim>::size + 2.0 + state_dim + packed_size(state_dim)) +
            sizeof(Status));
  }
  /// The second bank's state and log-weight.
  static double step_pair_bytes_per_particle(const ParticleFilterOptions& options) {
    return stored_bytes(options) * (state_dim + 1.0);
  }

  /// Whether a bank with `options` and `particles` particles per member fuses step_pair's two steps (the team
  /// kernel with chunked systematic resampling).
  static bool fuses_step_pairs(const ParticleFilterOptions& options, int particles) {
    return uses_team_kernel(options) && options.scheme == ResamplingScheme::systematic &&
           chunked_resample_supports(particles);
  }

  /// Steps k and k + 1 (increments dy, then dy_next): the same results as step(k) then step(k + 1), apart
  /// from the last bits of the sums. With the team kernel and systematic resampling (the GPU's default) the
  /// particles go through memory once for both steps: ParticleTeamPairStep reads the bank and writes a
  /// second one, and the members that step k resamples (whose step k + 1 used the wrong particles) are stepped
  /// again from the untouched first bank: step k, resampling, step k + 1, on the listed members only.
  /// Otherwise it is the two steps. Afterwards the posterior accessors give step k + 1 and first_step()
  /// step k.
  void step_pair(long k, double dt, const BankVector<MemSpace>& dy, const BankVector<MemSpace>& dy_next);

  /// The posterior after the first step of the last step_pair (allocated by the first step_pair): (member, i),
  /// (member, packed), (member), and the members' status then.
  struct PosteriorViews {
    BankVector<MemSpace> mean;
    BankSymmetric<MemSpace> covariance;
    BankScalar<double, MemSpace> ess;
    BankScalar<Status, MemSpace> status;
  };
  const PosteriorViews& first_step() const { return first_; }
  /// Whether step_pair takes its two steps in one pass over the particles (else it is two steps).
  bool fuses_step_pairs() const { return use_chunked_resample_; }

  int num_members() const { return num_members_; }
  int num_particles() const { return num_particles_; }
  const ParticleFilterOptions& options() const { return options_; }

  /// (member, i): posterior mean after the last step.
  const BankVector<MemSpace>& posterior_mean() const { return mean_; }
  /// (member, k): posterior covariance, packed upper triangle (kushner/bank.hpp).
  const BankSymmetric<MemSpace>& posterior_covariance() const { return covariance_; }
  /// (member): effective sample size (sum w)^2 / sum w^2 of the last step, before any resampling.
  const BankScalar<double, MemSpace>& effective_sample_size() const { return ess_; }
  /// (member): resamplings so far.
  const BankScalar<int, MemSpace>& resample_count() const { return resample_count_; }
  /// (member, i): sqrt(P_ii / ESS), the Monte Carlo standard error of the posterior mean as if the ESS
  /// particles were independent draws from the posterior (Kong, Liu & Wong 1994). It ignores the variance
  /// that earlier resamplings added, so it understates the error; independent seeds give the honest figure.
  BankVector<MemSpace> monte_carlo_standard_error() const;
  /// (member): ok, or non_finite once every particle of the member has left the finite numbers.
  const BankScalar<Status, MemSpace>& status() const { return status_; }
  /// (particle, member, i) and (particle, member): the particles and their log-weights; the normalized weight
  /// of particle j is exp(log_weights(j, m) - log_normalizer(m)).
  const ParticleBank<MemSpace, Real>& particles() const { return x_; }
  const ParticleColumn<MemSpace, Real>& log_weights() const { return workspace_.cumulative; }
  const BankScalar<double, MemSpace>& log_normalizer() const { return log_normalizer_; }

  /// What a checkpoint holds: the particles, their log-weights and everything a step reads from the step
  /// before. Scratch (the resampling copy, ancestors, partial sums) is rewritten by every step, and so are
  /// step_pair's second bank and first-step posterior (a checkpoint is taken between pairs).
  template <class Archive>
  void visit_state(Archive& archive) {
    archive.view("particles", x_);
    archive.view("log_weights", workspace_.cumulative);
    archive.view("log_normalizer", log_normalizer_);
    archive.view("reference", reference_);
    archive.view("mean", mean_);
    archive.view("covariance", covariance_);
    archive.view("ess", ess_);
    archive.view("resample_now", resample_);
    archive.view("resample_count", resample_count_);
    archive.view("status", status_);
  }

 private:
  static bool uses_team_kernel(const ParticleFilterOptions& options) {
    return options.kernel == ParticleKernel::team ||
           (options.kernel == ParticleKernel::automatic && !std::is_same<MemSpace, Kokkos::HostSpace>::value);
  }

  void require_increments_shape(const BankVector<MemSpace>& dy) const {
    KUSHNER_REQUIRE(dy.extent_int(0) == num_members_ && dy.extent_int(1) == Model::obs_dim,
                    "dy has shape (" << dy.extent(0) << ", " << dy.extent(1) << "), expected (" << num_members_ << ", "
                                     << Model::obs_dim << ")");
  }

  /// (R R^T)^{-1} at t; the identity for a discrete-time model (its weights read z itself).
  Mat<Model::obs_dim, Model::obs_dim> observation_precision(double t) const {
    constexpr int p = Model::obs_dim;
    if constexpr (Model::discrete_time) return Mat<p, p>::identity();
    const Mat<p, p> r = model_.observation_noise(t);
    Mat<p, p> root;
    KUSHNER_REQUIRE(cholesky(r * transpose(r), root),
                    Model::name << ": observation noise R R^T not positive definite at t=" << t);
    return cholesky_inverse(root);
  }

  ParticleStepData<Model, MemSpace, Real> step_data(double t, double dt, std::uint32_t step,
                                                    const BankVector<MemSpace>& dy) const {
    ParticleStepData<Model, MemSpace, Real> d;
    d.model = model_;
    d.x = x_;
    d.log_weight = workspace_.cumulative;
    d.log_normalizer = log_normalizer_;
    d.reference = reference_;
    d.dy = dy;
    d.status = status_;
    d.partials = partials_;
    d.observation_precision = observation_precision(t);
    d.initial_mean = Vec<Model::state_dim>::zero();
    d.initial_root = Mat<Model::state_dim, Model::state_dim>::zero();
    d.t = t;
    d.set_step_length(dt);
    d.seed = seed_;
    d.step = step;
    d.num_particles = num_particles_;
    d.block_size = block_size_;
    d.fp32_normals = options_.precision != ParticlePrecision::fp64;
    return d;
  }

  void run_step_kernels(const ParticleStepData<Model, MemSpace, Real>& d) {
    constexpr int n = state_dim;
    if (use_team_) {
      with_team_arithmetic(
          [&](auto mixed) { run_team_kernel(ParticleTeamStep<Model, ExecSpace, Real, decltype(mixed)::value>{d}); });
    } else {
      run_host_block_kernel(d);
    }
    run_posterior(partials_, current_posterior(), log_normalizer_, true);
    if (d.initialize) return;
    if (use_chunked_resample_) {
      resample_listed(resample_data(log_normalizer_, d.step));
      return;
    }
    if constexpr (!std::is_same<MemSpace, Kokkos::HostSpace>::value) {
      // A team per member, most of which return at once; the few that resample are latency-bound, so they
      // get big teams (the launch bound keeps the kernel within the registers 1024 threads have).
      const int team = options_.team_size > 0 ? options_.team_size : device_resample_team;
      Kokkos::TeamPolicy<ExecSpace, Kokkos::LaunchBounds<device_resample_team, 1>> policy(space_, num_members_, team);
      policy.set_scratch_size(0, Kokkos::PerTeam(sizeof(double) * scan_num_blocks(num_particles_)));
      Kokkos::parallel_for(
          "kushner::particle_resample", policy,
          ParticleResampleStep<n, ExecSpace, Real>{x_, x_scratch_, workspace_, log_normalizer_, resample_,
                                                   num_particles_, options_.scheme, seed_, d.step});
      return;
    }
    Kokkos::TeamPolicy<ExecSpace> policy(space_, num_members_, team_size_);
    policy.set_scratch_size(0, Kokkos::PerTeam(sizeof(double) * scan_num_blocks(num_particles_)));
    Kokkos::parallel_for(
        "kushner::particle_resample", policy,
        ParticleResampleStep<n, ExecSpace, Real>{x_, x_scratch_, workspace_, log_normalizer_, resample_, num_particles_,
                                                 options_.scheme, seed_, d.step});
  }

  /// The posterior of a step from its block partials, into `out` and `log_normalizer` (the members' status into
  /// out.status too, where that is not the bank's own); resampling decisions and counts into the bank's, and the
  /// members to resample into the next of its two lists (whose size it found zero), the other list's size set to zero
  /// for the posterior after.
  void run_posterior(const Kokkos::View<double***, Kokkos::LayoutLeft, MemSpace>& partials, const PosteriorViews& out,
                     const BankScalar<double, MemSpace>& log_normalizer, bool update_reference) {
    ParticlePosterior<state_dim, MemSpace> posterior{
        partials, num_blocks_,    reference_, update_reference, out.mean, out.covariance,
        out.ess,  log_normalizer, resample_,  resample_count_,  status_,  options_.ess_threshold * num_particles_};
    if (use_chunked_resample_) {
      list_ = 1 - list_;
      posterior.resample_list = resample_lists_[list_];
      posterior.resample_list_size = resample_list_sizes_[list_];
      posterior.next_list_size = resample_list_sizes_[1 - list_];
    }
    if (out.status.data() != status_.data()) posterior.status_copy = out.status;
    parallel_for_members("kushner::particle_posterior", space_, num_members_, posterior);
  }

  PosteriorViews current_posterior() const { return {mean_, covariance_, ess_, status_}; }

  /// Chunked systematic resampling, in place, of the listed members at `step`, from the log-weights less
  /// `log_normalizer`.
  ChunkedResampleData<MemSpace, Real> resample_data(const BankScalar<double, MemSpace>& log_normalizer,
                                                    std::uint32_t step) const {
    return {x_,
            x_scratch_,
            workspace_.cumulative,
            workspace_.ancestors,
            block_sums_,
            log_normalizer,
            resample_lists_[list_],
            resample_list_sizes_[list_],
            num_particles_,
            seed_,
            step};
  }
  void resample_listed(const ChunkedResampleData<MemSpace, Real>& r) {
    // A fixed league loops over (member, chunk) items: the number of members to resample stays on the device.
    const long items = static_cast<long>(num_members_) * resample_chunks(num_particles_);
    const int league = static_cast<int>(items < chunked_resample_league ? items : chunked_resample_league);
    constexpr bool host_memory = std::is_same<MemSpace, Kokkos::HostSpace>::value;
    chunked_systematic_resample<state_dim>(space_, r, host_memory ? team_size_ : device_chunked_resample_team, league);
  }

  void allocate_first_step() {
    if (first_.mean.extent(0) > 0) return;
    first_ = {BankVector<MemSpace>("kushner::particle_mean_first", num_members_, state_dim),
              BankSymmetric<MemSpace>("kushner::particle_covariance_first", num_members_, packed_size(state_dim)),
              BankScalar<double, MemSpace>("kushner::ess_first", num_members_),
              BankScalar<Status, MemSpace>("kushner::particle_status_first", num_members_)};
    first_log_normalizer_ = BankScalar<double, MemSpace>("kushner::log_normalizer_first", num_members_);
  }

  /// f(std::bool_constant<Mixed>()) with the team kernels' Mixed: true for the mixed precision where the model has
  /// float increments (those kernels of its own), else false (fp64's kernels, and mixed's normals as a run-time flag).
  template <class F>
  void with_team_arithmetic(F&& f) {
    if constexpr (has_mixed_increments<Model, Real>) {
      if (options_.precision == ParticlePrecision::mixed) {
        f(std::true_type());
        return;
      }
    }
    f(std::false_type());
  }

  /// A team kernel (ParticleTeamStep, ParticleTeamPairStep) over every (chunk, member), a team each.
  template <class Kernel>
  void run_team_kernel(const Kernel& kernel) {
    launch_team_kernel<Kernel>(static_cast<long>(num_blocks_) * num_members_,
                               EveryMemberChunk<Kernel>{kernel, num_blocks_});
  }

  /// ... over the chunks of the members on the last posterior's resampling list only: a fixed league loops over them.
  template <class Kernel>
  void run_team_kernel_listed(const Kernel& kernel) {
    const long items = static_cast<long>(num_blocks_) * num_members_;
    launch_team_kernel<Kernel>(
        items < listed_team_league ? items : listed_team_league,
        ListedMemberChunks<Kernel>{kernel, resample_lists_[list_], resample_list_sizes_[list_], num_blocks_});
  }

  /// Launched with its arguments as kernel parameters (Kokkos' light-weight hint): the functor is over the 512
  /// bytes below which Kokkos does that by default, and copies larger ones to constant memory first. At the
  /// default team size, with the launch bound of tuning.hpp.
  template <class Kernel, class Launcher>
  void launch_team_kernel(long league, const Launcher& launcher) {
    using LightWeight = Kokkos::Experimental::WorkItemProperty::HintLightWeight_t;
    if (team_size_ == device_particle_team) {
      Kokkos::TeamPolicy<ExecSpace, Kokkos::LaunchBounds<device_particle_team, device_particle_teams_per_sm>,
                         LightWeight>
          policy(space_, static_cast<int>(league), team_size_);
      policy.set_scratch_size(0, Kokkos::PerTeam(Kernel::scratch_bytes(team_size_)));
      Kokkos::parallel_for("kushner::particle_team_step", policy, launcher);
      return;
    }
    Kokkos::TeamPolicy<ExecSpace, LightWeight> policy(space_, static_cast<int>(league), team_size_);
    policy.set_scratch_size(0, Kokkos::PerTeam(Kernel::scratch_bytes(team_size_)));
    Kokkos::parallel_for("kushner::particle_team_step", policy, launcher);
  }

  void run_host_block_kernel(const ParticleStepData<Model, MemSpace, Real>& d) {
    if constexpr (std::is_same<MemSpace, Kokkos::HostSpace>::value) {
      Kokkos::parallel_for("kushner::particle_block_step",
                           Kokkos::RangePolicy<ExecSpace>(space_, 0, num_blocks_ * num_members_),
                           ParticleBlockStep<Model, Real>{d, num_blocks_});
    }
  }

  ExecSpace space_;
  Model model_;
  ParticleFilterOptions options_;
  Seed seed_;
  int num_members_, num_particles_;
  bool use_team_ = false;
  int block_size_ = 0, num_blocks_ = 0, team_size_ = 1;
  ParticleBank<MemSpace, Real> x_, x_scratch_;
  ResamplingWorkspace<MemSpace, Real> workspace_;
  // step_pair: the second bank, the second step's partials, step k's posterior.
  ParticleBank<MemSpace, Real> x_next_;
  ParticleColumn<MemSpace, Real> log_weight_next_;
  Kokkos::View<double***, Kokkos::LayoutLeft, MemSpace> partials_next_;
  PosteriorViews first_;
  BankScalar<double, MemSpace> first_log_normalizer_;
  bool use_chunked_resample_ = false;
  // The chunked resampling's two lists of members to resample, taken in turn by the posterior kernels (the last one's:
  // list_), each list's size zeroed by the posterior kernel before the one that appends to it.
  Kokkos::View<int*, MemSpace> resample_lists_[2];
  Kokkos::View<int, MemSpace> resample_list_sizes_[2];
  int list_ = 0;
  Kokkos::View<double**, Kokkos::LayoutLeft, MemSpace> block_sums_;
  Kokkos::View<double***, Kokkos::LayoutLeft, MemSpace> partials_;
  BankScalar<double, MemSpace> log_normalizer_, ess_;
  BankVector<MemSpace> reference_, mean_;
  BankSymmetric<MemSpace> covariance_;
  BankScalar<int, MemSpace> resample_, resample_count_;
  BankScalar<Status, MemSpace> status_;
};

template <class ExecSpace, class Model, class Real>
ParticleFilterBank<ExecSpace, Model, Real>::ParticleFilterBank(const ExecSpace& space, const Model& model,
                                                               int num_members, int num_particles, Seed seed,
                                                               const ParticleFilterOptions& options)
    : space_(space),
      model_(model),
      options_(options),
      seed_(seed),
      num_members_(num_members),
      num_particles_(num_particles) {
  KUSHNER_REQUIRE(num_members >= 0, "members: " << num_members);
  KUSHNER_REQUIRE(num_particles >= 1, "particles: " << num_particles);
  KUSHNER_REQUIRE(options.ess_threshold >= 0.0 && options.ess_threshold <= 1.0,
                  "ess_threshold: " << options.ess_threshold);
  static_assert(std::is_same_v<Real, double> || std::is_same_v<Real, float>);
  constexpr bool stores_float = std::is_same_v<Real, float>;
  KUSHNER_REQUIRE((options.precision == ParticlePrecision::fp32) == stores_float,
                  "ParticleFilterBank: precision " << to_string(options.precision) << " stored as "
                                                   << (stores_float ? "float" : "double"));
  use_team_ = uses_team_kernel(options);
  constexpr bool host_memory = std::is_same<MemSpace, Kokkos::HostSpace>::value;
  KUSHNER_REQUIRE(use_team_ || host_memory, "the host block kernel needs host memory");
  team_size_ = options.team_size > 0 ? options.team_size : (host_memory ? 1 : device_particle_team);
  const int per_thread =
      options.particles_per_thread > 0 ? options.particles_per_thread : device_particles_per_thread<Real>;
  // The team kernel on the host (tests) keeps 1024-particle chunks, so small tests still merge several.
  block_size_ = use_team_ ? (host_memory ? 1024 : team_size_ * per_thread) : host_particle_block;
  num_blocks_ = (num_particles + block_size_ - 1) / block_size_;
  KUSHNER_REQUIRE(block_size_ % 2 == 0,
                  "particle blocks must hold whole pairs of particles (block of " << block_size_ << ")");

  const int n = state_dim;
  x_ = ParticleBank<MemSpace, Real>("kushner::particles", num_particles, num_members, n);
  x_scratch_ = ParticleBank<MemSpace, Real>("kushner::particles_scratch", num_particles, num_members, n);
  workspace_.cumulative = decltype(workspace_.cumulative)("kushner::log_weights", num_particles, num_members);
  workspace_.ancestors = decltype(workspace_.ancestors)("kushner::ancestors", num_particles, num_members);
  use_chunked_resample_ = fuses_step_pairs(options, num_particles);
  if (use_chunked_resample_) {
    for (int i = 0; i < 2; ++i) {
      resample_lists_[i] = Kokkos::View<int*, MemSpace>("kushner::resample_list", num_members);
      resample_list_sizes_[i] = Kokkos::View<int, MemSpace>("kushner::resample_list_size");
    }
    block_sums_ = decltype(block_sums_)("kushner::resample_block_sums", scan_num_blocks(num_particles), num_members);
  }
  if (options.scheme == ResamplingScheme::residual)
    workspace_.copies = decltype(workspace_.copies)("kushner::offspring", num_particles, num_members);
  partials_ = decltype(partials_)("kushner::particle_partials", num_blocks_, num_members, WeightedMoments<n>::size);
  log_normalizer_ = BankScalar<double, MemSpace>("kushner::log_normalizer", num_members);
  reference_ = BankVector<MemSpace>("kushner::particle_reference", num_members, n);
  mean_ = BankVector<MemSpace>("kushner::particle_mean", num_members, n);
  covariance_ = BankSymmetric<MemSpace>("kushner::particle_covariance", num_members, packed_size(n));
  ess_ = BankScalar<double, MemSpace>("kushner::ess", num_members);
  resample_ = BankScalar<int, MemSpace>("kushner::resample_now", num_members);
  resample_count_ = BankScalar<int, MemSpace>("kushner::resample_count", num_members);
  status_ = BankScalar<Status, MemSpace>("kushner::particle_status", num_members);

  const bool prior = options.initial_law == ParticleInitialLaw::prior;
  const Vec<n> initial_mean = prior ? model.prior_mean : model.x0_mean;
  const Mat<n, n> initial_root = covariance_square_root(prior ? model.prior_cov : model.x0_cov);
  auto reference = Kokkos::create_mirror_view(reference_);  // moments are taken relative to the initial mean
  for (int m = 0; m < num_members; ++m) store(reference, m, initial_mean);
  Kokkos::deep_copy(space_, reference_, reference);
  ParticleStepData<Model, MemSpace, Real> d = step_data(0.0, 0.0, 0, BankVector<MemSpace>());
  d.initialize = true;
  d.initial_mean = initial_mean;
  d.initial_root = initial_root;
  run_step_kernels(d);
}

template <class ExecSpace, class Model, class Real>
void ParticleFilterBank<ExecSpace, Model, Real>::step(long k, double dt, const BankVector<MemSpace>& dy,
                                                      const BankVector<MemSpace>& control) {
  require_increments_shape(dy);
  KUSHNER_REQUIRE(k >= 0 && k < (1L << 32), "step " << k << " outside the counter range");
  KUSHNER_REQUIRE(
      control.extent(0) == 0 || (control.extent_int(0) == num_members_ && control.extent_int(1) == Model::control_dim),
      "control bank has shape (" << control.extent(0) << ", " << control.extent(1) << ")");
  ParticleStepData<Model, MemSpace, Real> d = step_data(k * dt, dt, static_cast<std::uint32_t>(k), dy);
  d.control = control;
  run_step_kernels(d);
}

template <class ExecSpace, class Model, class Real>
void ParticleFilterBank<ExecSpace, Model, Real>::step_pair(long k, double dt, const BankVector<MemSpace>& dy,
                                                           const BankVector<MemSpace>& dy_next) {
  KUSHNER_REQUIRE(k >= 0 && k + 1 < (1L << 32), "steps " << k << ", " << k + 1 << " outside the counter range");
  allocate_first_step();
  if (!use_chunked_resample_) {
    step(k, dt, dy);
    Kokkos::deep_copy(space_, first_.mean, mean_);
    Kokkos::deep_copy(space_, first_.covariance, covariance_);
    Kokkos::deep_copy(space_, first_.ess, ess_);
    Kokkos::deep_copy(space_, first_.status, status_);
    step(k + 1, dt, dy_next);
    return;
  }
  require_increments_shape(dy);
  require_increments_shape(dy_next);
  if (x_next_.extent(0) == 0) {
    x_next_ = ParticleBank<MemSpace, Real>("kushner::particles_next", num_particles_, num_members_, state_dim);
    log_weight_next_ = decltype(log_weight_next_)("kushner::log_weights_next", num_particles_, num_members_);
    partials_next_ = decltype(partials_next_)("kushner::particle_partials_next", num_blocks_, num_members_,
                                              WeightedMoments<state_dim>::size);
  }
  const auto first = static_cast<std::uint32_t>(k), second = first + 1;
  const ParticleSecondStep<Model, MemSpace, Real> next{
      x_next_, log_weight_next_, dy_next, partials_next_, observation_precision((k + 1) * dt), (k + 1) * dt};
  with_team_arithmetic([&](auto mixed) {
    run_team_kernel(
        ParticleTeamPairStep<Model, ExecSpace, Real, decltype(mixed)::value>{step_data(k * dt, dt, first, dy), next});
  });
  // The pass's output becomes the bank; its input (step k - 1's particles) stays in the second bank for the redo.
  std::swap(x_, x_next_);
  std::swap(workspace_.cumulative, log_weight_next_);
  // Step k's posterior. The reference point and log-normalizer stay step k - 1's: both steps of the pass
  // were taken relative to them.
  run_posterior(partials_, first_, first_log_normalizer_, false);
  // The members step k resamples: step k again, in the second bank (from step k - 1's particles, no copy of them);
  // resampled from there into the bank (log-weights 0, log-normalizer log N: no copy back); step k + 1 again.
  ParticleStepData<Model, MemSpace, Real> again = step_data(k * dt, dt, first, dy);
  again.x = x_next_;
  again.log_weight = log_weight_next_;
  with_team_arithmetic([&](auto mixed) {
    run_team_kernel_listed(ParticleTeamStep<Model, ExecSpace, Real, decltype(mixed)::value>{again});
  });
  ChunkedResampleData<MemSpace, Real> into_bank = resample_data(first_log_normalizer_, first);
  into_bank.x = x_next_;
  into_bank.log_weight = log_weight_next_;
  into_bank.x_into = x_;
  into_bank.log_weight_into = workspace_.cumulative;
  into_bank.log_normalizer_into = log_normalizer_;
  resample_listed(into_bank);
  ParticleStepData<Model, MemSpace, Real> redo = step_data((k + 1) * dt, dt, second, dy_next);
  redo.partials = partials_next_;
  with_team_arithmetic([&](auto mixed) {
    run_team_kernel_listed(ParticleTeamStep<Model, ExecSpace, Real, decltype(mixed)::value>{redo});
  });
  // Step k + 1's posterior and resampling, as in step().
  run_posterior(partials_next_, current_posterior(), log_normalizer_, true);
  resample_listed(resample_data(log_normalizer_, second));
}

template <class ExecSpace, class Model, class Real>
auto ParticleFilterBank<ExecSpace, Model, Real>::monte_carlo_standard_error() const -> BankVector<MemSpace> {
  BankVector<MemSpace> se("kushner::particle_mc_se", num_members_, state_dim);
  parallel_for_members("kushner::particle_mc_se", space_, num_members_,
                       MonteCarloStandardError<state_dim, MemSpace>{covariance_, ess_, se});
  return se;
}

/// The model type the shared instances compile the particle filter's classes for (SharedModel,
/// engine/shared_instances.hpp): Model, or NotShared<Model> above the particle filter's largest dimension.
template <class Model>
using ParticleInstanceModel = SharedModel<Model, particle_filter_unsupported<Model>() == nullptr>;
template <class ExecSpace, class Model, class Real>
class ParticleFilterBank<ExecSpace, NotShared<Model>, Real> {};

#define KUSHNER_SHARED_INSTANCE(Space, Model)                                    \
  extern template class ParticleFilterBank<Space, ParticleInstanceModel<Model>>; \
  extern template class ParticleFilterBank<Space, ParticleInstanceModel<Model>, float>;
KUSHNER_FOR_EACH_SHARED_INSTANCE
#undef KUSHNER_SHARED_INSTANCE

}  // namespace kushner
