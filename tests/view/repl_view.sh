#!/bin/sh
# repl_view.sh: :view at the prompt, in a terminal played by tmux (like
# suite-repl.sh): it prints a URL, the page and /state answer with the
# token (and not without it), Enter stops it, and the prompt and the
# definitions made before survive. Run by suite-view.sh.
#   usage: repl_view.sh QCS WORKDIR
QCS=$1; tmp=$2
case $QCS in /*) ;; *) QCS=$PWD/$QCS ;; esac
CHECKS="view-repl-url view-repl-fetch view-repl-token view-repl-enter view-repl-defs view-repl-errors"
if ! command -v tmux >/dev/null 2>&1; then
  for c in $CHECKS; do echo "skip $c: tmux is not installed"; done; exit 0
fi
if ! command -v curl >/dev/null 2>&1; then
  for c in $CHECKS; do echo "skip $c: curl is not installed"; done; exit 0
fi
unset TMUX
mkdir -p "$tmp/home"
sock=qcs-view-test-$$
T() { tmux -L "$sock" -f /dev/null "$@"; }
trap 'T kill-server >/dev/null 2>&1' EXIT
ok() { echo "ok $1"; }
fail() { printf 'FAIL %s: %s\n' "$1" "$(printf '%s' "$2" | tr '\n' '|' | cut -c1-300)"; }
T new-session -d -s qcs -x 160 -y 40 \
  "cd '$tmp' && env HOME='$tmp/home' INPUTRC=/dev/null TERM=xterm '$QCS'; echo qcs-exit-status=\$?; sleep 60" ||
  { for c in $CHECKS; do echo "skip $c: tmux could not start"; done; exit 0; }
pane() { T capture-pane -p -J -t qcs -S - 2>/dev/null; }
count() { pane | grep -cE -- "$1"; }
wait_count() { # PATTERN N [tenths of a second]
  i=0
  while [ "$(count "$1")" -lt "$2" ]; do
    i=$((i + 1)); [ $i -gt "${3:-100}" ] && return 1; sleep 0.05
  done
}
enter() {
  n=$(count "$1")
  T send-keys -t qcs -l "$2"; T send-keys -t qcs Enter
  wait_count "$1" $((n + 1)) "${3:-100}"
}
why() { echo "$1; screen ends: $(pane | grep -v '^$' | tail -n 4 | tr '\n' '|')"; }

if ! wait_count '^qcs> ' 1; then
  for c in $CHECKS; do echo "skip $c: the REPL showed no prompt"; done; exit 0
fi
enter '^qcs> ' 'keep = 41' >/dev/null
enter '^qcs> ' 'sc = Union UnitCube (Halfspace ((0, 1, 0), 0))' >/dev/null
if enter 'qcs view: http://' ':view sc' 400; then ok view-repl-url
else
  fail view-repl-url "$(why ':view sc printed no URL')"
  for c in view-repl-fetch view-repl-token view-repl-enter view-repl-defs view-repl-errors; do echo "skip $c: no URL"; done
  exit 0
fi
url=$(pane | grep -oE 'http://[0-9.]+:[0-9]+/\?t=[0-9a-f]+' | tail -n 1)
base=${url%%/\?t=*}; token=${url##*t=}
page=$(curl -s -m 10 "$url")
state=$(curl -s -m 15 "$base/state?t=$token")
if printf '%s' "$page" | grep -q '<canvas id="pic"' &&
   printf '%s' "$state" | grep -q '"width":'; then ok view-repl-fetch
else fail view-repl-fetch "page $(printf '%s' "$page" | head -c 80), state $(printf '%s' "$state" | head -c 120)"; fi
code=$(curl -s -m 10 -o /dev/null -w '%{http_code}' "$base/state")
code2=$(curl -s -m 10 -o /dev/null -w '%{http_code}' "$base/state?t=0123456789abcdef0123456789abcdef")
if [ "$code" = 403 ] && [ "$code2" = 403 ]; then ok view-repl-token
else fail view-repl-token "without the token $code, a wrong token $code2 (want 403)"; fi
if enter '^qcs> ' '' 200 && ! curl -s -m 3 -o /dev/null "$base/state?t=$token"; then ok view-repl-enter
else fail view-repl-enter "$(why 'Enter did not give the prompt back, or the server still answers')"; fi
if enter '^42$' 'keep + 1' && enter '^qcs> ' ':view nosuchname' && enter '^43$' 'keep + 2'; then
  ok view-repl-defs
else fail view-repl-defs "$(why 'the definitions did not survive :view')"; fi
# errors name what was typed: no internal "<view>" source
if enter '^qcs> ' ':view' && pane | grep -q 'no `scene` is defined' &&
   pane | grep -q "^:view:1:1: error: unknown name 'nosuchname'" && ! pane | grep -q '<view>'; then
  ok view-repl-errors
else fail view-repl-errors "$(why ':view without a scene, or with an unknown name, was not said plainly')"; fi
