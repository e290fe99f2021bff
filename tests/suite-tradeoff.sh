#!/bin/sh
# suite-tradeoff.sh: `qcs tradeoff` on a small figure12: one table row per
# rung (1e-2 ... 1e-12), the plot written, and errors bounded by each
# rung's tolerance and falling from the loose rungs to the tight ones (a
# property, no hard-coded numbers). One line per check: "ok NAME" or
# "FAIL NAME: why".   QCS  the binary under test (default ./qcs)
cd "$(dirname "$0")/.." || exit 1
QCS=${QCS:-./qcs}
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
if ! "$QCS" tradeoff --size 60x38 --repeats 2 -o "$tmp/t.svg" \
     examples/figure12.qcs >"$tmp/out" 2>"$tmp/err"; then
  echo "FAIL tradeoff-runs: exit status $? ($(head -c 300 "$tmp/err"))"
  exit 1
fi
echo "ok tradeoff-runs"
rows=$(grep -c '^| 1e-' "$tmp/out")
[ "$rows" -eq 11 ] && echo "ok tradeoff-one-row-per-rung" ||
  echo "FAIL tradeoff-one-row-per-rung: $rows rows"
grep -q 'best wall time' "$tmp/out" && echo "ok tradeoff-says-best-of" ||
  echo "FAIL tradeoff-says-best-of"
grep -q '<svg' "$tmp/t.svg" 2>/dev/null && grep -q 'wall time' "$tmp/t.svg" &&
  grep -q '1e-05' "$tmp/t.svg" && echo "ok tradeoff-plot" ||
  echo "FAIL tradeoff-plot: no labelled SVG"
# columns: | tol | time | evals | steps | maxdZ | rmsdZ | rgb | changed |
awk -F'|' '/^\| 1e-/ && $6 !~ /ref/ {
    tol = $2 + 0; mx = $6 + 0; rms = $7 + 0;
    if (mx > tol) bad = bad " max dZ " mx " > tol " tol;
    if (rms > mx) bad = bad " rms > max at " tol;
    if (tol >= 1e-6 && mx > loose) loose = mx;
    if (tol <= 1e-9 && mx > tight) tight = mx;
    n++
  }
  END {
    if (n != 10) bad = bad " " n " compared rungs";
    if (!(tight < loose)) bad = bad " tight rungs (" tight ") not below loose (" loose ")";
    if (bad) { print "FAIL tradeoff-errors-fall:" bad; exit }
    print "ok tradeoff-errors-fall"
  }' "$tmp/out"
# the evaluation count rises as the tolerance tightens, end to end
awk -F'|' '/^\| 1e-0[2]/ {a = $4 + 0} /^\| 1e-12/ {b = $4 + 0}
  END { if (b > a) print "ok tradeoff-evals-rise"; else print "FAIL tradeoff-evals-rise: " a " then " b }' "$tmp/out"
# a scene the tolerance cannot change (sharp and soft only) says so
if "$QCS" tradeoff --size 30x20 --repeats 1 -o "$tmp/m.svg" examples/mould.qcs \
     >"$tmp/out2" 2>"$tmp/err2" && grep -q 'no Rounded object' "$tmp/out2"; then
  echo "ok tradeoff-says-tolerance-unused"
else echo "FAIL tradeoff-says-tolerance-unused: $(head -c 200 "$tmp/err2")"; fi
# the cost line: the spread of times over the ladder against the noise
grep -Eq '^time varies by [0-9]+% over the ladder.*(within|beyond) run-to-run' "$tmp/out" &&
  echo "ok tradeoff-says-cost-against-noise" ||
  echo "FAIL tradeoff-says-cost-against-noise: $(grep 'time varies' "$tmp/out")"
# the samples-per-pixel ladder: 1, 4, 16, 64 against a 256-sample reference
if "$QCS" tradeoff --spp --size 48x30 --repeats 1 -o "$tmp/s.svg" \
     examples/figure12.qcs >"$tmp/out3" 2>"$tmp/err3"; then
  echo "ok tradeoff-spp-runs"
else echo "FAIL tradeoff-spp-runs: $(head -c 300 "$tmp/err3")"; fi
# columns: | spp | time | rgb |
awk -F'|' '/^\| [0-9]+ \|/ { s = $2 + 0; e[s] = $4; t[s] = $3 + 0; n++ }
  END {
    if (n != 5 || e[256] !~ /ref/) { print "FAIL tradeoff-spp-errors-fall: " n " rows"; exit }
    if (!(e[1] + 0 > e[4] + 0 && e[4] + 0 > e[16] + 0 && e[1] + 0 > e[64] + 0 && e[64] + 0 > 0))
      { print "FAIL tradeoff-spp-errors-fall: " e[1] e[4] e[16] e[64]; exit }
    if (!(t[64] > t[1])) { print "FAIL tradeoff-spp-errors-fall: 64 spp not slower than 1"; exit }
    print "ok tradeoff-spp-errors-fall"
  }' "$tmp/out3"
if grep -q '<svg' "$tmp/s.svg" 2>/dev/null && grep -q '</svg>' "$tmp/s.svg" &&
   grep -q 'RMS RGB error against 256 samples' "$tmp/s.svg" &&
   grep -q '>64 spp<' "$tmp/s.svg" &&
   { ! command -v python3 >/dev/null ||
     python3 -c 'import sys, xml.dom.minidom as m; m.parse(sys.argv[1])' "$tmp/s.svg"; }; then
  echo "ok tradeoff-spp-plot"
else echo "FAIL tradeoff-spp-plot: no well-formed labelled SVG"; fi
# the mesh-tolerance ladder: a sphere (one key) over a floor, which is left
# out; triangles rise rung by rung, each rung within the mesher's promise
# (certified <= tolerance), and the sampled distance (at least the true
# distance of each point; for a sphere the normal is nearly radial, so
# about it) within the certified bound and falling.
cat > "$tmp/ball.qcs" <<'QCS'
scene = Union (SoftObject 0.5 [Key (0, 1, 0) 1 1]) (Halfspace ((0, 1, 0), 0));
QCS
if "$QCS" tradeoff --mesh -o "$tmp/mesh.svg" "$tmp/ball.qcs" >"$tmp/out4" 2>"$tmp/err4"; then
  echo "ok tradeoff-mesh-runs"
else echo "FAIL tradeoff-mesh-runs: $(head -c 300 "$tmp/err4")"; fi
grep -q '1 unbounded part left out' "$tmp/out4" && echo "ok tradeoff-mesh-says-floor-left-out" ||
  echo "FAIL tradeoff-mesh-says-floor-left-out: $(head -2 "$tmp/out4")"
# columns: | tolerance | triangles | time | certified | max | rms | points |
awk -F'|' '/^\| [0-9.e-]+ \| [0-9]+ \|/ {
    tol = $2 + 0; tri = $3 + 0; cert = $5 + 0; mx = $6 + 0; rms = $7 + 0;
    if (cert > tol) bad = bad " certified " cert " > tol " tol;
    if (!(mx > 0) || mx > cert) bad = bad " sampled " mx " vs certified " cert;
    if (rms > mx) bad = bad " rms > max at " tol;
    if (n && !(tri > prev_tri)) bad = bad " triangles " prev_tri " then " tri;
    if (n && !(mx < prev_mx)) bad = bad " sampled " prev_mx " then " mx;
    if ($8 ~ /beyond/) bad = bad " unresolved points at " tol;
    prev_tri = tri; prev_mx = mx; n++
  }
  END {
    if (n != 4) bad = bad " " n " rungs";
    if (bad) { print "FAIL tradeoff-mesh-ladder:" bad; exit }
    print "ok tradeoff-mesh-ladder"
  }' "$tmp/out4"
if grep -q 'distance of the mesh to the surface' "$tmp/mesh.svg" 2>/dev/null &&
   grep -q 'triangles</text>' "$tmp/mesh.svg" &&
   { ! command -v python3 >/dev/null ||
     python3 -c 'import sys, xml.dom.minidom as m; m.parse(sys.argv[1])' "$tmp/mesh.svg"; }; then
  echo "ok tradeoff-mesh-plot"
else echo "FAIL tradeoff-mesh-plot: no well-formed labelled SVG"; fi
printf 'scene = Halfspace ((0, 1, 0), 0);\n' > "$tmp/floor.qcs"
if "$QCS" tradeoff --mesh -o "$tmp/no.svg" "$tmp/floor.qcs" >/dev/null 2>"$tmp/err5"; then
  echo "FAIL tradeoff-mesh-nothing-bounded: succeeded"
elif grep -q 'no bounded part to mesh' "$tmp/err5" && [ ! -e "$tmp/no.svg" ]; then
  echo "ok tradeoff-mesh-nothing-bounded"
else echo "FAIL tradeoff-mesh-nothing-bounded: $(head -c 200 "$tmp/err5")"; fi
