// A planted bug for each sanitizer of a sanitizer build (tests/sanitize/run.sh), so that its clean ctest run means
// something: ctest expects the sanitizer's own report from each case.
//   sanitizer_canary race       two OpenMP threads add to one double in a Kokkos kernel (ThreadSanitizer)
//   sanitizer_canary overflow   a read one past the end of a heap array (AddressSanitizer)
//   sanitizer_canary signed     a signed integer overflow (UndefinedBehaviorSanitizer)
#include <Kokkos_Core.hpp>

#include <climits>
#include <cstdio>
#include <cstring>
#include <memory>

namespace {

int planted_race() {
  double sum = 0.0;
  double* shared_sum = &sum;
  Kokkos::parallel_for(
      "planted_race", Kokkos::RangePolicy<Kokkos::DefaultHostExecutionSpace>(0, 4096),
      KOKKOS_LAMBDA(int i) { *shared_sum += i; });
  Kokkos::fence();
  std::printf("sum %g\n", sum);
  return 0;
}

int planted_overflow() {
  // A plain heap array: Kokkos' HostSpace over-allocates for alignment, so one past a view's end is still inside
  // its block and AddressSanitizer rightly says nothing there.
  std::unique_ptr<double[]> values(new double[16]());
  volatile int past_end = 16;
  std::printf("value %g\n", values[past_end]);
  return 0;
}

int planted_signed_overflow() {
  volatile int big = INT_MAX;
  std::printf("sum %d\n", big + 1);
  return 0;
}

}  // namespace

int main(int argc, char* argv[]) {
  if (argc != 2) return 2;
  Kokkos::ScopeGuard kokkos;
  if (std::strcmp(argv[1], "race") == 0) return planted_race();
  if (std::strcmp(argv[1], "overflow") == 0) return planted_overflow();
  if (std::strcmp(argv[1], "signed") == 0) return planted_signed_overflow();
  return 2;
}
