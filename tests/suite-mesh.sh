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
meshWith [Tolerance 0.03, Quiet] "soft.stl" (SoftObject 0.5 [Key (0, 0, 0) 1 1, Key (0.5, 0, 0) 0.5 (-1)])
Q
if (cd "$tmp" && "$top/$QCS" part.qcs > out 2> err) && [ -s "$tmp/ring.obj" ] && [ -s "$tmp/soft.stl" ] &&
   grep -q "certified <=" "$tmp/err"; then echo "ok mesh: mesh and meshWith write .obj and .stl with a report"
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
printf 'meshWith [MaxTriangles 1000] "big.stl" (Rounded 0.2 UnitCube)\n' > "$tmp/big.qcs"
if (cd "$tmp" && "$top/$QCS" big.qcs > out 2> err); then echo "FAIL mesh: MaxTriangles ignored"
elif grep -q "max-triangles" "$tmp/err" && [ ! -e "$tmp/big.stl" ]; then echo "ok mesh: MaxTriangles refuses, no file"
else echo "FAIL mesh: MaxTriangles: $(head -c 300 "$tmp/err" | tr '\n' ' ')"; fi

if command -v admesh > /dev/null 2>&1; then
  for f in cli.stl soft.stl slab.stl; do
    admesh "$tmp/$f" > "$tmp/adm" 2>&1
    if grep -q "No holes need to be filled" "$tmp/adm" &&
       grep -q "Total disconnected facets *: *0 " "$tmp/adm"; then
      echo "ok mesh: admesh reads $f: 0 holes, 0 disconnected facets"
    else echo "FAIL mesh: admesh on $f: $(grep -iE 'holes|disconnected' "$tmp/adm" | tr '\n' ' ')"; fi
  done
else
  echo "skip mesh: admesh is not installed (apt-get install admesh)"
fi
