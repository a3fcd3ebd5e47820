#pragma once
// The bank of truths: initial states, and one step of every member in one kernel. Continuous-time models
// take an Euler-Maruyama step and produce the observation increment dy over the step; discrete-time models
// take x[k+1] = F(k, x[k], u) + w[k] and produce z[k+1] = h(k+1, x[k+1]) + v[k+1] in the same bank.
#include "core/errors.hpp"
#include "core/linear_algebra.hpp"
#include "kernels/bank.hpp"
#include "kernels/ensemble_moments.hpp"
#include "kernels/for_each_member.hpp"
#include "kernels/particle_filter/particle_draws.hpp"
#include "kernels/rng.hpp"
#include "models/sine_observation_noise.hpp"

#include <Kokkos_Core.hpp>

#include <cstdint>
#include <type_traits>
#include <utility>
#include <vector>

namespace kushner {

namespace detail {
template <class Model, class = void>
struct has_process_noise_columns : std::false_type {};
template <class Model>
struct has_process_noise_columns<Model, std::void_t<decltype(std::declval<const Model&>().process_noise_columns())>>
    : std::true_type {};
template <class Model, class = void>
struct has_sine_observation_noise_option : std::false_type {};
template <class Model>
struct has_sine_observation_noise_option<
    Model, std::void_t<decltype(std::declval<const Model&>().observation_noise_is_sine())>> : std::true_type {};
}  // namespace detail

/// Whether the truths' observation noise is Basin's sin t path (models/sine_observation_noise.hpp: a run-time
/// parameter of the models that have the option): they then take dv = cos t - cos(t + dt) instead of a Brownian
/// increment.
template <class Model>
KOKKOS_INLINE_FUNCTION bool sine_observation_noise(const Model& model) {
  if constexpr (detail::has_sine_observation_noise_option<Model>::value)
    return model.observation_noise_is_sine();
  else
    return false;
}

/// The normals a continuous-time truth of `model` uses per step: its obs_dim observation normals and the process
/// normals its diffusion has columns for; fewer than obs_dim + noise_dim where a model file's diffusion is padded with
/// columns of zeros to its state dimension (PolynomialModel::process_noise_columns), so that it draws the numbers of
/// the built-in model it writes out (truth_normals: which normal is drawn per member pair depends on the count).
template <class Model>
KOKKOS_INLINE_FUNCTION int truth_normal_count(const Model& model) {
  if constexpr (detail::has_process_noise_columns<Model>::value)
    return Model::obs_dim + model.process_noise_columns();
  else
    return Model::obs_dim + Model::noise_dim;
}

/// x(member) = mean + root z, z standard normal from Stream::truth_initial (root: any square root of the
/// initial covariance, computed on the host, so that a singular covariance (fixed start) is allowed).
template <int N, class MemSpace>
struct GaussianInitialize {
  BankVector<MemSpace> x;
  Vec<N> mean;
  Mat<N, N> root;
  RngKey key;
  KOKKOS_INLINE_FUNCTION void operator()(const int member) const {
    const Vec<N> z = normal_vector<N>(key, member, 0, 0);
    store(x, member, mean + root * z);
  }
};

template <class ExecSpace, int N, class MemSpace>
void initialize_gaussian(const ExecSpace& space, const BankVector<MemSpace>& x, const Vec<N>& mean,
                         const Mat<N, N>& root, RngKey key) {
  KUSHNER_REQUIRE(x.extent_int(1) == N, "x has " << x.extent(1) << " columns, expected " << N);
  parallel_for_members("kushner::initialize_gaussian", space, x.extent(0),
                       GaussianInitialize<N, MemSpace>{x, mean, root, key});
}

/// A truth's step of one member (at the truth's own t and step) from the state its bank holds: Truth::step_from.
template <class Model, class Truth>
KOKKOS_INLINE_FUNCTION void step_stored_state(const Truth& truth, const int member, const typename Model::Control& u) {
  Vec<Model::state_dim> next;
  Vec<Model::obs_dim> increment;
  truth.step_from(member, truth.t, truth.step, u, load<Model::state_dim>(truth.x, member), next, increment);
}

/// One Euler-Maruyama step of every member over [t, t + dt]:
///   dy = h(t, x) dt + R dv,   x <- x + f(t, x, u) dt + G(t, x) dw,   dw, dv ~ N(0, dt I),
/// with u = 0 (open loop) or, in a closed loop, the member's control (step_member). The draws depend on seed,
/// member and step only, so every controller's loop sees the same noise (common random numbers); or
/// dv = cos t - cos(t + dt) where the model's observation noise is the sine path (sine_observation_noise).
/// A step's p observation and q process normals are one vector, v then w, of the process-noise stream
/// (truth_normals): where p and q are both odd a Philox block and a Box-Muller pair serve the last of v and the first
/// of w (the sine model: one block, one log and one square root per member-step instead of two each), and where p + q
/// is odd two neighbouring members share the block of the last normal (the cubic oscillator: 1.5 blocks per
/// member-step instead of 2). v is drawn with sine observation noise too (and not used), so the state paths are the
/// same for both.
template <class Model, class MemSpace>
struct EulerMaruyamaTruthStep {
  Model model;
  BankVector<MemSpace> x, dy;
  double t = 0.0, dt = 0.0;
  Seed seed{};
  std::uint32_t step = 0;
  double sqrt_dt = 0.0;  // sqrt(dt), once per step: each member-step took a double square root (~20 instructions)

  EulerMaruyamaTruthStep() = default;
  EulerMaruyamaTruthStep(const Model& model_, const BankVector<MemSpace>& x_, const BankVector<MemSpace>& dy_,
                         const double t_, const double dt_, const Seed seed_, const std::uint32_t step_)
      : model(model_), x(x_), dy(dy_), t(t_), dt(dt_), seed(seed_), step(step_), sqrt_dt(math::sqrt(dt_)) {}

  KOKKOS_INLINE_FUNCTION void operator()(const int member) const { step_member(member, Model::Control::zero()); }

  /// The step of one member driven by the control u over it (a closed loop's, kernels/control/).
  KOKKOS_INLINE_FUNCTION void step_member(const int member, const typename Model::Control& u) const {
    step_stored_state<Model>(*this, member, u);
  }

  /// step_member as step k at time `at` (the fields t and step in a step at a time; a GPU's segment passes each of
  /// its steps' and leaves the kernel as it is) from x(at) = xm, read by the caller (the bank reads it with the
  /// truth's status: one wait for memory); stores and returns x(at + dt) and dy.
  KOKKOS_INLINE_FUNCTION void step_from(const int member, const double at, const std::uint32_t k,
                                        const typename Model::Control& u, const Vec<Model::state_dim>& xm,
                                        Vec<Model::state_dim>& next, Vec<Model::obs_dim>& increment) const {
    constexpr int p = Model::obs_dim, q = Model::noise_dim;
    const RngKey key{seed, Stream::process_noise};
    const auto who = static_cast<std::uint32_t>(member);
    Vec<p> zv;
    Vec<q> zw;
    truth_normals<p, q>(key, who, k, truth_normal_count(model), zv, zw);  // zv unused with sine observation noise
    advance_state(at, u, xm, zw, zv, next, increment);
    store(dy, member, increment);
    store(x, member, next);
  }

  /// The step from x(at) = xm with the standard normals zw (process noise) and zv (observation noise; unused where
  /// the model's observation noise is the sine path).
  KOKKOS_INLINE_FUNCTION void advance_state(const double at, const typename Model::Control& u,
                                            const Vec<Model::state_dim>& xm, const Vec<Model::noise_dim>& zw,
                                            const Vec<Model::obs_dim>& zv, Vec<Model::state_dim>& next,
                                            Vec<Model::obs_dim>& increment) const {
    constexpr int p = Model::obs_dim;
    const auto dw = zw * sqrt_dt;
    Vec<p> dv;
    if (sine_observation_noise(model))
      dv = Vec<p>::constant(SineObservationNoiseOption::sine_noise_increment(at, dt));
    else
      dv = zv * sqrt_dt;
    increment = model.observation(at, xm) * dt + model.observation_noise(at) * dv;
    next = xm + model.drift(at, xm, u) * dt + model.diffusion(at, xm) * dw;
  }

  /// A member's normals on the host: truth_normals', in their layout.
  using LaneLayout = ObservationAndProcessLayout<Model::obs_dim, Model::noise_dim>;
  static constexpr int lane_draws = LaneLayout::normals;

  /// Host: the chunk's normals in SIMD lanes, truth_normals' numbers: z[k * host_lane_capacity + member - begin] for
  /// normal k of lane_draws (draw_block_lanes, the last of an odd count draw_member_pair_normal_lanes; zero beyond
  /// truth_normal_count).
  KUSHNER_FLATTEN void draw_lanes(const int begin, const int end, double* const z) const {
    const RngKey key{seed, Stream::process_noise};
    const std::uint32_t k = step;
    const int drawn = truth_normal_count(model);
    for (int i = 0; i + 1 < drawn; i += 2) {
      const Counter first{static_cast<std::uint32_t>(begin), 0, k, static_cast<std::uint32_t>(i / 2)};
      draw_block_lanes(key, {first, Counter{1, 0, 0, 0}}, end - begin, z + i * host_lane_capacity,
                       z + (i + 1) * host_lane_capacity);
    }
    if (drawn % 2 == 1)  // z's row holds host_lane_capacity (even) values: room for an odd chunk's last z1
      draw_member_pair_normal_lanes(begin, end, key, k, static_cast<std::uint32_t>(drawn / 2),
                                    z + (drawn - 1) * host_lane_capacity);
    for (int i = drawn; i < lane_draws; ++i)
      for (int member = begin; member < end; ++member) z[i * host_lane_capacity + member - begin] = 0.0;
  }

  /// Host: the members of one chunk in SIMD lanes (kernels/for_each_member.hpp's run_member_chunk): the draws
  /// (draw_lanes), then the step (step_lane).
  KUSHNER_FLATTEN void run_chunk(const int begin, const int end) const {
    double z[lane_draws * host_lane_capacity];
    draw_lanes(begin, end, z);
    double* const xs = x.data();  // raw pointers: GCC does not vectorize a loop that reloads a View's pointer
    double* const dys = dy.data();
    const std::size_t x_stride = x.stride(1), dy_stride = dy.stride(1);
    KUSHNER_SIMD
    for (int member = begin; member < end; ++member)
      step_lane(member, xs, x_stride, dys, dy_stride, true, z + (member - begin));
  }

  /// One member of run_chunk: x(member) and dy(member) at xs[member + i x_stride], dys[member + i dy_stride], its
  /// normals at z[k * host_lane_capacity] (draw_lanes); `ok` false: computed but not stored (a truth that has left
  /// the run). Returns whether x and dy are finite. The loop body is this one call with scalar arguments: a local
  /// of the body whose address is taken (a Vec, whose operator[] is a call before inlining) becomes an `omp simd`
  /// array, and GCC does not vectorize copies of those.
  KOKKOS_INLINE_FUNCTION bool step_lane(const int member, double* const xs, const std::size_t x_stride,
                                        double* const dys, const std::size_t dy_stride, const bool ok,
                                        const double* const z) const {
    constexpr int n = Model::state_dim, p = Model::obs_dim, q = Model::noise_dim;
    Vec<n> xm, next;
    Vec<p> increment, zv;
    Vec<q> zw;
    for (int i = 0; i < n; ++i) xm[i] = xs[member + i * x_stride];
    for (int k = 0; k < p; ++k) zv[k] = z[(LaneLayout::v + k) * host_lane_capacity];
    for (int k = 0; k < q; ++k) zw[k] = z[(LaneLayout::w + k) * host_lane_capacity];
    advance_state(t, Model::Control::zero(), xm, zw, zv, next, increment);
    for (int i = 0; i < p; ++i) dys[member + i * dy_stride] = ok ? increment[i] : dys[member + i * dy_stride];
    for (int i = 0; i < n; ++i) xs[member + i * x_stride] = ok ? next[i] : xm[i];
    return all_finite(next) && all_finite(increment);
  }
};

/// The draws of one discrete-time noise vector of dimension Q at (member, step): Q standard normals (Gaussian
/// noise) and one uniform (bounded noise by its inverse CDF), from distinct Philox blocks of `key`. A model's
/// process_noise / observation_noise_sample takes what its law needs of them.
template <int Q>
struct DiscreteNoiseDraws {
  Vec<Q> normals;
  double uniform;
};
template <int Q>
KOKKOS_INLINE_FUNCTION DiscreteNoiseDraws<Q> discrete_noise_draws(const RngKey& key, std::uint32_t member,
                                                                  std::uint32_t step) {
  DiscreteNoiseDraws<Q> d;
  d.normals = normal_vector<Q>(key, member, 0, step);  // blocks 0 .. ceil(Q/2) - 1
  double unused;
  uniform_pair(key, Counter{member, 0, step, static_cast<std::uint32_t>(Q)}, d.uniform, unused);
  return d;
}

/// One step k of a discrete-time model: x <- F(k, x, u) + w[k], then dy <- z[k+1] = h(k+1, x) + v[k+1] (the
/// field keeps the continuous step's name: every bank reads the step's observation from it). t = k, dt = 1.
template <class Model, class MemSpace>
struct DiscreteTruthStep {
  Model model;
  BankVector<MemSpace> x, dy;
  double t, dt;
  Seed seed;
  std::uint32_t step;

  KOKKOS_INLINE_FUNCTION void operator()(const int member) const { step_member(member, Model::Control::zero()); }

  KOKKOS_INLINE_FUNCTION void step_member(const int member, const typename Model::Control& u) const {
    step_stored_state<Model>(*this, member, u);
  }

  /// step_member as step k at time `at` (= k) from x[k] = xm, read by the caller; stores and returns x[k+1] and
  /// z[k+1].
  KOKKOS_INLINE_FUNCTION void step_from(const int member, const double at, const std::uint32_t k,
                                        const typename Model::Control& u, const Vec<Model::state_dim>& xm,
                                        Vec<Model::state_dim>& next, Vec<Model::obs_dim>& increment) const {
    constexpr int p = Model::obs_dim, q = Model::noise_dim;
    const auto w = discrete_noise_draws<q>(RngKey{seed, Stream::process_noise}, member, k);
    const auto v = discrete_noise_draws<p>(RngKey{seed, Stream::observation_noise}, member, k);
    next = model.transition(at, xm, u) + model.process_noise(w.normals, w.uniform);
    increment = model.observation(at + 1.0, next) + model.observation_noise_sample(v.normals, v.uniform);
    store(x, member, next);
    store(dy, member, increment);
  }
};

/// The truth step of Model's time: Euler-Maruyama, or the discrete-time transition.
template <class Model, class MemSpace>
using TruthStep = std::conditional_t<Model::discrete_time, DiscreteTruthStep<Model, MemSpace>,
                                     EulerMaruyamaTruthStep<Model, MemSpace>>;

/// The banks a truth step of Model takes: x (members, state_dim) and its observations (members, obs_dim).
template <class Model, class MemSpace>
void require_truth_banks(const BankVector<MemSpace>& x, const BankVector<MemSpace>& observations) {
  KUSHNER_REQUIRE(x.extent_int(1) == Model::state_dim,
                  "x has " << x.extent(1) << " columns, " << Model::name << " has state_dim " << Model::state_dim);
  KUSHNER_REQUIRE(observations.extent_int(1) == Model::obs_dim && observations.extent(0) == x.extent(0),
                  "observation bank has shape (" << observations.extent(0) << ", " << observations.extent(1) << ")");
}

/// Fewest members for which a host truth step goes by blocks of moment_block_size members (TruthSegmentBlocks) rather
/// than by parallel_for_members' chunks of host_member_chunk: below it the blocks are too few to share among a host's
/// threads (engine/filter_run.hpp's segments start at the same count).
constexpr long truth_block_min_members = 16 * moment_block_size;

/// Steps a host truth segment takes at most (TruthBank::step_segment): a block's columns stay in its core's cache
/// through them, so the bank's x and dy go to and from memory once per segment instead of once per step (as the
/// filter bank's segments: FilterBank::segment_steps).
constexpr int truth_segment_steps = 16;

/// A host truth segment by blocks of moment_block_size members: block b takes steps first_step .. first_step + steps -
/// 1, each in runs of host_lane_capacity (run_member_runs: the truth's chunk function sets itself up once per 128
/// members instead of once per 32), the same bits as a step at a time. At an output step (output_of[s] >= 0) the
/// thread that just wrote the block leaves each column's block_statistic of FiniteRowValue, as ensemble_moments'
/// one-thread form takes it (the same bits: finite_row_block_statistics), while it is in that core's cache: at rows +
/// (output_of[s] num_blocks + b) 3 Columns, BlockStatistics' layout.
template <class Step, class View, int Columns>
struct TruthSegmentBlocks {
  Step first;  // step first_step's kernel; each step's time and index are set from it
  View x;
  int members;
  long first_step;
  int steps;
  double dt;
  const int* output_of;  // per step of the segment: its output's index, or -1
  double* rows;
  int num_blocks;

  void operator()(const int b) const {
    const int begin = b * moment_block_size, end = block_end(b, members);
    Step step = first;
    for (int s = 0; s < steps; ++s) {
      const long k = first_step + s;
      step.t = k * dt;  // simulate_truth_step's time, bit for bit
      step.step = static_cast<std::uint32_t>(k);
      run_member_runs(step, begin, end);
      if (output_of[s] < 0) continue;
      BlockStatistic statistics[Columns];
      finite_row_block_statistics(x, begin, end, statistics);
      double* const row = rows + (static_cast<std::size_t>(output_of[s]) * num_blocks + b) * 3 * Columns;
      for (int c = 0; c < Columns; ++c) store_block_row(row, Columns, c, statistics[c]);
    }
  }
};

/// Whether a host truth step of bank x goes by blocks (TruthSegmentBlocks).
inline bool truth_step_by_blocks(const BankVector<Kokkos::HostSpace>& x) {
  return static_cast<long>(x.extent(0)) >= truth_block_min_members;
}

/// TruthSegmentBlocks over every block of x: steps first_step .. first_step + output_of.size() - 1; `rows`: (outputs,
/// blocks of x, 3 state_dim) doubles for the outputs that output_of names (none: no moments).
template <class ExecSpace, class Model>
void step_truth_segment(const ExecSpace& space, const Model& model, const BankVector<Kokkos::HostSpace>& x,
                        const BankVector<Kokkos::HostSpace>& observations, const long first_step,
                        const std::vector<int>& output_of, const double dt, const Seed seed, double* const rows) {
  const int members = x.extent_int(0), num_blocks = static_cast<int>(moment_blocks(members));
  const double t = first_step * dt;
  Kokkos::parallel_for(
      "kushner::truth_segment", Kokkos::RangePolicy<ExecSpace>(space, 0, num_blocks),
      TruthSegmentBlocks<TruthStep<Model, Kokkos::HostSpace>, BankVector<Kokkos::HostSpace>, Model::state_dim>{
          {model, x, observations, t, dt, seed, static_cast<std::uint32_t>(first_step)},
          x,
          members,
          first_step,
          static_cast<int>(output_of.size()),
          dt,
          output_of.data(),
          rows,
          num_blocks});
}

/// Advances every member of the bank by step k, over [k dt, (k + 1) dt]; `observations` receives dy (continuous time)
/// or z[k+1] (discrete time). No fence: the caller fences before reading results on the host.
template <class ExecSpace, class Model, class MemSpace>
void simulate_truth_step(const ExecSpace& space, const Model& model, const BankVector<MemSpace>& x,
                         const BankVector<MemSpace>& observations, const long k, const double dt, const Seed seed) {
  static_assert(Kokkos::SpaceAccessibility<ExecSpace, MemSpace>::accessible, "bank not accessible from ExecSpace");
  require_truth_banks<Model>(x, observations);
  if constexpr (std::is_same<MemSpace, Kokkos::HostSpace>::value) {
    if (truth_step_by_blocks(x)) {
      step_truth_segment(space, model, x, observations, k, {-1}, dt, seed, nullptr);
      return;
    }
  }
  parallel_for_members(
      "kushner::truth_step", space, x.extent(0),
      TruthStep<Model, MemSpace>{model, x, observations, k * dt, dt, seed, static_cast<std::uint32_t>(k)});
}

}  // namespace kushner
