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
# built_backends: the backends $kushner was built with, from its --version line (e.g. "serial openmp").
built_backends() { "$kushner" --version | sed -n 's/^available backends: \(.*\) (select.*/\1/p'; }
# host_backend: where the bit-for-bit comparisons run: openmp where built, else serial (a GPU's math library differs
# from the host's in the last bits, so a CUDA build's default backend is compared to a tolerance elsewhere).
host_backend() { if grep -qw openmp <<<"$(built_backends)"; then echo openmp; else echo serial; fi; }
# can_draw_figures: whether the interpreter kushner plots with (drivers/plots.cpp: $KUSHNER_PYTHON, else
# /usr/bin/python3, else python3) has matplotlib; sets $plot_python to it.
can_draw_figures() {
  plot_python=${KUSHNER_PYTHON:-}
  if [ -z "$plot_python" ]; then
    plot_python=python3
    [ ! -x /usr/bin/python3 ] || plot_python=/usr/bin/python3
  fi
  "$plot_python" -c "import matplotlib" 2>/dev/null
}
# expect_refused "exact message" args...: kushner exits 2 with exactly "kushner: error: <message>" on stderr and
# creates no output directory (--out $work/refused is added). Scripts that match a fragment define their own.
expect_refused() {
  local expected=$1; shift
  run_kushner "$work/r" "$@" --out "$work/refused"
  [ "$rc" -eq 2 ] || fail "exit $rc (want 2) for: $*; stderr: $(cat "$work/r.err")"
  [ "$(wc -l <"$work/r.err")" -eq 1 ] || fail "stderr is not one line for: $*: $(cat "$work/r.err")"
  [ "$(cat "$work/r.err")" = "kushner: error: $expected" ] || fail "message for: $*: $(cat "$work/r.err") (want: $expected)"
  [ ! -e "$work/refused" ] || fail "a refused run created its output directory: $*"
  echo "ok: $expected"
}
