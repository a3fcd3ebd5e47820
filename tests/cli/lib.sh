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
