#!/bin/sh
# suite-fuzz.sh: replay the committed fuzz corpora (fuzz/corpus/TARGET) and
# the crash regressions (fuzz/crashes/TARGET-*) through each fuzz target,
# built as a plain program (fuzz/replay.c). One "ok" line per target, or
# "FAIL" naming the input that made it die.
#   QCS_UNIT_DIR  where the test binaries are (default build/tests); the
#                 replay programs are in its sibling fuzz/ directory.
cd "$(dirname "$0")/.." || exit 1
UNIT_DIR=${QCS_UNIT_DIR:-build/tests}
BIN_DIR=$(dirname "$UNIT_DIR")/fuzz
for t in parse eval probes image render; do
  bin=$BIN_DIR/replay_$t
  if [ ! -x "$bin" ]; then echo "FAIL fuzz-replay $t: $bin not built"; continue; fi
  set -- fuzz/corpus/$t
  for c in fuzz/crashes/$t-*; do [ -f "$c" ] && set -- "$@" "$c"; done
  [ -d fuzz/corpus/$t ] || { echo "skip fuzz-replay $t: no corpus"; continue; }
  out=$("$bin" "$t" "$@" 2>/dev/null </dev/null)
  rc=$?
  if [ $rc -eq 0 ]; then echo "$out" | grep '^ok '
  else
    last=$(QCS_REPLAY_VERBOSE=1 "$bin" "$t" "$@" 2>&1 >/dev/null </dev/null | grep '^replay: ' | tail -1)
    echo "FAIL fuzz-replay $t: status $rc at ${last#replay: }"
  fi
done
