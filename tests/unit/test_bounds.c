/* test_bounds.c: sharp CSG tapes (point classification, Roth spans) and
 * the outer/inner bounds of Figure 8 / Theorems 1-6, checked against the
 * independent references of ref_density.h. */
#include <float.h>

#include "core/bounds.h"
#include "check.h"
#include "core/csg.h"
#include "core/density.h"
#include "ref_density.h"

/* A sharp reading of an rtree: products are intersections, sums and
 * unions are unions, differences are differences. */
static int ref_in(const rtree *t, int i, const double p[3]) {
  const rnode *x = &t->nodes[i];
  if (x->op == R_LEAF)
    return (long double)x->n[0] * p[0] + (long double)x->n[1] * p[1] +
               (long double)x->n[2] * p[2] < x->d;
  int a = ref_in(t, x->a, p), b = ref_in(t, x->b, p);
  switch (x->op) {
  case R_PROD: return a && b;
  case R_DIFF: return a && !b;
  default: return a || b;
  }
}

static void emit_csg(const rtree *t, int i, csg_builder *b) {
  const rnode *x = &t->nodes[i];
  if (x->op == R_LEAF) { csg_builder_plane(b, x->n, x->d); return; }
  emit_csg(t, x->a, b);
  emit_csg(t, x->b, b);
  csg_builder_op(b, x->op == R_PROD ? CSG_INTER
                    : x->op == R_DIFF ? CSG_DIFF : CSG_UNION);
}

static csg_tape *csg_of(const rtree *t, int root) {
  csg_builder *b = csg_builder_new();
  emit_csg(t, root, b);
  int err;
  return csg_builder_finish(b, &err);
}

static void rand_dir(rng_t *g, double len, double d[3]) {
  double l;
  do {
    for (int i = 0; i < 3; i++) d[i] = rng_range(g, -1, 1);
    l = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  } while (l < 0.1 || l > 1);
  for (int i = 0; i < 3; i++) d[i] *= len / l;
}

/* Spans against sampled point classification.  A sample may disagree only
 * within 1e-9 (relative to the ray's extent) of a span end, where the
 * sample's own rounding decides. */
static void test_csg_spans(void) {
  rng_t g = {12111};
  int bad = 0, bad_inside = 0, nspan_total = 0;
  csg_span out[64], scratch[256];
  for (int sc = 0; sc < 200; sc++) {
    rtree t;
    int root = rt_random_scene(&t, &g);
    csg_tape *ct = csg_of(&t, root);
    for (int k = 0; k < 20; k++) {
      double p[3] = {rng_range(&g, -1.5, 2.5), rng_range(&g, -1.5, 2.5),
                     rng_range(&g, -1.5, 2.5)};
      if (csg_inside(ct, p) != ref_in(&t, root, p)) bad_inside++;
      double len = pow(10, rng_range(&g, -6, 6)), d[3];
      rand_dir(&g, len, d);
      if (k % 5 == 0) {             /* parallel to the coordinate planes */
        int ax = (int)(rng_u64(&g) % 3);
        d[ax] = 0;
        if (k % 10 == 0) d[(ax + 1) % 3] = 0;
        if (d[0] == 0 && d[1] == 0 && d[2] == 0) d[0] = len;
      }
      double o[3];
      for (int i = 0; i < 3; i++) o[i] = p[i] - 2 * d[i] / len;
      double s0 = 0, s1 = 4 / len;
      int n = csg_ray_spans(ct, o, d, s0, s1, out, 64, scratch, 256);
      if (n < 0) { bad++; continue; }
      nspan_total += n;
      for (int j = 0; j < n; j++)
        if (!(out[j].t0 < out[j].t1) || (j && out[j].t0 < out[j - 1].t1))
          bad++;
      for (int m = 0; m <= 400; m++) {
        double s = s0 + (s1 - s0) * m / 400, q[3];
        for (int i = 0; i < 3; i++) q[i] = o[i] + s * d[i];
        int in = 0, near = 0;
        for (int j = 0; j < n; j++) {
          if (s > out[j].t0 && s < out[j].t1) in = 1;
          if (fabs(s - out[j].t0) <= 1e-9 * s1 ||
              fabs(s - out[j].t1) <= 1e-9 * s1)
            near = 1;
        }
        if (!near && in != ref_in(&t, root, q)) {
          if (bad < 5)
            printf("# mismatch scene %d ray %d sample %d: span says %d\n", sc,
                   k, m, in);
          bad++;
        }
      }
    }
    csg_tape_free(ct);
  }
  printf("# spans: %d total, bad %d\n", nspan_total, bad);
  CHECK("csg_inside matches a reference classifier (4000 points)",
        bad_inside == 0);
  CHECK("ray spans: sorted, disjoint, match sampled classification "
        "(|d| 1e-6..1e6, parallel rays)", bad == 0 && nspan_total > 200);
}

static void test_csg_basics(void) {
  rtree t;
  double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, r[6] = {0};
  t.n = 0;
  int root = rt_box(&t, lo, hi, r);
  csg_tape *ct = csg_of(&t, root);
  double o[3] = {-1, 0.5, 0.5}, d[3] = {1e-6, 0, 0};
  csg_span sp[4];
  int n = csg_ray_spans(ct, o, d, 0, 1e7, sp, 4, NULL, 0);
  CHECK("axis ray through unit cube: one span", n == 1);
  /* x = -1 + s*1e-6 crosses 0 at s = 1e6 and 1 at 2e6 (tol 1e-9 rel). */
  CHECK_NEAR("span start", sp[0].t0, 1e6, 1e-3);
  CHECK_NEAR("span end", sp[0].t1, 2e6, 1e-3);
  CHECK("span ends name the planes x=0 (n=-x) and x=1 (n=+x)",
        sp[0].id0 >= 0 && sp[0].id1 >= 0 &&
        ct->planes[sp[0].id0].n[0] == -1 && ct->planes[sp[0].id1].n[0] == 1);
  double o2[3] = {-1, 1, 0.5};    /* grazing along the face y = 1 */
  n = csg_ray_spans(ct, o2, d, 0, 1e7, sp, 4, NULL, 0);
  CHECK("ray in the plane y=1 (parallel, on the boundary) is outside", n == 0);
  double o3[3] = {-1, 1 - 1e-12, 0.5};
  n = csg_ray_spans(ct, o3, d, 0, 1e7, sp, 4, NULL, 0);
  CHECK("parallel ray just inside the face is inside", n == 1);
  csg_tape_free(ct);
  /* Constant folding. */
  csg_builder *b = csg_builder_new();
  double nn[3] = {0, 0, 1};
  csg_builder_plane(b, nn, 0);
  csg_builder_const(b, CSG_EMPTY);
  csg_builder_op(b, CSG_UNION);
  csg_builder_const(b, CSG_ALL);
  csg_builder_op(b, CSG_INTER);
  int err;
  ct = csg_builder_finish(b, &err);
  CHECK("(P u Empty) n All folds to P", ct && ct->ncode == 1 &&
                                            ct->code[0].op == CSG_PLANE);
  csg_tape_free(ct);
  b = csg_builder_new();
  csg_builder_plane(b, nn, 0);
  csg_builder_const(b, CSG_ALL);
  csg_builder_op(b, CSG_DIFF);
  ct = csg_builder_finish(b, &err);
  CHECK("P - All folds to Empty", ct && csg_is_empty(ct));
  csg_tape_free(ct);
  double z[3] = {0, 0, 0};
  b = csg_builder_new();
  CHECK("zero normal rejected", csg_builder_plane(b, z, 0) == CSG_EPLANE);
  csg_builder_free(b);
}

/* The bound property at random points: outside outer(level) the MPFR
 * density is <= level, inside inner(level) it is >= level.  Tolerance
 * 0: the bounds carry their own rounding margins, and the MPFR density is
 * exact to ~1e-90. */
static int check_bounds(const rtree *t, int root, const dt_tape *tp,
                        double level, rng_t *g, int npts, int *flags_out,
                        double box_lo, double box_hi) {
  int fo, fi, bad = 0;
  csg_tape *ob = bnd_outer(tp, level, &fo);
  csg_tape *oc = bnd_outer_chamfered(tp, level, &fo);
  csg_tape *ib = bnd_inner(tp, level, &fi);
  *flags_out = fo | fi;
  for (int k = 0; k < npts; k++) {
    double p[3];
    for (int i = 0; i < 3; i++) p[i] = rng_range(g, box_lo, box_hi);
    if (k % 2) {  /* half the points near a random leaf plane */
      int leaf;
      do leaf = (int)(rng_u64(g) % (unsigned)t->n);
      while (t->nodes[leaf].op != R_LEAF);
      const rnode *x = &t->nodes[leaf];
      double nl = sqrt(x->n[0] * x->n[0] + x->n[1] * x->n[1] +
                       x->n[2] * x->n[2]);
      double s = (x->n[0] * p[0] + x->n[1] * p[1] + x->n[2] * p[2] - x->d) / nl;
      double want = rng_range(g, -1.2, 1.2) * x->r;
      for (int i = 0; i < 3; i++) p[i] += (want - s) * x->n[i] / nl;
    }
    int in_o = csg_inside(ob, p), in_i = csg_inside(ib, p);
    double rho = ref_density(t, root, p);
    if (!in_o && rho > level) bad++;
    if (!csg_inside(oc, p) && rho > level) bad++;
    if (in_i && rho < level) bad++;
  }
  csg_tape_free(ob);
  csg_tape_free(oc);
  csg_tape_free(ib);
  return bad;
}

static void test_bounds_random(void) {
  rng_t g = {8086};
  int bad = 0, fallback = 0;
  for (int sc = 0; sc < 60; sc++) {
    rtree t;
    int root = rt_random_scene(&t, &g);
    dt_tape *tp = rt_tape(&t, root);
    double levels[4] = {0.5, 0.25, 0.75, rng_range(&g, 0.05, 0.95)};
    for (int k = 0; k < 4; k++) {
      int fl;
      bad += check_bounds(&t, root, tp, levels[k], &g, 150, &fl, -1.4, 2.4);
      if (fl & BND_FALLBACK) fallback++;
    }
    dt_tape_free(tp);
  }
  printf("# bounds: %d of 240 random scene/level pairs needed the fallback\n",
         fallback);
  CHECK("random scenes: outside outer (Figure 8's and the chamfered) => "
        "rho <= t, inside inner => rho >= t (36000 points, MPFR)", bad == 0);
}

static void test_bounds_figure15b(void) {
  rtree t;
  t.n = 0;
  double rr[6] = {0.1, 0.1, 0.1, 0.1, 0.1, 0.1};
  double off[4][2] = {{0, 0}, {0.95, 0}, {0, 0.95}, {0.95, 0.95}};
  int k = -1, box[4];
  for (int i = 0; i < 4; i++) {
    double lo[3] = {off[i][0], 0, off[i][1]};
    double hi[3] = {off[i][0] + 1, 1, off[i][1] + 1};
    box[i] = rt_box(&t, lo, hi, rr);
    k = k < 0 ? box[i] : rt_op(&t, R_SUM, k, box[i]);
  }
  dt_tape *tp = rt_tape(&t, k);
  rng_t g = {15};
  int fl, bad = check_bounds(&t, k, tp, 0.5, &g, 4000, &fl, -0.3, 2.3);
  CHECK("Figure 15b sum: bounds hold (4000 points, MPFR)", bad == 0);
  CHECK("Figure 15b sum: BND_RANGE reported, no fallback needed",
        (fl & BND_RANGE) && !(fl & BND_FALLBACK));
  dt_tape_free(tp);
  /* Products and differences of such sums: the sum's range [0,4] breaks
   * Theorem 1/3's [0,1] premise; the generalised forms must still hold. */
  double lo[3] = {0.4, 0.3, 0.4}, hi[3] = {1.6, 1.4, 1.6};
  int clip = rt_box(&t, lo, hi, rr);
  int pr = rt_op(&t, R_PROD, k, clip);
  int df = rt_op(&t, R_DIFF, k, clip);
  int dd = rt_op(&t, R_DIFF, clip, k);
  int m1 = rt_op(&t, R_DIFF, box[0], box[3]);
  int mix = rt_op(&t, R_PROD, m1, rt_op(&t, R_SUM, box[1], box[2]));
  int mix2 = rt_op(&t, R_UNION, k, m1);
  int roots[5] = {pr, df, dd, mix, mix2};
  const char *names[5] = {"Product(Sum4, box)", "Difference(Sum4, box)",
                          "Difference(box, Sum4)",
                          "Product(Difference, Sum)", "Union(Sum4, Diff)"};
  for (int i = 0; i < 5; i++) {
    tp = rt_tape(&t, roots[i]);
    int badi = 0, flags = 0;
    double levels[3] = {0.5, 0.3, 0.8};
    for (int j = 0; j < 3; j++) {
      badi += check_bounds(&t, roots[i], tp, levels[j], &g, 1500, &fl, -0.3,
                           2.3);
      flags |= fl;
    }
    char name[128];
    snprintf(name, sizeof name, "%s: bounds hold at t = 0.5, 0.3, 0.8 "
             "(flags %d)", names[i], flags);
    CHECK(name, badi == 0);
    dt_tape_free(tp);
  }
  tp = rt_tape(&t, mix);
  csg_tape *o = bnd_outer(tp, 0.5, &fl);
  CHECK("Product(Difference, Sum) reports the fallback", fl & BND_FALLBACK);
  csg_tape_free(o);
  dt_tape_free(tp);
}

/* The unit cube rounded by 0.3: outer(0.5) of Figure 8 is the cube itself (plus
 * ulps); the chamfered one is the cube with its edges and
 * corners chamfered (bounds.c: a pair of faces at radius r cannot reach
 * 0.5 beyond a1 + a2 = 2 a*_2, a triple beyond a1 + a2 + a3 = 3 a*_3),
 * the inner bound is strictly inside. */
static void test_bounds_cube(void) {
  rtree t;
  double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  double r[6] = {0.3, 0.3, 0.3, 0.3, 0.3, 0.3};
  t.n = 0;
  int root = rt_box(&t, lo, hi, r);
  dt_tape *tp = rt_tape(&t, root);
  int fl;
  csg_tape *ob = bnd_outer_chamfered(tp, 0.5, &fl), *ib = bnd_inner(tp, 0.5, &fl);
  double c[3] = {1, 1, 1}, in[3] = {0.5, 0.5, 0.5}, face[3] = {0.5, 0.5, 1};
  double out[3] = {0.5, 0.5, 1 + 1e-9}, e[3] = {0.5, 1, 1};
  csg_tape *o8 = bnd_outer(tp, 0.5, &fl);
  CHECK("cube outer bound of Figure 8 is the sharp cube (holds the corner)",
        csg_inside(o8, c) && !csg_inside(o8, out));
  csg_tape_free(o8);
  CHECK("cube outer bound cuts off the corner", !csg_inside(ob, c));
  CHECK("cube outer bound cuts off the edge", !csg_inside(ob, e));
  /* the surface's own points on the diagonal and at the edge's middle
   * (found by bisection on the MPFR density) lie inside */
  double sd[2] = {0.5, 1}, se[2] = {0.5, 1};
  for (int k = 0; k < 60; k++) {
    double m = 0.5 * (sd[0] + sd[1]), q[3] = {m, m, m};
    sd[ref_density(&t, root, q) >= 0.5 ? 0 : 1] = m;
    m = 0.5 * (se[0] + se[1]);
    double w[3] = {0.5, m, m};
    se[ref_density(&t, root, w) >= 0.5 ? 0 : 1] = m;
  }
  double qd[3] = {sd[0], sd[0], sd[0]}, qe[3] = {0.5, se[0], se[0]};
  CHECK("cube outer bound contains the rounded corner's surface point",
        csg_inside(ob, qd));
  CHECK("cube outer bound contains the rounded edge's surface point",
        csg_inside(ob, qe));
  CHECK("cube outer bound contains the face centre", csg_inside(ob, face));
  CHECK("cube outer bound excludes points beyond the face",
        !csg_inside(ob, out));
  CHECK("cube inner bound contains the centre", csg_inside(ib, in));
  CHECK("cube inner bound excludes the face", !csg_inside(ib, face));
  CHECK("well-formed cube: no flags", fl == 0);
  csg_tape_free(ob);
  csg_tape_free(ib);
  dt_tape_free(tp);
  /* radius 0.07: the chamfers would cut 2% of the cube's extent, less
     than they cost a ray (CHAMFER_GAIN): none, the corner stays */
  rtree t2;
  double r2[6] = {0.07, 0.07, 0.07, 0.07, 0.07, 0.07};
  t2.n = 0;
  tp = rt_tape(&t2, rt_box(&t2, lo, hi, r2));
  ob = bnd_outer_chamfered(tp, 0.5, &fl);
  CHECK("cube rounded by 0.07: no chamfers worth their planes",
        ob && csg_inside(ob, c) && ob->nplanes == 6);
  csg_tape_free(ob);
  dt_tape_free(tp);
}

/* Chamfers where they cut: rounded boxes and random convex polyhedra
 * (products of 4 to 8 random planes around a centre), radii from 0.002 to
 * 0.8 and unequal per face, at t = 0.5, 0.293 (a Union's request) and a
 * random level, with points drawn around the polyhedra's edges and
 * corners: outside the outer bound the MPFR density is <= t everywhere;
 * and the chamfers must cut (some sampled points near corners fall
 * outside the bound although inside the sharp polyhedron). */
static void test_bounds_chamfers(void) {
  rng_t g = {1999};
  int bad = 0, cut = 0, total = 0;
  for (int sc = 0; sc < 80; sc++) {
    rtree t;
    t.n = 0;
    int root;
    double c[3] = {0, 0, 0};
    if (sc % 2 == 0) {
      double lo[3], hi[3], r[6];
      for (int j = 0; j < 3; j++) {
        lo[j] = rng_range(&g, -1, 0);
        hi[j] = lo[j] + rng_range(&g, 0.3, 1.5);
        c[j] = 0.5 * (lo[j] + hi[j]);
      }
      for (int j = 0; j < 6; j++)
        r[j] = sc % 8 == 2 ? (j % 2 ? 0.002 : 0.8) : rng_range(&g, 0.01, 0.6);
      root = rt_box(&t, lo, hi, r);
    } else {
      int m = 4 + (int)(rng_u64(&g) % 5);
      root = -1;
      for (int k = 0; k < m; k++) {
        double n[3];
        rand_dir(&g, 1, n);
        int lf = rt_leaf(&t, n[0], n[1], n[2], rng_range(&g, 0.3, 1),
                         rng_range(&g, 0.005, 0.7));
        root = root < 0 ? lf : rt_op(&t, R_PROD, root, lf);
      }
    }
    dt_tape *tp = rt_tape(&t, root);
    double levels[3] = {0.5, 0.293, rng_range(&g, 0.05, 0.95)};
    for (int k = 0; k < 3; k++) {
      int fl;
      csg_tape *ob = bnd_outer_chamfered(tp, levels[k], &fl);
      for (int q = 0; q < 400; q++) {
        /* a point on the sharp surface near two or three planes: from the
           centre out along a random direction to the first plane, then
           pulled towards the others' intersection by a random amount */
        double d[3], p[3];
        rand_dir(&g, 1, d);
        double smin = INFINITY;
        for (int i = 0; i < t.n; i++) {
          const rnode *x = &t.nodes[i];
          if (x->op != R_LEAF) continue;
          double nd = x->n[0] * d[0] + x->n[1] * d[1] + x->n[2] * d[2];
          double nc = x->n[0] * c[0] + x->n[1] * c[1] + x->n[2] * c[2];
          if (nd > 1e-9) smin = fmin(smin, (x->d - nc) / nd);
        }
        if (!isfinite(smin)) continue;
        double s = smin * rng_range(&g, 0.7, 1.05);
        for (int j = 0; j < 3; j++) p[j] = c[j] + s * d[j];
        double rho = ref_density(&t, root, p);
        int in_o = csg_inside(ob, p);
        total++;
        if (!in_o && rho > levels[k]) bad++;
        if (!in_o && ref_in(&t, root, p)) cut++;
      }
      csg_tape_free(ob);
    }
    dt_tape_free(tp);
  }
  printf("# chamfers: %d of %d points near edges and corners cut off\n", cut,
         total);
  CHECK("chamfers: outside outer => rho <= t (boxes and random convex "
        "polyhedra, radii 0.002 to 0.8, MPFR)", bad == 0);
  CHECK("chamfers: they cut (points inside the sharp polyhedron outside "
        "the bound)", cut > total / 50);
}

/* csg_box_class and dt_range_box (the mesher's cell proofs) against the
 * references at points of the box: a box called OUT or IN has no sampled
 * point on the other side, and every sampled density lies in the range
 * (MPFR reference; 1e-12 for its own rounding). */
static void test_box_proofs(void) {
  rng_t g = {4242};
  int bad_class = 0, bad_range = 0, decided = 0, boxes = 0;
  for (int sc = 0; sc < 60; sc++) {
    rtree t;
    int root = rt_random_scene(&t, &g);
    dt_tape *tp = rt_tape(&t, root);
    csg_tape *ct = csg_of(&t, root);
    for (int k = 0; k < 40; k++, boxes++) {
      double lo[3], hi[3], w = rng_range(&g, 1e-3, 1.5);
      for (int i = 0; i < 3; i++) {
        lo[i] = rng_range(&g, -1.4, 2.4);
        hi[i] = lo[i] + w * rng_range(&g, 0.2, 1);
      }
      int c = csg_box_class(ct, lo, hi);
      double dl, dh;
      dt_range_box(tp, lo, hi, &dl, &dh);
      decided += c != CSG_BOX_MIX;
      for (int j = 0; j < 30; j++) {
        double p[3];
        for (int i = 0; i < 3; i++) p[i] = rng_range(&g, lo[i], hi[i]);
        int in = ref_in(&t, root, p);
        if ((c == CSG_BOX_IN && !in) || (c == CSG_BOX_OUT && in)) bad_class++;
        double rho = ref_density(&t, root, p);
        if (rho < dl - 1e-12 || rho > dh + 1e-12) bad_range++;
      }
    }
    dt_tape_free(tp);
    csg_tape_free(ct);
  }
  printf("# box proofs: %d of %d boxes decided IN or OUT\n", decided, boxes);
  CHECK("csg_box_class: no sampled point contradicts IN or OUT (72000 points)",
        bad_class == 0 && decided > boxes / 10);
  CHECK("dt_range_box: every sampled density within the range (MPFR)",
        bad_range == 0);
}

/* csg_prune_box (the mesher's views of a cell's bound solids): over
 * boxes inside the box it was pruned for, the view classifies as the
 * tape does, and points inside the box are inside the view exactly when
 * the reference says so; it is never longer than the tape, and shorter
 * for many boxes. */
static void test_box_prune(void) {
  rng_t g = {777};
  int differ = 0, wrong = 0, longer = 0, shorter = 0, boxes = 0, sub = 0;
  for (int sc = 0; sc < 60; sc++) {
    rtree t;
    int root = rt_random_scene(&t, &g);
    csg_tape *ct = csg_of(&t, root);
    csg_instr *buf = malloc(((size_t)ct->ncode + 1) * sizeof *buf);
    for (int k = 0; k < 40; k++, boxes++) {
      double lo[3], hi[3], w = rng_range(&g, 1e-3, 1.5);
      for (int i = 0; i < 3; i++) {
        lo[i] = rng_range(&g, -1.4, 2.4);
        hi[i] = lo[i] + w * rng_range(&g, 0.2, 1);
      }
      csg_tape v;
      int n = csg_prune_box(ct, lo, hi, buf, &v);
      longer += n > ct->ncode;
      shorter += n < ct->ncode;
      for (int j = 0; j < 10; j++, sub++) {
        double sl[3], sh[3];
        for (int i = 0; i < 3; i++) {
          double a = rng_range(&g, lo[i], hi[i]), b = rng_range(&g, lo[i], hi[i]);
          sl[i] = fmin(a, b);
          sh[i] = fmax(a, b);
        }
        if (j == 0) memcpy(sl, lo, sizeof sl), memcpy(sh, hi, sizeof sh);
        differ += csg_box_class(&v, sl, sh) != csg_box_class(ct, sl, sh);
        double p[3];
        for (int i = 0; i < 3; i++) p[i] = rng_range(&g, sl[i], sh[i]);
        wrong += csg_inside(&v, p) != ref_in(&t, root, p);
      }
    }
    free(buf);
    csg_tape_free(ct);
  }
  printf("# box prune: %d of %d views shorter than their tape\n", shorter, boxes);
  CHECK("csg_prune_box: the view classifies every box inside as the tape "
        "(24000 boxes)", differ == 0);
  CHECK("csg_prune_box: points inside the box in the view as in the "
        "reference (24000 points)", wrong == 0);
  CHECK("csg_prune_box: never longer, shorter for a tenth of the boxes",
        longer == 0 && shorter > boxes / 10);
}

int main(void) {
  check_prefix = "bounds";
  test_box_proofs();
  test_box_prune();
  test_csg_basics();
  test_csg_spans();
  test_bounds_cube();
  test_bounds_random();
  test_bounds_figure15b();
  test_bounds_chamfers();
  CHECK_DONE();
}
