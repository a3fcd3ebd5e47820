#pragma once
// Member kernels: one functor call per ensemble member, the same bits on every host backend.
//
// GCC vectorizes the loop of Kokkos' Serial backend around an inlined functor but not the OpenMP backend's,
// and a vectorized loop calls glibc's vector sin/cos/exp/log (kernels/vector_math.hpp), which
// differ from the scalar ones in the last bits: the same kernel gave Serial and OpenMP results one ulp apart
// (Box-Muller of the initial states, -march=native). So on the host the members go in fixed chunks through
// one function per functor type that is never inlined or cloned: every backend and every thread count runs
// the same machine code on the same chunks. On a GPU it is a RangePolicy over the members.
//
// The vector-math declarations are included here, not only where the particle filter needs them: a chunk
// function is instantiated in every translation unit that runs the functor and the linker keeps one copy, so
// every unit must compile it alike. Without them in one unit its copy was scalar (bench_simulate_truth's truth
// step ran 5.4 times slower than the same step in bench_filter_bank), and which copy a program ran, and so its
// last bits, depended on link order.
#include "kernels/vector_math.hpp"

#include <Kokkos_Core.hpp>

#include <string>
#include <type_traits>
#include <utility>

// A host function compiled once for all its callers (no inlining, no call-site specialized clones).
#if defined(__GNUC__) && !defined(__clang__) && !defined(__CUDACC__)
#define KUSHNER_SAME_CODE_FOR_ALL_CALLERS __attribute__((noipa))
#elif defined(__GNUC__) || defined(__clang__)
#define KUSHNER_SAME_CODE_FOR_ALL_CALLERS __attribute__((noinline))
#else
#define KUSHNER_SAME_CODE_FOR_ALL_CALLERS
#endif

namespace kushner {

/// Members per host work item: small enough that 200 members keep 2 threads busy, large enough for SIMD. (As work
/// items, 128 left 300 members 3 items, 256 and 44 on 2 threads: `compare` at 300 members 14-21% slower.)
constexpr int host_member_chunk = 32;

/// The most members one host chunk function takes (its lane arrays hold this many). A host segment's block, whose
/// thread is already chosen, goes through its steps in runs of this many (run_member_runs): each filter's lane loop
/// sets itself up once per run (its model, views' pointers, spills), 9% of the sine bank at 1e6 members in runs of
/// 32 (perf/filter_bank.md). A multiple of every vector width, so it changes no bits: which members a vector body
/// takes, and which its remainder, depends only on the number of members.
constexpr int host_lane_capacity = 128;
static_assert(host_lane_capacity % host_member_chunk == 0, "a work item must fit a chunk function's lanes");

/// The end of the host chunk of at most `size` members that starts at `begin`, of members that end at `end`.
KOKKOS_INLINE_FUNCTION constexpr int host_chunk_end(const int begin, const int end,
                                                    const int size = host_member_chunk) {
  return end - begin < size ? end : begin + size;
}

namespace detail {
template <class Functor, class = void>
struct has_run_chunk : std::false_type {};
template <class Functor>
struct has_run_chunk<Functor, std::void_t<decltype(std::declval<const Functor&>().run_chunk(0, 0))>> : std::true_type {
};
}  // namespace detail

/// f(member) for the members of one chunk; a functor with a host `run_chunk(begin, end)` (the same work with
/// member lanes in SIMD loops) runs that instead.
template <class Functor>
KUSHNER_SAME_CODE_FOR_ALL_CALLERS void run_member_chunk(const Functor& f, int begin, int end) {
  if constexpr (detail::has_run_chunk<Functor>::value) {
    f.run_chunk(begin, end);
  } else {
    for (int member = begin; member < end; ++member) f(member);
  }
}

/// run_member_chunk over the members [begin, end) in runs of host_lane_capacity (one thread's block of members).
template <class Functor>
void run_member_runs(const Functor& f, const int begin, const int end) {
  for (int run = begin; run < end; run += host_lane_capacity)
    run_member_chunk(f, run, host_chunk_end(run, end, host_lane_capacity));
}

template <class Functor>
struct MemberChunks {
  Functor f;
  int members;
  void operator()(const int chunk) const {
    const int begin = chunk * host_member_chunk;
    run_member_chunk(f, begin, host_chunk_end(begin, members));
  }
};

/// Whether a GPU member kernel's functor goes to the device as its launch's parameters (Kokkos' light-weight
/// launch; CUDA's parameters hold 4 KB, the launch adds its policy). Kokkos copies a functor of more than 512 bytes
/// to constant memory otherwise, and such a launch first waits for the kernel of the one before it: the bank's step
/// and reference scores (3.1-3.3 KB for sine) stopped the host behind the particle filter's pass at every step pair,
/// and the device then sat idle while the host launched the next pair's kernels (perf/particle_filter.md).
template <class Functor>
constexpr bool member_functor_in_parameters = sizeof(Functor) + 256 <= 4096;

/// f(member) for member in [0, members). No fence.
template <class ExecSpace, class Functor>
void parallel_for_members(const std::string& name, const ExecSpace& space, long members, const Functor& f) {
  const int m = static_cast<int>(members);
  if constexpr (std::is_same<typename ExecSpace::memory_space, Kokkos::HostSpace>::value) {
    Kokkos::parallel_for(name,
                         Kokkos::RangePolicy<ExecSpace>(space, 0, (m + host_member_chunk - 1) / host_member_chunk),
                         MemberChunks<Functor>{f, m});
  } else if constexpr (member_functor_in_parameters<Functor>) {
    using LightWeight = Kokkos::Experimental::WorkItemProperty::HintLightWeight_t;
    Kokkos::parallel_for(name, Kokkos::RangePolicy<ExecSpace, LightWeight>(space, 0, m), f);
  } else {
    Kokkos::parallel_for(name, Kokkos::RangePolicy<ExecSpace>(space, 0, m), f);
  }
}

}  // namespace kushner
