#!/bin/sh
# run-all.sh: every test suite of qcs, then one closing line
# "N passed, N failed, N skipped". Each suite prints one line per test:
# "ok NAME", "FAIL NAME: why" or "skip NAME: why".
#   QCS           the binary under test (default ./qcs)
#   QCS_UNIT_DIR  where the C unit test binaries are (default build/tests)
cd "$(dirname "$0")/.." || exit 1
QCS=${QCS:-./qcs}; export QCS
UNIT_DIR=${QCS_UNIT_DIR:-build/tests}
log=$(mktemp); trap 'rm -f "$log"' EXIT

for t in "$UNIT_DIR"/test_*; do
  [ -x "$t" ] || continue
  "$t" >>"$log" 2>&1 || grep -q '^FAIL' "$log" || echo "FAIL $(basename "$t"): exited with status $?" >>"$log"
done
for s in tests/suite-*.sh; do
  [ -f "$s" ] || continue
  sh "$s" >>"$log" 2>&1 || grep -q '^FAIL' "$log" || echo "FAIL $s: exited with status $?" >>"$log"
done

grep -E '^(FAIL|skip) ' "$log"
passed=$(grep -c '^ok ' "$log"); failed=$(grep -c '^FAIL ' "$log"); skipped=$(grep -c '^skip ' "$log")
echo "$passed passed, $failed failed, $skipped skipped"
[ "$failed" -eq 0 ] && [ "$passed" -gt 0 ]
