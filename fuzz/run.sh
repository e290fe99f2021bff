#!/bin/sh
# fuzz/run.sh: run libFuzzer targets for FUZZ_TIME seconds each (make fuzz).
#   sh fuzz/run.sh [parse eval probes image]
# Each target keeps a working corpus in build-fuzz/corpus/TARGET, seeded
# from fuzz/corpus/TARGET (the committed corpus) and, for the language
# targets, from tests/ and examples/. Crashes, timeouts and out-of-memory
# inputs go to build-fuzz/crashes/; the run goes on past them (fork mode)
# and the script exits 1 if any was found. A line per target is appended
# to build-fuzz/fuzz.log: date, target, seconds, executions, crashes.
cd "$(dirname "$0")/.." || exit 1
FUZZ_TIME=${FUZZ_TIME:-60}
B=build-fuzz
mkdir -p "$B/crashes"
status=0
[ $# -gt 0 ] || set -- parse eval probes image
for t in "$@"; do
  bin=$B/fuzz/fuzz_$t
  [ -x "$bin" ] || { echo "fuzz: $bin is not built (make fuzz-build)" >&2; exit 1; }
  mkdir -p "$B/corpus/$t" "fuzz/corpus/$t"
  seeds="fuzz/corpus/$t"; dict=""; len=4096; TIMEOUT=10
  case $t in
    parse|eval) seeds="$seeds tests/lang tests/bad examples"; dict="-dict=fuzz/qcs.dict" ;;
    probes) len=512; TIMEOUT=120 ;;
    image) len=65536 ;;
  esac
  for d in $seeds; do [ -d "$d" ] || seeds=$(echo "$seeds" | sed "s|$d||"); done
  before=$(ls "$B/crashes" | wc -l)
  echo "fuzz: $t for ${FUZZ_TIME}s"
  log=$B/fuzz-$t.log
  # -fork=1 with -ignore_*: a crash is saved and the run goes on.
  "$bin" "$B/corpus/$t" $seeds $dict -max_len=$len \
    -max_total_time="$FUZZ_TIME" -timeout=$TIMEOUT -rss_limit_mb=3072 \
    -fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1 \
    -close_fd_mask=3 -artifact_prefix="$B/crashes/$t-" >"$log" 2>&1
  runs=$(grep -o '#[0-9]*' "$log" | tail -1 | tr -d '#')
  after=$(ls "$B/crashes" | wc -l)
  found=$((after - before))
  echo "$(date -u +%FT%TZ) $t ${FUZZ_TIME}s ${runs:-0} runs $(( ${runs:-0} / FUZZ_TIME ))/s $found new crash files" | tee -a "$B/fuzz.log"
  [ "$found" -eq 0 ] || status=1
done
if [ "$status" -ne 0 ]; then
  echo "fuzz: crashes in $B/crashes/ (reproduce: $B/fuzz/fuzz_TARGET FILE)" >&2
fi
exit $status
