#!/bin/sh
# suite-frames.sh: animation (--frames, --animation, frame and clock) and
# parameters (--set, qcs params). Frames 5-8 of a 10-frame animation
# rendered alone must equal the same frames of the whole run, byte for
# byte; a definition not depending on frame is evaluated once; bad --set
# and --frames write nothing. Prints "ok NAME" or "FAIL NAME: why".
QCS=${QCS:-./qcs}
case $QCS in /*) ;; *) QCS=$PWD/$QCS ;; esac
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
cat > "$tmp/spin.qcs" <<'QCS'
param r = 0.2 in [0, 0.5] "the rounding radius"
ang = clock * 90
scene = Rotate "y" ang (Rounded r UnitCube)
QCS
mkdir "$tmp/all" "$tmp/part"
(cd "$tmp/all" && "$QCS" --size 48x32 -o 'spin.####.png' --frames 1-10 ../spin.qcs > out 2> err)
(cd "$tmp/part" && "$QCS" --size 48x32 -o 'spin.####.png' --frames 5-8 --animation 1-10 ../spin.qcs > out 2> err)
n=$(ls "$tmp/all" | grep -c '^spin\.00[01][0-9]\.png$')
if [ "$n" = 10 ]; then echo "ok frames: 1-10 writes spin.0001.png ... spin.0010.png"
else echo "FAIL frames: 1-10 wrote $n files: $(ls "$tmp/all" | tr '\n' ' ')"; fi
same=1
for f in 5 6 7 8; do
  cmp -s "$tmp/all/spin.000$f.png" "$tmp/part/spin.000$f.png" || same=0
done
[ "$(ls "$tmp/part" | grep -c png)" = 4 ] || same=0
if [ $same = 1 ]; then echo "ok frames: 5-8 alone equal frames 5-8 of 1-10"
else echo "FAIL frames: 5-8 alone differ from the whole run"; fi
if cmp -s "$tmp/all/spin.0005.png" "$tmp/all/spin.0006.png"; then
  echo "FAIL frames: frames 5 and 6 are the same picture"
else echo "ok frames: the picture moves with clock"; fi

# clock over the whole animation; frame numbers; a step
out=$(cd "$tmp" && "$QCS" --frames 3-9:3 --animation 1-9 -e '(frame, clock)' spin.qcs 2>&1 | tr '\n' ' ')
if [ "$out" = "(3, 0.25) (6, 0.625) (9, 1) " ]; then echo "ok frames: clock over --animation, step 3"
else echo "FAIL frames: clock: $out"; fi

# only what depends on frame is evaluated again: slow takes ~1 s per run
cat > "$tmp/lazy.qcs" <<'QCS'
slow = length [1 .. 1000000]
moving = frame + slow
moving
QCS
t0=$(date +%s%N)
(cd "$tmp" && "$QCS" --frames 1-1 lazy.qcs > /dev/null 2>&1)
t1=$(date +%s%N)
out=$(cd "$tmp" && "$QCS" --frames 1-8 lazy.qcs 2>&1 | tail -n 1)
t2=$(date +%s%N)
one=$(( (t1 - t0) / 1000000 )) eight=$(( (t2 - t1) / 1000000 ))
if [ "$out" = 1000008 ] && [ "$eight" -lt $(( one * 3 + 200 )) ]; then
  echo "ok frames: a definition not depending on frame is kept (1 frame ${one} ms, 8 frames ${eight} ms)"
else echo "FAIL frames: 8 frames took ${eight} ms against ${one} ms for 1 ($out)"; fi

# --set of parameters
out=$(cd "$tmp" && "$QCS" --set r=0.3 -e r spin.qcs 2>&1)
[ "$out" = 0.3 ] && echo "ok params: --set r=0.3" || echo "FAIL params: --set r=0.3 gave $out"
for bad in 'rr=0.3:did you mean r?' 'r=2:outside the range [0, 0.5]' 'r="x":takes a number in [0, 0.5], not a String'; do
  arg=${bad%%:*} want=${bad#*:}
  rm -f "$tmp"/bad*.png
  err=$(cd "$tmp" && "$QCS" --set "$arg" -o bad.png spin.qcs 2>&1); st=$?
  if [ $st = 1 ] && printf '%s' "$err" | grep -qF "$want" && [ ! -e "$tmp/bad.png" ]; then
    echo "ok params: --set $arg refused, nothing written"
  else echo "FAIL params: --set $arg: status $st: $err"; fi
done
for bad in '5-x' '8-5' '1-10:0' ''; do
  err=$(cd "$tmp" && "$QCS" --frames "$bad" -o 'bad.####.png' spin.qcs 2>&1); st=$?
  if [ $st = 1 ] && printf '%s' "$err" | grep -q 'needs FIRST-LAST' && ! ls "$tmp"/bad* > /dev/null 2>&1; then
    echo "ok frames: --frames '$bad' refused"
  else echo "FAIL frames: --frames '$bad': status $st: $err"; fi
done
err=$(cd "$tmp" && "$QCS" --frames 1-20 --animation 1-10 -o 'bad.####.png' spin.qcs 2>&1); st=$?
[ $st = 1 ] && ! ls "$tmp"/bad* > /dev/null 2>&1 && echo "ok frames: --frames outside --animation refused" || echo "FAIL frames: outside: $st $err"

out=$("$QCS" params examples/figure15a.qcs)
want="name  default  range   doc
side  0.3      [0, 1]  radius on x = 0, x = 2, z = 0, z = 1
flat  0.03     [0, 1]  radius on y = 0, y = 1"
[ "$out" = "$want" ] && echo "ok params: qcs params figure15a.qcs" || echo "FAIL params: qcs params: $out"
# the examples run with --set declare their parameters
for a in 'n=300 examples/soft-cloud.qcs' 'side=0 examples/figure15a.qcs' 'lidAngle=90 examples/lid.qcs'; do
  if (cd "$tmp" && "$QCS" --set ${a%% *} --size 40x30 -o ex.png "$OLDPWD/${a#* }" > /dev/null 2>&1); then
    echo "ok params: --set ${a%% *} ${a#* }"
  else echo "FAIL params: --set $a"; fi
done

# Imports: beside the importing file first, then each folder of QCS_PATH in
# order; not found anywhere is an error that says where it looked.
mkdir -p "$tmp/lib1" "$tmp/lib2" "$tmp/w" "$tmp/w2"
printf 'teeth = 12\n' > "$tmp/lib2/gear.qcs"
printf 'teeth = 16\n' > "$tmp/lib1/gear.qcs"
printf 'import "gear.qcs"\nteeth * 2\n' > "$tmp/w/main.qcs"
cp "$tmp/w/main.qcs" "$tmp/w2/main.qcs"
printf 'teeth = 7\n' > "$tmp/w2/gear.qcs"
out=$(cd / && QCS_PATH="$tmp/nowhere:$tmp/lib2:$tmp/lib1" "$QCS" "$tmp/w/main.qcs" 2>&1)
if [ "$out" = 24 ]; then echo "ok import-qcs-path: the first folder of QCS_PATH that has the file"
else echo "FAIL import-qcs-path: got '$out', want 24"; fi
out=$(cd / && QCS_PATH="$tmp/lib1" "$QCS" "$tmp/w2/main.qcs" 2>&1)
if [ "$out" = 14 ]; then echo "ok import-beside-first: the file beside the importer wins over QCS_PATH"
else echo "FAIL import-beside-first: got '$out', want 14"; fi
out=$(cd / && QCS_PATH="$tmp/nowhere" "$QCS" "$tmp/w/main.qcs" 2>&1); rc=$?
if [ $rc = 1 ] && printf '%s' "$out" | grep -q 'main.qcs:1:1: error: cannot find "gear.qcs" to import' &&
   printf '%s' "$out" | grep -q "$tmp/nowhere"; then echo "ok import-not-found: says where it looked"
else echo "FAIL import-not-found: status $rc, '$out'"; fi
