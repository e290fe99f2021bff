#!/bin/sh
# suite-view.sh: qcs view in headless Chromium (load and compare with
# qcs -o, follow the file and an imported file, an error, a deleted file,
# click to probe against the prompt's Density/Gradient/Trace, orbit, copy
# camera rendered by qcs -o, reset, save PNG and EXR, shadows, channels), a
# load test of 10,000 requests from 50 clients with hostile ones mixed in,
# and :view at the prompt under tmux (tests/view/repl_view.sh). Loopback
# only.
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
