#!/bin/sh
# suite-preview.sh: pictures at the prompt. A tmux server on a private
# socket plays a terminal that knows no graphics (so qcs draws Unicode
# symbols, which tmux can capture); the kitty and sixel paths are written
# to files and parsed back; a pipe must get no escape codes at all.
# One line per check: "ok NAME", "FAIL NAME: why" or "skip NAME: why".
#   QCS  the binary under test (default ./qcs), run from the project root
cd "$(dirname "$0")/.." || exit 1
QCS=${QCS:-./qcs}
case $QCS in /*) ;; *) QCS=$PWD/$QCS ;; esac

TMUX_CHECKS="preview-auto preview-summary preview-show-with preview-ctrl-c
preview-key-stops preview-nothing-hit preview-off preview-size-bad
preview-show-not-object preview-list preview-resize"

tmp=$(mktemp -d) || exit 1
sock=qcs-preview-$$
T() { tmux -L "$sock" -f /dev/null "$@"; }
cleanup() {
  T kill-server >/dev/null 2>&1
  rm -rf "$tmp"
}
trap cleanup EXIT
trap 'exit 1' INT TERM

ok() { echo "ok $1"; }
fail() { printf 'FAIL %s: %s\n' "$1" "$(printf '%s' "$2" | tr '\n' '|' | cut -c1-300)"; }
if command -v timeout >/dev/null 2>&1; then lim="timeout 20"; else lim=""; fi
ESC=$(printf '\033')

# ---- no terminal: no escape codes ----

out=$(echo 'Rounded 0.1 UnitCube' | HOME=$tmp $lim "$QCS" 2>"$tmp/err"); rc=$?
if [ $rc -eq 0 ] && printf '%s' "$out" | grep -q '^Rounded 0.1 (Product' &&
   ! printf '%s' "$out" | grep -q "$ESC"; then ok pipe-no-escapes
else fail pipe-no-escapes "status $rc, got '$(printf '%s' "$out" | head -c 200 | cat -v)'"; fi

printf 'scene = Rounded 0.1 UnitCube\n' >"$tmp/cube.qcs"
out=$(HOME=$tmp $lim "$QCS" --show "$tmp/cube.qcs" 2>"$tmp/err"); rc=$?
if [ $rc -eq 1 ] && grep -q 'not a terminal' "$tmp/err" &&
   ! printf '%s' "$out" | grep -q "$ESC"; then ok show-pipe-refused
else fail show-pipe-refused "status $rc, stderr '$(head -c 200 "$tmp/err")'"; fi

# graphics asked for by name inside tmux: said to need passing through
printf ':set preview sixel\n:set preview symbols\n' | TMUX=/tmp/x,1,0 HOME=$tmp $lim "$QCS" >/dev/null 2>"$tmp/err"
if [ "$(grep -c 'tmux and screen do not pass sixel graphics through' "$tmp/err")" = 1 ]; then ok preview-tmux-graphics-note
else fail preview-tmux-graphics-note "stderr '$(head -c 200 "$tmp/err")'"; fi

# ---- kitty and sixel, parsed back ----

if command -v python3 >/dev/null 2>&1; then
  for mode in kitty sixel; do
    HOME=$tmp $lim "$QCS" --show --preview $mode --cells 24x8 "$tmp/cube.qcs" \
      >"$tmp/$mode.out" 2>"$tmp/$mode.err"; rc=$?
    why=$(python3 tests/preview/parse_graphics.py $mode "$tmp/$mode.out" 2>&1)
    if [ $rc -eq 0 ] && [ -z "$why" ]; then ok preview-$mode-well-formed
    else fail preview-$mode-well-formed "status $rc: $why $(head -c 200 "$tmp/$mode.err")"; fi
  done
else
  echo "skip preview-kitty-well-formed: python3 is not installed"
  echo "skip preview-sixel-well-formed: python3 is not installed"
fi

# ---- a terminal asked what it is (DA1), on a pseudo-terminal ----
# It answers with sixels, without, or not at all; and an output redirected
# to a file gets values only, the prompt staying on the terminal.
if command -v python3 >/dev/null 2>&1; then
  for c in sixel nosixel silent redirect; do
    $lim python3 tests/preview/pty_term.py "$QCS" $c # prints its ok/FAIL line
    rc=$?; [ $rc -gt 1 ] && fail pty-$c "the pseudo-terminal run ended with status $rc"
  done
else
  for c in sixel nosixel silent redirect; do echo "skip pty-$c: python3 is not installed"; done
fi
v=$("$QCS" --version 2>&1); rc=$?
if [ $rc -eq 0 ] && printf '%s\n' "$v" | grep -qE '^qcs [0-9]+\.[0-9]+'; then ok version
else fail version "status $rc, '$v'"; fi

# ---- the terminal, through tmux ----

if ! command -v tmux >/dev/null 2>&1; then
  for c in $TMUX_CHECKS; do echo "skip $c: tmux is not installed"; done
  exit 0
fi
unset TMUX

home=$tmp/home
mkdir -p "$home"
T new-session -d -s qcs -x 100 -y 40 \
  "env HOME='$home' INPUTRC=/dev/null TERM=xterm-256color '$QCS'; echo qcs-exit-status=\$?; sleep 60" ||
  { for c in $TMUX_CHECKS; do echo "skip $c: tmux could not start"; done; exit 0; }

pane() { T capture-pane -p -J -t qcs -S - 2>/dev/null; }
count() { pane | grep -cE -- "$1"; }
wait_count() {
  i=0
  while [ "$(count "$1")" -lt "$2" ]; do
    i=$((i + 1))
    [ $i -gt 200 ] && return 1
    sleep 0.05
  done
  return 0
}
enter() {
  pat=$1
  n=$(count "$pat")
  T send-keys -t qcs -l "$2"
  T send-keys -t qcs Enter
  wait_count "$pat" $((n + 1))
}
why() { echo "$1; screen ends: $(pane | grep -v '^$' | tail -n 3 | tr '\n' '|')"; }
# symbols: lines of the pane holding block or box-drawing characters
symbols() { pane | grep -c '[▀▄█▌▐▁▂▃▅▆▇▔▕▏▎▍▋▊╴╵╶╷─│┌┐└┘]'; }

if ! wait_count '^qcs> ' 1; then
  for c in $TMUX_CHECKS; do echo "skip $c: the REPL showed no prompt"; done
  exit 0
fi
if [ "$(pane | grep -c '^qcs [0-9.]*: type an expression or a definition; :help for help')" -eq 1 ]; then
  ok repl-banner
else fail repl-banner "no one-line banner on the terminal"; fi
out=$(echo '1' | HOME=$tmp $lim "$QCS" 2>&1)
if [ "$out" = 1 ]; then ok pipe-no-banner
else fail pipe-no-banner "a pipe got '$out'"; fi

s0=$(symbols)
if enter 'rounded, 6 leaves, box \(0, 0, 0\) \.\. \(1, 1, 1\)' 'Rounded 0.1 UnitCube'; then
  ok preview-summary
else fail preview-summary "$(why 'no one-line summary for Rounded 0.1 UnitCube')"; fi
wait_count '^qcs> ' 2
s1=$(symbols)
if [ $((s1 - s0)) -ge 10 ] && [ "$(count '^Rounded 0.1 \(Product \(Product \(Product')" -eq 0 ]; then
  ok preview-auto
else fail preview-auto "$(why "$((s1 - s0)) lines of symbols, or the tree was printed")"; fi

enter '^qcs> ' 'b = Box (0, 0, 0) (2, 1, 1)'
if enter 'sharp CSG, 6 leaves, box \(0, 0, 0\) \.\. \(2, 1, 1\)' \
  ':show b with [Camera (4, 3, 5) (1, 0.5, 0.5) 30, Size 300 200]'; then
  ok preview-show-with
else fail preview-show-with "$(why ':show b with [...] showed no summary')"; fi
wait_count '^qcs> ' 4

# A slow picture (64 samples a pixel) stopped by Ctrl-C keeps every definition.
enter '^qcs> ' 'keep = 41'
T send-keys -t qcs -l ':show Rounded 0.3 (Sum UnitCube b) with [Samples 64, Size 1200 800]'
T send-keys -t qcs Enter
sleep 0.4
n=$(count '^qcs> ')
T send-keys -t qcs C-c
if wait_count '\(picture stopped\)' 1 && wait_count '^qcs> ' $((n + 1)) &&
   enter '^42$' 'keep + 1'; then ok preview-ctrl-c
else fail preview-ctrl-c "$(why 'no "(picture stopped)", or keep lost')"; fi

# A key typed during a picture stops it and reaches the prompt.
T send-keys -t qcs -l ':show Rounded 0.3 (Sum UnitCube b) with [Samples 64, Size 1200 800]'
T send-keys -t qcs Enter
sleep 0.4
T send-keys -t qcs -l 'keep * 2'
T send-keys -t qcs Enter
if wait_count '^82$' 1 && [ "$(count '\(picture stopped\)')" -eq 1 ]; then ok preview-key-stops
else fail preview-key-stops "$(why 'typing during a picture did not reach the prompt')"; fi

if enter 'nothing hit: 0 of [0-9]+ primary rays met a surface' \
  ':show UnitCube with [Camera (0, 0, 5) (0, 0, 10) 30]'; then ok preview-nothing-hit
else fail preview-nothing-hit "$(why 'a camera looking away did not say nothing hit')"; fi

if enter '^qcs> ' ':set preview off' &&
   enter '^Rounded 0.1 \(Product \(Product \(Product' 'Rounded 0.1 UnitCube'; then
  ok preview-off
else fail preview-off "$(why ':set preview off did not print the tree')"; fi
enter '^qcs> ' ':set preview auto'

if enter 'preview-size 100000x1 is too large' ':set preview-size 100000x1' &&
   enter 'needs COLUMNSxROWS' ':set preview-size lots'; then ok preview-size-bad
else fail preview-size-bad "$(why 'no clear error for a bad preview-size')"; fi

if enter ':show draws scene objects \(or lists of them\), not a Real: 3' ':show 1 + 2'; then
  ok preview-show-not-object
else fail preview-show-not-object "$(why ':show 1 + 2 gave no clear error')"; fi

if enter 'sharp CSG, 12 leaves, box \(0, 0, 0\) \.\. \(5, 1, 1\)' \
  '[UnitCube, Shift (4, 0, 0) UnitCube]'; then ok preview-list
else fail preview-list "$(why 'a list of objects was not shown as one picture')"; fi

# The window resized while a picture is drawn: the picture ends or stops,
# the prompt comes back and works.
T send-keys -t qcs -l ':show Rounded 0.3 (Sum UnitCube b) with [Samples 16, Size 800 500]'
T send-keys -t qcs Enter
sleep 0.3
T resize-window -t qcs -x 70 -y 30 2>/dev/null || T resize-pane -t qcs -x 70 -y 30
sleep 0.2
T resize-window -t qcs -x 100 -y 40 2>/dev/null || T resize-pane -t qcs -x 100 -y 40
if enter '^6\.5$' '13 / 2'; then ok preview-resize
else fail preview-resize "$(why 'after a resize during a picture the prompt did not answer')"; fi

T send-keys -t qcs -l ':quit'
T send-keys -t qcs Enter
exit 0
