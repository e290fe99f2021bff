#!/bin/sh
# suite-mesh.sh: mesh and meshWith from the language, qcs -o FILE.stl,
# the errors (unbounded object named, bad tolerance, limit), no file left
# by a failure, and the STL read back by admesh (0 holes, 0 disconnected
# facets) when it is installed. Prints "ok NAME", "FAIL NAME: why" or
# "skip NAME: why".
QCS=${QCS:-./qcs}
top=$(pwd)
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT

cat > "$tmp/part.qcs" <<'Q'
hole = Shift (0.25, -0.5, 0.25) (Scale (0.5, 2, 0.5) UnitCube);
scene = Rounded 0.07 (Difference UnitCube hole);
mesh "ring.obj" (SetDifference UnitCube hole)
meshWith [Tolerance 0.03] "soft.stl" (SoftObject 0.5 [Key (0, 0, 0) 1 1, Key (0.5, 0, 0) 0.5 (-1)])
Q
if (cd "$tmp" && "$top/$QCS" part.qcs > out 2> err) && [ -s "$tmp/ring.obj" ] && [ -s "$tmp/soft.stl" ] &&
   grep -q "certified <=" "$tmp/err" &&
   grep -q "checked: no self-intersections, [0-9]* triangle pairs tested exactly" "$tmp/err" &&
   grep -q "topology: 1 component, Euler characteristic 0 (genus 1 in all)" "$tmp/err" &&
   grep -q "topology: 1 component, Euler characteristic 2 (genus 0 in all)" "$tmp/err" &&
   grep -q "surface to mesh: every part proven within 0.0001 of the mesh (0 smooth cells by 0 columns, the rest by 0 boxes" "$tmp/err" &&
   grep -q "surface to mesh: every part proven within 0.03 of the mesh ([1-9][0-9]* smooth cells by [1-9][0-9]* columns" "$tmp/err"; then
  echo "ok mesh: mesh and meshWith write .obj and .stl with a report (the topology's, the self-intersection check's and the surface-to-mesh proof's lines too: the cube with a hole genus 1, the soft pair genus 0)"
else echo "FAIL mesh: mesh/meshWith: $(head -c 300 "$tmp/err" | tr '\n' ' ')"; fi
if grep -q '^vn ' "$tmp/ring.obj" && grep -q '^f [0-9]*//[0-9]*' "$tmp/ring.obj"; then
  echo "ok mesh: .obj has vertex normals"; else echo "FAIL mesh: .obj without normals"; fi

cat > "$tmp/scene.qcs" <<'Q'
hole = Shift (0.25, -0.5, 0.25) (Scale (0.5, 2, 0.5) UnitCube);
scene = Rounded 0.07 (Difference UnitCube hole);
Q
if (cd "$tmp" && "$top/$QCS" -o cli.stl scene.qcs > out 2> err) && [ -s "$tmp/cli.stl" ]; then
  echo "ok mesh: qcs -o part.stl meshes the scene"
else echo "FAIL mesh: -o part.stl: $(head -c 300 "$tmp/err" | tr '\n' ' ')"; fi

# qcs -o part.stl on a scene with a floor: refused, naming the floor and
# the command line's way to give a box; --bounds meshes the part inside
# it (the floor's slab below the raised cube: 2 components), and
# --mesh-tolerance is the tolerance the report proves
cat > "$tmp/floored.qcs" <<'Q'
cube = Shift (0, 0.5, 0) (Rounded 0.07 UnitCube);
floor = Halfspace ((0, 1, 0), 0);
scene = Union cube floor;
Q
if (cd "$tmp" && "$top/$QCS" -o fl.stl floored.qcs > out 2> err); then echo "FAIL mesh: -o part.stl meshed a floor"
elif grep -q "unbounded.*give --bounds X0,Y0,Z0,X1,Y1,Z1" "$tmp/err" && grep -q "floored.qcs:2:9" "$tmp/err" && [ ! -e "$tmp/fl.stl" ]; then
  echo "ok mesh: -o part.stl refuses a floor, naming it and --bounds"
else echo "FAIL mesh: -o part.stl with a floor: $(head -c 300 "$tmp/err" | tr '\n' ' ')"; fi
# the refusal suggests a box (the cube's, padded: the cube stands 0.5
# above the floor, so the box misses it), and that box meshes the cube
# alone, proven
sug=$(grep -o 'e\.g\. --bounds [-0-9.e,]*' "$tmp/err" | sed 's/^e\.g\. //')
if [ -n "$sug" ] && (cd "$tmp" && "$top/$QCS" -o sug.stl $sug floored.qcs > out 2> err) &&
   grep -q "topology: 1 component, Euler characteristic 2" "$tmp/err" &&
   grep -q "surface to mesh: every part proven" "$tmp/err"; then
  echo "ok mesh: the refusal suggests a box ($sug) that meshes the cube alone, proven"
else echo "FAIL mesh: the suggested box '$sug': $(head -c 300 "$tmp/err" | tr '\n' ' ')"; fi
# a rounded plate with the kit's holes standing on the floor (bracket.qcs's
# base): the suggested box's low face on the floor's plane, and through it
# the plate alone, genus 2; a script's meshWith gets the same box as Bounds
cat > "$tmp/plate.qcs" <<'Q'
plate = Rounded 0.04 (Difference (Box (0, 0, 0) (1.6, 0.18, 0.8))
          (DensityUnion (Shift (0.4, -0.5, 0.4) (Cylinder 0.1 1)) (Shift (1.2, -0.5, 0.4) (Cylinder 0.1 1))));
scene = Union plate (Halfspace ((0, 1, 0), 0));
Q
"$top/$QCS" -o "$tmp/plate.stl" "$tmp/plate.qcs" > "$tmp/out" 2> "$tmp/err"
sug=$(grep -o 'e\.g\. --bounds [-0-9.e,]*' "$tmp/err" | sed 's/^e\.g\. //')
if [ -n "$sug" ] && grep -q "its low y face on the unbounded part's plane" "$tmp/err" &&
   [ "$(echo "$sug" | cut -d, -f2)" = 0 ] &&
   (cd "$tmp" && "$top/$QCS" -o plate.stl $sug plate.qcs > out 2> err) &&
   grep -q "topology: 1 component, Euler characteristic -2 (genus 2" "$tmp/err" &&
   grep -q "surface to mesh: every part proven" "$tmp/err"; then
  echo "ok mesh: a rounded plate with two holes on the floor: the suggested box ($sug) from the floor's plane meshes the plate alone, genus 2, proven"
else echo "FAIL mesh: the plate on the floor '$sug': $(head -c 400 "$tmp/err" | tr '\n' ' ')"; fi
printf 'mesh "%s/plw.stl" scene\n' "$tmp" | cat "$tmp/plate.qcs" - > "$tmp/plw.qcs"
if ! "$top/$QCS" "$tmp/plw.qcs" > "$tmp/out" 2> "$tmp/err" && [ ! -e "$tmp/plw.stl" ] &&
   grep -q "give Bounds lo hi to mesh the part inside a box, e.g. Bounds (-0.[0-9]*, 0, -0.[0-9]*) (1.[0-9]*, 0.[0-9]*, 0.[0-9]*)" "$tmp/err"; then
  echo "ok mesh: meshWith's refusal suggests the box as Bounds lo hi"
else echo "FAIL mesh: meshWith's suggestion: $(head -c 300 "$tmp/err" | tr '\n' ' ')"; fi
if (cd "$tmp" && "$top/$QCS" -o fl.stl --bounds -1,-0.25,-1,2,2,2 --mesh-tolerance 0.02 floored.qcs > out 2> err) &&
   [ -s "$tmp/fl.stl" ] && grep -q "topology: 2 components" "$tmp/err" &&
   grep -q "requested 0.02;" "$tmp/err" && grep -q "surface to mesh: every part proven within 0.02 of the mesh" "$tmp/err"; then
  echo "ok mesh: -o part.stl --bounds --mesh-tolerance meshes the part inside the box at that tolerance (the floor's slab and the cube, 2 components, proven)"
else echo "FAIL mesh: --bounds/--mesh-tolerance: $(head -c 400 "$tmp/err" | tr '\n' ' ')"; fi
# a sharp cube on a slab of the floor: the box's faces are sharp planes,
# so the cut is exact: 28 triangles, volume 2.8 (1 + 3 x 0.2 x 3)
printf 'scene = Union UnitCube (Halfspace ((0, 1, 0), 0));\n' > "$tmp/slab2.qcs"
if (cd "$tmp" && "$top/$QCS" -o slab2.stl --bounds -1,-0.2,-1,2,2,2 slab2.qcs > out 2> err) &&
   grep -q "^qcs: mesh slab2.stl: 28 triangles" "$tmp/err" &&
   grep -q "surface to mesh: every part proven" "$tmp/err"; then
  echo "ok mesh: --bounds cutting a floor under a cube: the cut exact, 28 triangles"
else echo "FAIL mesh: the cut slab: $(head -c 300 "$tmp/err" | tr '\n' ' ')"; fi
# the box's low face in the floor's plane: the floor is left out, the
# cube alone is meshed and proven (before, the proof failed along the
# whole face)
if (cd "$tmp" && "$top/$QCS" -o fl0.stl --bounds -1,0,-1,2,2,2 --mesh-tolerance 0.02 floored.qcs > out 2> err) &&
   [ -s "$tmp/fl0.stl" ] && grep -q "topology: 1 component, Euler characteristic 2" "$tmp/err" &&
   grep -q "surface to mesh: every part proven within 0.02 of the mesh" "$tmp/err"; then
  echo "ok mesh: --bounds from the floor's plane up meshes the cube alone, proven"
else echo "FAIL mesh: --bounds on the floor's plane: $(head -c 400 "$tmp/err" | tr '\n' ' ')"; fi
bad=0
for a in "--mesh-tolerance 0" "--mesh-tolerance nan" "--mesh-tolerance 1e999" "--bounds 1,2,3" "--bounds 0,0,0,1,1,1," \
         "--bounds 0,0,0,0,1,1" "--bounds 0,0,0,1,inf,1" "--bounds x,0,0,1,1,1"; do
  # shellcheck disable=SC2086
  if (cd "$tmp" && "$top/$QCS" -o bad.stl $a floored.qcs > out 2> err) || [ -e "$tmp/bad.stl" ] ||
     ! grep -q "^qcs: error: --[a-z-]* needs" "$tmp/err"; then bad=1; echo "FAIL mesh: $a: $(head -c 200 "$tmp/err")"; fi
done
if (cd "$tmp" && "$top/$QCS" -o bad.png --bounds 0,0,0,1,1,1 floored.qcs > out 2> err) || [ -e "$tmp/bad.png" ] ||
   ! grep -q "is for a mesh: it needs -o FILE.stl" "$tmp/err"; then bad=1; echo "FAIL mesh: --bounds with a picture: $(head -c 200 "$tmp/err")"; fi
[ $bad = 0 ] && echo "ok mesh: bad --mesh-tolerance and --bounds values, and either without a mesh -o, are refused before anything runs"

printf 'floor = Halfspace ((0, 1, 0), 0);\nmesh "floor.stl" floor\n' > "$tmp/floor.qcs"
if (cd "$tmp" && "$top/$QCS" floor.qcs > out 2> err); then echo "FAIL mesh: a floor was meshed"
elif grep -q "unbounded" "$tmp/err" && grep -q "floor.qcs:1:" "$tmp/err" && [ ! -e "$tmp/floor.stl" ]; then
  echo "ok mesh: an unbounded floor is refused, naming it, no file"
else echo "FAIL mesh: floor error: $(head -c 300 "$tmp/err" | tr '\n' ' ')"; fi
printf 'meshWith [Bounds (-1, -1, -1) (1, 1, 1), Quiet] "slab.stl" (Halfspace ((0, 1, 0), 0))\n' > "$tmp/slab.qcs"
if (cd "$tmp" && "$top/$QCS" slab.qcs > out 2> err) && [ -s "$tmp/slab.stl" ]; then
  echo "ok mesh: a floor with Bounds is meshed"; else echo "FAIL mesh: Bounds: $(head -c 300 "$tmp/err")"; fi

for t in 0 "0/0" 1e-300; do
  printf 'meshWith [Tolerance (%s)] "t.stl" UnitCube\n' "$t" > "$tmp/tol.qcs"
  if (cd "$tmp" && "$top/$QCS" tol.qcs > out 2> err); then echo "FAIL mesh: tolerance $t accepted"
  elif grep -q "tolerance" "$tmp/err" && [ ! -e "$tmp/t.stl" ]; then echo "ok mesh: tolerance $t refused"
  else echo "FAIL mesh: tolerance $t: $(head -c 300 "$tmp/err" | tr '\n' ' ')"; fi
done
# a rod 0.03 thick beside a block, at a tolerance whose cells are 0.07
# wide: its cells split until each side of the rod is one sheet, so it is
# meshed (two parts, read back closed) and the report says so; a hair
# 1e-6 thick (under the deepest cell, 3.9e-5 here) is refused, naming it
cat > "$tmp/rod.qcs" <<'Q'
rod = Rounded 0.01 (Shift (2, 0, 0) (Scale (0.03, 0.03, 1.5) UnitCube));
meshWith [Tolerance 0.1] "rod.stl" (Union (Rounded 0.01 UnitCube) rod)
Q
if (cd "$tmp" && "$top/$QCS" rod.qcs > out 2> err) && [ -s "$tmp/rod.stl" ] &&
   grep -q "thin parts: [0-9]* cells split below the finest level" "$tmp/err"; then
  r=$(python3 tests/mesh_read.py "$tmp/rod.stl" 2>&1)
  case $r in
    *"parts=2 closed=1"*) echo "ok mesh: a rod thinner than a cell is meshed: $r" ;;
    *) echo "FAIL mesh: a rod thinner than a cell: $r" ;;
  esac
else echo "FAIL mesh: thin rod: $(head -c 300 "$tmp/err" | tr '\n' ' ')"; fi
# a gap 0.02 wide between two rounded cubes at cells 0.07 wide: two
# parts, not closed (one part on the branch that added this), every cell
# proven (no "two surfaces" line); figure12's obj5 (a rounded box resting
# flush on a rounded cube) meshed as one part, the cells along the end of
# the groove under the box's edge counted by the report
cat > "$tmp/gap.qcs" <<'Q'
meshWith [Tolerance 0.1] "gap.stl" (Union (Rounded 0.01 UnitCube) (Rounded 0.01 (Shift (1.02, 0, 0) UnitCube)))
meshWith [Tolerance 0.02] "obj5.stl" (Union (Rounded 0.07 UnitCube) (Rounded 0.07 (Shift (0.25, 1, 0.25) (Scale (0.5, 0.5, 0.5) UnitCube))))
Q
if (cd "$tmp" && "$top/$QCS" gap.qcs > out 2> err) && [ -s "$tmp/gap.stl" ] && [ -s "$tmp/obj5.stl" ] &&
   [ "$(grep -c "two surfaces: [0-9]* cells (side up to [0-9.e-]*, the finest level's)" "$tmp/err")" = 1 ]; then
  r=$(python3 tests/mesh_read.py "$tmp/gap.stl" 2>&1; python3 tests/mesh_read.py "$tmp/obj5.stl" 2>&1)
  case $r in
    *"parts=2 closed=1"*"parts=1 closed=1"*) echo "ok mesh: a gap thinner than a cell stays open, obj5 one part, the report counts obj5's groove cells" ;;
    *) echo "FAIL mesh: gap and obj5: $r" ;;
  esac
else echo "FAIL mesh: gap and obj5: $(head -c 400 "$tmp/err" | tr '\n' ' ')"; fi
# random scene 575 of the tests' generator: an island of a box about
# 0.002 across that the first cells (0.0045) miss; the round that proves
# every part has it, 5 parts for 2, and the report says the topology
# changed and gives the first mesh's (mesh_read.py counts the parts)
cat > "$tmp/island.qcs" <<'Q'
meshWith [Tolerance 0.03] "island.stl" (SetDifference (Union (Rounded 0.11596058744294679 (Rotate "x" 45.591 (Shift (0.234, -0.269, -0.349) (Scale (0.328, 0.701, 0.358) UnitCube)))) (Rotate "y" 30.408 (Shift (-0.004, 0.391, 0.403) (Scale (0.698, 0.474, 0.368) UnitCube)))) (SoftObject 0.5 [Key (0.479, 0.243, -0.367) 0.851 1, Key (0.120, -0.461, 0.338) 0.635 1, Key (0.449, 0.495, 0.351) 0.526 1, Key (-0.276, -0.455, -0.168) 0.524 (-1)]))
Q
if (cd "$tmp" && "$top/$QCS" island.qcs > out 2> err) && [ -s "$tmp/island.stl" ] &&
   grep -q "topology changed by the rounds: the mesh first made had 2 components, Euler characteristic -8" "$tmp/err" &&
   grep -q "surface to mesh: every part proven within" "$tmp/err"; then
  r=$(python3 tests/mesh_read.py "$tmp/island.stl" 2>&1)
  case $r in
    *"parts=5 closed=1"*) echo "ok mesh: an island smaller than the first cells is found by a round, which is kept and reported: $r" ;;
    *) echo "FAIL mesh: island: $r" ;;
  esac
else echo "FAIL mesh: island: $(head -c 600 "$tmp/err" | tr '\n' ' ')"; fi
printf 'meshWith [Tolerance 0.1] "hair.stl" (Union UnitCube (Rounded 0.0000001 (Shift (0, 2, 0) (Scale (20, 0.000001, 0.000001) UnitCube))))\n' > "$tmp/hair.qcs"
if (cd "$tmp" && "$top/$QCS" hair.qcs > out 2> err); then echo "FAIL mesh: a hair thinner than the deepest cell gave no error"
elif grep -q "hair.qcs:1:54: error: hair.stl: a part of the object is thinner than the finest cell the octree can make" "$tmp/err" &&
     [ ! -e "$tmp/hair.stl" ]; then echo "ok mesh: a hair thinner than the deepest cell is refused, naming it, no file"
else echo "FAIL mesh: hair: $(head -c 400 "$tmp/err" | tr '\n' ' ')"; fi
# max-memory bounds a mesh too. The peak resident memory of the whole
# process (python's getrusage over the child, independent of qcs's own
# count): B for a unit cube at 0.1 (the program and a tiny mesh), P for
# the mesh below, made without a limit; the growth G = P - B. With the
# limit at P the mesh is made; at 40M, where the octree alone takes 5M
# to 10M, it is refused before the crossings are sought, with qcs's
# estimate E ("would need about E"); at G / 2 it is refused; between E
# and G the estimate lets it start and the growth measured as the work
# goes on refuses it ("meshing took more than"); no file any time
peak() { python3 -c 'import resource, subprocess, sys
r = subprocess.run(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss if r.returncode == 0 else -1)' "$@"; }
limit_msg="(limit max-memory; raise it with :set max-memory SIZE or --max-memory SIZE)"
if [ ! -r /proc/self/statm ]; then
  echo "skip mesh: max-memory: no /proc/self/statm here, so qcs has no measure of its memory"
else
memexpr='meshWith [Tolerance 0.0005, Quiet] "mem.stl" (Rounded 0.1 UnitCube)'
base=$(cd "$tmp" && peak "$top/$QCS" --max-memory 0 -e 'meshWith [Tolerance 0.1, Quiet] "mem.stl" UnitCube')
pk=$(cd "$tmp" && peak "$top/$QCS" --max-memory 0 -e "$memexpr")
rm -f "$tmp/mem.stl"
est=-1 mid=-1
if [ "${base:--1}" -gt 0 ] && [ "${pk:--1}" -gt "$base" ] &&
   (cd "$tmp" && "$top/$QCS" --max-memory "$pk"K -e "$memexpr" > out 2> err) && [ -s "$tmp/mem.stl" ] &&
   rm -f "$tmp/mem.stl" &&
   ! (cd "$tmp" && "$top/$QCS" --max-memory 40M -e "$memexpr" > out 2> err) &&
   grep -q "the mesh would need about [0-9.]*M of memory, over 40M $limit_msg" "$tmp/err" &&
   [ ! -e "$tmp/mem.stl" ] &&
   est=$(sed -n 's/.*would need about \([0-9.]*\)M of memory.*/\1/p' "$tmp/err" | awk '{printf "%d", $1 * 1024}') &&
   mid=$(((est + pk - base) / 2)) && [ "$est" -lt "$((pk - base))" ] &&
   ! (cd "$tmp" && "$top/$QCS" --max-memory "$mid"K -e "$memexpr" > out 2> err) &&
   grep -q "meshing took more than [0-9.]*M of memory $limit_msg" "$tmp/err" &&
   [ ! -e "$tmp/mem.stl" ] &&
   ! (cd "$tmp" && "$top/$QCS" --max-memory "$(((pk - base) / 2))"K -e "$memexpr" > out 2> err) &&
   grep -q "$limit_msg" "$tmp/err" && [ ! -e "$tmp/mem.stl" ]; then
  echo "ok mesh: max-memory bounds a mesh: made under its peak ($pk KB), refused before the work under 40M (estimate $est KB), during it under $mid KB (growth $((pk - base)) KB), and under half the growth; no file any time"
else echo "FAIL mesh: max-memory (peak $pk KB, base $base KB, estimate $est KB, between $mid KB): $(head -c 400 "$tmp/err" | tr '\n' ' ')"; fi
# a later round over the limit is refused too (it kept the round before
# it and wrote the file): the island scene above grows about 5M in its
# first meshing and 7M with the round that finds the island
rm -f "$tmp/island.stl"
if ! (cd "$tmp" && "$top/$QCS" --max-memory 6M island.qcs > out 2> err) &&
   grep -q "$limit_msg" "$tmp/err" && [ ! -e "$tmp/island.stl" ]; then
  echo "ok mesh: max-memory refuses a round over it, with no file"
else echo "FAIL mesh: max-memory, a later round: $(head -c 400 "$tmp/err" | tr '\n' ' ')"; fi
fi
printf 'meshWith [MaxTriangles 1000] "big.stl" (Rounded 0.2 UnitCube)\n' > "$tmp/big.qcs"
if (cd "$tmp" && "$top/$QCS" big.qcs > out 2> err); then echo "FAIL mesh: MaxTriangles ignored"
elif grep -q "max-triangles" "$tmp/err" && [ ! -e "$tmp/big.stl" ]; then echo "ok mesh: MaxTriangles refuses, no file"
else echo "FAIL mesh: MaxTriangles: $(head -c 300 "$tmp/err" | tr '\n' ' ')"; fi

# .ply and .3mf: read back by tests/mesh_read.py (struct, zipfile, xml):
# closed by edge counting, and the two Colours of the parts kept
cat > "$tmp/col.qcs" <<'Q'
a = Colour (0.8, 0.1, 0.1) (Rounded 0.1 UnitCube);
b = Colour (0.1, 0.2, 0.9) (Shift (0.5, 0.5, 0.5) (Scale (0.7, 0.7, 0.7) UnitCube));
meshWith [Tolerance 0.02, Quiet] "col.ply" (Union a b)
meshWith [Tolerance 0.02, Quiet] "col.3mf" (Union a b)
Q
if (cd "$tmp" && "$top/$QCS" col.qcs > out 2> err); then
  for f in col.ply col.3mf; do
    r=$(python3 tests/mesh_read.py "$tmp/$f" 2>&1)
    case $r in
      *"closed=1 colours=2") echo "ok mesh: $f read back: closed, 2 colours ($r)" ;;
      *) echo "FAIL mesh: $f read back: $r" ;;
    esac
  done
else echo "FAIL mesh: .ply/.3mf: $(head -c 300 "$tmp/err" | tr '\n' ' ')"; fi
printf 'mesh "x.off" UnitCube\n' > "$tmp/ext.qcs"
if (cd "$tmp" && "$top/$QCS" ext.qcs > out 2> err); then echo "FAIL mesh: .off accepted"
elif grep -q "ext.qcs:1:1: .*\.stl, \.obj, \.ply or \.3mf" "$tmp/err" && [ ! -e "$tmp/x.off" ]; then
  echo "ok mesh: an unknown mesh extension is refused with the formats named"
else echo "FAIL mesh: .off: $(head -c 300 "$tmp/err" | tr '\n' ' ')"; fi

# OpenSCAD read-back: import() of qcs's STL rendered by OpenSCAD (z up:
# the model turned so that qcs's y is up) against qcs's own render of the
# object from the same camera, looking down a through hole (the background
# shows through it); the silhouettes must agree, and the same cube without
# the hole must not (the comparison can fail)
if command -v openscad > /dev/null 2>&1 && command -v xvfb-run > /dev/null 2>&1; then
  cat > "$tmp/os.qcs" <<'Q'
hole = Shift (0.25, -0.5, 0.25) (Scale (0.5, 2, 0.5) UnitCube);
obj = SetDifference (Rounded 0.07 UnitCube) hole;
view = [Size 300 200, Camera (1.2, 4, 1.6) (0.5, 0.5, 0.5) 22.5, Quiet];
meshWith [Tolerance 0.002, Quiet] "os.stl" obj
renderWith view "qcs.png" obj
renderWith view "full.png" (Rounded 0.07 UnitCube)
Q
  printf 'rotate([90, 0, 0]) import("os.stl");\n' > "$tmp/os.scad"
  if (cd "$tmp" && "$top/$QCS" os.qcs > out 2> err) &&
     (cd "$tmp" && xvfb-run -a openscad -o openscad.png --imgsize=300,200 \
        --camera=1.2,-1.6,4,0.5,-0.5,0.5 --projection=p os.scad > osout 2>&1) &&
     [ -s "$tmp/openscad.png" ]; then
    r=$(python3 tests/mesh_silhouette.py "$tmp/openscad.png" "$tmp/qcs.png" 0.99)
    if [ $? = 0 ]; then echo "ok mesh: OpenSCAD imports the STL: $r against qcs's render"
    else echo "FAIL mesh: OpenSCAD's picture of the STL: $r"; fi
    r=$(python3 tests/mesh_silhouette.py "$tmp/openscad.png" "$tmp/full.png" 0.99)
    if [ $? = 0 ]; then echo "FAIL mesh: the silhouette test passes a cube without its hole: $r"
    else echo "ok mesh: the silhouette test tells the cube without its hole apart ($r)"; fi
  else echo "FAIL mesh: OpenSCAD read-back: $(tail -c 300 "$tmp/osout" "$tmp/err" 2>/dev/null | tr '\n' ' ')"; fi
else
  echo "skip mesh: openscad or xvfb-run is not installed (apt-get install openscad xvfb)"
fi

# parts touching along an edge, parted so that the STL's floats keep
# them apart: admesh reads two parts of volume 2, every facet oriented;
# boxes overlapping by a sliver of 1e-9 (below the floats) warn that the
# STL is not the mesh that was checked, and the parted pair does not
printf 'scene = Union UnitCube (Shift (1, 1, 0) UnitCube)\n' > "$tmp/edge.qcs"
printf 'scene = Union UnitCube (Shift (0.999999999, 1, 0) UnitCube)\n' > "$tmp/sliver.qcs"
"$top/$QCS" -o "$tmp/edge.stl" "$tmp/edge.qcs" > "$tmp/out" 2> "$tmp/err.edge"
"$top/$QCS" -o "$tmp/sliver.stl" "$tmp/sliver.qcs" > "$tmp/out" 2> "$tmp/err.sliver"
if grep -q "^  pinches: 4 vertices" "$tmp/err.edge" && ! grep -q "warning" "$tmp/err.edge" &&
   grep -q "keeps floats, and 1 of the mesh's vertices falls" "$tmp/err.sliver"; then
  echo "ok mesh: two cubes edge to edge parted (4 vertices), no float warning; a 1e-9 sliver warns"
else echo "FAIL mesh: parting and the float warning: $(cat "$tmp/err.edge" "$tmp/err.sliver" | grep -E 'pinches|warning' | tr '\n' ' ')"; fi

# a prism's corner all but on another's face (tools/fuzz-prisms.py seed
# 41, s99): features 1e-16 wide that the floats join; the floats' mesh
# made one again (mesh_float.h) and checked: no warning, the report says
# so, and the STL and the PLY read back closed, in one part
printf '%s\n' 'scene = Rotate "z" 30.379 (Rotate "y" 38.114 (Rotate "z" 17.204 (Union (CylinderWith [Sides 6] 0.5 1) (Shift (0.8752892688256854,0,0) (Rotate "y" 12.0 (CylinderWith [Sides 15] 0.37528926882568536 1))))))' > "$tmp/corner.qcs"
"$top/$QCS" --mesh-tolerance 0.056 -o "$tmp/corner.stl" "$tmp/corner.qcs" > "$tmp/out" 2> "$tmp/err.corner"
"$top/$QCS" --mesh-tolerance 0.056 -o "$tmp/corner.ply" "$tmp/corner.qcs" > "$tmp/out" 2> "$tmp/err.cornerp"
r=$(python3 tests/mesh_read.py "$tmp/corner.stl" 2>&1; python3 tests/mesh_read.py "$tmp/corner.ply" 2>&1)
if grep -q "^  floats: 2 vertices that the file's floats put on another's place joined" "$tmp/err.corner" &&
   ! grep -q "warning" "$tmp/err.corner" "$tmp/err.cornerp" &&
   [ "$(printf '%s\n' "$r" | grep -c 'parts=1 closed=1')" = 2 ]; then
  echo "ok mesh: a corner all but on a face: the floats' mesh made one again (no warning); STL and PLY read back closed, one part"
else echo "FAIL mesh: the floats' mesh: $(grep -E 'floats|warning' "$tmp/err.corner" "$tmp/err.cornerp" | tr '\n' ' ') $r"; fi

if command -v admesh > /dev/null 2>&1; then
  admesh "$tmp/edge.stl" > "$tmp/adm" 2>&1
  if grep -q "Number of parts *: *2" "$tmp/adm" && grep -q "Facets reversed *: *0" "$tmp/adm" &&
     grep -q "Volume *: *1.99999" "$tmp/adm"; then
    echo "ok mesh: admesh reads the parted edge-to-edge cubes: 2 parts, volume 2, none reversed"
  else echo "FAIL mesh: admesh on the parted cubes: $(grep -iE 'parts|volume|reversed' "$tmp/adm" | tr '\n' ' ')"; fi
  for f in cli.stl soft.stl slab.stl plate.stl corner.stl; do
    admesh "$tmp/$f" > "$tmp/adm" 2>&1
    if grep -q "No holes need to be filled" "$tmp/adm" &&
       grep -q "Total disconnected facets *: *0 " "$tmp/adm"; then
      echo "ok mesh: admesh reads $f: 0 holes, 0 disconnected facets"
    else echo "FAIL mesh: admesh on $f: $(grep -iE 'holes|disconnected' "$tmp/adm" | tr '\n' ' ')"; fi
  done
else
  echo "skip mesh: admesh is not installed (apt-get install admesh)"
fi

# planes one plane but for rounding joined (two hexagonal prisms glued
# face to face, rotated: one part, the glued face gone, admesh reads one
# part); never a part's own two faces (a plate 2e-14 thick beside a cube
# is refused, as thinner than the finest cell, not deleted); never a
# Bounds face (a cube on a floor, the box's bottom 1e-16 above the
# floor's plane: the sharp cell kept, 12 triangles)
printf '%s\n' 'scene = Rotate "z" 12.5 (Union (Rotate "y" 30.0 (CylinderWith [Sides 6] 0.5 1)) (Shift (0.8660254037844387,0,0) (Rotate "y" 30.0 (CylinderWith [Sides 6] 0.5 1))))' > "$tmp/jglued.qcs"
printf '%s\n' 'scene = Union UnitCube (Shift (2,0,0) (Scale (1,0.00000000000002,1) UnitCube))' > "$tmp/jplate.qcs"
printf '%s\n' 'meshWith [Bounds (-0.5,0.0000000000000001,-0.5) (1.5,1.5,1.5)] "jfloor.stl" (Union UnitCube (Halfspace ((0,1,0), 0)))' > "$tmp/jfloor.qcs"
"$top/$QCS" -o "$tmp/jglued.stl" "$tmp/jglued.qcs" > "$tmp/out" 2> "$tmp/err.jglued"
"$top/$QCS" -o "$tmp/jplate.stl" "$tmp/jplate.qcs" > "$tmp/out" 2> "$tmp/err.jplate"; plate_rc=$?
(cd "$tmp" && "$top/$QCS" jfloor.qcs > out 2> err.jfloor)
if grep -q "^  planes joined: 1 plane within 2^-46" "$tmp/err.jglued" &&
   grep -q "topology: 1 component, Euler characteristic 2" "$tmp/err.jglued" &&
   [ $plate_rc -ne 0 ] && [ ! -e "$tmp/jplate.stl" ] && grep -q "thinner than the finest cell" "$tmp/err.jplate" &&
   grep -q "mesh jfloor.stl: 12 triangles" "$tmp/err.jfloor" && grep -q "1 sharp" "$tmp/err.jfloor" &&
   ! grep -q "planes joined" "$tmp/err.jfloor"; then
  echo "ok mesh: glued prisms' faces joined (one part); a 2e-14 plate refused, not deleted; a Bounds face 1e-16 off kept (12 triangles)"
else echo "FAIL mesh: joined planes: $(cat "$tmp/err.jglued" "$tmp/err.jplate" "$tmp/err.jfloor" | grep -E 'qcs: mesh|planes joined|topology|error' | tr '\n' ' ' | head -c 600)"; fi
if command -v admesh > /dev/null 2>&1 && [ -s "$tmp/jglued.stl" ]; then
  admesh "$tmp/jglued.stl" > "$tmp/adm" 2>&1
  if grep -q "Number of parts *: *1" "$tmp/adm" && grep -q "Facets reversed *: *0" "$tmp/adm" &&
     grep -q "Backwards edges *: *0" "$tmp/adm"; then
    echo "ok mesh: admesh reads the glued prisms as one part, none reversed"
  else echo "FAIL mesh: admesh on the glued prisms: $(grep -E 'parts|reversed|Backwards' "$tmp/adm" | tr '\n' ' ')"; fi
fi
