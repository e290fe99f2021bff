#!/bin/sh
# suite-repl.sh: the REPL driven for real. A tmux server on a private socket
# plays the terminal (keys in, screen out); piped stdin is checked plainly.
# One line per check: "ok NAME", "FAIL NAME: why" or "skip NAME: why".
#   QCS  the binary under test (default ./qcs), run from the project root
cd "$(dirname "$0")/.." || exit 1
QCS=${QCS:-./qcs}
case $QCS in /*) ;; *) QCS=$PWD/$QCS ;; esac

TMUX_CHECKS="repl-prompt repl-expression repl-definition repl-error-keeps-defs
repl-continuation repl-paste repl-ctrl-c-eval repl-ctrl-c-prompt repl-tab-name
repl-tab-command repl-tab-file repl-browse repl-unknown-command repl-history-live
repl-set-list repl-set-bad repl-limit-steps-keeps-defs repl-limit-stack-keeps-defs
repl-limit-list-keeps-defs repl-history-after-error repl-ctrl-d repl-history-file"

if [ ! -x "$QCS" ]; then
  echo "FAIL repl: no binary at $QCS"
  exit 1
fi

tmp=$(mktemp -d) || exit 1
sock=qcs-test-$$
T() { tmux -L "$sock" -f /dev/null "$@"; }
cleanup() {
  T kill-server >/dev/null 2>&1
  rm -rf "$tmp"
}
trap cleanup EXIT
trap 'exit 1' INT TERM

ok() { echo "ok $1"; }
fail() { printf 'FAIL %s: %s\n' "$1" "$(printf '%s' "$2" | tr '\n' '|' | cut -c1-300)"; }
# qcs_piped: $QCS on piped stdin, with a clean HOME and a time limit
if command -v timeout >/dev/null 2>&1; then lim="timeout 10"; else lim=""; fi
qcs_piped() { HOME=$tmp $lim "$QCS" "$@"; }

# ---- piped stdin: no terminal, no prompts ----

out=$(echo '1 + 2' | qcs_piped 2>"$tmp/err"); rc=$?
if [ "$out" = 3 ] && [ $rc -eq 0 ]; then ok pipe-expression
else fail pipe-expression "got '$out' (status $rc), want '3' (status 0)"; fi

out=$(echo 'undefinedname' | qcs_piped 2>"$tmp/err"); rc=$?
if [ $rc -eq 1 ] && grep -q 'error:' "$tmp/err"; then ok pipe-error-status
else fail pipe-error-status "status $rc, stderr '$(head -c 200 "$tmp/err")'"; fi

out=$(printf 'g x =\n  x + 1\ng 1\n' | qcs_piped 2>"$tmp/err"); rc=$?
if [ "$out" = 2 ] && [ $rc -eq 0 ]; then ok pipe-continuation
else fail pipe-continuation "got '$out' (status $rc), want '2'"; fi

out=$(printf ':{\na = 1\nb = a + 1\n:}\nb\n' | qcs_piped 2>"$tmp/err"); rc=$?
if [ "$out" = 2 ] && [ $rc -eq 0 ]; then ok pipe-block
else fail pipe-block "got '$out' (status $rc), want '2'"; fi

out=$(printf ':laod x\n' | qcs_piped 2>"$tmp/err"); rc=$?
if [ $rc -eq 1 ] && grep -q "did you mean ':load'" "$tmp/err"; then ok pipe-unknown-command
else fail pipe-unknown-command "status $rc, stderr '$(head -c 200 "$tmp/err")'"; fi

printf 'h x = x + 100\n' >"$tmp/lib.qcs"
out=$(printf ':load %s\nh 1\n:reload\nh 2\n' "$tmp/lib.qcs" | qcs_piped 2>"$tmp/err"); rc=$?
if [ "$out" = "$(printf '101\n102')" ] && [ $rc -eq 0 ]; then ok pipe-load-reload
else fail pipe-load-reload "got '$out' (status $rc), stderr '$(head -c 200 "$tmp/err")'"; fi

if [ -e "$tmp/.qcs_history" ]; then fail pipe-no-history "piped input wrote a history file"
else ok pipe-no-history; fi

# ---- the terminal, through tmux ----

if ! command -v tmux >/dev/null 2>&1; then
  for c in $TMUX_CHECKS; do echo "skip $c: tmux is not installed"; done
  exit 0
fi
unset TMUX

home=$tmp/home
mkdir -p "$home"
# The shell after qcs reports its exit status and keeps the pane open.
T new-session -d -s qcs -x 100 -y 30 \
  "env HOME='$home' INPUTRC=/dev/null TERM=xterm '$QCS'; echo qcs-exit-status=\$?; sleep 60" ||
  { for c in $TMUX_CHECKS; do echo "skip $c: tmux could not start"; done; exit 0; }

pane() { T capture-pane -p -J -t qcs -S - 2>/dev/null; }
# count PATTERN: lines of the whole pane history matching the ERE
count() { pane | grep -cE -- "$1"; }
# wait_count PATTERN N: poll (5 s at most) until N lines match
wait_count() {
  i=0
  while [ "$(count "$1")" -lt "$2" ]; do
    i=$((i + 1))
    [ $i -gt 100 ] && return 1
    sleep 0.05
  done
  return 0
}
# keys_then PATTERN KEYS...: send keys, wait for one more line matching
keys_then() {
  pat=$1; shift
  n=$(count "$pat")
  T send-keys -t qcs "$@"
  wait_count "$pat" $((n + 1))
}
# enter PATTERN TEXT: type TEXT, press Enter, wait for PATTERN once more
enter() {
  pat=$1
  n=$(count "$pat")
  T send-keys -t qcs -l "$2"
  T send-keys -t qcs Enter
  wait_count "$pat" $((n + 1))
}
why() { echo "$1; screen ends: $(pane | grep -v '^$' | tail -n 3 | tr '\n' '|')"; }

if wait_count '^qcs> ' 1; then ok repl-prompt
else
  fail repl-prompt "$(why 'no "qcs> " prompt')"
  for c in $TMUX_CHECKS; do
    [ "$c" = repl-prompt ] || echo "skip $c: the REPL showed no prompt"
  done
  exit 0
fi

if enter '^3$' '1 + 2'; then ok repl-expression
else fail repl-expression "$(why '1 + 2 did not show 3')"; fi

enter '^qcs> f x = x \* 2$' 'f x = x * 2'
if enter '^42$' 'f 21'; then ok repl-definition
else fail repl-definition "$(why 'f 21 did not show 42')"; fi

if enter 'error:' 'f 1 2 3' && enter '^10$' 'f 5'; then ok repl-error-keeps-defs
else fail repl-error-keeps-defs "$(why 'no error for f 1 2 3, or f 5 not 10 after it')"; fi

if enter '^\.\.\.> ' 'g x =' && enter '^qcs> ' 'x + 1' && enter '^2$' 'g 1'; then
  ok repl-continuation
else fail repl-continuation "$(why 'g x = / x + 1 / g 1 did not show 2')"; fi

# A multi-line paste (bracketed) runs as a script, items in column 1.
T set-buffer "$(printf 'pa = 50\npb = 61\npa + pb')"
T paste-buffer -p -t qcs
if enter '^111$' ''; then ok repl-paste
else fail repl-paste "$(why 'pasted definitions and pa + pb did not show 111')"; fi

# Ctrl-C while an endless evaluation runs; the sleep lets it start. A loop
# that allocates nothing, so that no limit but max-steps (minutes away)
# can end it first (length [1..] streams now, and met max-list in 0.4 s).
n=$(count '^qcs> ')
enter '^qcs> ' 'spin x = if x < 0 then 0 else spin (x + 1)'
n=$(count '^qcs> ')
T send-keys -t qcs -l 'spin 0'; T send-keys -t qcs Enter
sleep 0.5
if keys_then 'interrupted' C-c && wait_count '^qcs> ' $((n + 1)) &&
   enter '^8$' 'f 4'; then ok repl-ctrl-c-eval
else fail repl-ctrl-c-eval "$(why 'no "interrupted" and fresh prompt, or f lost')"; fi

# Ctrl-C at the prompt drops the line and a pending continuation.
enter '^\.\.\.> ' 'h x ='
T send-keys -t qcs -l 'f 1000'
if keys_then '\^C$' C-c && enter '^14$' 'f 7' && [ "$(count '^2000$')" -eq 0 ]; then
  ok repl-ctrl-c-prompt
else fail repl-ctrl-c-prompt "$(why 'line or continuation not discarded by Ctrl-C')"; fi

enter '^qcs> myLongName = 7$' 'myLongName = 7'
T send-keys -t qcs -l 'myLo'
if keys_then '^qcs> myLongName' Tab && T send-keys -t qcs Enter && wait_count '^7$' 1; then
  ok repl-tab-name
else fail repl-tab-name "$(why 'myLo<Tab> did not complete to myLongName')"; fi

T send-keys -t qcs -l ':bro'
if keys_then '^qcs> :browse' Tab; then ok repl-tab-command
else fail repl-tab-command "$(why ':bro<Tab> did not complete to :browse')"; fi
T send-keys -t qcs Enter
if wait_count '^myLongName' 1 && [ "$(count '^g( |$)')" -ge 1 ]; then ok repl-browse
else fail repl-browse "$(why ':browse did not list myLongName and g')"; fi

printf 'zq = 31\n' >"$tmp/completeme-unique.qcs"
T send-keys -t qcs -l ":load $tmp/completeme-u"
if keys_then "completeme-unique\\.qcs" Tab && T send-keys -t qcs Enter &&
   enter '^31$' 'zq'; then ok repl-tab-file
else fail repl-tab-file "$(why ':load DIR/completeme-u<Tab> did not complete the file name')"; fi

if enter "did you mean ':load'" ':laod x'; then ok repl-unknown-command
else fail repl-unknown-command "$(why 'no did-you-mean for :laod')"; fi

# Each line is in the file as soon as it is entered.
if grep -qx 'f x = x \* 2' "$home/.qcs_history" 2>/dev/null; then ok repl-history-live
else fail repl-history-live "~/.qcs_history lacks 'f x = x * 2' during the session"; fi

# Limits: :set lists them, changes one, refuses a bad one; a limit hit
# stops the entry with an error naming it, and every definition stays.
if enter '^max-steps +10000000000 ' ':set' && [ "$(count '^max-(stack|steps|list|memory|pixels|spp) ')" -ge 6 ]; then
  ok repl-set-list
else fail repl-set-list "$(why ':set did not list the six limits')"; fi
if enter "unknown limit 'max-stpes' \(did you mean max-steps\?\)" ':set max-stpes 5' &&
   enter "max-steps needs a whole number" ':set max-steps lots'; then ok repl-set-bad
else fail repl-set-bad "$(why 'no clear errors for a bad :set')"; fi
enter '^qcs> :set max-steps 200000$' ':set max-steps 200000'
if enter 'evaluation stopped after 200000 steps \(limit max-steps; raise it with :set max-steps N or --max-steps N\)' 'length [1..]' &&
   enter '^12$' 'f 6'; then ok repl-limit-steps-keeps-defs
else fail repl-limit-steps-keeps-defs "$(why 'no max-steps error for length [1..], or f lost after it')"; fi
enter '^qcs> :set max-steps 0$' ':set max-steps 0'
if [ -n "${QCS_TSAN:-}" ]; then
  # ThreadSanitizer keeps a shadow call stack of 64K frames a thread: a
  # recursion a million calls deep overflows it long before max-stack.
  echo "skip repl-limit-stack-keeps-defs: ThreadSanitizer's shadow stack holds 64K frames"
else
enter '^qcs> deep n = 1 \+ deep \(n \+ 1\)$' 'deep n = 1 + deep (n + 1)'
if enter 'recursion too deep.*limit max-stack' 'deep 0' && enter '^16$' 'f 8' &&
   enter '^qcs> deep' 'deep'; then ok repl-limit-stack-keeps-defs
else fail repl-limit-stack-keeps-defs "$(why 'no max-stack error for deep 0, or definitions lost')"; fi
fi
enter '^qcs> :set max-list 1000$' ':set max-list 1000'
if enter 'a list longer than 1000 elements \(limit max-list' 'sum [1..5000]' && enter '^18$' 'f 9' &&
   enter '^500500$' 'sum [1..1000]'; then ok repl-limit-list-keeps-defs
else fail repl-limit-list-keeps-defs "$(why 'no max-list error for sum [1..5000], or f lost')"; fi
# Every line is in the history file as it is entered, failed ones too.
if grep -qxF 'length [1..]' "$home/.qcs_history" 2>/dev/null &&
   grep -qxF 'sum [1..5000]' "$home/.qcs_history" 2>/dev/null; then ok repl-history-after-error
else fail repl-history-after-error "~/.qcs_history lacks lines that ended in errors"; fi

if keys_then '^qcs-exit-status=0$' C-d; then ok repl-ctrl-d
else fail repl-ctrl-d "$(why 'Ctrl-D did not leave with status 0')"; fi

missing=""
deep=${QCS_TSAN:-deep 0}; [ -n "${QCS_TSAN:-}" ] && deep=':set max-steps 0'
for want in '1 + 2' 'f x = x * 2' 'g x =' 'x + 1' 'myLongName = 7' 'f 21' ':set max-steps 200000' "$deep"; do
  grep -qxF "$want" "$home/.qcs_history" 2>/dev/null || missing="$missing '$want'"
done
if [ -z "$missing" ]; then ok repl-history-file
else fail repl-history-file "~/.qcs_history lacks$missing"; fi
exit 0
