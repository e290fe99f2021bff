#!/bin/sh
# tsan.sh (make tsan): the threaded parts of qcs under ThreadSanitizer.
# QCS and QCS_UNIT_DIR name a -fsanitize=thread build (build-tsan). Runs
# the render and fast-path unit tests, every rendering example on 4
# threads, three meshes (the proofs' threads), the REPL, preview and viewer suites (the viewer: libmicrohttpd threads, the render thread, 10,000 requests from 50 clients); prints "ok NAME" / "FAIL NAME: why" lines
# and a closing "N passed, N failed". halt_on_error=1: the first report
# ends the program with status 66, which is a failure here.
cd "$(dirname "$0")/.." || exit 1
QCS=${QCS:-build-tsan/qcs}; export QCS
UNIT_DIR=${QCS_UNIT_DIR:-build-tsan/tests}
TSAN_OPTIONS="halt_on_error=1 exitcode=66 second_deadlock_stack=1 ${TSAN_OPTIONS:-}"
[ -f tools/tsan.supp ] && TSAN_OPTIONS="$TSAN_OPTIONS suppressions=$PWD/tools/tsan.supp"
export TSAN_OPTIONS
log=$(mktemp); tmp=$(mktemp -d); trap 'rm -rf "$log" "$tmp"' EXIT

for t in test_render test_fastpaths test_image; do
  if "$UNIT_DIR/$t" >"$tmp/$t.out" 2>&1; then echo "ok tsan/$t" >>"$log"
  else echo "FAIL tsan/$t: status $?: $(grep -m3 -E 'WARNING: ThreadSanitizer|FAIL|SUMMARY' "$tmp/$t.out" | tr '\n' ' ')" >>"$log"; fi
done
for f in examples/*.qcs; do
  grep -q -E '^[^/]*render(With)? ' "$f" || continue
  n=$(basename "$f" .qcs)
  if timeout 600 "$QCS" --threads 4 --size 120x76 -o "$tmp/$n.exr" "$f" >/dev/null 2>"$tmp/$n.err" </dev/null &&
     ! grep -q ThreadSanitizer "$tmp/$n.err"; then echo "ok tsan/example-$n" >>"$log"
  else echo "FAIL tsan/example-$n: $(grep -m3 -E 'ThreadSanitizer|error' "$tmp/$n.err" | tr '\n' ' ')" >>"$log"; fi
done
for a in "" --alpha; do
  if timeout 600 "$QCS" --threads 4 --size 300x190 $a -o "$tmp/png$a.png" examples/figure12.qcs >/dev/null 2>"$tmp/png.err" </dev/null &&
     ! grep -q ThreadSanitizer "$tmp/png.err"; then echo "ok tsan/png$a" >>"$log"
  else echo "FAIL tsan/png$a: $(grep -m3 -E 'ThreadSanitizer|error' "$tmp/png.err" | tr '\n' ' ')" >>"$log"; fi
done
# meshes: the cover proof's and the self-intersection check's threads
# (rounded, soft, and a mix of the two with a sharp box)
i=0
for o in 'Rounded 0.1 UnitCube' 'SoftObject 0.5 [Key (0, 0, 0) 1 1, Key (0.5, 0, 0) 0.5 (-1)]' \
         'SetDifference (Union (Rounded 0.1 UnitCube) (Shift (0.5, 0.5, 0.5) UnitCube)) (SoftObject 0.5 [Key (1, 1, 0.5) 0.7 1])'; do
  i=$((i + 1))
  if timeout 600 "$QCS" -e "meshWith [Tolerance 0.02] \"$tmp/m$i.stl\" ($o)" >/dev/null 2>"$tmp/m$i.err" </dev/null &&
     ! grep -q ThreadSanitizer "$tmp/m$i.err" && grep -q "surface to mesh" "$tmp/m$i.err"; then echo "ok tsan/mesh-$i" >>"$log"
  else echo "FAIL tsan/mesh-$i: $(grep -m3 -E 'ThreadSanitizer|error' "$tmp/m$i.err" | tr '\n' ' ')" >>"$log"; fi
done
for s in tests/suite-repl.sh tests/suite-preview.sh tests/suite-view.sh; do QCS_TSAN=1 sh "$s" 2>&1 | sed 's/^\(ok\|FAIL\|skip\) /\1 tsan\//' >>"$log"; done

grep -E '^(FAIL|skip) ' "$log"
passed=$(grep -c '^ok ' "$log"); failed=$(grep -c '^FAIL ' "$log")
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ] && [ "$passed" -gt 0 ]
