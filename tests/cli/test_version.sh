#!/usr/bin/env bash
# `kushner --version` names kushner, Kokkos, and the backend in use with its thread count or device.
set -euo pipefail
kushner=$1
source "$(dirname "$0")/lib.sh"
out=$("$kushner" --version)
echo "$out"
grep -q '^kushner [0-9.]* (git ' <<<"$out" || fail "no kushner version line"
grep -q '^Kokkos [0-9]' <<<"$out" || fail "no Kokkos version line"
default=$(sed -n 's/^available backends: \([a-z]*\).*/\1/p' <<<"$out")
grep -q "^backend: $default (" <<<"$out" || fail "the default backend is not the first available one"
if grep -q 'available backends:.* openmp' <<<"$out"; then
  out=$(OMP_NUM_THREADS=2 KUSHNER_BACKEND=openmp "$kushner" --version)
  grep -q '^backend: openmp (2 threads)' <<<"$out" || fail "expected the OpenMP backend with 2 threads"
fi
out=$(KUSHNER_BACKEND=serial "$kushner" --version)
grep -q '^backend: serial (1 threads)' <<<"$out" || fail "KUSHNER_BACKEND=serial not honoured"
set +e
err=$(KUSHNER_BACKEND=vulkan "$kushner" --version 2>&1 >/dev/null); rc=$?
set -e
[ $rc -eq 2 ] || fail "unknown backend: exit $rc"
grep -q "^kushner: error: KUSHNER_BACKEND: backend 'vulkan' is not available (built: .*serial)$" <<<"$err" ||
  fail "message: $err"
echo ok
