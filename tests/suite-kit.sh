#!/bin/sh
# suite-kit.sh: the modeller's kit (stdlib/kit.qcs, issue 19) against
# independent geometry: tests/kit/geometry.py computes inside/outside of
# every solid, transform and pattern from its definition (vertices, hulls,
# inverse maps, distances) and compares with qcs's PointInObject on
# random points (fixed seed), and Density under rigid maps. The error
# cases are tests/lang/kit/*.qcs (suite-lang.sh); the editors' keyword
# lists are checked by suite-editors.sh. One line per check.
#   QCS  the binary under test (default ./qcs), run from the project root
cd "$(dirname "$0")/.." || exit 1
QCS=${QCS:-./qcs}
case $QCS in /*) ;; *) QCS=$PWD/$QCS ;; esac
if [ ! -x "$QCS" ]; then
  echo "FAIL kit: no binary at $QCS"
  exit 1
fi
if ! command -v python3 >/dev/null 2>&1; then
  echo "skip kit: no python3"
  exit 0
fi
python3 tests/kit/geometry.py "$QCS" --points 400 --seed 19
