#pragma once
// Host stores that bypass the caches, for a column a kernel only writes and a later kernel reads (the bank's
// snapshot columns at an output step). An ordinary store first reads the line it writes into the cache; on the
// 2-core development machine (AMD EPYC, 1 thread, 1e6 members, 4 filters) an output step took 81 ms against 42 ms
// for a step without output with the 8 snapshot columns written that way, 53 ms as streaming stores
// (perf/filter_bank.md). Elsewhere (another architecture, nvcc's host pass) they are ordinary stores.
#include <cstring>

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__CUDACC__)
#include <immintrin.h>
#define KUSHNER_STREAMING_STORES 1
#else
#define KUSHNER_STREAMING_STORES 0
#endif

namespace kushner {

/// *address = value, written around the caches where the host can (x86-64: movnti). The value is the same bits.
inline void store_streaming(double* address, double value) {
#if KUSHNER_STREAMING_STORES
  long long bits;
  std::memcpy(&bits, &value, sizeof bits);
  _mm_stream_si64(reinterpret_cast<long long*>(address), bits);
#else
  *address = value;
#endif
}

/// Orders the streaming stores before every later store of this thread (they are weakly ordered), so that the
/// thread's end of a kernel publishes them.
inline void streaming_stores_done() {
#if KUSHNER_STREAMING_STORES
  _mm_sfence();
#endif
}

}  // namespace kushner
