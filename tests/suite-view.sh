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
# a file that does not exist: said plainly, exit 1, nothing served
if "$QCS" view "$work/nonexistent.qcs" >"$work/o" 2>"$work/e"; then
  echo "FAIL view-nonexistent: exit status 0"
elif grep -q "nonexistent.qcs: no such file" "$work/e" && ! grep -q http "$work/o"; then
  echo "ok view-nonexistent"
else
  echo "FAIL view-nonexistent: $(cat "$work/e" "$work/o" | head -n 3 | tr '\n' '|')"
fi
# a file in error from the start has no picture yet (none "stays"); a
# loopback address other than 127.0.0.1 gets no warning
printf 'scene = Union UnitCube +;\n' >"$work/bad.qcs"
"$QCS" view --listen 127.0.0.2:0 "$work/bad.qcs" >"$work/o" 2>"$work/e" &
pid=$!
i=0
while ! grep -q "error (" "$work/o" && [ $i -lt 400 ]; do sleep 0.05; i=$((i + 1)); done
kill -INT $pid; wait $pid
if grep -q "bad.qcs: error (no picture yet)" "$work/o" && grep -q "bad.qcs:1:[0-9]*: error:" "$work/e" &&
   grep -q "http://127.0.0.2:" "$work/o" && ! grep -q "warning" "$work/e"; then
  echo "ok view-no-picture-yet"
else
  echo "FAIL view-no-picture-yet: $(cat "$work/o" "$work/e" | head -n 6 | tr '\n' '|')"
fi
timeout 400 python3 tests/view/viewtest.py "$QCS" "$work/t"; rc=$?
sh tests/view/repl_view.sh "$QCS" "$work/r"
exit $rc
