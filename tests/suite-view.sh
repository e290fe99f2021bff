#!/bin/sh
# suite-view.sh: qcs view in headless Chromium (load and compare with
# qcs -o, follow the file and an imported file, an error, a deleted file,
# click to probe against the prompt's Density/Gradient/Trace, orbit, copy
# camera rendered by qcs -o, reset, save PNG and EXR, shadows, channels,
# the parameters' slider and number box against qcs -o --set, their values
# over a save, reset), a load test of 10,000 requests from 50 clients with
# hostile ones mixed in (hostile /param requests too), and :view at the
# prompt under tmux (tests/view/repl_view.sh). Loopback only. The viewer
# processes run with ASAN_OPTIONS=detect_leaks=1 (make sanitize turns leak
# checks off for the rest): an ASan build's leak report fails view-stop.
cd "$(dirname "$0")/.." || exit 1
QCS=${QCS:-./qcs}
if ! "$QCS" view --help >/dev/null 2>&1; then
  echo "skip view: $QCS has no view subcommand"; exit 0
fi
if ! command -v python3 >/dev/null 2>&1; then
  echo "skip view: python3 is not installed"; exit 0
fi
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
# bad arguments are refused before anything listens
if "$QCS" view --listen nowhere x.qcs 2>"$work/e" || ! grep -q "ADDR:PORT" "$work/e"; then
  echo "FAIL view-args: a bad --listen was not refused clearly"
else
  echo "ok view-args"
fi
timeout 150 python3 tests/view/viewtest.py "$QCS" "$work/t"; rc=$?
sh tests/view/repl_view.sh "$QCS" "$work/r"
exit $rc
