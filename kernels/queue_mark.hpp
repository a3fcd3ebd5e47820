#pragma once
// A point in an execution space's queue that the host can wait for without waiting for the work queued after it:
// a CUDA event on a GPU's stream. An output step queues its reductions and their copies to the host, marks the
// queue, queues the next step, and only then waits for the mark, so the host merges while the GPU steps
// (engine/filter_run.hpp). A fence would wait for the next step too. Host spaces finish their work as they queue
// it, and there wait() is a fence.
#include "core/errors.hpp"

#include <Kokkos_Core.hpp>

#include <memory>

namespace kushner {

template <class ExecSpace>
class QueueMark {
 public:
  void record(const ExecSpace& space) { space_ = space; }
  void wait() const { space_.fence(); }

 private:
  ExecSpace space_;
};

#if defined(KOKKOS_ENABLE_CUDA)
template <>
class QueueMark<Kokkos::Cuda> {
 public:
  void record(const Kokkos::Cuda& space) {
    if (!event_) {
      cudaEvent_t event;
      check(cudaEventCreateWithFlags(&event, cudaEventDisableTiming), "cudaEventCreateWithFlags");
      event_ = std::shared_ptr<CUevent_st>(event, [](cudaEvent_t e) { cudaEventDestroy(e); });
    }
    check(cudaEventRecord(event_.get(), space.cuda_stream()), "cudaEventRecord");
  }
  void wait() const {
    if (event_) check(cudaEventSynchronize(event_.get()), "cudaEventSynchronize");
  }

 private:
  static void check(cudaError_t error, const char* call) {
    KUSHNER_REQUIRE(error == cudaSuccess, call << ": " << cudaGetErrorString(error));
  }

  std::shared_ptr<CUevent_st> event_;  // shared: the classes holding a mark stay copyable
};
#endif

}  // namespace kushner
