#!/bin/sh
# suite-bad.sh: the catalogue of malformed and hostile input (tests/bad/,
# listed in tests/bad/README.md). Each case must end with exit status 1
# (never a signal, never a hang) and the exact standard error given:
#   tests/bad/NAME.qcs       the script, run as the last argument
#   tests/bad/NAME.expected  its whole standard error
#   tests/bad/NAME.args      extra options before it (optional, one line)
# Cases run from tests/bad, so positions read "NAME.qcs:LINE:COL"; in
# .args and .expected, {TMP} stands for the case's scratch folder.
# Inputs too large or too strange to commit (a million brackets, a NUL
# byte, bytes that are not UTF-8) are generated below into a temporary
# folder, with their expected errors; so are the output-file cases.
# One line per case: "ok NAME", "FAIL NAME: why" or "skip NAME: why".
#   QCS  the binary under test (default ./qcs), run from the project root
cd "$(dirname "$0")/.." || exit 1
QCS=${QCS:-./qcs}
case $QCS in /*) ;; *) QCS=$PWD/$QCS ;; esac
if [ ! -x "$QCS" ]; then
  echo "FAIL bad: no binary at $QCS"
  exit 1
fi
tmp=$(mktemp -d) || exit 1
trap 'chmod -R u+w "$tmp" 2>/dev/null; rm -rf "$tmp"' EXIT
trap 'exit 1' INT TERM
if command -v timeout >/dev/null 2>&1; then lim="timeout 300"; else lim=""; fi

ok() { echo "ok $1"; }
fail() { printf 'FAIL %s: %s\n' "$1" "$(printf '%s' "$2" | tr '\n' '|' | cut -c1-400)"; }

# run NAME DIR ARGS...: $QCS ARGS in DIR, stdin empty; sets $st and
# leaves the streams in $tmp/out and $tmp/err
run() {
  name=$1 dir=$2
  shift 2
  (cd "$dir" && $lim $RUNAS "$QCS" "$@" >"$tmp/out" 2>"$tmp/err" </dev/null)
  st=$?
}

# judge NAME WANTFILE: the status is 1 and stderr is WANTFILE exactly.
# AddressSanitizer's note on a longjmp out of a deep stack (the recursion
# and nesting limits do that) is not the program's output: it is dropped.
judge() {
  grep -a -v -e '^==[0-9]*==WARNING: ASan is ignoring requested __asan_handle_no_return' \
    -e '^False positive error reports may follow$' \
    -e '^For details see https://github.com/google/sanitizers/issues/189$' \
    "$tmp/err" >"$tmp/err.san"
  mv "$tmp/err.san" "$tmp/err"
  if [ "$st" -eq 124 ] && [ -n "$lim" ]; then
    fail "$1" "did not finish in 300 s"
  elif [ "$st" -gt 128 ]; then
    fail "$1" "killed by signal $((st - 128)): $(head -c 300 "$tmp/err")"
  elif [ "$st" -ne 1 ]; then
    fail "$1" "exit status $st, expected 1: $(head -c 300 "$tmp/err")"
  elif ! cmp -s "$2" "$tmp/err"; then
    fail "$1" "stderr differs: $(diff "$2" "$tmp/err" | head -8)"
  else
    ok "$1"
  fi
}

# ---- the committed cases ----

for f in tests/bad/*.qcs; do
  name=$(basename "$f" .qcs)
  want=tests/bad/$name.expected
  if [ ! -f "$want" ]; then
    fail "bad/$name" "no $want"
    continue
  fi
  mkdir -p "$tmp/$name"
  args=""
  [ -f "tests/bad/$name.args" ] &&
    args=$(sed "s|{TMP}|$tmp/$name|g" "tests/bad/$name.args")
  sed "s|{TMP}|$tmp/$name|g" "$want" >"$tmp/want"
  # shellcheck disable=SC2086 # the options are words
  run "$name" tests/bad $args "$name.qcs"
  judge "bad/$name" "$tmp/want"
done
# renders that were refused must have written nothing
for f in tests/bad/*.png tests/bad/*.exr; do
  [ -e "$f" ] && { fail bad/no-stray-output "a refused render wrote $f"; rm -f "$f"; }
done

# ---- generated inputs ----

g=$tmp/gen
mkdir -p "$g"
# want TEXT: the expected stderr, from printf's format TEXT
want() { printf "$@" >"$g/want"; }
MAXSTACK="(limit max-stack; raise it with :set max-stack SIZE or --max-stack SIZE)"
# window FILE COL: how an error shows line 1 of FILE at a far column COL
# (ASCII): 200 bytes from 60 before it, between "...", and the caret
window() {
  len=$(head -n 1 "$1" | wc -c) # with the newline
  printf '  ...%s' "$(head -n 1 "$1" | cut -c$(($2 - 60))-$(($2 + 139)))"
  if [ "$len" -gt $(($2 + 140)) ]; then printf '...'; fi
  printf '\n%65s^\n' ''
}

# A million '(' closed, and unclosed: the parser stops at its nesting
# limit (16384 brackets with the default max-stack), not the C stack.
awk 'BEGIN { printf "x = "; for (i = 0; i < 1000000; i++) printf "("; printf "1";
             for (i = 0; i < 1000000; i++) printf ")"; print "" }' >"$g/parens.qcs"
run parens "$g" parens.qcs
want 'parens.qcs:1:16389: error: expression nested too deeply to parse %s\n' "$MAXSTACK"
window "$g/parens.qcs" 16389 >>"$g/want"
judge gen/million-parens "$g/want"

awk 'BEGIN { printf "x = "; for (i = 0; i < 1000000; i++) printf "("; print "" }' >"$g/open.qcs"
run open "$g" open.qcs
sed 's/parens\.qcs/open.qcs/' "$g/want" >"$g/want2"
judge gen/million-open-parens "$g/want2"

# A chain of a million '+': parsed in a loop, but a million deep as a
# tree: the checker stops it before evaluation could overflow.
awk 'BEGIN { printf "x = 1"; for (i = 0; i < 1000000; i++) printf " + 1"; print ""; print "x" }' >"$g/chain.qcs"
run chain "$g" chain.qcs
want 'chain.qcs:1:3868931: error: expression nested too deeply to evaluate %s\n' "$MAXSTACK"
window "$g/chain.qcs" 3868931 >>"$g/want"
judge gen/million-operators "$g/want"

# A million nested lets: let x = 1 in let x = 1 in ... x
awk 'BEGIN { printf "y = "; for (i = 0; i < 1000000; i++) printf "let x = 1 in "; print "x"; print "y" }' >"$g/lets.qcs"
run lets "$g" lets.qcs
want 'lets.qcs:1:212988: error: expression nested too deeply to parse %s\n' "$MAXSTACK"
window "$g/lets.qcs" 212988 >>"$g/want"
judge gen/million-lets "$g/want"

# A NUL byte, and bytes that are not UTF-8.
printf 'x = 1\ny = 2 \000 + 3\n' >"$g/nul.qcs"
run nul "$g" nul.qcs
want 'nul.qcs:2:7: error: NUL byte in source\n'
judge gen/nul-byte "$g/want"

printf 'x = 1\nname = "caf\351"\ny = \377\376\n' >"$g/latin1.qcs"
run latin1 "$g" latin1.qcs
want 'latin1.qcs:3:5: error: invalid UTF-8 byte 0xFF in source\n  y = \377\376\n      ^\n'
judge gen/not-utf8 "$g/want"

# A million soft-object keys work within the default limits (the
# committed keys-million case hits --max-list 500000 instead).
printf 'keys = [Key (sin k, cos k, 0) 0.05 1 \\\\ k <- [1 .. 1000000]]\nrenderWith [Size 16 10, Quiet] "keys.png" (SoftObject 0.5 keys)\n' >"$g/keys.qcs"
run keys "$g" keys.qcs
if [ "$st" -eq 0 ] && [ -s "$g/keys.png" ]; then ok gen/million-keys-work
else fail gen/million-keys-work "status $st: $(head -c 300 "$tmp/err")"; fi

# A CSG tree 10^5 nodes deep reaches the renderer: it used to render on
# one thread and segfault on several (span evaluation recursed once per
# node on a worker's default-size stack). Both thread counts must render
# it, to the same picture.
cat >"$g/deep.qcs" <<'DEEP'
cube k = Intersection UnitCube (Halfspace ((0, 0, -1), k / 1000000))
scene = foldr (\k acc -> Intersection (Union (cube k) acc) UnitCube) UnitCube [1 .. 100000]
DEEP
for th in 1 4; do
  # 1G of stack: the interpreter's frames under AddressSanitizer (make
  # sanitize) are several times larger than in a plain build.
  run deep$th "$g" --max-stack 1G --threads $th --size 16x12 -o deep$th.png deep.qcs
  if [ "$st" -eq 0 ] && [ -s "$g/deep$th.png" ]; then ok gen/deep-csg-100k-threads-$th
  else fail gen/deep-csg-100k-threads-$th "status $st: $(head -c 300 "$tmp/err")"; fi
done
if cmp -s "$g/deep1.png" "$g/deep4.png"; then ok gen/deep-csg-100k-same-image
else fail gen/deep-csg-100k-same-image "1 and 4 threads made different pictures"; fi

# A CSG tree 10^6 nodes deep (built by the strict foldl, so the only deep
# walk is the scene compiler's), on 4 threads under a max-stack of 128M:
# refused with the named limit at the scene's definition, never a signal.
# Which frame crosses the limit, the compiler's or a thunk's it forces (on
# either line), follows the frame sizes (ASan's are larger): the file, the
# named limit and the status are checked.
cat >"$g/deep6.qcs" <<'DEEP'
cube k = Intersection UnitCube (Halfspace ((0, 0, -1), k / 1000000))
scene = foldl (\acc k -> Intersection (Union (cube k) acc) UnitCube) UnitCube [1 .. 1000000]
DEEP
run deep6 "$g" --threads 4 --max-stack 128M --size 16x12 -o deep6.png deep6.qcs
if [ "$st" -eq 1 ] && grep -v -e '__asan_handle_no_return' -e '^False positive error reports may follow$' -e '^For details see https://github.com/google/sanitizers/issues/189$' "$tmp/err" | head -1 | grep -qE '^deep6\.qcs:[12]:[0-9]+: error: recursion too deep: nested calls use more than 128M of stack; .*\(limit max-stack' &&
   [ ! -e "$g/deep6.png" ]; then ok gen/deep-csg-million
else fail gen/deep-csg-million "status $st: $(head -c 300 "$tmp/err")"; fi

# A file that does not exist.
run missing "$g" no-such-file.qcs
want 'qcs: error: cannot read no-such-file.qcs: No such file or directory\n'
judge gen/missing-file "$g/want"

# ---- output files: whole or not at all ----

printf 'scene = Rounded 0.1 UnitCube\n' >"$g/scene.qcs"

# An EXR in a folder that cannot be written. Root ignores a folder's
# permissions, so as root qcs runs as nobody (setpriv, util-linux) for
# these cases; without setpriv, /proc (where no file can be made) stands in.
mkdir "$g/ro"
chmod 555 "$g/ro"
RUNAS=""
if [ "$(id -u)" -eq 0 ]; then
  nobody="setpriv --reuid=65534 --regid=65534 --clear-groups"
  chmod 755 "$tmp" "$g"
  if $nobody test -x "$QCS" 2>/dev/null && $nobody test -r "$g/scene.qcs" 2>/dev/null; then
    RUNAS=$nobody
  fi
fi
if [ "$(id -u)" -eq 0 ] && [ -z "$RUNAS" ]; then
  out=/proc/qcs-test.exr
  why="No such file or directory"
  run exr-ro "$g" -o "$out" scene.qcs
  want 'scene.qcs:1:1: error: cannot write %s: %s\n  scene = Rounded 0.1 UnitCube\n  ^\n' "$out" "$why"
  judge gen/exr-read-only-folder "$g/want"
  echo "skip gen/exr-read-only-folder-chmod: running as root without setpriv, which ignores chmod 555 (tested /proc instead)"
else
  run exr-ro "$g" -o ro/x.exr scene.qcs
  want 'qcs: error: -o: cannot write ro/x.exr: Permission denied\n'
  judge gen/exr-read-only-folder "$g/want"
  printf 'render "ro/x.exr" scene\n' >>"$g/scene2.qcs"
  cat "$g/scene.qcs" "$g/scene2.qcs" >"$g/scene3.qcs"
  run exr-ro-script "$g" scene3.qcs
  want 'scene3.qcs:2:1: error: cannot write ro/x.exr: Permission denied\n  render "ro/x.exr" scene\n  ^\n  in renderWith, called at <prelude>:75:21\n  in render, called at scene3.qcs:2:1\n'
  judge gen/exr-read-only-folder-script "$g/want"
fi
RUNAS=""
if [ -n "$(ls -A "$g/ro")" ]; then fail gen/read-only-folder-empty "files left in it: $(ls -A "$g/ro")"
else ok gen/read-only-folder-empty; fi

# A write that fails half way (the file-size limit, with SIGXFSZ
# ignored so that write() fails instead of killing): the old file is
# intact and no temporary is left.
printf 'old picture\n' >"$g/keep.png"
(trap '' XFSZ; ulimit -f 8 && cd "$g" && $lim "$QCS" -o keep.png --size 400x300 scene.qcs \
  >"$tmp/out" 2>"$tmp/err" </dev/null)
st=$?
want 'scene.qcs:1:1: error: cannot write keep.png: File too large\n  scene = Rounded 0.1 UnitCube\n  ^\n'
judge gen/write-fails-midway "$g/want"
if [ "$(cat "$g/keep.png")" = "old picture" ] && [ -z "$(ls -A "$g" | grep '\.tmp\.')" ]; then
  ok gen/write-fails-midway-old-file-intact
else
  fail gen/write-fails-midway-old-file-intact "keep.png changed or a temporary is left: $(ls -A "$g")"
fi

# An interrupted render: Ctrl-C (SIGINT) while a large render runs. The
# render stops with an error, the old file is intact, nothing is left.
printf 'old picture\n' >"$g/big.png"
(cd "$g" && exec $lim "$QCS" -o big.png --size 4096x4096 --spp 64 scene.qcs \
  >"$tmp/out" 2>"$tmp/err" </dev/null) &
pid=$!
sleep 1 # the scene takes milliseconds; the render, minutes
kill -INT $pid 2>/dev/null
wait $pid
st=$?
grep -v '^\r\?big.png: [0-9]*%' "$tmp/err" | tr -d '\r' >"$tmp/err2"; mv "$tmp/err2" "$tmp/err"
want 'scene.qcs:1:1: error: render interrupted; big.png was not written\n  scene = Rounded 0.1 UnitCube\n  ^\n'
judge gen/render-interrupted "$g/want"
if [ "$(cat "$g/big.png")" = "old picture" ] && [ -z "$(ls -A "$g" | grep '\.tmp\.')" ]; then
  ok gen/render-interrupted-old-file-intact
else
  fail gen/render-interrupted-old-file-intact "big.png changed or a temporary is left: $(ls -A "$g")"
fi
exit 0
