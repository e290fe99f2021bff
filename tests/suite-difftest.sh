#!/bin/sh
# suite-difftest.sh: qcs against Hugs 98 on random programs of the subset
# the two languages share (issue 20; tests/difftest/difftest.py). A fixed
# seed, so that make test is repeatable; make difftest N=5000 SEED=S runs
# more. Prints "ok difftest/..." or "FAIL difftest/...", with both
# programs of every disagreement. runhugs (Debian package hugs, installed
# by make deps) is required: without it the suite fails.
#   QCS               the binary under test (default ./qcs)
#   QCS_DIFFTEST_N    how many programs (default 300)
#   QCS_DIFFTEST_SEED the seed (default 1)
cd "$(dirname "$0")/.." || exit 1
QCS=${QCS:-./qcs}
N=${QCS_DIFFTEST_N:-300}
SEED=${QCS_DIFFTEST_SEED:-1}
if ! command -v python3 >/dev/null 2>&1; then
  echo "FAIL difftest: python3 not found"; exit 1
fi
if ! command -v runhugs >/dev/null 2>&1; then
  echo "FAIL difftest: runhugs not found (Debian package hugs: run make deps as root)"; exit 1
fi
python3 tests/difftest/difftest.py -n "$N" --seed "$SEED" --qcs "$QCS" ||
  echo "FAIL difftest: to see the programs again: make difftest N=$N SEED=$SEED"
