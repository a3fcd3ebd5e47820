#pragma once
// Host stores that bypass the caches, for a column a kernel only writes and a later kernel reads (the bank's
// snapshot columns at an output step). An ordinary store first reads the line it writes into the cache; on the
// 2-core development machine (AMD EPYC, 1 thread, 1e6 members, 4 filters) an output step took 81 ms against 42 ms
// for a step without output with the 8 snapshot columns written that way, 53 ms as streaming stores
// (perf/filter_bank.md). Elsewhere (another architecture, nvcc's host pass) they are ordinary stores.
#include <cstdint>
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

/// to[i] = from[i], i < n, as store_streaming does it, whole cache lines at once where the host can (AVX-512: the
/// 64-byte-aligned runs of `to`). Scalar streaming stores, one per value, made copying a block's snapshot values to
/// their columns a third of a host segment's own time at 1e6 members.
inline void store_streaming_run(double* to, const double* from, const int n) {
  int i = 0;
#if KUSHNER_STREAMING_STORES && defined(__AVX512F__)
  for (; i < n && reinterpret_cast<std::uintptr_t>(to + i) % 64 != 0; ++i) store_streaming(to + i, from[i]);
  for (; i + 8 <= n; i += 8) _mm512_stream_pd(to + i, _mm512_loadu_pd(from + i));
#endif
  for (; i < n; ++i) store_streaming(to + i, from[i]);
}

/// Orders the streaming stores before every later store of this thread (they are weakly ordered), so that the
/// thread's end of a kernel publishes them.
inline void streaming_stores_done() {
#if KUSHNER_STREAMING_STORES
  _mm_sfence();
#endif
}

}  // namespace kushner
