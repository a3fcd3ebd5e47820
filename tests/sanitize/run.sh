#!/usr/bin/env bash
# The test suite under sanitizers, Kokkos built with them; any report ends the test that meets it, so a clean ctest
# run is 0 reports.
#   tests/sanitize/run.sh [BUILD_DIR]      AddressSanitizer + UndefinedBehaviorSanitizer (GCC; the OpenMP
#                                          backend; default BUILD_DIR: build-sanitize)
#   KUSHNER_SANITIZE=thread tests/sanitize/run.sh build-tsan
#                                          ThreadSanitizer on the OpenMP backend: clang++-14 with LLVM's OpenMP
#                                          runtime and its TSan tool (Archer, libomp-14-dev), which tells TSan about
#                                          OpenMP's barriers and tasks (GCC's libgomp is not instrumented: every
#                                          parallel region would be reported)
# Environment:
#   KUSHNER_SANITIZE   -fsanitize= list (default address,undefined)
#   SANITIZE_CXX       the compiler (default: g++, or clang++-14 for thread)
#   SANITIZE_TARGETS   build only these targets (space-separated; default all); CI builds a few unit tests
#   SANITIZE_TESTS     ctest -R regex (default: every test; give one when SANITIZE_TARGETS leaves tests unbuilt)
#   SANITIZE_OPT       optimization (default -O1). -O0 compiles CI's seven unit tests in 221 s against 474 s at -O1
#                      (fresh clone, 2 cores) but runs them 4x slower (87 s against 20 s): CI takes -O0, the whole
#                      suite, whose CLI tests run for minutes under the sanitizers, -O1
#   SANITIZE_TIMEOUT   seconds per test (default 1500: the CLI tests run 10-20 times slower than in Release)
# Leaks: OpenMPI's runtime keeps its start-up allocations to exit; lsan.supp names its libraries and the loader only.
set -euo pipefail
here=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$here/build-sanitize}
sanitize=${KUSHNER_SANITIZE:-address,undefined}
jobs=${KUSHNER_JOBS:-$(nproc)}
configure=(-DCMAKE_BUILD_TYPE=Sanitize -DCMAKE_CXX_FLAGS_SANITIZE="${SANITIZE_OPT:--O1} -g" -DKUSHNER_SANITIZE="$sanitize"
           -DKUSHNER_ENABLE_CUDA=OFF -DKUSHNER_ENABLE_BENCHMARKS=OFF)
# A few targets compile only the banks they run; the whole suite shares each model's banks (engine/shared_instances.hpp).
# The few targets are built as one group (KUSHNER_TARGET_GROUP, CMakeLists.txt): given to `cmake --build --target` as a
# list, they compiled one after another.
if [ -n "${SANITIZE_TARGETS:-}" ]; then
  # shellcheck disable=SC2086
  configure+=(-DKUSHNER_SHARED_INSTANCES=OFF "-DKUSHNER_TARGET_GROUP=$(echo $SANITIZE_TARGETS | tr ' ' ';')")
else
  configure+=(-DKUSHNER_SHARED_INSTANCES=ON -DKUSHNER_TARGET_GROUP=)
fi
if [[ "$sanitize" == *thread* ]]; then
  archer=/usr/lib/llvm-14/lib/libarcher.so
  [ -e "$archer" ] || { echo "sanitize: ThreadSanitizer needs $archer (Debian: apt-get install clang-14 libomp-14-dev)" >&2; exit 2; }
  configure+=(-DCMAKE_CXX_COMPILER="${SANITIZE_CXX:-clang++-14}" -DKUSHNER_ENABLE_MPI=OFF)
  export OMP_TOOL_LIBRARIES=$archer
  # Archer asks for ignore_noninstrumented_modules: without it TSan reports libomp's own mutexes (measured).
  export TSAN_OPTIONS=${TSAN_OPTIONS:-halt_on_error=1:second_deadlock_stack=1:ignore_noninstrumented_modules=1}
elif [ -n "${SANITIZE_CXX:-}" ]; then
  configure+=(-DCMAKE_CXX_COMPILER="$SANITIZE_CXX")
fi
start=$(date +%s)
cmake -S "$here" -B "$build" "${configure[@]}" >/dev/null
if [ -n "${SANITIZE_TARGETS:-}" ]; then
  cmake --build "$build" -j "$jobs" --target kushner_target_group
else
  cmake --build "$build" -j "$jobs"
fi
echo "sanitize: built in $(( $(date +%s) - start )) s"

export ASAN_OPTIONS=${ASAN_OPTIONS:-halt_on_error=1:detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$here/tests/sanitize/lsan.supp:print_suppressions=0}
tests=()
if [ -n "${SANITIZE_TESTS:-}" ]; then tests=(-R "$SANITIZE_TESTS"); fi
test_start=$(date +%s)
ctest --test-dir "$build" -j "$jobs" --output-on-failure --timeout "${SANITIZE_TIMEOUT:-1500}" "${tests[@]}"
echo "sanitize: tests ran in $(( $(date +%s) - test_start )) s (whole run $(( $(date +%s) - start )) s)"
