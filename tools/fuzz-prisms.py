#!/usr/bin/env python3
"""fuzz-prisms.py: two many-sided prisms that touch, meshed by qcs.

Issue 16's hardest inputs: two `CylinderWith [Sides n]` prisms corner to
corner (Shift r1 + r2; an odd prism on the right turned by 180/n so a
corner faces the other) or a corner on a face (Shift r1 + r2 cos(pi/n2),
the right prism's face towards the left), the pair turned about one to
three axes by random or round angles, meshed at a tolerance of 0.01 to
0.04 of its size. Such pairs meet along a line (or at a point), where
the corners' faces are all but in one plane: the exact points where they
meet spread along the line.

Each scene is meshed by `qcs -o x.stl`; a scene fails when qcs refuses
it, gives up sharp cells or the flat regions' second triangulation (the
report says so), warns (an STL whose floats join vertices), takes more triangles than the prisms alone (4 n - 4
each) plus 16, or its genus is not 0. Run from the repository's root:

  python3 tools/fuzz-prisms.py --seed 41 --count 400 --sides 3-24
  python3 tools/fuzz-prisms.py --seed 42 --count 200 --sides 20-80 -j 2

prints one line per failing scene (its seed index, why, and the
scene's source) and a summary; --keep DIR writes the failing scenes as
.qcs files there. Not part of `make test` (a few minutes a hundred
scenes); bench/NOTES.md records the sets run and what they found.
"""
import argparse
import math
import os
import random
import re
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor


def scene(rng, lo, hi):
    n1, n2 = rng.randint(lo, hi), rng.randint(lo, hi)
    r1 = 0.5
    f = rng.choice([1.0, 1.0, 0.6, rng.uniform(0.6, 1.0)])
    r2 = r1 * f
    if rng.random() < 0.7:  # corner to corner
        dx = r1 + r2
        turn = 180.0 / n2 if n2 % 2 else 0.0
    else:  # the left prism's corner on the right one's face
        dx = r1 + r2 * math.cos(math.pi / n2)
        turn = 0.0 if n2 % 2 else 180.0 / n2
    right = "CylinderWith [Sides %d] %r 1" % (n2, r2)
    if turn:
        right = 'Rotate "y" %r (%s)' % (turn, right)
    obj = "Union (CylinderWith [Sides %d] %r 1) (Shift (%r,0,0) (%s))" % (n1, r1, dx, right)
    for _ in range(rng.randint(1, 3)):
        ax = rng.choice("xyz")
        ang = rng.choice([rng.uniform(-60, 60), float(rng.choice([7, 15, 20, 30, 45, 60]))])
        ang = round(ang, 3) if rng.random() < 0.5 else ang
        obj = 'Rotate "%s" %s (%s)' % (ax, repr(ang) if ang >= 0 else "(%r)" % ang, obj)
    tol = round(rng.uniform(0.01, 0.04), 3)
    return n1, n2, obj, tol


def run(qcs, idx, n1, n2, obj, tol, timeout):
    with tempfile.TemporaryDirectory() as d:
        src = os.path.join(d, "s.qcs")
        stl = os.path.join(d, "s.stl")
        size = 2.0 + 0.0  # the pair spans about 2 (x) by 1 (y)
        with open(src, "w") as fh:
            fh.write("scene = %s\n" % obj)
        try:
            p = subprocess.run([qcs, "--mesh-tolerance", repr(tol * size), "-o", stl, src],
                               capture_output=True, text=True, timeout=timeout)
        except subprocess.TimeoutExpired:
            return "timeout"
        rep = p.stdout + p.stderr
        if p.returncode != 0 or not os.path.exists(stl):
            m = re.search(r"qcs: (.*)", rep)
            return "refused: " + (m.group(1)[:160] if m else "rc %d" % p.returncode)
        why = []
        if "given up" in rep:
            why.append("sharp cells given up")
        if "the mesh as made was kept" in rep:
            why.append("flat regions not triangulated again (their mesh failed a check)")
        m = re.search(r"warning: \S+ (.*)", rep)
        if m:
            why.append("warning: " + m.group(1)[:100])
        m = re.search(r"mesh \S+: (\d+) triangles", rep)
        nt = int(m.group(1)) if m else -1
        want = 4 * n1 - 4 + 4 * n2 - 4
        g = re.search(r"\(genus (\d+) in all\)", rep)
        genus = int(g.group(1)) if g else -1
        if genus != 0:
            why.append("genus %d, %d triangles" % (genus, nt))
        elif nt > want + 16:
            why.append("%d triangles (the prisms alone %d)" % (nt, want))
        if why:
            return "; ".join(why)
    return None


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seed", type=int, default=41)
    ap.add_argument("--count", type=int, default=100)
    ap.add_argument("--sides", default="3-24")
    ap.add_argument("--qcs", default="./qcs")
    ap.add_argument("--timeout", type=float, default=120)
    ap.add_argument("--only", default="", help="comma-separated indices to run")
    ap.add_argument("--keep", default="", help="write failing scenes to this directory")
    ap.add_argument("-j", type=int, default=1)
    a = ap.parse_args()
    lo, hi = (int(x) for x in a.sides.split("-"))
    rng = random.Random(a.seed)
    cases = [(i,) + scene(rng, lo, hi) for i in range(a.count)]
    if a.only:
        keep = {int(x) for x in a.only.split(",")}
        cases = [c for c in cases if c[0] in keep]
    if a.keep:
        os.makedirs(a.keep, exist_ok=True)

    def one(c):
        return c, run(a.qcs, *c, a.timeout)

    bad = 0
    with ThreadPoolExecutor(max_workers=a.j) as ex:
        for (i, n1, n2, obj, tol), why in ex.map(one, cases):
            if why is None:
                continue
            bad += 1
            print("s%d %d/%d tol %g: %s\n  %s" % (i, n1, n2, tol, why, obj), flush=True)
            if a.keep:
                with open(os.path.join(a.keep, "s%d.qcs" % i), "w") as fh:
                    fh.write("// fuzz-prisms --seed %d --sides %s s%d (tol %g of 2): %s\n"
                             "scene = %s\n" % (a.seed, a.sides, i, tol, why, obj))
    print("# seed %d, sides %s: %d scenes, %d failing" % (a.seed, a.sides, len(cases), bad))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
