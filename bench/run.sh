#!/bin/bash
# bench/run.sh -- `make bench`: time qcs on the canonical scenes, side by side
# with POV-Ray 3.7 (bench/povray/), and check issue 7's targets.
#
# Usage: bench/run.sh [-n REPS] [-p POV_REPS] [-c] [SCENE ...]
#   SCENE     figure12 figure12-sharp figure13 figure15a figure15a-sharp
#             figure15b soft-cloud-N (any N); default: all of them, with
#             N = 10 100 1000 10000 100000 (figure15b is an extra)
#   -n REPS   renders per scene (default 7), each qcs run paired with a
#             POV-Ray run right after it (A B A B ...), so both see the
#             same load; min and median of whole-process wall for both
#   -p REPS   POV-Ray renders per scene (default: as many as qcs's; 0 =
#             skip POV-Ray)
#   -c        also run the callgrind counts (bench/callgrind.sh)
# Environment: QCS (default ./qcs), THREADS (2), SIZE (600x380),
#   OUT (/tmp/qcs-bench), POVDIR (bench/povray),
#   POV_ISO (1: render POV-Ray's exact Wyvill isosurface soft-cloud-iso-100
#   once, for the "exact field at N = 100" target; 0 to skip),
#   MESH_BENCH (1: bench/mesh.sh, meshing; 0 to skip),
#   FRAMES_BENCH (1: bench/frames.sh, a 100-frame animation in one process
#   against 100 processes; 0 to skip),
#   TILES_BENCH (1: bench/tiles.sh, 16 tiles of a 1920x1080 figure12 as
#   processes of their own against the whole; 0 to skip),
#   KIT_BENCH (1: bench/kit.sh, a 10x10x10 grid of rounded cubes; 0 to skip),
#   INTERP_BENCH (1: bench/interp.sh, the interpreter against Hugs on
#   bench/hugs/; 0 to skip), SOFT_1M (1: soft-cloud with 10^6 keys, once).
# Writes bench/results.csv and bench/README.md (the summary of this run).
#
# Each repetition renders the scene with qcs, then at once with POV-Ray, so
# both see the same machine load: the ratios are the figures to report,
# as the ratio of the medians and the ratio of the minimums (the minimum is
# the run least disturbed by other load; the two agreeing says the ratio
# is sound).
set -u
cd "$(dirname "$0")/.." || exit 1
ROOT=$(pwd)

REPS=7; POV_REPS=""; CALLGRIND=0
while getopts "n:p:c" opt; do
  case $opt in
    n) REPS=$OPTARG ;;
    p) POV_REPS=$OPTARG ;;
    c) CALLGRIND=1 ;;
    *) sed -n '2,18p' "$0"; exit 2 ;;
  esac
done
shift $((OPTIND - 1))
[ -n "$POV_REPS" ] || POV_REPS=$REPS

QCS=${QCS:-./qcs}
THREADS=${THREADS:-2}
SIZE=${SIZE:-600x380}
OUT=${OUT:-/tmp/qcs-bench}
POVDIR=${POVDIR:-$ROOT/bench/povray}
POV_ISO=${POV_ISO:-1}
W=${SIZE%x*}; H=${SIZE#*x}
CLOUD_NS="10 100 1000 10000 100000"
CSV=bench/results.csv
MD=bench/README.md
mkdir -p "$OUT/qcs" "$OUT/pov"

[ $# -eq 0 ] && set -- figure12 figure12-sharp figure13 figure15a figure15a-sharp figure15b \
  $(for n in $CLOUD_NS; do printf 'soft-cloud-%s ' "$n"; done)

[ -x "$QCS" ] || { echo "error: $QCS not built (run make)" >&2; exit 1; }

HAVE_POV=0; POV_NOTE=""
if [ "$POV_REPS" -gt 0 ] 2>/dev/null; then
  if ! command -v povray >/dev/null 2>&1; then
    POV_NOTE="POV-Ray is not installed (Debian package povray): the POV-Ray half is skipped"
  elif [ ! -f "$POVDIR/figure12.pov" ]; then
    POV_NOTE="no POV-Ray scenes in $POVDIR: the POV-Ray half is skipped"
  else
    HAVE_POV=1
  fi
else
  POV_NOTE="POV-Ray half skipped (-p 0)"
fi

now() { date +%s.%N; }
median() { sort -g | awk '{ v[NR] = $1 } END { if (NR == 0) { print "" } else printf "%.4f\n", (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
minimum() { sort -g | head -1; }
div() { awk -v a="$1" -v b="$2" -v f="${3:-%.2f}" 'BEGIN { if (a == "" || b == "" || b + 0 == 0) print "-"; else printf f "\n", a / b }'; }

# qcs arguments for a scene, or nothing (status 1) when its file is missing.
qcs_args() {
  case $1 in
    figure15a-sharp)
      if [ -f examples/figure15a.qcs ] && grep -q '^side *=' examples/figure15a.qcs \
           && grep -q '^flat *=' examples/figure15a.qcs; then
        echo "--set side=0 --set flat=0 examples/figure15a.qcs"
      elif [ -f bench/figure15a-sharp.qcs ]; then echo "bench/figure15a-sharp.qcs"
      else return 1; fi ;;
    soft-cloud-[0-9]*)
      [ -f examples/soft-cloud.qcs ] || return 1
      echo "--set n=${1#soft-cloud-} examples/soft-cloud.qcs" ;;
    *) [ -f "examples/$1.qcs" ] || return 1; echo "examples/$1.qcs" ;;
  esac
}
qcs_file() { case $1 in soft-cloud-*) echo examples/soft-cloud.qcs ;; figure15a-sharp) echo "examples/figure15a.qcs (sharp via --set, or bench/figure15a-sharp.qcs)" ;; *) echo "examples/$1.qcs" ;; esac; }

pov_args() {
  case $1 in
    figure12|figure12-sharp|figure13|figure15a|figure15b) echo "$1.pov" ;;
    soft-cloud-iso-[0-9]*) echo "soft-cloud-iso.pov Declare=N=${1#soft-cloud-iso-}" ;;
    soft-cloud-[0-9]*)     echo "soft-cloud.pov Declare=N=${1#soft-cloud-}" ;;
    *) return 1 ;;
  esac
}

run_qcs() {  # run_qcs SCENE I -> prints wall seconds; report in $OUT/qcs/SCENE.I.log
  local s=$1 i=$2 args t0 t1 rc
  args=$(qcs_args "$s")
  t0=$(now)
  # shellcheck disable=SC2086
  "$QCS" --threads "$THREADS" --size "$SIZE" -o "$OUT/qcs/$s.png" $args \
    > "$OUT/qcs/$s.$i.out" 2> "$OUT/qcs/$s.$i.log"
  rc=$?; t1=$(now)
  [ $rc -eq 0 ] || return 1
  awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.4f\n", b - a }'
}

run_pov() {  # run_pov SCENE I -> prints "WALL TRACE"
  local s=$1 i=$2 args pov t0 t1 rc log=$OUT/pov/$s.$i.log
  args=$(pov_args "$s") || return 1
  set -- $args; pov=$1; shift
  t0=$(now)
  ( cd "$POVDIR" && povray +I"$pov" +O"$OUT/pov/$s.png" +FN +W"$W" +H"$H" -A -D +WT2 \
      File_Gamma=sRGB "$@" ) > "$log" 2>&1
  rc=$?; t1=$(now)
  if [ $rc -ne 0 ] || grep -q "Render failed\|Parse Error" "$log"; then return 1; fi
  local tr; tr=$(tr '\r' '\n' < "$log" | awk '/Trace Time:/ { t = $(NF-1); gsub(/[()]/, "", t) } END { print t }')
  awk -v a="$t0" -v b="$t1" -v t="$tr" 'BEGIN { printf "%.4f %s\n", b - a, t }'
}

# Figures from qcs's stderr report: "RENDER PRIMARY SHADOW EVALS SEGS POLISH(+soft-object polynomial solves) HITS EVALS_PER_HIT"
parse_report() {
  awk '
    / s on [0-9]+ threads?/ { for (i = 1; i <= NF; i++) if ($i == "s" && $(i+1) == "on") rt = $(i-1) }
    /^ *rays:/ { p = $2; s = $4 }
    /^ *density:/ { for (i = 1; i <= NF; i++) {
        if ($i ~ /^evaluations/) ev = $(i-1)
        if ($i ~ /^segments/) sg = $(i-1)
        if ($i == "polishing") po = $(i-1) } }
    /^ *soft objects:/ { for (i = 1; i <= NF; i++) if ($i == "polynomial") so = $(i-1) }
    /hitting a rounded surface:/ { h = $(NF-4); sub(/,$/, "", h); eh = $(NF-3) }
    END { printf "%s %s %s %s %s %s %s %s\n", rt+0, p+0, s+0, ev+0, sg+0, po+so, h+0, (eh == "" ? "-" : eh) }' "$1"
}

MACHINE="$(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | sed 's/.*: //')"
DATE=$(date -u '+%Y-%m-%d %H:%M UTC')
POV_VERSION=$( [ $HAVE_POV -eq 1 ] && povray --version 2>&1 | grep -m1 'POV-Ray 3' )
QCS_COMMIT=$(git rev-parse --short HEAD 2>/dev/null)$(git diff --quiet -- src 2>/dev/null || echo "+dirty src")

echo "qcs bench: $DATE, $MACHINE"
echo "qcs: $QCS (commit $QCS_COMMIT), --threads $THREADS --size $SIZE, $REPS runs per scene, median whole-process wall time"
if [ $HAVE_POV -eq 1 ]; then
  echo "POV-Ray: $POV_VERSION, +W$W +H$H -A -D +WT2, $POV_REPS runs per scene, interleaved with qcs's"
else
  echo "NOTE: $POV_NOTE"
fi
echo

echo "scene,qcs_runs,qcs_wall_median_s,qcs_wall_min_s,qcs_render_median_s,rays,rays_per_s_wall,density_evals,evals_per_ray,root_steps_per_ray,rounded_hits,evals_per_rounded_hit,pov_runs,pov_wall_median_s,pov_trace_median_s,pov_over_qcs,pov_wall_min_s,pov_over_qcs_min" > "$CSV.tmp"

declare -A QW PW PT EPH MISSING PWMIN RMIN WRT RMRAY
ROWS=()
for s in "$@"; do
  if ! qcs_args "$s" > /dev/null; then
    echo "missing: $s -- $(qcs_file "$s") does not exist yet; not timed"
    MISSING[$s]=1
    echo "$s,0,,,,,,,,,,,,,,,," >> "$CSV.tmp"
    continue
  fi
  walls=(); renders=(); writes=(); povw=(); povt=(); failed=""
  n=$REPS; pn=$POV_REPS; [ $HAVE_POV -eq 1 ] && pov_args "$s" > /dev/null || pn=0
  for i in $(seq 1 "$n"); do
    if t=$(run_qcs "$s" "$i"); then
      walls+=("$t"); rep=$(parse_report "$OUT/qcs/$s.$i.log"); renders+=("${rep%% *}")
      writes+=("$(awk '/file written in/ { w = $4 } END { print w + 0 }' "$OUT/qcs/$s.$i.log")")
      last=$i
    else
      failed="qcs failed, see $OUT/qcs/$s.$i.log"; break
    fi
    if [ "$i" -le "$pn" ]; then
      if pt=$(run_pov "$s" "$i"); then povw+=("${pt% *}"); povt+=("${pt#* }")
      else echo "  POV-Ray failed on $s, see $OUT/pov/$s.$i.log"; pn=0; fi
    fi
    # a very slow scene: stop at three runs
    if [ "$i" -ge 3 ] && awk -v t="$t" 'BEGIN { exit !(t > 20) }'; then
      echo "  $s: $t s per run, stopping after $i runs"; break
    fi
  done
  if [ ${#walls[@]} -eq 0 ]; then
    echo "FAILED: $s ($failed)"; sed 's/^/    /' "$OUT/qcs/$s.1.log" | head -5
    echo "$s,0,,,,,,,,,,,,,,,," >> "$CSV.tmp"; MISSING[$s]=1; continue
  fi
  [ -n "$failed" ] && echo "  $s: $failed"
  wmed=$(printf '%s\n' "${walls[@]}" | median)
  wmin=$(printf '%s\n' "${walls[@]}" | minimum)
  rmed=$(printf '%s\n' "${renders[@]}" | median)
  WRT[$s]=$(printf '%s\n' "${writes[@]}" | median)
  read -r rt prim shad ev sg po hits eph <<< "$(parse_report "$OUT/qcs/$s.$last.log")"
  rays=$((prim + shad))
  rps=$(div "$rays" "$wmed" "%.0f")
  RMRAY[$s]=$(div "$rays" "$(awk -v r="$rmed" 'BEGIN { print r * 1e6 }')" "%.2f")
  epr=$(div "$ev" "$rays" "%.2f")
  spr=$(div "$((sg + po))" "$rays" "%.2f")
  pwmed=""; ptmed=""; pwmin=""; ratio="-"; ratio_min="-"
  if [ ${#povw[@]} -gt 0 ]; then
    pwmed=$(printf '%s\n' "${povw[@]}" | median)
    pwmin=$(printf '%s\n' "${povw[@]}" | minimum)
    ptmed=$(printf '%s\n' "${povt[@]}" | median)
    ratio=$(div "$pwmed" "$wmed" "%.2f")
    # the minimums over the same paired runs (qcs's first n, where n POV-Ray runs)
    qmin_paired=$(printf '%s\n' "${walls[@]:0:${#povw[@]}}" | minimum)
    ratio_min=$(div "$pwmin" "$qmin_paired" "%.2f")
  fi
  PWMIN[$s]=$pwmin; RMIN[$s]=$ratio_min
  QW[$s]=$wmed; PW[$s]=$pwmed; PT[$s]=$ptmed; EPH[$s]=$eph
  echo "$s,${#walls[@]},$wmed,$wmin,$rmed,$rays,$rps,$ev,$epr,$spr,$hits,$eph,${#povw[@]},$pwmed,$ptmed,$ratio,$pwmin,$ratio_min" >> "$CSV.tmp"
  ROWS+=("$(printf '%-18s %9.3f %9.3f %8.2f %10s %10s %11s %10s %10s %10s %10s' "$s" "$wmed" "$rmed" \
    "$(awk -v r="$rps" 'BEGIN { printf "%.2f", r / 1e6 }')" "$epr" "$spr" "$eph" \
    "${pwmed:--}" "${ptmed:--}" "$ratio" "$ratio_min")")
  echo "  done: $s (${#walls[@]} qcs runs, ${#povw[@]} POV-Ray runs)"
done

# POV-Ray's exact Wyvill-field isosurface at N = 100 (about 22 s): once.
ISO_WALL=""
if [ $HAVE_POV -eq 1 ] && [ "$POV_ISO" = 1 ] && [ -n "${QW[soft-cloud-100]:-}" ]; then
  if pt=$(run_pov soft-cloud-iso-100 1); then ISO_WALL=${pt% *}; echo "  done: POV-Ray soft-cloud-iso-100 (exact Wyvill isosurface), 1 run: $ISO_WALL s"; fi
fi
mv "$CSV.tmp" "$CSV"

TABLE=$(
  printf '%-18s %9s %9s %8s %10s %10s %11s %10s %10s %10s %10s\n' scene "qcs wall" "render" "Mray/s" \
    "evals/ray" "steps/ray" "evals/rhit" "pov wall" "pov trace" "pov/qcs" "(of mins)"
  printf '%s\n' "${ROWS[@]}"
)
echo
echo "$TABLE"
echo "(seconds; qcs wall = median whole-process wall time, render = qcs's own render time;"
echo " Mray/s = primary + shadow rays / qcs wall; evals/ray and steps/ray = density evaluations and"
echo " root-search steps (segments + polishing steps, or soft-object polynomial solves) per ray; evals/rhit = per ray hitting a rounded"
echo " surface; pov wall / trace = POV-Ray medians, pov/qcs = POV-Ray wall / qcs wall, medians and mins)"

q() { echo "${QW[$1]:-}"; }
R12=$(div "$(q figure12)" "$(q figure12-sharp)")
R15=$(div "$(q figure15a)" "$(q figure15a-sharp)")
P12=$(div "${PW[figure12]:-}" "${PW[figure12-sharp]:-}")
P12T=$(div "${PT[figure12]:-}" "${PT[figure12-sharp]:-}")
GROWTH=$(div "$(q soft-cloud-100000)" "$(q soft-cloud-100)")
PGROWTH=$(div "${PW[soft-cloud-100000]:-}" "${PW[soft-cloud-100]:-}")
ISO_RATIO=$(div "$ISO_WALL" "$(q soft-cloud-100)" "%.1f")

RATIOS=$(
  echo "rounded / sharp (qcs wall):  figure12 / figure12-sharp = $R12   figure15a / figure15a-sharp = $R15"
  echo "rounded / sharp (POV-Ray):   figure12 wall $P12, trace $P12T"
  echo "soft-cloud growth (qcs wall per key):"
  for n in $CLOUD_NS; do
    t=$(q "soft-cloud-$n")
    if [ -n "$t" ]; then
      printf '  N = %6s: %8.3f s, %10s us per key;  POV-Ray blob %s s\n' "$n" "$t" \
        "$(awk -v t="$t" -v n="$n" 'BEGIN { printf "%.3f", t / n * 1e6 }')" "${PW[soft-cloud-$n]:--}"
    else
      printf '  N = %6s: missing\n' "$n"
    fi
  done
  echo "  T(N=100000) / T(N=100): qcs $GROWTH, POV-Ray blob $PGROWTH"
  echo "exact Wyvill field, N = 100: POV-Ray isosurface ${ISO_WALL:--} s / qcs $(q soft-cloud-100) s = $ISO_RATIO"
)
echo
echo "$RATIOS"

# Pictures at the prompt (issue 13): qcs --show draws figure12 coarse to
# fine in 100 x 32 cells; --timings says when the scene was ready (after
# process start, the prelude and the script), then the first and the full
# picture. Medians of PV_REPS runs for symbols and for sixels (drawn to a
# file: the encoding is timed, not the terminal).
PV_REPS=${PV_REPS:-7}
pv_run() {  # pv_run MODE -> "FIRST FULL PIXELS" (first counted from start)
  "$QCS" --show --preview "$1" --cells 100x32 --timings --threads "$THREADS" \
    examples/figure12.qcs 2>&1 >/dev/null | awk '/scene ready/ {
      for (i = 1; i <= NF; i++) {
        if ($i == "ready") r = $(i + 1)
        if ($i == "picture" && $(i - 1) == "first") f = $(i + 1)
        if ($i == "full") u = $(i + 1)
      }
      printf "%.4f %.4f %s\n", r + f, r + u, $2 }'
}
declare -A PV_FIRST PV_FULL PV_PIX
for m in symbols sixel; do
  : > "$OUT/preview-$m.txt"
  for i in $(seq "$PV_REPS"); do pv_run $m >> "$OUT/preview-$m.txt"; done
  PV_FIRST[$m]=$(awk '{ print $1 }' "$OUT/preview-$m.txt" | median)
  PV_FULL[$m]=$(awk '{ print $2 }' "$OUT/preview-$m.txt" | median)
  PV_PIX[$m]=$(awk 'NR == 1 { print $3 }' "$OUT/preview-$m.txt")
done
PREVIEW=$(
  echo "| figure12 at the prompt, 100 x 32 cells | pixels | first picture | full picture |"
  echo "|---|---|---|---|"
  for m in symbols sixel; do
    echo "| $m | ${PV_PIX[$m]:--} | ${PV_FIRST[$m]:--} s | ${PV_FULL[$m]:--} s |"
  done
)
echo
echo "pictures at the prompt (from process start; medians of $PV_REPS):"
echo "$PREVIEW" | tail -n +3 | sed 's/^| //; s/ |$//; s/ | /: /; s/ | / /g'

# The side benches, each a script of bench/ run unless its switch is 0;
# its output is kept for bench/README.md.
#   side VAR SWITCH LABEL COMMAND...: VAR=$(COMMAND), printed under LABEL
side() {
  local var=$1 switch=$2 label=$3 out=""
  shift 3
  if [ "${!switch:-1}" = 1 ]; then
    out=$("$@" 2>&1)
    echo
    echo "$label"
    echo "$out"
  fi
  printf -v "$var" '%s' "$out"
}
export QCS
# An animation in one process against one a frame (issue 17):
# examples/lid.qcs at 160x100, frames 1-100.
side FRAMES_SUMMARY FRAMES_BENCH \
  "animation, one process against one a frame (bench/frames.sh):" \
  sh bench/frames.sh "$THREADS"
# A farm's tiles against the whole picture (issue 17).
side TILES_SUMMARY TILES_BENCH \
  "tiles as separate processes against the whole (bench/tiles.sh):" \
  sh bench/tiles.sh "$THREADS"
# The kit's patterns at scale (issue 19): bench/grid1000.qcs.
side KIT_SUMMARY KIT_BENCH \
  "a 10x10x10 grid of rounded cubes (bench/kit.sh):" \
  env SIZE="$SIZE" sh bench/kit.sh "$THREADS"
# The interpreter against Hugs (issue 18).
side INTERP_SUMMARY INTERP_BENCH \
  "the interpreter against Hugs (bench/interp.sh):" bash bench/interp.sh -n "$REPS"
# Meshing (issue 16): the figure12 objects at 1e-3 of their size against a
# uniform grid, the unit cube at 1e-4, OpenSCAD's export.
side MESH_SUMMARY MESH_BENCH "meshing (bench/mesh.sh):" sh bench/mesh.sh

# Issue 7's targets.
verdict() { if [ "$1" = "-" ] || [ -z "$1" ]; then echo "not measured"; elif awk "BEGIN { exit !($2) }"; then echo "met"; else echo "NOT met"; fi; }
ge() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a != "-" && a != "" && a + 0 >= b) }'; }
F12=$(q figure12); F12S=$(q figure12-sharp)
R_F12=$(div "${PW[figure12]:-}" "$F12")
T1a=$(verdict "$F12" "${F12:-0} <= 0.1"); T1b=$(verdict "$R_F12" "${R_F12:-0} >= 20")
T2=$(verdict "$F12S" "${F12S:-0} < 0.08")
T3a=$(verdict "$R12" "$R12 <= 1.5"); T3b=$(verdict "$R15" "$R15 <= 2.5")
R1k=$(div "${PW[soft-cloud-1000]:-}" "$(q soft-cloud-1000)"); R10k=$(div "${PW[soft-cloud-10000]:-}" "$(q soft-cloud-10000)")
T4a=$(verdict "$R1k" "$R1k >= 3"); T4b=$(verdict "$R10k" "$R10k >= 3")
S100k=$(q soft-cloud-100000); T4c=$(verdict "$S100k" "${S100k:-0} < 2")
T4d=$(verdict "$GROWTH" "$GROWTH <= 4")
T5=$(verdict "$ISO_RATIO" "$ISO_RATIO >= 100")
E12=${EPH[figure12]:-}; T6=$(verdict "$E12" "${E12:-0} <= 12")

TARGETS=$(
  echo "| target | measured | verdict |"
  echo "|---|---|---|"
  echo "| figure12 in at most 0.1 s | ${F12:--} s | $T1a |"
  echo "| figure12 at least 20x faster than POV-Ray | POV-Ray / qcs = $R_F12 | $T1b |"
  echo "| figure12-sharp below POV-Ray's trace time (0.08 s; this run ${PT[figure12-sharp]:--} s) | ${F12S:--} s | $T2 |"
  echo "| rounded / sharp at most 1.5 on figure12 | $R12 | $T3a |"
  echo "| rounded / sharp at most 2.5 on figure15a | $R15 | $T3b |"
  echo "| soft-cloud N = 1000 at least 3x faster than POV-Ray's blob | $R1k | $T4a |"
  echo "| soft-cloud N = 10000 at least 3x faster than POV-Ray's blob | $R10k | $T4b |"
  echo "| soft-cloud N = 100000 under 2 s | ${S100k:--} s | $T4c |"
  echo "| soft-cloud T(100000) / T(100) at most 4 | $GROWTH | $T4d |"
  echo "| exact Wyvill field N = 100 at least 100x faster than POV-Ray's isosurface | $ISO_RATIO | $T5 |"
  echo "| figure12 at most 12 density evaluations per rounded hit | ${E12:--} | $T6 |"
  for m in symbols sixel; do
    echo "| figure12's first picture at the prompt ($m) within 0.05 s | ${PV_FIRST[$m]:--} s | $(verdict "${PV_FIRST[$m]:-}" "${PV_FIRST[$m]:-0} <= 0.05") |"
    echo "| figure12's full picture at the prompt ($m) within 0.3 s | ${PV_FULL[$m]:--} s | $(verdict "${PV_FULL[$m]:-}" "${PV_FULL[$m]:-0} <= 0.3") |"
  done
)
# Issue 18's targets (the interpreter's are in bench/interp.sh's table).
R_F12_MIN=${RMIN[figure12]:-}
S1M=""
if [ "${SOFT_1M:-1}" = 1 ] && [ -f examples/soft-cloud.qcs ]; then
  t0=$(now); "$QCS" --threads "$THREADS" --size "$SIZE" -o "$OUT/qcs/soft-cloud-1000000.png" \
    --set n=1000000 examples/soft-cloud.qcs > /dev/null 2>&1 && S1M=$(awk -v a="$t0" -v b="$(now)" 'BEGIN { printf "%.3f", b - a }')
fi
R10k18=$(div "${PW[soft-cloud-10000]:-}" "$(q soft-cloud-10000)"); R100k18=$(div "${PW[soft-cloud-100000]:-}" "$(q soft-cloud-100000)")
# every rounded canonical scene at least 40x POV-Ray: the least ratio of medians
R_ROUNDED=""; R_ROUNDED_WHICH=""
for r in figure12 figure13 figure15a figure15b; do
  x=$(div "${PW[$r]:-}" "$(q "$r")")
  [ "$x" = "-" ] && continue
  if [ -z "$R_ROUNDED" ] || awk -v a="$x" -v b="$R_ROUNDED" 'BEGIN { exit !(a < b) }'; then R_ROUNDED=$x; R_ROUNDED_WHICH=$r; fi
done
PNG_SHARE=$(awk -v w="${WRT[figure12]:-}" -v t="$(q figure12)" 'BEGIN { if (w == "" || t == "" || t + 0 == 0) print "-"; else printf "%.1f", 100 * w / t }')
# qcs -e 1: start-up, prelude and one expression, median of 7
E1=""
: > "$OUT/e1.times"
for i in 1 2 3 4 5 6 7; do
  t0=$(now); "$QCS" -e 1 > /dev/null 2>&1 && awk -v a="$t0" -v b="$(now)" 'BEGIN { printf "%.4f\n", b - a }' >> "$OUT/e1.times"
done
[ -s "$OUT/e1.times" ] && E1=$(awk '{ print 1000 * $1 }' "$OUT/e1.times" | median | awk '{ printf "%.1f", $1 }')
TARGETS18=$(
  echo "| target | measured | verdict |"
  echo "|---|---|---|"
  echo "| figure12 at least 40x POV-Ray, whole process, paired (ratio of medians; of mins) | $R_F12; ${R_F12_MIN:--} | $(verdict "$R_F12" "${R_F12:-0} >= 40") |"
  echo "| every rounded canonical scene at least 40x POV-Ray (the least, ratio of medians) | ${R_ROUNDED:--} (${R_ROUNDED_WHICH:--}) | $(verdict "$R_ROUNDED" "${R_ROUNDED:-0} >= 40") |"
  echo "| figure12 at least 15 Mray/s, primary + shadow over the render's time ($THREADS threads) | ${RMRAY[figure12]:--} | $(verdict "${RMRAY[figure12]:-}" "${RMRAY[figure12]:-0} >= 15") |"
  echo "| figure12's PNG writing at most 10% of the wall time (median write / median wall) | ${PNG_SHARE}% | $(verdict "$PNG_SHARE" "${PNG_SHARE:-100} <= 10") |"
  echo "| qcs -e 1 under 20 ms (median of 7) | ${E1:--} ms | $(verdict "$E1" "${E1:-99} < 20") |"
  echo "| rounded / sharp on figure12 at most 1.2 | $R12 | $(verdict "$R12" "$R12 <= 1.2") |"
  echo "| soft-cloud T(100000) / T(100) at most 4 | $GROWTH | $T4d |"
  echo "| soft-cloud 10^6 keys under 3 s whole process (one run) | ${S1M:--} s | $(verdict "$S1M" "${S1M:-0} < 3") |"
  echo "| soft-cloud at least 10x POV-Ray's blob at 10^4 | $R10k18 | $(verdict "$R10k18" "$R10k18 >= 10") |"
  echo "| soft-cloud at least 10x POV-Ray's blob at 10^5 | $R100k18 | $(verdict "$R100k18" "$R100k18 >= 10") |"
)
echo
echo "issue 18 targets:"
echo "$TARGETS18" | tail -n +3 | sed 's/^| //; s/ |$//; s/ | /: /; s/ | / -> /'

echo
echo "issue 7 targets:"
echo "$TARGETS" | tail -n +3 | sed 's/^| //; s/ |$//; s/ | /: /; s/ | / -> /'

MISS=""
for s in "${!MISSING[@]}"; do MISS="$MISS $s"; done

CG=""
if [ $CALLGRIND -eq 1 ]; then
  echo
  bash bench/callgrind.sh && CG=1
fi

# bench/README.md: how to run, this run's summary, then bench/NOTES.md.
# The file is written whole each run: observations that must last go in
# bench/NOTES.md, never into bench/README.md by hand.
{
  cat <<EOF
# bench: qcs against POV-Ray 3.7 (issue 7)

\`make bench\` builds qcs, installs what is missing (the build's packages and
the Debian package \`povray\`, as root), then runs \`bench/run.sh\`: every
canonical scene (\`examples/\`) at $SIZE, rendered
$REPS times by qcs (\`--threads $THREADS\`) and, interleaved with those runs so that both
see the same load, $POV_REPS times by POV-Ray from \`bench/povray/\`
(\`+W$W +H$H -A -D +WT2 File_Gamma=sRGB\`, as the POV-Ray project peers time them). Times are medians
of whole-process wall time. The machines are shared and noisy: the
**ratios** measured side by side are the figures to report.

- \`bench/run.sh [-n REPS] [-p POV_REPS] [-c] [SCENE ...]\` (\`-p 0\` skips POV-Ray;
  \`POV_ISO=0\` skips the 22 s POV-Ray isosurface run).
- \`bench/results.csv\`: the table of the last run, one row per scene.
- \`make bench-callgrind\` (\`bench/callgrind.sh\`): instruction counts per scene
  at 150x95, one thread, under \`valgrind --tool=callgrind\`, into
  \`bench/callgrind.csv\`; these are repeatable, so regressions show. Where
  they go: each function's own count per scene in
  \`bench/callgrind-functions.csv\`, and the run prints every scene's top
  functions (\`CG_TOP\`, 8) against the previous file's, so a gain or a loss
  names the functions it came from. \`bash bench/callgrind.sh SCENE ...\` runs
  a few scenes and keeps the other rows.
- \`bash bench/interp.sh [-n REPS]\` (run by \`make bench\`; \`INTERP_BENCH=0\` skips it):
  the interpreter against Hugs 98 on the programs of \`bench/hugs/\` (each
  written in qcs and in Haskell), paired runs, medians of wall time and of
  peak RSS, into \`bench/interp.csv\`.
- figure15a's sharp baseline is \`examples/figure15a.qcs\` with
  \`--set side=0 --set flat=0\` (every plane's radius 0: the sharp cuboid).
- The exact-Wyvill-field target compares qcs's soft-cloud N = 100 with one
  render of POV-Ray's \`soft-cloud-iso.pov\` at N = 100.

## Last run

- date: $DATE
- machine: $MACHINE
- qcs: commit $QCS_COMMIT
- POV-Ray: ${POV_VERSION:-not run ($POV_NOTE)}
EOF
  [ -n "$MISS" ] && echo "- missing example files (not timed):$MISS"
  echo
  echo '```'
  echo "$TABLE"
  echo '```'
  echo
  echo "Columns: seconds; qcs wall = median whole-process wall time; render = qcs's own"
  echo "render time; Mray/s = (primary + shadow rays) / qcs wall; evals/ray and steps/ray ="
  echo "density evaluations and root-search steps (segments + polishing steps; for soft"
  echo "objects, polynomial solves) per ray;"
  echo "evals/rhit = density evaluations per ray hitting a rounded surface; pov/qcs ="
  echo "POV-Ray wall / qcs wall."
  echo
  echo '```'
  echo "$RATIOS"
  echo '```'
  echo
  echo "## Targets (issue 18)"
  echo
  echo "$TARGETS18"
  echo
  echo "The interpreter's targets: see the interpreter section below and bench/NOTES.md."
  if [ -n "$INTERP_SUMMARY" ]; then
    echo
    echo "## The interpreter against Hugs (issue 18)"
    echo
    echo "\`bash bench/interp.sh -n $REPS\`: the programs of \`bench/hugs/\` (NAME.qcs and"
    echo "NAME.hs), each run by qcs and then by \`runhugs\`, $REPS pairs; medians of"
    echo "whole-process wall time and of peak resident memory (max RSS)."
    echo
    echo '```'
    echo "$INTERP_SUMMARY"
    echo '```'
  fi
  echo
  echo "## Targets (issues 7 and 13)"
  echo
  echo "$TARGETS"
  echo
  echo "## Pictures at the prompt"
  echo
  echo "\`qcs --show --preview MODE --cells 100x32 --timings examples/figure12.qcs\`,"
  echo "drawn to a file (the encoding is timed, not a terminal); times from"
  echo "process start, medians of $PV_REPS runs."
  echo
  echo "$PREVIEW"
  if [ -n "$FRAMES_SUMMARY" ]; then
    echo
    echo "## Animation: one process against one a frame (issue 17)"
    echo
    echo "\`sh bench/frames.sh $THREADS\`: examples/lid.qcs at 160x100, frames 1-100, as one"
    echo "\`qcs --frames 1-100\` and as 100 runs of \`qcs --frames k-k --animation 1-100\`."
    echo
    echo '```'
    echo "$FRAMES_SUMMARY"
    echo '```'
  fi
  if [ -n "$TILES_SUMMARY" ]; then
    echo
    echo "## Tiles as separate processes against the whole (issue 17)"
    echo
    echo "\`sh bench/tiles.sh $THREADS\`: figure12 at 1920x1080 once, then as 16 tiles"
    echo "(\`--tile I/16\`), each a process of its own, merged by \`qcs merge\`."
    echo
    echo '```'
    echo "$TILES_SUMMARY"
    echo '```'
  fi
  if [ -n "$KIT_SUMMARY" ]; then
    echo
    echo "## Patterns at scale (issue 19)"
    echo
    echo "\`sh bench/kit.sh $THREADS\`: \`bench/grid1000.qcs\`, \`UnionAll (Grid (10, 10, 10) ...)\` of"
    echo "rounded unit cubes, 1000 objects in the BVH, at $SIZE; whole-process wall times."
    echo
    echo '```'
    echo "$KIT_SUMMARY"
    echo '```'
fi

  if [ -n "$MESH_SUMMARY" ]; then
    echo
    echo "## Meshing (issue 16)"
    echo
    echo "\`sh bench/mesh.sh\`: peak MB is the process's maximum resident set."
    echo
    echo "$MESH_SUMMARY"
  fi
  if [ -f bench/callgrind.csv ]; then
    echo
    echo "## Callgrind instruction counts (150x95, 1 thread)"
    echo
    echo '```'
    column -s, -t < bench/callgrind.csv 2>/dev/null || cat bench/callgrind.csv
    echo '```'
  fi
  if [ -f bench/NOTES.md ]; then echo; cat bench/NOTES.md; fi
} > "$MD.tmp" && mv "$MD.tmp" "$MD"
echo
echo "wrote $CSV and $MD"
