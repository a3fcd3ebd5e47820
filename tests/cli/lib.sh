# Helpers for the command-line tests: fail with a message, run kushner capturing stdout, stderr, exit code.
set -u
fail() { echo "FAIL: $*" >&2; exit 1; }
# run_kushner OUTFILE_PREFIX args... -> sets $rc; stdout in $prefix.out, stderr in $prefix.err
run_kushner() {
  local prefix=$1; shift
  set +e
  "$kushner" "$@" >"$prefix.out" 2>"$prefix.err"
  rc=$?
  set -e
}
