#!/bin/sh
# suite-prompt.sh: seeing what you model at the prompt (issue 13): :type,
# :info, :doc, the docs and examples of every built-in and prelude
# function, shadowing warnings, continuation lines, :reload and renders,
# errors at the user's line. Piped stdin (the plain loop) for most checks;
# the ...> prompt through tmux. One line per check: "ok NAME", "FAIL NAME:
# why" or "skip NAME: why".
#   QCS  the binary under test (default ./qcs), run from the project root
cd "$(dirname "$0")/.." || exit 1
QCS=${QCS:-./qcs}
case $QCS in /*) ;; *) QCS=$PWD/$QCS ;; esac
if [ ! -x "$QCS" ]; then
  echo "FAIL prompt: no binary at $QCS"
  exit 1
fi
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
trap 'exit 1' INT TERM
ok() { echo "ok $1"; }
fail() { printf 'FAIL %s: %s\n' "$1" "$(printf '%s' "$2" | tr '\n' '|' | cut -c1-300)"; }
if command -v timeout >/dev/null 2>&1; then lim="timeout 60"; else lim=""; fi
# q: $QCS on piped stdin (given as arguments, one line each), clean HOME,
# in $tmp; stdout in $tmp/out, stderr in $tmp/err, status in $rc
q() { printf '%s\n' "$@" >"$tmp/in"; (cd "$tmp" && HOME=$tmp $lim "$QCS" <in >out 2>err); rc=$?; }
# expect NAME FILE PATTERN...: every (grep -E) pattern is a line of FILE
expect() {
  name=$1 file=$2; shift 2
  for p in "$@"; do
    if ! grep -Eq -- "$p" "$tmp/$file"; then
      fail "$name" "no line '$p' in $file: $(cat "$tmp/out" "$tmp/err")"
      return 1
    fi
  done
  ok "$name"
}

# ---- :type ----
q ':type 1 + 2' ':t "a"' ':t (1, 2, 3)' ':t [1, 2]' ':t Shift' ':t Shift (1, 0, 0)' \
  ':t Rounded' ':t Rounded 0.1 UnitCube' ':t sqrt'
expect type-kinds out '^a Real$' '^a String$' '^a 3-tuple$' \
  '^a list whose first element is a Real$' '^Shift :: Vector a -> a$' \
  '^a function of 2 arguments \(Shift\)$' \
  '^a function of 1 more argument \(Shift given 1 of 2\)$' \
  '^the constructor Rounded of SceneObject: a function of 2 arguments$' \
  '^a SceneObject, made by the constructor Rounded$' \
  '^a scene object: rounded, 6 leaves, box \(0, 0, 0\) \.\. \(1, 1, 1\)$' \
  '^a built-in function of 1 argument \(sqrt\)$'
# a soft object's box is where its surface is (Wyvill's C(r) = magic, solved
# here by bisection), not the keys' reach R
q ':t SoftObject 0.3 [Key (1, 2, 3) 2 1.5]'
why=$(python3 - "$tmp/out" <<'PY'
import re, sys
txt = open(sys.argv[1]).read()
m = re.search(r"soft, 1 key, box \(([^)]*)\) \.\. \(([^)]*)\)", txt)
if not m: print("no box in %r" % txt); sys.exit()
lo = [float(x) for x in m.group(1).split(",")]
hi = [float(x) for x in m.group(2).split(",")]
C = lambda s: 1.5 * (1 - 22/9*s + 17/9*s*s - 4/9*s**3)  # s = (r/R)^2
a, b = 0.0, 2.0
for _ in range(200):
    r = (a + b) / 2
    a, b = (r, b) if C((r / 2) ** 2) > 0.3 else (a, r)
for c, l, h in zip((1, 2, 3), lo, hi):
    if abs((c - l) - r) > 2e-3 or abs((h - c) - r) > 2e-3:
        print("box %s .. %s, surface radius %.6f" % (lo, hi, r))
PY
)
if [ "$rc" = 0 ] && [ -z "$why" ]; then ok type-soft-box; else fail type-soft-box "status $rc: $why"; fi
q ':t nosuchname' '1 + 1'
if [ "$rc" = 1 ] && grep -q "unknown name 'nosuchname'" "$tmp/err" && [ "$(cat "$tmp/out")" = 2 ]
then ok type-error; else fail type-error "status $rc: $(cat "$tmp/out" "$tmp/err")"; fi

# ---- :info and :doc ----
q ':info Shift' ':i sqrt' ':i Rounded' ':i UnitCube' 'f x = x * 2' ':i f' ':i lenght'
expect info-kinds out '^Shift  -- prelude function, 2 arguments, defined at <prelude>:[0-9]+$' \
  '^  Shift v obj: ' '^  e\.g\. Shift ' \
  '^sqrt  -- built-in, 1 argument$' '^  sqrt x: square root$' '^  e\.g\. sqrt 16$' \
  '^Rounded  -- constructor of SceneObject, 2 arguments, defined at <prelude>:' \
  '^UnitCube  -- prelude value, defined at' \
  '^f  -- your definition, 1 argument, defined at the prompt$' &&
expect info-unknown err "'lenght' is not defined \(did you mean 'length'\?\)"
printf '// doc: twice x: x added to itself\n// e.g. twice 4\ntwice :: Real -> Real;\ntwice x = x + x;\n' >"$tmp/lib.qcs"
q ':load lib.qcs' ':doc twice' ':doc map'
expect doc-user-file out '^twice :: Real -> Real$' '^twice x: x added to itself$' '^e\.g\. twice 4$' \
  '^map f xs: f applied to every element$'

# Every built-in and prelude function has a doc and an example, and the
# examples run without an error (renders write into $tmp).
q ':browse!'
names=$(grep -v -- '-- constructor' "$tmp/out" | awk '{print $1}')
n=$(printf '%s\n' $names | wc -l)
set --
for nm in $names; do set -- "$@" ":doc $nm"; done
q "$@"
undoc=$(grep 'has no doc' "$tmp/out")
neg=$(grep -c '^e\.g\. ' "$tmp/out")
if [ -z "$undoc" ] && [ "$neg" -eq "$n" ] && [ "$n" -gt 100 ]; then ok doc-every-name
else fail doc-every-name "$n names, $neg examples: $undoc"; fi
grep '^e\.g\. ' "$tmp/out" | sed 's/^e\.g\. //' >"$tmp/examples"
(cd "$tmp" && HOME=$tmp $lim "$QCS" <examples >out 2>err); rc=$?
if [ "$rc" = 0 ] && ! grep -q 'error' "$tmp/err"; then ok doc-examples-run
else fail doc-examples-run "status $rc: $(grep -A2 error "$tmp/err" | head -5)"; fi

# ---- shadowing ----
q 'map f xs = 42' 'map f xs = 43' 'map 1 2' ':browse'
nwarn=$(grep -c 'warning: map shadows the prelude' "$tmp/err")
if [ "$rc" = 0 ] && [ "$nwarn" = 1 ] && grep -q '^43$' "$tmp/out" &&
   grep -q "^map  -- yours, shadows the prelude's map" "$tmp/out"
then ok shadow-warn-once; else fail shadow-warn-once "status $rc, $nwarn warnings: $(cat "$tmp/out" "$tmp/err")"; fi
q 'sqrt x = x' 'sqrt 9' 'length [1, 2]'
if [ "$rc" = 0 ] && grep -q 'warning: sqrt shadows the built-in sqrt' "$tmp/err" &&
   [ "$(cat "$tmp/out")" = "$(printf '9\n2')" ]
then ok shadow-builtin; else fail shadow-builtin "status $rc: $(cat "$tmp/out" "$tmp/err")"; fi
printf 'floor = Halfspace ((0, 1, 0), 0)\n' >"$tmp/fl.qcs"
(cd "$tmp" && $lim "$QCS" fl.qcs >out 2>err); rc=$?
if [ "$rc" = 0 ] && [ ! -s "$tmp/err" ]; then ok shadow-script-quiet
else fail shadow-script-quiet "status $rc: $(cat "$tmp/err")"; fi

# ---- continuation lines (piped: the definition is joined before it runs) ----
q 'f x = y' '  where' '    y = x + 1' 'f 1' \
  'g x' '  | x < 0 = 0' '  | otherwise = x' 'g 5' 'g (-1)' \
  'h x = x' '  + 1' 'h 1' 'k x = x * w where' '  w = 3' 'k 2'
if [ "$rc" = 0 ] && [ ! -s "$tmp/err" ] && [ "$(cat "$tmp/out")" = "$(printf '2\n5\n0\n2\n6')" ]
then ok continuation-pipe; else fail continuation-pipe "status $rc: $(cat "$tmp/out" "$tmp/err")"; fi
q 'let y = 1 in y' '  + 1'
if [ "$rc" = 1 ] && [ "$(cat "$tmp/out")" = 1 ]; then ok continuation-not-expression
else fail continuation-not-expression "status $rc: $(cat "$tmp/out" "$tmp/err")"; fi

# ---- :reload leaves renders out; :reload! and reload-renders run them ----
printf 'h x = x + 1\nrender "r.png" (Rounded 0.1 UnitCube)\nh 1\n' >"$tmp/r.qcs"
rm -f "$tmp/r.png"
printf ':load r.qcs\n' >"$tmp/in1"
(cd "$tmp" && HOME=$tmp $lim "$QCS" <in1 >/dev/null 2>&1)
if [ -f "$tmp/r.png" ]; then ok reload-load-renders; else fail reload-load-renders ":load did not write r.png"; fi
rm -f "$tmp/r.png"
# the render reports: one for :load, none for :reload
q ':load r.qcs' ':reload' 'h 5'
nrep=$(grep -c '^r\.png: 600x380' "$tmp/err")
if [ "$rc" = 0 ] && [ "$nrep" = 1 ] && grep -q '^(1 render in r.qcs not run again; :reload! runs them)$' "$tmp/out" &&
   [ "$(grep -c '^2$' "$tmp/out")" = 2 ] && grep -q '^6$' "$tmp/out"
then ok reload-no-render; else fail reload-no-render "status $rc, $nrep renders: $(cat "$tmp/out" "$tmp/err")"; fi
q ':load r.qcs' ':reload!' ':set reload-renders on' ':reload'
nrep=$(grep -c '^r\.png: 600x380' "$tmp/err")
if [ "$rc" = 0 ] && [ "$nrep" = 3 ]; then ok reload-bang-renders
else fail reload-bang-renders "status $rc, $nrep renders, want 3: $(cat "$tmp/err")"; fi
printf 'map f xs = 0\nmine = 7\n' >"$tmp/m.qcs"
q ':load m.qcs' 'map (\x -> x) [1]' ':unload m.qcs' 'map (\x -> x) [1]' 'mine'
if [ "$rc" = 1 ] && [ "$(cat "$tmp/out")" = "$(printf '0\nunloaded m.qcs: 2 definitions removed\n[1]')" ] &&
   grep -q "unknown name 'mine'" "$tmp/err"
then ok unload; else fail unload "status $rc: $(cat "$tmp/out" "$tmp/err")"; fi

# ---- errors raised in the prelude are reported at the user's call ----
printf 'obj = Shift (1, 2) UnitCube\nDensity 0.1 (0, 0, 0) obj\n' >"$tmp/e1.qcs"
(cd "$tmp" && $lim "$QCS" e1.qcs >out 2>err); rc=$?
if [ "$rc" = 1 ] && [ "$(head -1 "$tmp/err")" = "e1.qcs:1:7: error: the second argument of dot must be a 3-tuple of Reals, not a tuple: (1, 2)" ] &&
   grep -q '^  (raised inside the prelude, at <prelude>:[0-9]*:[0-9]*)$' "$tmp/err" &&
   grep -q '^  in Density, called at e1.qcs:2:1$' "$tmp/err"
then ok error-at-user-shift; else fail error-at-user-shift "status $rc: $(cat "$tmp/err")"; fi
printf 'b = Rounded 0.1 (Box (1, 1, 1) (0, 0, 0))\nrender "b.png" b\n' >"$tmp/e2.qcs"
(cd "$tmp" && $lim "$QCS" e2.qcs >out 2>err); rc=$?
if [ "$rc" = 1 ] && [ "$(head -1 "$tmp/err")" = "e2.qcs:1:18: error: Scale needs finite factors > 0, not (-1, -1, -1)" ] &&
   grep -q '^  in the prelude: error, ScalePlane, ShiftPlane, renderWith (4 calls)$' "$tmp/err" &&
   grep -q '^  in render, called at e2.qcs:2:1$' "$tmp/err"
then ok error-at-user-box; else fail error-at-user-box "status $rc: $(cat "$tmp/err")"; fi
q 'c = Shift (1, 2) UnitCube' 'Density 0.1 (0, 0, 0) c'
if [ "$rc" = 1 ] && grep -q '^<stdin>:1:5: error: the second argument of dot' "$tmp/err" &&
   grep -q '^  c = Shift (1, 2) UnitCube$' "$tmp/err"
then ok error-at-user-prompt; else fail error-at-user-prompt "status $rc: $(cat "$tmp/err")"; fi

# ---- the terminal, through tmux: the ...> prompt of a continued definition ----
TMUX_CHECKS="prompt-tmux-where prompt-tmux-guards prompt-tmux-type
prompt-tmux-doc prompt-tmux-shadow prompt-tmux-reload"
if ! command -v tmux >/dev/null 2>&1; then
  for c in $TMUX_CHECKS; do echo "skip $c: tmux is not installed"; done
  exit 0
fi
unset TMUX
sock=qcs-prompt-$$
T() { tmux -L "$sock" -f /dev/null "$@"; }
trap 'T kill-server >/dev/null 2>&1; rm -rf "$tmp"' EXIT
mkdir -p "$tmp/home"
T new-session -d -s qcs -x 100 -y 40 \
  "env HOME='$tmp/home' INPUTRC=/dev/null TERM=xterm '$QCS'; sleep 60" ||
  { for c in $TMUX_CHECKS; do echo "skip $c: tmux could not start"; done; exit 0; }
pane() { T capture-pane -p -J -t qcs -S - 2>/dev/null; }
count() { pane | grep -cE -- "$1"; }
wait_count() {
  i=0
  while [ "$(count "$1")" -lt "$2" ]; do
    i=$((i + 1)); [ $i -gt 100 ] && return 1; sleep 0.05
  done
}
enter() {
  n=$(count "$1")
  T send-keys -t qcs -l "$2"; T send-keys -t qcs Enter
  wait_count "$1" $((n + 1))
}
why() { echo "$1; screen ends: $(pane | grep -v '^$' | tail -n 4 | tr '\n' '|')"; }
if ! wait_count '^qcs> ' 1; then
  for c in $TMUX_CHECKS; do echo "skip $c: the REPL showed no prompt"; done
  exit 0
fi
# f x = y runs (y is unknown); "  where" continues it at ...>; the
# definition is then run whole
if enter "unknown name 'y'" 'f x = y' && enter '^\.\.\.> ' '  where' &&
   enter '^qcs> ' '    y = x + 1' && enter '^2$' 'f 1'
then ok prompt-tmux-where; else fail prompt-tmux-where "$(why 'f x = y / where / y = x + 1 / f 1')"; fi
if enter '^qcs> ' 'g x' && enter '^qcs> ' '  | x < 0 = 0' && enter '^qcs> ' '  | otherwise = x' &&
   enter '^5$' 'g 5' && enter '^0$' 'g (-3)'
then ok prompt-tmux-guards; else fail prompt-tmux-guards "$(why 'g x / guards / g 5 / g (-3)')"; fi
if enter '^a function of 1 argument \(f\)$' ':t f' && enter '^  e\.g\. Shift ' ':i Shift'
then ok prompt-tmux-type; else fail prompt-tmux-type "$(why ':t f / :i Shift')"; fi
if enter '^e\.g\. map ' ':doc map' && [ "$(count '^map f xs: f applied to every element')" -ge 1 ]
then ok prompt-tmux-doc; else fail prompt-tmux-doc "$(why ':doc map showed no doc and example')"; fi
if enter "warning: map shadows the prelude" 'map f xs = 42' && enter '^qcs> ' 'map f xs = 43' &&
   enter '^43$' 'map 1 2' && [ "$(count 'warning: map shadows the prelude')" -eq 1 ]
then ok prompt-tmux-shadow; else fail prompt-tmux-shadow "$(why 'one shadowing warning for two definitions of map')"; fi
printf 'h x = x + 1\nrender "%s/tr.png" (Rounded 0.1 UnitCube)\n' "$tmp" >"$tmp/tr.qcs"
rm -f "$tmp/tr.png"
if enter 'tr\.png: 600x380' ":load $tmp/tr.qcs" && [ -f "$tmp/tr.png" ] && rm -f "$tmp/tr.png" &&
   enter '^\(1 render in .*tr\.qcs not run again; :reload! runs them\)$' ':reload' &&
   enter '^6$' 'h 5' && [ ! -f "$tmp/tr.png" ] && [ "$(count 'tr\.png: 600x380')" -eq 1 ]
then ok prompt-tmux-reload; else fail prompt-tmux-reload "$(why ':reload ran the render again, or lost h')"; fi
