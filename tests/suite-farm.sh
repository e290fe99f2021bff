#!/bin/sh
# suite-farm.sh: partial renders and their merge (issue 17). A 4x4 tiling
# rendered as 16 processes by GNU parallel and merged is the one-shot
# render byte for byte (PNG, and EXR with Z, N, cost and alpha); each
# template of examples/farm/ runs locally with its index variable set;
# --index-env with --frames (and --tiles) gives each task the frame (and
# tile) that rendering it directly gives, byte for byte;
# alpha and the EXR header are read back by readers that are not qcs's
# (tests/exr_pixels.py, OpenEXR's exrheader); bad input is refused with
# status 1 and no file touched. Prints "ok NAME" or "FAIL NAME: why".
QCS=${QCS:-./qcs}
case $QCS in /*) ;; *) QCS=$(pwd)/$QCS ;; esac
top=$(pwd)
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
SCENE=$top/examples/figure12.qcs
SZ=160x100

ok() { echo "ok farm: $1"; }
fail() { echo "FAIL farm: $1"; }
check() { # check NAME COMMAND...: ok if the command succeeds
  name=$1; shift
  if "$@" > "$tmp/check.out" 2>&1; then ok "$name"
  else fail "$name: $(head -c 300 "$tmp/check.out" | tr '\n' ' ')"; fi
}

# The one-shot renders, on all cores.
"$QCS" -o "$tmp/one.png" --size $SZ --spp 4 "$SCENE" >/dev/null 2>&1
"$QCS" -o "$tmp/one.exr" --size $SZ --spp 4 --cost "$SCENE" >/dev/null 2>&1

# 16 tiles, 16 processes, one thread each, by GNU parallel.
if command -v parallel >/dev/null 2>&1; then
  for ext in png exr; do
    mkdir -p "$tmp/$ext"
    cost=; [ $ext = exr ] && cost=--cost
    seq 16 | parallel --will-cite -j 8 "$QCS" --size $SZ --spp 4 $cost \
      --threads 1 --tile {}/16 -o "$tmp/$ext/t{}.$ext" "$SCENE" \
      >/dev/null 2>&1
    n=$(ls "$tmp/$ext" | wc -l)
    if [ "$n" -eq 16 ] && "$QCS" merge "$tmp/m.$ext" "$tmp/$ext"/t*.$ext \
        2> "$tmp/err" && cmp -s "$tmp/m.$ext" "$tmp/one.$ext"; then
      ok "16 tiles by GNU parallel merge to the one-shot $ext, byte for byte"
    else
      fail "16 tiles ($n files) to $ext: $(head -c 300 "$tmp/err")"
    fi
  done
else
  echo "skip farm: GNU parallel is not installed (Debian parallel)"
fi

# Crops in pixels and in fractions, of a render with alpha, in float.
"$QCS" -o "$tmp/a.exr" --size $SZ --alpha --float "$SCENE" >/dev/null 2>&1
"$QCS" -o "$tmp/c1.exr" --size $SZ --alpha --float --crop 0,57,0,100 "$SCENE" >/dev/null 2>&1
"$QCS" -o "$tmp/c2.exr" --size $SZ --alpha --float --crop 57,160,0,33 "$SCENE" >/dev/null 2>&1
"$QCS" -o "$tmp/c3.exr" --size $SZ --alpha --float --crop 57,160,33,100 "$SCENE" >/dev/null 2>&1
check "three crops merge to the whole (float, alpha)" sh -c \
  "'$QCS' merge '$tmp/ma.exr' '$tmp'/c?.exr && cmp '$tmp/ma.exr' '$tmp/a.exr'"
"$QCS" -o "$tmp/f.exr" --size $SZ --crop 0.5,1.0,0.0,0.5 "$SCENE" >/dev/null 2>&1
check "a fractional crop has its data window" sh -c \
  "exrheader '$tmp/f.exr' | grep -q 'dataWindow (type box2i): (80 0) - (159 49)'"

# The header, read by OpenEXR's own exrheader.
if command -v exrheader >/dev/null 2>&1; then
  exrheader "$tmp/one.exr" > "$tmp/hdr" 2>&1
  for a in 'worldToCamera (type m44f)' 'worldToNDC (type m44f)' \
           'qcs.size (type string): "160x100"' 'qcs.samples (type string): "4"' \
           'qcs.camera (type string)' 'qcs.scene (type string)' \
           'qcs.tolerance (type string)' 'qcs.alpha (type string): "off"' \
           'displayWindow (type box2i): (0 0) - (159 99)'; do
    if grep -qF "$a" "$tmp/hdr"; then ok "exrheader reads $a"
    else fail "exrheader does not show $a"; fi
  done
  # the eye goes to the camera-space origin: its row is -eye . axes
  row=$(sed -n '/worldToCamera/,/)/p' "$tmp/hdr" | tail -1)
  case $row in *" 1)") ok "worldToCamera is affine (last row ends 1)" ;;
    *) fail "worldToCamera's last row: $row" ;; esac
else
  echo "skip farm: exrheader is not installed (Debian openexr)"
fi

# Alpha: 0 where nothing is hit, RGB 0 there (premultiplied), 1 on the
# object; without --alpha, A = 1 and the background colour.
cat > "$tmp/ball.qcs" <<'QCS'
scene = Rounded 0.2 UnitCube;
QCS
"$QCS" -o "$tmp/ball.exr" --size 64x48 --alpha "$tmp/ball.qcs" >/dev/null 2>&1
"$QCS" -o "$tmp/ball1.exr" --size 64x48 "$tmp/ball.qcs" >/dev/null 2>&1
v=$(python3 tests/exr_pixels.py "$tmp/ball.exr" A 0,0 32,24 | tr '\n' ' ')
[ "$v" = "0.0 1.0 " ] && ok "EXR A is 0 off the object, 1 on it (--alpha)" \
  || fail "EXR A at a corner and the centre: $v"
v=$(python3 tests/exr_pixels.py "$tmp/ball.exr" R 0,0)
[ "$v" = "0.0" ] && ok "EXR RGB is 0 where A is 0" || fail "R at a corner: $v"
v=$(python3 tests/exr_pixels.py "$tmp/ball1.exr" A 0,0)
[ "$v" = "1.0" ] && ok "without --alpha, A is 1 on the background" || fail "A: $v"
"$QCS" -o "$tmp/ball.png" --size 64x48 --alpha "$tmp/ball.qcs" >/dev/null 2>&1
v=$(python3 - "$tmp/ball.png" <<'PY'
import sys, struct, zlib
b = open(sys.argv[1], 'rb').read(); p = 8; idat = b''
while p < len(b):
    n, t = struct.unpack_from('>I4s', b, p)
    if t == b'IHDR': w, h, depth, ctype = struct.unpack_from('>IIBB', b, p + 8)
    if t == b'IDAT': idat += b[p + 8:p + 8 + n]
    p += 12 + n
print(ctype, zlib.decompress(idat)[1 + 3])  # type 6 = RGBA; A of pixel (0, 0)
PY
)
[ "$v" = "6 0" ] && ok "PNG with --alpha is RGBA, transparent off the object" \
  || fail "PNG colour type and corner alpha: $v"

# The templates, each run here with its index variable set.
run_tiles() { # run_tiles NAME: merge $tmp/NAME/tile-*.exr, compare
  if "$QCS" merge "$tmp/$1.exr" "$tmp/$1"/tile-*.exr 2> "$tmp/err" &&
      cmp -s "$tmp/$1.exr" "$tmp/t160.exr"; then
    ok "template $1: 16 tasks and the merge give the one-shot render"
  else fail "template $1: $(head -c 300 "$tmp/err")"; fi
}
"$QCS" -o "$tmp/t160.exr" --size $SZ "$SCENE" >/dev/null 2>&1
# The templates run ./qcs from the qcs folder: give them a folder whose
# ./qcs is the binary under test (a sanitizer build's pictures may differ
# from the plain build's in the last bits, so the two must not be mixed).
mkdir -p "$tmp/tpl"
ln -s "$QCS" "$tmp/tpl/qcs"
ln -s "$top/examples" "$tmp/tpl/examples"
cd "$tmp/tpl" || exit 1
mkdir -p "$tmp/slurm"
for i in $(seq 1 16); do
  SLURM_ARRAY_TASK_ID=$i SLURM_ARRAY_TASK_MIN=1 SIZE=$SZ OUT="$tmp/slurm" \
    sh examples/farm/slurm.sh >/dev/null 2>&1
done
SIZE=$SZ OUT="$tmp/slurm" sh examples/farm/slurm.sh merge >/dev/null 2>&1
if cmp -s "$tmp/slurm/figure12.exr" "$tmp/t160.exr"; then
  ok "template slurm.sh: 16 array tasks and its merge step"
else fail "template slurm.sh: the merged file differs or is missing"; fi
# Kubernetes and OpenJD: their commands taken from the YAML.
python3 - examples/farm/k8s-indexed-job.yaml examples/farm/openjd-job.yaml \
  "$tmp" <<'PY' > "$tmp/cmds" 2> "$tmp/err"
import sys, yaml
k8s = list(yaml.safe_load_all(open(sys.argv[1])))
tile = k8s[0]['spec']['template']['spec']['containers'][0]['args'][0]
assert k8s[0]['spec']['completionMode'] == 'Indexed'
merge = k8s[1]['spec']['template']['spec']['containers'][0]['command'][2]
fix = lambda s: s.replace('1920x1080', '160x100').replace('/frames', sys.argv[3] + '/k8s')
for i in range(16):
    print('JOB_COMPLETION_INDEX=%d sh -c %r' % (i, fix(tile)))
print(fix(merge))
jd = yaml.safe_load(open(sys.argv[2]))
assert jd['specificationVersion'] == 'jobtemplate-2023-09'
run = jd['steps'][0]['script']['actions']['onRun']
mrg = jd['steps'][1]['script']['actions']['onRun']
lo, hi = map(int, jd['steps'][0]['parameterSpace']['taskParameterDefinitions'][0]['range'].split('-'))
sub = lambda s, t: (s.replace('{{Task.Param.Tile}}', str(t)).replace('{{Param.OutDir}}', sys.argv[3] + '/openjd')
                     .replace('{{Param.Scene}}', 'examples/figure12.qcs').replace('1920x1080', '160x100'))
q = lambda a: "'" + a.replace("'", "'\\''") + "'"
for t in range(lo, hi + 1):
    print(' '.join(q(sub(a, t)) for a in [run['command']] + run['args']))
print(' '.join(q(sub(a, 0)) for a in [mrg['command']] + mrg['args']))
PY
mkdir -p "$tmp/k8s" "$tmp/openjd"
if [ -s "$tmp/cmds" ]; then
  sh "$tmp/cmds" >/dev/null 2>"$tmp/err"
  for t in k8s openjd; do
    if cmp -s "$tmp/$t/figure12.exr" "$tmp/t160.exr"; then
      ok "template $t: 16 tasks and its merge step"
    else fail "template $t: $(head -c 300 "$tmp/err")"; fi
  done
else fail "templates k8s, openjd: $(head -c 300 "$tmp/err")"; fi
if command -v parallel >/dev/null 2>&1; then
  mkdir -p "$tmp/par" && cp examples/farm/parallel.sh "$tmp/par/"
  ln -s "$QCS" "$tmp/par/qcs"; ln -s "$top/examples" "$tmp/par/examples"
  if (cd "$tmp/par" && SIZE=$SZ sh parallel.sh : >/dev/null 2>&1) &&
      cmp -s "$tmp/par/figure12.exr" "$tmp/t160.exr"; then
    ok "template parallel.sh (this machine as the host): tiles and merge"
  else fail "template parallel.sh"; fi
  # its animation variant: 2 frames x 16 tiles, merged per frame
  "$QCS" -o "$tmp/pad.####.exr" --size 80x50 --frames 1-3:2 "$top/examples/lid.qcs" \
    >/dev/null 2>&1
  if (cd "$tmp/par" && FRAMES=1-3:2 SIZE=80x50 SCENE=examples/lid.qcs \
        sh parallel.sh : >/dev/null 2>&1) &&
      cmp -s "$tmp/par/frames/f0001.exr" "$tmp/pad.0001.exr" &&
      cmp -s "$tmp/par/frames/f0003.exr" "$tmp/pad.0003.exr"; then
    ok "template parallel.sh, animation: 2 frames x 16 tiles, merged per frame"
  else fail "template parallel.sh animation: $(ls "$tmp/par/frames" 2>&1 | head -3 | tr '\n' ' ')"; fi
fi

# --index-env: each engine's variable picks the tile.
"$QCS" -o "$tmp/i3.exr" --size $SZ --tile 3/16 "$SCENE" >/dev/null 2>&1
for v in SLURM_ARRAY_TASK_ID=2 JOB_COMPLETION_INDEX=2 \
         AWS_BATCH_JOB_ARRAY_INDEX=2 PARALLEL_SEQ=3; do
  rm -f "$tmp/ie.exr"
  env $v "$QCS" -o "$tmp/ie.exr" --size $SZ --tiles 16 --index-env "$SCENE" \
    >/dev/null 2>&1
  cmp -s "$tmp/ie.exr" "$tmp/i3.exr" && ok "--index-env with $v is tile 3" \
    || fail "--index-env with $v"
done

# --index-env with --frames: task k is the k-th frame of the range; with
# --tiles N too, frame k / N and tile k % N + 1. Each task's file is the
# same frame (and tile) rendered directly, byte for byte.
LID=$top/examples/lid.qcs
mkdir -p "$tmp/fr" "$tmp/frd"
for k in 0 1 2; do
  f=$((1 + 3 * k))
  SLURM_ARRAY_TASK_ID=$k "$QCS" -o "$tmp/fr/f####.exr" --size 80x50 \
    --frames 1-7:3 --index-env "$LID" >/dev/null 2>&1
  "$QCS" -o "$tmp/frd/f####.exr" --size 80x50 --frames $f-$f --animation 1-7 \
    "$LID" >/dev/null 2>&1
done
n=$(ls "$tmp/fr" | tr '\n' ' ')
if [ "$n" = "f0001.exr f0004.exr f0007.exr " ] &&
    (for f in 0001 0004 0007; do cmp -s "$tmp/fr/f$f.exr" "$tmp/frd/f$f.exr" || exit 1; done); then
  ok "--frames 1-7:3 --index-env: tasks 0-2 are frames 1, 4, 7 rendered directly"
else fail "--frames --index-env: wrote $n, or a frame differs"; fi
mkdir -p "$tmp/ft"
bad=0
for k in $(seq 0 11); do
  f=$((k / 4 + 1)) t=$((k % 4 + 1))
  JOB_COMPLETION_INDEX=$k "$QCS" -o "$tmp/ft/k$k.####.exr" --size 80x50 \
    --frames 1-3 --tiles 4 --index-env "$LID" >/dev/null 2>&1
  "$QCS" -o "$tmp/ft/d$k.####.exr" --size 80x50 --frames $f-$f --animation 1-3 \
    --tile $t/4 "$LID" >/dev/null 2>&1
  cmp -s "$tmp/ft/k$k.000$f.exr" "$tmp/ft/d$k.000$f.exr" || bad=$((bad + 1))
done
[ $bad = 0 ] && [ "$(ls "$tmp/ft" | wc -l)" = 24 ] &&
  ok "--frames 1-3 --tiles 4 --index-env: task k is frame k / 4 + 1, tile k % 4 + 1" ||
  fail "--frames --tiles --index-env: $bad of 12 tasks differ ($(ls "$tmp/ft" | wc -l) files)"
# The Slurm template's animation variant: 3 frames x 4 tiles, 12 array
# tasks from 0, its merge step; each merged frame is the frame rendered
# whole in one process.
mkdir -p "$tmp/sa" "$tmp/sad"
for i in $(seq 0 11); do
  SLURM_ARRAY_TASK_ID=$i SLURM_ARRAY_TASK_MIN=0 FRAMES=1-3 TILES=4 SIZE=80x50 \
    SCENE="$LID" OUT="$tmp/sa" sh examples/farm/slurm.sh >/dev/null 2>&1
done
FRAMES=1-3 TILES=4 SIZE=80x50 OUT="$tmp/sa" sh examples/farm/slurm.sh merge \
  >/dev/null 2>&1
"$QCS" -o "$tmp/sad/f####.exr" --size 80x50 --frames 1-3 "$LID" >/dev/null 2>&1
if (for f in 0001 0002 0003; do cmp -s "$tmp/sa/f$f.exr" "$tmp/sad/f$f.exr" || exit 1; done); then
  ok "template slurm.sh, animation: 3 frames x 4 tiles, merged per frame"
else fail "template slurm.sh animation: $(ls "$tmp/sa" | tr '\n' ' ')"; fi

# Bad input: status 1, a clear message, the output untouched.
echo keep > "$tmp/keep.exr"
bad() { # bad NAME PATTERN COMMAND...
  name=$1 pat=$2; shift 2
  "$@" > "$tmp/out" 2>&1; st=$?
  if [ $st -eq 1 ] && grep -q "$pat" "$tmp/out" &&
      [ "$(cat "$tmp/keep.exr")" = keep ]; then ok "refused: $name"
  else fail "$name: status $st: $(head -c 300 "$tmp/out")"; fi
}
bad "a crop outside the image" "not a part of the 160x100 image" \
  "$QCS" -o "$tmp/keep.exr" --size $SZ --crop 0,200,0,10 "$SCENE"
bad "--tile 0/4" "1 <= I <= N" "$QCS" -o "$tmp/keep.exr" --tile 0/4 "$SCENE"
bad "--tile 5/4" "1 <= I <= N" "$QCS" -o "$tmp/keep.exr" --tile 5/4 "$SCENE"
bad "an index past the tiles" "past the last" env PARALLEL_SEQ=17 \
  "$QCS" -o "$tmp/keep.exr" --tiles 16 --index-env "$SCENE"
bad "a task past the frames" "past the last of 3 frames" env SLURM_ARRAY_TASK_ID=3 \
  "$QCS" -o "$tmp/keep.exr" --frames 1-7:3 --index-env "$LID"
bad "a task past frames x tiles" "past the last of 12 tasks (3 frames x 4 tiles" \
  env PARALLEL_SEQ=13 "$QCS" -o "$tmp/keep.exr" --frames 1-3 --tiles 4 \
  --index-env "$LID"
bad "--index-env alone" "needs --tiles N" env PARALLEL_SEQ=1 \
  "$QCS" -o "$tmp/keep.exr" --index-env "$SCENE"
bad "--index-env with no index" "none of" env -u SLURM_ARRAY_TASK_ID \
  -u JOB_COMPLETION_INDEX -u AWS_BATCH_JOB_ARRAY_INDEX -u PARALLEL_SEQ \
  "$QCS" -o "$tmp/keep.exr" --tiles 16 --index-env "$SCENE"
"$QCS" -o "$tmp/o1.exr" --size $SZ --spp 1 --tile 1/2 "$SCENE" >/dev/null 2>&1
"$QCS" -o "$tmp/o2.exr" --size $SZ --spp 4 --tile 2/2 "$SCENE" >/dev/null 2>&1
"$QCS" -o "$tmp/o3.exr" --size 170x100 --tile 2/2 "$SCENE" >/dev/null 2>&1
"$QCS" -o "$tmp/o4.exr" --size $SZ --tile 2/2 "$SCENE" >/dev/null 2>&1
bad "merging tiles of different renders" "another render (its qcs.samples" \
  "$QCS" merge "$tmp/keep.exr" "$tmp/o1.exr" "$tmp/o2.exr"
bad "merging tiles of different sizes" "a part of a 170x100 picture" \
  "$QCS" merge "$tmp/keep.exr" "$tmp/o1.exr" "$tmp/o3.exr"
bad "a missing tile" "a part is missing" \
  "$QCS" merge "$tmp/keep.exr" "$tmp/o1.exr"
bad "overlapping tiles" "overlap" \
  "$QCS" merge "$tmp/keep.exr" "$tmp/o1.exr" "$tmp/o4.exr" "$tmp/o4.exr"
bad "a tile that is not there" "No such file" \
  "$QCS" merge "$tmp/keep.exr" "$tmp/o1.exr" "$tmp/nothere.exr"
"$QCS" merge "$tmp/o14.exr" "$tmp/o1.exr" "$tmp/o4.exr" 2>/dev/null
"$QCS" -o "$tmp/o0.exr" --size $SZ "$SCENE" >/dev/null 2>&1
cmp -s "$tmp/o14.exr" "$tmp/o0.exr" && ok "two tiles merge to the whole" \
  || fail "two tiles do not merge to the whole"

# --skip-existing leaves a file that is there alone.
"$QCS" -o "$tmp/keep.exr" --size $SZ --skip-existing "$SCENE" > "$tmp/out" 2>&1
[ $? -eq 0 ] && [ "$(cat "$tmp/keep.exr")" = keep ] &&
  grep -q "not rendered again" "$tmp/out" &&
  ok "--skip-existing does not render over a file" ||
  fail "--skip-existing: $(head -c 200 "$tmp/out")"

# -o with a script of several renders: out.png, out.2.png, never one over
# another.
cat > "$tmp/two.qcs" <<'QCS'
renderWith [Size 32 20] "a.png" UnitCube;
renderWith [Size 32 20, Samples 4] "b.png" UnitCube;
QCS
(cd "$tmp" && "$QCS" -o out.png two.qcs >/dev/null 2>&1)
[ -f "$tmp/out.png" ] && [ -f "$tmp/out.2.png" ] && [ ! -f "$tmp/a.png" ] &&
  ok "-o with two renders writes out.png and out.2.png" ||
  fail "-o with two renders: $(ls "$tmp" | grep out | tr '\n' ' ')"
