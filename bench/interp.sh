#!/bin/bash
# bench/interp.sh -- the interpreter against Hugs 98 (issue 18): the same
# programs written in qcs and in Haskell (bench/hugs/NAME.qcs, NAME.hs), run
# as whole processes, paired (qcs then runhugs, REPS times, so both see the
# same load), whole-process wall time and peak resident memory (max RSS,
# /usr/bin/time). Medians of each. Also `length [1 .. 10^7]` by qcs alone
# for the absolute target. Writes bench/interp.csv and prints a table with
# the targets: every case at least 3x faster than Hugs, peak memory within
# 2x of Hugs' on the streaming cases, length [1 .. 10^7] under 1 s in under
# 50 MB. Wall times on a shared machine are noisy; max RSS is not.
# The cases are issue 18's list: length, foldl, comprehension, pipeline
# (a map/filter/zipWith pipeline of 10^5), fib, strings (a string built by
# ++ from 3000 numbers), keys (10^5 soft-object keys built as
# examples/soft-cloud.qcs builds them) and tree (a 1000-deep scene tree
# moved by the prelude's Shift, 200 times). GHCi is not run: Debian's ghc
# installs 776 MB, more than the bench's set-up should fetch for one column.
# Usage: bench/interp.sh [-n REPS] [CASE ...]   (default 5; all cases)
# Environment: QCS (./qcs), HUGS (runhugs).
set -u
cd "$(dirname "$0")/.." || exit 1
REPS=5
while getopts "n:" opt; do
  case $opt in
    n) REPS=$OPTARG ;;
    *) sed -n '2,13p' "$0"; exit 2 ;;
  esac
done
shift $((OPTIND - 1))
QCS=${QCS:-./qcs}; HUGS=${HUGS:-runhugs}
CSV=bench/interp.csv
[ $# -eq 0 ] && set -- length foldl comprehension pipeline fib strings keys tree
# the cases whose list is consumed as it is made: memory within 2x of Hugs
STREAMING=" length foldl comprehension pipeline "
TIMEF=/usr/bin/time
[ -x "$TIMEF" ] || { echo "interp: /usr/bin/time is missing (Debian package time): skipped"; exit 1; }
[ -x "$QCS" ] || { echo "interp: $QCS not built" >&2; exit 1; }
HAVE_HUGS=1
command -v "$HUGS" >/dev/null 2>&1 || { HAVE_HUGS=0; echo "interp: $HUGS is not installed (Debian package hugs): qcs alone"; }
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT

median() { sort -g | awk '{ v[NR] = $1 } END { if (NR == 0) print "-"; else printf "%.4g\n", (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
# run1 OUTFILE CMD...: appends "seconds maxrss_kb" of one run to OUTFILE
run1() {
  local out=$1; shift
  if "$TIMEF" -f '%e %M' -o "$tmp/t" "$@" > "$tmp/stdout" 2> "$tmp/stderr"; then
    cat "$tmp/t" >> "$out"
  else
    echo "interp: failed: $* ($(head -c 200 "$tmp/stderr"))" >&2
  fi
}

echo "case,reps,qcs_s_median,qcs_s_min,qcs_rss_mb_median,hugs_s_median,hugs_s_min,hugs_rss_mb_median,hugs_over_qcs_time,qcs_over_hugs_rss" > "$CSV.tmp"
printf '%-14s %9s %9s %9s %9s %9s %9s\n' case "qcs s" "qcs MB" "hugs s" "hugs MB" "hugs/qcs" "mem q/h"
VERDICTS=""
for c in "$@"; do
  q=bench/hugs/$c.qcs; h=bench/hugs/$c.hs
  [ -f "$q" ] && [ -f "$h" ] || { echo "missing: $c"; continue; }
  # the answers must agree before anything is timed (qcs prints Reals
  # without a fraction as whole numbers, Haskell's Integers likewise)
  if [ $HAVE_HUGS = 1 ]; then
    a=$("$QCS" "$q" 2>&1 | tr -d '"'); b=$("$HUGS" "$h" 2>&1)
    [ "$a" = "$b" ] || { echo "interp: $c: qcs and Hugs disagree: $(echo "$a" | head -c 80) / $(echo "$b" | head -c 80)" >&2; continue; }
  fi
  : > "$tmp/q"; : > "$tmp/h"
  for ((i = 0; i < REPS; i++)); do
    run1 "$tmp/q" "$QCS" "$q"
    [ $HAVE_HUGS = 1 ] && run1 "$tmp/h" "$HUGS" "$h"
  done
  qs=$(awk '{ print $1 }' "$tmp/q" | median); qmin=$(awk '{ print $1 }' "$tmp/q" | sort -g | head -1)
  qm=$(awk '{ print $2 / 1024 }' "$tmp/q" | median)
  hs=-; hmin=-; hm=-; r=-; mr=-
  if [ -s "$tmp/h" ]; then
    hs=$(awk '{ print $1 }' "$tmp/h" | median); hmin=$(awk '{ print $1 }' "$tmp/h" | sort -g | head -1)
    hm=$(awk '{ print $2 / 1024 }' "$tmp/h" | median)
    r=$(awk -v a="$hs" -v b="$qs" 'BEGIN { printf "%.2f", a / (b > 0 ? b : 0.001) }')
    mr=$(awk -v a="$qm" -v b="$hm" 'BEGIN { printf "%.2f", a / b }')
  fi
  printf '%-14s %9s %9s %9s %9s %9s %9s\n' "$c" "$qs" "$qm" "$hs" "$hm" "$r" "$mr"
  echo "$c,$REPS,$qs,$qmin,$qm,$hs,$hmin,$hm,$r,$mr" >> "$CSV.tmp"
  v=$(awk -v r="$r" 'BEGIN { print (r == "-") ? "not measured" : (r >= 3 ? "met" : "NOT met") }')
  VERDICTS="$VERDICTS| $c at least 3x faster than Hugs | $r | $v |
"
  case $STREAMING in *" $c "*)
    v=$(awk -v r="$mr" 'BEGIN { print (r == "-") ? "not measured" : (r <= 2 ? "met" : "NOT met") }')
    VERDICTS="$VERDICTS| $c peak memory within 2x of Hugs' | qcs / Hugs = $mr | $v |
"
  esac
done

# length [1 .. 10^7], qcs alone (Hugs takes minutes)
echo 'length [1 .. 10000000]' > "$tmp/l7.qcs"
: > "$tmp/l7"
for ((i = 0; i < REPS; i++)); do run1 "$tmp/l7" "$QCS" "$tmp/l7.qcs"; done
l7s=$(awk '{ print $1 }' "$tmp/l7" | median); l7m=$(awk '{ print $2 / 1024 }' "$tmp/l7" | median)
printf '%-14s %9s %9s\n' "length 10^7" "$l7s" "$l7m"
echo "length-1e7,$REPS,$l7s,$(awk '{ print $1 }' "$tmp/l7" | sort -g | head -1),$l7m,-,-,-,-,-" >> "$CSV.tmp"
mv "$CSV.tmp" "$CSV"
v=$(awk -v s="$l7s" -v m="$l7m" 'BEGIN { print (s < 1 && m < 50) ? "met" : "NOT met" }')
echo
echo "| target | measured | verdict |"
echo "|---|---|---|"
printf '%s' "$VERDICTS"
echo "| length [1 .. 10^7] under 1 s in under 50 MB | $l7s s, $l7m MB | $v |"
echo
echo "(medians of $REPS paired runs; wall seconds, peak RSS in MB; wrote $CSV)"
