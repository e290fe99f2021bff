#!/bin/sh
# mesh.sh: meshing (issue 16). Prints a Markdown table:
#  - the twelve figure12 objects (examples/figure12.qcs, rounded, and
#    figure12-sharp.qcs) at a tolerance of 1e-3 of the object's size (its
#    largest side: 1 for obj1-4, 1.5 for obj5-6): triangles, seconds,
#    peak RSS;
#  - the triangles of a uniform grid of the same error (meshWith
#    [Uniform]: every surface cell at the finest level, marching
#    tetrahedra, no sharp cells), measured at 10x the tolerance and scaled
#    by 100 (triangles go as 1/tolerance^2; at 1e-3 itself the uniform
#    grid is 10^7 - 10^8 triangles);
#  - the teapot (examples/teapot.qcs, a soft object) at 0.002, about
#    1e-3 of its size, against its uniform grid the same way;
#  - UnitCube and Rounded 0.1 UnitCube at 1e-4 (peak RSS and time);
#  - with openscad installed: OpenSCAD's own STL export of the sharp
#    objects (the same CSG written as .scad, CGAL), side by side.
#   sh bench/mesh.sh        (QCS overrides ./qcs)
QCS=${QCS:-./qcs}
top=$(pwd)
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
defs() { sed -n '/^r *=/p;/^param r /p;/^box/p;/^obj/p' "$top/examples/$1.qcs"; }
# run NAME OBJ TOL [SETTING]: "triangles seconds peakKB"
run() {
  { defs "$4"; echo "meshWith [Tolerance $3, MaxTriangles 200000000$5] \"$tmp/m.stl\" ($2)"; } > "$tmp/m.qcs"
  /usr/bin/time -f "%e %M" -o "$tmp/time" "$QCS" "$tmp/m.qcs" > /dev/null 2> "$tmp/err" ||
    { echo "- - -"; return; }
  tri=$(sed -n 's/^qcs: mesh .*: \([0-9]*\) triangles.*/\1/p' "$tmp/err")
  echo "$tri $(cat "$tmp/time")"
}
echo "| object | tolerance | triangles | s | peak MB | uniform grid, same error (est.) | fewer |"
echo "|---|---|---|---|---|---|---|"
for v in figure12 figure12-sharp; do
  for i in 1 2 3 4 5 6; do
    size=1; [ $i -ge 5 ] && size=1.5
    tol=$(echo "$size * 0.001" | bc -l | sed 's/^\./0./')
    set -- $(run "$v obj$i" "obj$i" "$tol" "$v" "")
    tri=$1 s=$2 kb=$3
    u=$(run "$v obj$i" "obj$i" "$(echo "$tol * 10" | bc -l | sed 's/^\./0./')" "$v" ", Uniform")
    ut=$(echo "$u" | cut -d' ' -f1)
    est=$(echo "$ut * 100" | bc 2>/dev/null)
    fewer=$(echo "scale=0; $est / $tri" | bc 2>/dev/null)
    echo "| $v obj$i | $tol | $tri | $s | $((kb / 1024)) | $est | ${fewer}x |"
  done
done
# the teapot's five quadric keys (examples/teapot.qcs, soft, one negative
# key; about 2 across): soft cells are proven smooth by soft_grad_box
tea() { sed -n '/^body/,/^base/p' "$top/examples/teapot.qcs"; }
set -- $( { tea; echo "meshWith [Tolerance 0.002, MaxTriangles 200000000] \"$tmp/m.stl\" (SoftObject 0.5 [body, lid, knob, spout, base])"; } > "$tmp/t.qcs"
  /usr/bin/time -f "%e %M" -o "$tmp/time" "$QCS" "$tmp/t.qcs" > /dev/null 2> "$tmp/err" && \
  echo "$(sed -n 's/^qcs: mesh .*: \([0-9]*\) triangles.*/\1/p' "$tmp/err") $(cat "$tmp/time")" || echo "- - -")
tri=$1 s=$2 kb=$3
{ tea; echo "meshWith [Tolerance 0.02, MaxTriangles 200000000, Uniform] \"$tmp/m.stl\" (SoftObject 0.5 [body, lid, knob, spout, base])"; } > "$tmp/t.qcs"
ut=$("$QCS" "$tmp/t.qcs" 2>&1 >/dev/null | sed -n 's/^qcs: mesh .*: \([0-9]*\) triangles.*/\1/p')
est=$(echo "$ut * 100" | bc 2>/dev/null)
fewer=$(echo "scale=0; $est / $tri" | bc 2>/dev/null)
echo "| teapot (soft) | 0.002 | $tri | $s | $((kb / 1024)) | $est | ${fewer}x |"
for o in UnitCube "Rounded 0.1 UnitCube"; do
  set -- $(run "$o" "$o" 0.0001 figure12 "")
  echo "| $o | 0.0001 | $1 | $2 | $(($3 / 1024)) | | |"
done
if command -v openscad > /dev/null 2>&1 && command -v xvfb-run > /dev/null 2>&1; then
  echo
  echo "OpenSCAD $(openscad --version 2>&1 | sed 's/OpenSCAD version //') exporting the sharp figure12 objects as STL (CGAL), against qcs at 1e-3:"
  echo
  echo "| object | OpenSCAD triangles | OpenSCAD s | qcs triangles | qcs s |"
  echo "|---|---|---|---|---|"
  box1='translate([0.25, 0.8, 0.25]) cube([0.5, 0.5, 0.5])'
  box2='translate([0.25, 0.8, 0.25]) cube([0.5, 1.0, 0.5])'
  box3='translate([0.25, 1.0, 0.25]) cube([0.5, 0.5, 0.5])'
  for i in 1 3 5; do
    case $i in
      1) scad="difference() { cube(1); $box1; }" ;;
      3) scad="difference() { cube(1); $box2; }" ;;
      5) scad="union() { cube(1); $box3; }" ;;
    esac
    echo "$scad" > "$tmp/o.scad"
    t0=$(date +%s.%N)
    openscad -o "$tmp/o.stl" "$tmp/o.scad" > /dev/null 2>&1
    t1=$(date +%s.%N)
    ot=$(grep -c 'facet normal' "$tmp/o.stl" 2>/dev/null)
    size=1; [ $i -ge 5 ] && size=1.5
    set -- $(run "figure12-sharp obj$i" "obj$i" "$(echo "$size * 0.001" | bc -l | sed 's/^\./0./')" figure12-sharp "")
    echo "| obj$i | $ot | $(printf '%.2f' "$(echo "$t1 - $t0" | bc)") | $1 | $2 |"
  done
fi
