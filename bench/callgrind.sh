#!/bin/bash
# bench/callgrind.sh -- `make bench-callgrind`: instructions executed by qcs per
# canonical scene at a small size (150x95), one thread, under
# valgrind --tool=callgrind. Instruction counts are repeatable on a noisy
# machine, so a regression shows as a larger count. Writes bench/callgrind.csv
# and prints each count against the one in the previous bench/callgrind.csv.
# Where the instructions go: every function's own (exclusive) count per scene,
# from callgrind_annotate, goes to bench/callgrind-functions.csv, and each
# scene's top functions are printed against the previous file's counts, so a
# gain or a loss shows the functions it came from (CG_TOP of them, 8 unless
# told).
# Environment: QCS (./qcs), CG_SIZE (150x95), OUT (/tmp/qcs-bench).
set -u
cd "$(dirname "$0")/.." || exit 1
QCS=${QCS:-./qcs}; SIZE=${CG_SIZE:-150x95}; OUT=${OUT:-/tmp/qcs-bench}/callgrind
mkdir -p "$OUT"
command -v valgrind >/dev/null || { echo "callgrind: valgrind is not installed (Debian package valgrind): skipped"; exit 1; }
[ $# -eq 0 ] && set -- figure12 figure12-sharp figure13 figure15a figure15b \
  soft-cloud-10 soft-cloud-100 soft-cloud-1000 soft-cloud-10000 soft-cloud-100000
TOP=${CG_TOP:-8}
declare -A PREV PREVF
if [ -f bench/callgrind.csv ]; then
  while IFS=, read -r s n _; do PREV[$s]=$n; done < bench/callgrind.csv
fi
if [ -f bench/callgrind-functions.csv ]; then
  while IFS=, read -r s f n; do PREVF[$s/$f]=$n; done < bench/callgrind-functions.csv
fi
echo "scene,function,instructions" > bench/callgrind-functions.csv.tmp
# functions(out): "count function" per line, the function's own instructions,
# with gcc's clone suffixes (.constprop.0, .isra.0, .part.0) folded into the
# function they were cloned from, the file name dropped, and a library
# without symbols counted as one (libgc(no symbols)).
functions() {
  callgrind_annotate --inclusive=no --auto=no --threshold=100 "$1" 2>/dev/null |
    awk '/^ *[0-9,]+ .*:/ {
           n = $1; gsub(",", "", n)
           f = $0; sub(/^ *[0-9,]+ (\([^)]*\) )?/, "", f)
           lib = ""; if (match(f, /\[[^]]*\]$/)) lib = substr(f, RSTART + 1, RLENGTH - 2)
           sub(/ \[.*$/, "", f); sub(/^.*:/, "", f)
           # a library without symbols (libgc): its name instead of an address
           if (f ~ /^0x/) { sub(/^.*\//, "", lib); sub(/\.so.*$/, "", lib); f = lib "(no symbols)" }
           sub(/\.(constprop|isra|part|cold)\..*$/, "", f)
           sub(/\.(constprop|isra|part|cold)\..*$/, "", f)
           c[f] += n
         }
         END { for (f in c) print c[f], f }' | sort -k1,1nr
}
echo "scene,instructions,size,threads,commit" > bench/callgrind.csv.tmp
commit=$(git rev-parse --short HEAD 2>/dev/null)
printf '%-18s %16s %10s\n' scene "Ir (callgrind)" "vs prev"
for s in "$@"; do
  case $s in
    soft-cloud-*) f=examples/soft-cloud.qcs; args="--set n=${s#soft-cloud-}" ;;
    *) f=examples/$s.qcs; args="" ;;
  esac
  [ -f "$f" ] || { echo "missing: $s ($f)"; continue; }
  # shellcheck disable=SC2086
  valgrind --tool=callgrind --callgrind-out-file="$OUT/$s.out" "$QCS" --threads 1 \
    --size "$SIZE" -o "$OUT/$s.png" $args "$f" > "$OUT/$s.log" 2>&1
  ir=$(grep -o 'Collected : [0-9]*' "$OUT/$s.log" | awk '{ print $3 }')
  [ -n "$ir" ] || { echo "FAILED: $s (see $OUT/$s.log)"; continue; }
  prev=${PREV[$s]:-}
  rel=$(awk -v a="$ir" -v b="$prev" 'BEGIN { if (b == "" || b + 0 == 0) print "-"; else printf "%+.1f%%", (a / b - 1) * 100 }')
  printf '%-18s %16s %10s\n' "$s" "$ir" "$rel"
  echo "$s,$ir,$SIZE,1,$commit" >> bench/callgrind.csv.tmp
  functions "$OUT/$s.out" > "$OUT/$s.functions"
  awk -v s="$s" '{ print s "," $2 "," $1 }' "$OUT/$s.functions" >> bench/callgrind-functions.csv.tmp
  head -n "$TOP" "$OUT/$s.functions" | while read -r n f; do
    p=${PREVF[$s/$f]:-}
    d=$(awk -v a="$n" -v b="$p" 'BEGIN { if (b == "") print "new"; else printf "%+d", a - b }')
    printf '    %-32s %14s %6.2f%% %14s\n' "$f" "$n" "$(awk -v a="$n" -v t="$ir" 'BEGIN { print 100 * a / t }')" "$d"
  done
done
# scenes not run this time keep their previous rows
ran=" $* "
if [ -f bench/callgrind.csv ]; then
  tail -n +2 bench/callgrind.csv | while IFS=, read -r s rest; do
    case $ran in *" $s "*) ;; *) echo "$s,$rest" >> bench/callgrind.csv.tmp ;; esac
  done
fi
if [ -f bench/callgrind-functions.csv ]; then
  tail -n +2 bench/callgrind-functions.csv | while IFS=, read -r s rest; do
    case $ran in *" $s "*) ;; *) echo "$s,$rest" >> bench/callgrind-functions.csv.tmp ;; esac
  done
fi
mv bench/callgrind.csv.tmp bench/callgrind.csv
mv bench/callgrind-functions.csv.tmp bench/callgrind-functions.csv
echo "wrote bench/callgrind.csv and bench/callgrind-functions.csv"
