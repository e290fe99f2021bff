#!/usr/bin/env python3
"""geometry.py: the modeller's kit (stdlib/kit.qcs) against independent
geometry (issue 19).

For every solid, transform and pattern, inside/outside is computed here
from the definition, not from the kit's planes: polygons and pyramids
from their vertices, the Platonic solids as the hulls of their classical
vertex sets (faces found by brute force over vertex triples; the
dodecahedron as the dual of the icosahedron), spheres from distances,
transforms by mapping the point back with the inverse map (Gauss-Jordan
for matrices, the reflection and Rodrigues-free quaternion turns for
mirrors and rotations), patterns as "some copy contains the point".
Random points (fixed seed) are asked of qcs's PointInObject in one
script; points closer to a boundary than 1e-7 are not asked.
Rounded objects under rigid maps are compared through Density at the
point against Density of the untransformed tree at the mapped-back point.

Usage: geometry.py QCS [--points N] [--seed S]. Prints "ok NAME" or
"FAIL NAME: why" per case; exit status 1 if any failed.
"""
import math
import random
import subprocess
import sys
import tempfile
import os

EPS = 1e-7
PHI = (1 + math.sqrt(5)) / 2


# ---- vectors ----

def sub(a, b): return tuple(x - y for x, y in zip(a, b))
def add(a, b): return tuple(x + y for x, y in zip(a, b))
def mul(a, k): return tuple(x * k for x in a)
def dot(a, b): return sum(x * y for x, y in zip(a, b))
def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
def norm(a): return math.sqrt(dot(a, a))
def unit(a): return mul(a, 1 / norm(a))


# ---- inside tests with a margin: (inside?, distance to the boundary) ----
# A predicate returns a signed margin: > 0 inside, < 0 outside, its size a
# lower bound on how far the point is from the boundary (roughly).

def polygon_margin(verts2, q):
    """verts2 counter-clockwise in the plane; q a 2-point."""
    m = float("inf")
    n = len(verts2)
    for k in range(n):
        a, b = verts2[k], verts2[(k + 1) % n]
        e = (b[0] - a[0], b[1] - a[1])
        # left of the edge is inside (counter-clockwise)
        c = (e[0] * (q[1] - a[1]) - e[1] * (q[0] - a[0])) / math.hypot(*e)
        m = min(m, c)
    return m


def regular_polygon(n, r):
    """Vertices on the circle of radius r in the (x, z) plane, one on +x,
    counter-clockwise (so that the polygon test's 'left' is inside)."""
    return [(r * math.cos(2 * math.pi * k / n), r * math.sin(2 * math.pi * k / n)) for k in range(n)]


def prism_margin(n, r, h, p):
    x, y, z = p
    return min(polygon_margin(regular_polygon(n, r), (x, z)), y, h - y)


def pyramid_margin(n, r, h, p):
    x, y, z = p
    if y <= 0:
        return y
    if y >= h:
        return h - y
    s = 1 - y / h           # the cross-section is the base scaled by s
    pm = polygon_margin(regular_polygon(n, r * s), (x, z))
    # a margin in the slanted direction is smaller: scale by the slope
    return min(y, pm * h / math.hypot(h, r))


def sides_for(r, tol):
    """The fewest sides whose polygon strays at most tol inside the circle."""
    n = 3
    while r * (1 - math.cos(math.pi / n)) > tol and n < 1024:
        n += 1
    return n


def hull_faces(verts):
    """Faces of the convex hull of verts: planes (unit n, d) through three
    vertices with every vertex on the side n . v <= d."""
    faces = []
    m = len(verts)
    for i in range(m):
        for j in range(i + 1, m):
            for k in range(j + 1, m):
                n = cross(sub(verts[j], verts[i]), sub(verts[k], verts[i]))
                if norm(n) < 1e-9:
                    continue
                n = unit(n)
                d = dot(n, verts[i])
                s = [dot(n, v) - d for v in verts]
                if all(x <= 1e-9 for x in s):
                    pass
                elif all(x >= -1e-9 for x in s):
                    n, d = mul(n, -1), -d
                else:
                    continue
                if not any(abs(dot(n, f[0]) - 1) < 1e-9 and abs(d - f[1]) < 1e-9 for f in faces):
                    faces.append((n, d))
    return faces


def signs(v):
    out = [()]
    for c in v:
        out = [o + (s,) for o in out for s in ([c] if c == 0 else [c, -c])]
    return out


def cyclic(v):
    x, y, z = v
    return [(x, y, z), (z, x, y), (y, z, x)]


def on_unit_sphere(vs):
    return [unit(v) for v in vs]


ICOSA = on_unit_sphere([w for v in cyclic((0, 1, PHI)) for w in signs(v)])
ICOSA_FACES = hull_faces(ICOSA)
# the dodecahedron: the icosahedron's face centres, on the unit sphere
DODECA = on_unit_sphere([
    mul(add(add(*[v for v in ICOSA if abs(dot(n, v) - d) < 1e-9][:2]),
            [v for v in ICOSA if abs(dot(n, v) - d) < 1e-9][2]), 1 / 3)
    for n, d in ICOSA_FACES])
PLATONIC = {
    "Tetrahedron": on_unit_sphere([(1, 1, 1), (1, -1, -1), (-1, 1, -1), (-1, -1, 1)]),
    "Hexahedron": on_unit_sphere(signs((1, 1, 1))),
    "Octahedron": on_unit_sphere([w for v in cyclic((1, 0, 0)) for w in signs(v)]),
    "Dodecahedron": DODECA,
    "Icosahedron": ICOSA,
}
FACE_COUNT = {"Tetrahedron": 4, "Hexahedron": 6, "Octahedron": 8, "Dodecahedron": 12,
              "Icosahedron": 20}


def faces_margin(faces, p):
    return min(d - dot(n, p) for n, d in faces)


# ---- maps ----

def inverse3x4(m):
    """The inverse of x -> L x + t, by Gauss-Jordan on [L | I]."""
    a = [list(m[i][:3]) + [1.0 if i == j else 0.0 for j in range(3)] for i in range(3)]
    for c in range(3):
        piv = max(range(c, 3), key=lambda r: abs(a[r][c]))
        a[c], a[piv] = a[piv], a[c]
        pv = a[c][c]
        a[c] = [x / pv for x in a[c]]
        for r in range(3):
            if r != c:
                f = a[r][c]
                a[r] = [x - f * y for x, y in zip(a[r], a[c])]
    li = [row[3:] for row in a]
    t = (m[0][3], m[1][3], m[2][3])
    return lambda y: tuple(dot(li[i], sub(y, t)) for i in range(3))


def reflect(n, d):
    """The reflection in n . x = d (its own inverse)."""
    q = dot(n, n)
    return lambda p: sub(p, mul(n, 2 * (dot(n, p) - d) / q))


def quat_turn(axis, point, degrees):
    """The turn by degrees about the line through point along axis, by
    quaternions: v -> q v q*."""
    u = unit(axis)
    h = math.radians(degrees) / 2
    w, (x, y, z) = math.cos(h), mul(u, math.sin(h))

    def qmul(a, b):
        a0, a1, a2, a3 = a
        b0, b1, b2, b3 = b
        return (a0 * b0 - a1 * b1 - a2 * b2 - a3 * b3, a0 * b1 + a1 * b0 + a2 * b3 - a3 * b2,
                a0 * b2 - a1 * b3 + a2 * b0 + a3 * b1, a0 * b3 + a1 * b2 - a2 * b1 + a3 * b0)

    def turn(p):
        v = sub(p, point)
        r = qmul(qmul((w, x, y, z), (0,) + tuple(v)), (w, -x, -y, -z))
        return add(r[1:], point)
    return turn


# ---- soft keys: Wyvill's field ----

def wyvill(dist2, R):
    if dist2 >= R * R:
        return 0.0
    q = dist2 / (R * R)
    return 1 - 4 / 9 * q ** 3 + 17 / 9 * q ** 2 - 22 / 9 * q


# ---- the cases ----

def fmt(x):
    s = repr(float(x))
    return "(%s)" % s if s.startswith("-") else s


def vec(v):
    return "(" + ", ".join(fmt(x) for x in v) + ")"


class Case:
    def __init__(self, name, expr, margin, lo, hi, density=None):
        self.name, self.expr, self.margin, self.lo, self.hi = name, expr, margin, lo, hi
        self.density = density   # (radius, reference tree expr, map back) for Density cases
        self.near = None         # (forward map, lo, hi): half the points are images of lo..hi


def build_cases(rng):
    cases = []
    box = lambda s: ((-s, -s, -s), (s, s, s))

    for n in (3, 5, 6, 7, 12):
        cases.append(Case("Prism %d" % n, "Sharp (Prism %d)" % n,
                          lambda p, n=n: prism_margin(n, 1, 1, p), (-1.2, -0.2, -1.2), (1.2, 1.2, 1.2)))
    for r, h in ((0.7, 1.3), (2.5, 0.4)):
        n = sides_for(r, r / 500)
        cases.append(Case("Cylinder %g %g (%d sides)" % (r, h, n), "Sharp (Cylinder %r %r)" % (r, h),
                          lambda p, r=r, h=h, n=n: prism_margin(n, r, h, p),
                          (-1.1 * r, -0.1, -1.1 * r), (1.1 * r, 1.1 * h, 1.1 * r)))
    cases.append(Case("CylinderWith [Sides 9]", "Sharp (CylinderWith [Sides 9] 0.8 2)",
                      lambda p: prism_margin(9, 0.8, 2, p), (-1, -0.2, -1), (1, 2.2, 1)))
    n = sides_for(1.5, 0.05)
    cases.append(Case("CylinderWith [Chord 0.05] (%d sides)" % n, "Sharp (CylinderWith [Chord 0.05] 1.5 1)",
                      lambda p, n=n: prism_margin(n, 1.5, 1, p), (-1.6, -0.1, -1.6), (1.6, 1.1, 1.6)))
    for n, r, h in ((3, 1, 1), (4, 0.6, 1.5), (8, 1.2, 0.5)):
        cases.append(Case("Pyramid %d %g %g" % (n, r, h), "Sharp (Pyramid %d %r %r)" % (n, r, h),
                          lambda p, n=n, r=r, h=h: pyramid_margin(n, r, h, p),
                          (-1.1 * r, -0.1, -1.1 * r), (1.1 * r, 1.1 * h, 1.1 * r)))
    n = sides_for(0.5, 0.001)
    cases.append(Case("Cone 0.5 1 (%d sides)" % n, "Sharp (Cone 0.5 1)",
                      lambda p, n=n: pyramid_margin(n, 0.5, 1, p), (-0.6, -0.1, -0.6), (0.6, 1.1, 0.6)))
    cases.append(Case("ConeWith [Sides 5]", "Sharp (ConeWith [Sides 5] 1 2)",
                      lambda p: pyramid_margin(5, 1, 2, p), (-1.1, -0.1, -1.1), (1.1, 2.1, 1.1)))
    n1, n2 = sides_for(1, 1 / 500), sides_for(0.6, 0.6 / 500)
    cases.append(Case("Tube 1 0.6 0.5", "Sharp (Tube 1 0.6 0.5)",
                      lambda p: min(prism_margin(n1, 1, 0.5, p), -prism_margin(n2, 0.6, 0.5, p)),
                      (-1.1, -0.1, -1.1), (1.1, 0.6, 1.1)))
    cases.append(Case("TubeWith [Sides 6]", "Sharp (TubeWith [Sides 6] 1 0.5 1)",
                      lambda p: min(prism_margin(6, 1, 1, p), -prism_margin(6, 0.5, 1, p)),
                      (-1.1, -0.1, -1.1), (1.1, 1.1, 1.1)))

    def wedge_margin(a, b, c, p):
        x, y, z = p
        # the triangle (0, 0), (a, 0), (0, b), counter-clockwise in (x, y)
        return min(polygon_margin([(0, 0), (a, 0), (0, b)], (x, y)), z, c - z)
    cases.append(Case("Wedge (2, 1, 0.5)", "Sharp (Wedge (2, 1, 0.5))",
                      lambda p: wedge_margin(2, 1, 0.5, p), (-0.2, -0.2, -0.2), (2.2, 1.2, 0.7)))

    sn = (0.3, -1.2, 0.5)
    cases.append(Case("Slab", "Sharp (Product (Slab %s (-0.2) 0.4) (Box (-1, -1, -1) (1, 1, 1)))" % vec(sn),
                      lambda p: min((dot(sn, p) + 0.2) / norm(sn), (0.4 - dot(sn, p)) / norm(sn),
                                    *[1 - abs(c) for c in p]), *box(1.2)))

    for name, verts in PLATONIC.items():
        faces = hull_faces(verts)
        if len(faces) != FACE_COUNT[name]:
            raise SystemExit("geometry.py: %s has %d hull faces, not %d"
                             % (name, len(faces), FACE_COUNT[name]))
        cases.append(Case(name, "Sharp %s" % name, lambda p, f=faces: faces_margin(f, p), *box(1.05)))

    cases.append(Case("Sphere 0.8", "Shift (0.1, 0.2, 0.3) (Sphere 0.8)",
                      lambda p: 0.8 - norm(sub(p, (0.1, 0.2, 0.3))), *box(1.0)))
    cases.append(Case("SphereKey", "SoftObject 0.5 [SphereKey (1, 0, 0) 0.4]",
                      lambda p: 0.4 - norm(sub(p, (1, 0, 0))), (0.5, -0.5, -0.5), (1.5, 0.5, 0.5)))

    # Ball: contains its sphere, within its chordal tolerance outside it.
    for settings, r, tol in (("[]", 1.0, 0.01), ("[Chord 0.02]", 0.5, 0.02)):
        cases.append(Case("BallWith %s %g: sphere inside, tolerance outside" % (settings, r),
                          "Sharp (BallWith %s %r)" % (settings, r),
                          lambda p, r=r, tol=tol: (r - norm(p)) if norm(p) < r else
                          ((r + tol - norm(p)) if norm(p) > r + tol else 0.0),
                          *box(r + 2 * tol)))

    # ---- transforms: the point mapped back onto the base solid ----
    base = ("Sharp Icosahedron", lambda p, f=hull_faces(PLATONIC["Icosahedron"]): faces_margin(f, p),
            (-1, -1, -1), (1, 1, 1))
    base2 = ("Sharp (Pyramid 5 1 1.5)", lambda p: pyramid_margin(5, 1, 1.5, p), (-1, 0, -1), (1, 1.5, 1))

    def image_box(fwd, lo, hi):
        """The box about the images of the corners of lo..hi, widened by 10%."""
        cs = [fwd((a, b, c)) for a in (lo[0], hi[0]) for b in (lo[1], hi[1]) for c in (lo[2], hi[2])]
        lo2 = tuple(min(c[k] for c in cs) for k in range(3))
        hi2 = tuple(max(c[k] for c in cs) for k in range(3))
        w = tuple(0.1 * (hi2[k] - lo2[k]) for k in range(3))
        return sub(lo2, w), add(hi2, w)

    def affine_case(name, kind_expr, fwd, back, b=base):
        c = Case(name, "%s (%s)" % (kind_expr, b[0]), lambda p: b[1](back(p)),
                 *image_box(fwd, b[2], b[3]))
        c.near = (fwd, b[2], b[3])
        cases.append(c)

    def forward3x4(m):
        return lambda x: tuple(dot(m[i][:3], x) + m[i][3] for i in range(3))

    for i in range(4):
        while True:
            m = [[rng.uniform(-2, 2) for _ in range(4)] for _ in range(3)]
            det = dot(m[0][:3], cross(m[1][:3], m[2][:3]))
            if abs(det) > 0.3:
                break
        mexpr = "(" + ", ".join("(" + ", ".join(fmt(x) for x in row) + ")" for row in m) + ")"
        affine_case("Transform random %d (det %.2f)" % (i, det), "Transform " + mexpr,
                    forward3x4(m), inverse3x4(m), base if i % 2 == 0 else base2)
    m = [[3, 0, 0, 1], [0, 0.5, 0, -1], [0, 0, 1.5, 0.25]]
    affine_case("Transform non-uniform scale", "Transform ((3, 0, 0, 1), (0, 0.5, 0, -1), (0, 0, 1.5, 0.25))",
                forward3x4(m), inverse3x4(m))
    for i in range(3):
        n = (rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1))
        d = rng.uniform(-1, 1)
        affine_case("Mirror random %d" % i, "Mirror (%s, %s)" % (vec(n), fmt(d)), reflect(n, d),
                    reflect(n, d), base2 if i == 1 else base)
    for i in range(4):
        axis = (rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1))
        pt = (rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1))
        g = rng.choice([90, 180, rng.uniform(-360, 360)])
        affine_case("RotateAbout random %d (%.1f degrees)" % (i, g),
                    "RotateAbout %s %s %s" % (vec(axis), vec(pt), fmt(g)),
                    quat_turn(axis, pt, g), quat_turn(axis, pt, -g), base if i % 2 == 0 else base2)
    affine_case("Translate", "Translate (0.5, -1, 2)", lambda p: add(p, (0.5, -1, 2)),
                lambda p: sub(p, (0.5, -1, 2)))

    # soft keys under maps: a key and a quadric key, the field computed here
    def key_field(back, c, R):
        return lambda p: wyvill(dot(sub(back(p), c), sub(back(p), c)), R) - 0.5
    keys = "SoftObject 0.5 [Key (0.2, 0.1, 0) 1.6 1]"
    m = [[1.5, 0.4, 0, 0.3], [0, 0.7, 0.2, 0], [0.1, 0, 1.2, -0.4]]
    cases.append(Case("Transform of a key (a quadric key)", "Transform ((1.5, 0.4, 0, 0.3), (0, 0.7, 0.2, 0), (0.1, 0, 1.2, -0.4)) (%s)" % keys,
                      key_field(inverse3x4(m), (0.2, 0.1, 0), 1.6), (-1.8,) * 3, (1.8,) * 3))
    cases.append(Case("RotateAbout of a key", "RotateAbout (1, 2, 3) (0, 1, 0) 40 (%s)" % keys,
                      key_field(quat_turn((1, 2, 3), (0, 1, 0), -40), (0.2, 0.1, 0), 1.6),
                      (-1.8,) * 3, (1.8,) * 3))
    cases.append(Case("Mirror of a scaled key", "Mirror ((1, 1, 0), 0.5) (Scale (2, 1, 1) (%s))" % keys,
                      lambda p: wyvill(sum(x * x for x in (
                          (reflect((1, 1, 0), 0.5)(p)[0] / 2 - 0.2), reflect((1, 1, 0), 0.5)(p)[1] - 0.1,
                          reflect((1, 1, 0), 0.5)(p)[2])), 1.6) - 0.5,
                      (-2.2,) * 3, (2.2,) * 3))

    # ---- patterns: some copy contains the point ----
    cube = lambda p: min(min(c, 1 - c) for c in p)
    cases.append(Case("Repeat", "UnionAll (Repeat 4 (1.5, 0.2, 0) (Sharp UnitCube))",
                      lambda p: max(cube(sub(p, (1.5 * k, 0.2 * k, 0))) for k in range(4)),
                      (-0.2, -0.2, -0.2), (6, 2, 1.2)))
    cases.append(Case("Grid", "UnionAll (Grid (3, 2, 2) (1.5, 2, 1.25) (Sharp UnitCube))",
                      lambda p: max(cube(sub(p, (1.5 * i, 2 * j, 1.25 * k)))
                                    for i in range(3) for j in range(2) for k in range(2)),
                      (-0.2, -0.2, -0.2), (4.2, 3.2, 2.5)))
    ring_box = lambda p: min(0.3 - abs(p[0]), p[1], 1 - p[1], 0.2 - abs(p[2]))
    cases.append(Case("Ring", "UnionAll (Ring 7 2 (Sharp (Box (-0.3, 0, -0.2) (0.3, 1, 0.2))))",
                      lambda p: max(ring_box(sub(quat_turn((0, 1, 0), (0, 0, 0), -360 * k / 7)(p), (2, 0, 0)))
                                    for k in range(7)),
                      (-2.5, -0.2, -2.5), (2.5, 1.2, 2.5)))

    # ---- rounded objects under rigid maps: the same density, moved ----
    tree = "(Difference (Cylinder 0.6 1) (Shift (0.3, 0.5, -1) (Box (0, 0, 0) (1, 1, 2))))"
    for name, expr, back in (
            ("RotateAbout", "RotateAbout (1, -1, 2) (0.5, 0, 0) 33", quat_turn((1, -1, 2), (0.5, 0, 0), -33)),
            ("Mirror", "Mirror ((1, 2, -1), 0.3)", reflect((1, 2, -1), 0.3)),
            ("Transform (a turn)", "Transform ((0, 0, 1, 1), (1, 0, 0, 0), (0, 1, 0, -1))",
             inverse3x4([[0, 0, 1, 1], [1, 0, 0, 0], [0, 1, 0, -1]]))):
        fwd = {"RotateAbout": quat_turn((1, -1, 2), (0.5, 0, 0), 33), "Mirror": reflect((1, 2, -1), 0.3),
               "Transform (a turn)": forward3x4([[0, 0, 1, 1], [1, 0, 0, 0], [0, 1, 0, -1]])}[name]
        cases.append(Case("Density of Rounded under %s" % name, "%s %s" % (expr, tree), None,
                          *image_box(fwd, (-0.7, -0.1, -0.7), (0.7, 1.1, 0.7)), density=(0.15, tree, back)))
    return cases


def main():
    args = sys.argv[1:]
    if not args:
        raise SystemExit(__doc__)
    qcs = args[0]
    npts = int(args[args.index("--points") + 1]) if "--points" in args else 400
    seed = int(args[args.index("--seed") + 1]) if "--seed" in args else 19
    rng = random.Random(seed)
    cases = build_cases(rng)
    script = []
    asked = []
    for i, c in enumerate(cases):
        pts, want = [], []
        while len(pts) < npts:
            if c.near and len(pts) % 2:
                fwd, lo, hi = c.near
                p = fwd(tuple(rng.uniform(lo[k], hi[k]) for k in range(3)))
            else:
                p = tuple(rng.uniform(c.lo[k], c.hi[k]) for k in range(3))
            if c.density:
                pts.append(p)
                continue
            m = c.margin(p)
            if abs(m) < EPS:
                continue
            pts.append(p)
            want.append(m > 0)
        plist = "[" + ", ".join(vec(p) for p in pts) + "]"
        if c.density:
            r, tree, back = c.density
            script.append("obj%d = %s;" % (i, c.expr))
            script.append("map (\\p -> Density %r p obj%d) %s" % (r, i, plist))
            script.append("map (\\p -> Density %r p %s) %s" % (r, tree, "[" + ", ".join(vec(back(p)) for p in pts) + "]"))
        else:
            script.append("obj%d = %s;" % (i, c.expr))
            script.append("map (\\p -> PointInObject p obj%d) %s" % (i, plist))
        asked.append((c, pts, want))
    with tempfile.TemporaryDirectory() as d:
        f = os.path.join(d, "kit-geometry.qcs")
        with open(f, "w") as fh:
            fh.write("\n".join(script) + "\n")
        run = subprocess.run([qcs, f], capture_output=True, text=True, timeout=600)
    if run.returncode != 0:
        print("FAIL kit-geometry: qcs status %d: %s" % (run.returncode, run.stderr[:500]))
        return 1
    lines = run.stdout.splitlines()
    failed = 0
    for c, pts, want in asked:
        if c.density:
            got = lines.pop(0).strip("[]").split(", ")
            ref = lines.pop(0).strip("[]").split(", ")
            worst = max(abs(float(a) - float(b)) for a, b in zip(got, ref))
            nonzero = sum(1 for a in ref if 1e-6 < float(a) < 1 - 1e-6)
            if worst > 1e-9 or nonzero < 10:
                failed += 1
                print("FAIL kit %s: largest density difference %g (%d points in the rounding zone)"
                      % (c.name, worst, nonzero))
            else:
                print("ok kit %s (%d points, %d in the rounding zone, largest difference %.1e)"
                      % (c.name, len(pts), nonzero, worst))
            continue
        got = [s == "True" for s in lines.pop(0).strip("[]").split(", ")]
        bad = [(p, w) for p, w, g in zip(pts, want, got) if w != g]
        nin = sum(want)
        if bad or len(got) != len(want) or nin == 0 or nin == len(want):
            failed += 1
            p, w = bad[0] if bad else (None, None)
            print("FAIL kit %s: %d of %d points disagree (%d inside), first %s should be %s"
                  % (c.name, len(bad), len(want), nin, p, "inside" if w else "outside"))
        else:
            print("ok kit %s (%d points, %d inside)" % (c.name, len(want), nin))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
