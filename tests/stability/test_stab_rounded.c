/* test_stab_rounded.c: numerical stability of rounded polyhedra through
 * the scene-level ray API (scenes written in qcs, compiled with
 * compile_scene, traced with ray_spans), against the MPFR reference of
 * stab.h (Lobb eq. (1) as a cap-volume fraction, combined as Figure 4).
 *
 * Cases (issue 6): radii 1e-12 .. 1e3 on a unit cube and Rounded 0;
 * coordinates up to 1e8 and direction lengths 1e-6 .. 1e6; grazing rays,
 * rays through exact edges and corners, rays parallel to a plane, tangent
 * and near-tangent rays (two crossings 1e-6 apart); ill-formed densities
 * (overlapping Sums, Figure 15b).  Work per ray: the root search's
 * density evaluations plus segments plus polishing steps (lg_stats),
 * capped at WORK_CAP. */
#include "stab.h"

/* The root tolerance given to the ray context, in scene units. */
#define TOL 1e-12
/* Work per ray: evaluations + segments + polishing steps of the LG search.
 * A crossing costs about 2 log2(span / tol) ~ 90 segments and 3 evaluations
 * each; the cap allows 40 crossing-equivalents per ray and catches any
 * runaway subdivision (which would cost ~ span / tol). */
#define WORK_CAP 20000L

static long ray_work(const RayCtx *c) {
  return c->stats.lg.evals + c->stats.lg.segments + c->stats.lg.rf_steps;
}

/* Run one ray through the scene and the reference; returns 1 if it agrees. */
static int one_ray(scase *cs, const Scene *s, RayCtx *c, stree *ref,
                   const double o[3], const double d[3], double T, int nsamp,
                   double tol) {
  double got[STAB_MAXR];
  long w0 = ray_work(c);
  int ng = stab_scene_roots(s, c, o, d, 0, T, got, STAB_MAXR);
  sc_work(cs, ray_work(c) - w0);
  sray R = {ref, NULL, 0.5, {o[0], o[1], o[2]}, {d[0], d[1], d[2]}, 0};
  double brk[3 * 128];
  int nb = stree_breaks(ref, o, d, brk);
  sroot rr[STAB_MAXR];
  int nr = sray_roots(&R, 0, T, brk, nb, nsamp, rr, STAB_MAXR);
  if (ng < 0) {
    cs->rays++;
    cs->missed++;
    sc_note(cs, "ray_spans failed");
    return 0;
  }
  int ok = sc_compare(cs, got, ng, rr, nr, tol, vlen(d));
  /* normals at every crossing: finite and unit */
  csg_span *sp;
  ray_reset(c);
  int n = ray_spans(s, s->root, o, d, 0, T, c, &sp);
  for (int i = 0; i < n; i++)
    for (int e = 0; e < 2; e++) {
      int id = e ? sp[i].id1 : sp[i].id0;
      double t = e ? sp[i].t1 : sp[i].t0;
      if (id < 0) continue;
      double p[3] = {o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]}, nn[3];
      ray_normal(s, id, e ? sp[i].flip1 : sp[i].flip0, p, nn);
      double l = vlen(nn);
      if (!(fabs(l - 1) < 1e-9)) {
        cs->nonfinite++;
        sc_note(cs, "ray %ld: normal (%g, %g, %g) at t = %g", cs->rays, nn[0],
                nn[1], nn[2], t);
        ok = 0;
      }
    }
  if (!ok && getenv("STAB_VERBOSE")) {
    printf("#   ray o = (%.17g, %.17g, %.17g) d = (%.17g, %.17g, %.17g)\n", o[0],
           o[1], o[2], d[0], d[1], d[2]);
    for (int i = 0; i < ng; i++) printf("#     got %.17g\n", got[i]);
    for (int i = 0; i < nr; i++)
      printf("#     ref %.17g kind %d allow %.3g\n", rr[i].t, rr[i].kind,
             rr[i].allow);
  }
  return ok;
}

static uint64_t rng = 12111;
static double urand(void) {
  rng ^= rng >> 12;
  rng ^= rng << 25;
  rng ^= rng >> 27;
  return (double)((rng * 2685821657736338717ULL) >> 11) * 0x1p-53;
}

static void unit_dir(double d[3]) {
  double l;
  do {
    for (int i = 0; i < 3; i++) d[i] = 2 * urand() - 1;
    l = vlen(d);
  } while (l < 0.2 || l > 1);
  for (int i = 0; i < 3; i++) d[i] /= l;
}

static void cube_tree(stree *t, double sh, double r) {
  t->n = 0;
  t->ready = 0;
  double lo[3] = {sh, sh, sh}, hi[3] = {sh + 1, sh + 1, sh + 1};
  st_box(t, lo, hi, r);
  stree_ready(t);
}

/* A ray through the point q (a target near the cube) from 3 units away,
 * direction d of length len: o = q - 3 d / len, searched on [0, 6/len]. */
static void aim(const double q[3], const double du[3], double len, double o[3],
                double d[3]) {
  for (int i = 0; i < 3; i++) {
    d[i] = du[i] * len;
    o[i] = q[i] - 3 * du[i];
  }
}

/* ---- radii 1e-12 .. 1e3, and Rounded 0 ---- */
static void test_radii(void) {
  static const double radii[] = {0, 1e-12, 1e-9, 1e-6, 1e-3, 0.1, 0.5, 0.7,
                                 10, 1e3};
  scase cs = {.name = "radii 0, 1e-12 .. 1e3 on UnitCube", .work_cap = WORK_CAP};
  for (size_t k = 0; k < sizeof radii / sizeof *radii; k++) {
    char src[200];
    snprintf(src, sizeof src, "Rounded %.17g UnitCube", radii[k]);
    Scene *s = stab_compile(src);
    stree t;
    cube_tree(&t, 0, radii[k]);
    RayCtx *c = ray_ctx_new(s, TOL);
    for (int j = 0; j < 30; j++) {
      double q[3], du[3], o[3], d[3];
      for (int i = 0; i < 3; i++) q[i] = -0.2 + 1.4 * urand();
      unit_dir(du);
      if (j < 6) {  /* axis rays through the face centres */
        q[0] = q[1] = q[2] = 0.5;
        du[0] = du[1] = du[2] = 0;
        du[j / 2] = j % 2 ? -1 : 1;
      } else if (j < 9) {  /* rays off axis, x = 0.93 */
        q[0] = 0.93; q[1] = 0.5; q[2] = 0.5;
        du[0] = 0; du[1] = 0; du[2] = 1;
        q[1] = 0.2 + 0.3 * (j - 6);
      }
      aim(q, du, 1, o, d);
      one_ray(&cs, s, c, &t, o, d, 6, 600, TOL);
    }
    if (radii[k] == 0) {
      int sharp = s && !(s->flags & SCENE_HAS_ROUNDED);
      CHECK("Rounded 0 UnitCube compiles to the sharp cube (no density tape)",
            sharp);
    }
    ray_ctx_free(c);
    scene_free(s);
    stree_free(&t);
  }
  sc_report(&cs, "MPFR cap fraction", "1e-12 + 8 eps A/|f'|");
}

/* ---- far coordinates and direction lengths ---- */
static void test_far(void) {
  static const double shifts[] = {0, 1e4, 1e6, 1e8};
  static const double lens[] = {1e-6, 1e-3, 1, 1e3, 1e6};
  scase cs = {.name = "shifted to 1e4 .. 1e8, |d| = 1e-6 .. 1e6, r = 0.1",
              .work_cap = WORK_CAP};
  for (size_t k = 0; k < sizeof shifts / sizeof *shifts; k++) {
    double sh = shifts[k];
    char src[200];
    snprintf(src, sizeof src, "Shift (%.17g, %.17g, %.17g) (Rounded 0.1 UnitCube)",
             sh, sh, sh);
    Scene *s = stab_compile(src);
    stree t;
    cube_tree(&t, sh, 0.1);
    RayCtx *c = ray_ctx_new(s, TOL);
    for (int j = 0; j < 20; j++) {
      double q[3], du[3], o[3], d[3];
      for (int i = 0; i < 3; i++) q[i] = sh - 0.2 + 1.4 * urand();
      unit_dir(du);
      double len = lens[j % 5];
      aim(q, du, len, o, d);
      one_ray(&cs, s, c, &t, o, d, 6 / len, 600, TOL);
    }
    /* from the origin of coordinates to the far cube */
    for (int j = 0; sh > 0 && j < 5; j++) {
      double q[3], o[3] = {0, 0, 0}, d[3];
      for (int i = 0; i < 3; i++) q[i] = sh + 0.1 + 0.8 * urand();
      double l = vlen(q), len = lens[j];
      for (int i = 0; i < 3; i++) d[i] = q[i] / l * len;
      /* search [l - 3, l + 3] in scene units */
      double got[STAB_MAXR];
      long w0 = ray_work(c);
      int ng = stab_scene_roots(s, c, o, d, 0, INFINITY, got, STAB_MAXR);
      sc_work(&cs, ray_work(c) - w0);
      sray R = {&t, NULL, 0.5, {0, 0, 0}, {d[0], d[1], d[2]}, 0};
      double brk[3 * 128];
      int nb = stree_breaks(&t, o, d, brk);
      sroot rr[STAB_MAXR];
      int nr = sray_roots(&R, (l - 3) / len, (l + 3) / len, brk, nb, 600, rr,
                          STAB_MAXR);
      sc_compare(&cs, got, ng, rr, nr, TOL, len);
    }
    ray_ctx_free(c);
    scene_free(s);
    stree_free(&t);
  }
  sc_report(&cs, "MPFR cap fraction", "1e-12 + 8 eps A/|f'| (A ~ S = |coords|)");

  /* a radius below what doubles resolve at the scene's coordinates */
  char warn[2000];
  Scene *s = stab_compile_warn("Shift (1e8, 1e8, 1e8) (Rounded 1e-6 UnitCube)",
                               warn, sizeof warn);
  CHECK("r = 1e-6 at 1e8: a warning names the Rounded (position and radius)",
        s && strstr(warn, "<stab>:1:") && strstr(warn, "warning") &&
            strstr(warn, "radius"));
  scene_free(s);
  s = stab_compile_warn("Shift (1e4, 1e4, 1e4) (Rounded 0.1 UnitCube)", warn,
                        sizeof warn);
  CHECK("r = 0.1 at 1e4: no warning", s && warn[0] == 0);
  scene_free(s);
}

/* ---- grazing, edges, corners, parallel, tangent ---- */

/* The 0.5 level on the diagonal of the rounded edge x = y = 1 (z = 0.5):
 * x0 with cap(x0)^2 = 1/2, by MPFR bisection of the reference. */
static double edge_x0(double r) {
  stree t = {.n = 0};
  st_leaf(&t, 1, 0, 0, 0, r);
  stree_ready(&t);
  sray R = {&t, NULL, sqrt(0.5), {0, 0, 0}, {1, 0, 0}, 0};
  double a = -r, b = r;
  double x = sray_bisect(&R, a, b, sray_f(&R, a), sray_f(&R, b));
  stree_free(&t);
  return x;
}

static void test_grazing(void) {
  scase cs = {.name = "grazing, edges, corners, parallel, tangent (r = 0.1 and "
              "sharp)", .work_cap = WORK_CAP};
  const double r = 0.1;
  Scene *s = stab_compile("Rounded 0.1 UnitCube");
  Scene *sh = stab_compile("Rounded 0 UnitCube");
  stree t, t0;
  cube_tree(&t, 0, r);
  cube_tree(&t0, 0, 0);
  RayCtx *c = ray_ctx_new(s, TOL), *c0 = ray_ctx_new(sh, TOL);
  /* exact edges and corners, entering and only touching */
  static const double rays[][6] = {
      {-1, 2, 0.5, 1, -1, 0},       /* enters through the edge x=0, y=1 */
      {0, 2, 0.5, 1, -1, 0},        /* touches the edge x=1, y=1 */
      {-1, -1, -1, 1, 1, 1},        /* through two corners */
      {-1, -1, 2, 1, 1, -1},        /* enters at the corner (0, 0, 1) */
      {-1, 1, 1, 1, 0, 0},          /* along an edge */
      {-1, 1, 0.5, 1, 0, 0},        /* in a face plane */
      {-1, 0.9, 0.5, 1, 0, 0},      /* parallel, r deep */
      {-1, 0.95, 0.5, 1, 0, 0},     /* parallel, inside the filter */
      {-1, 1.05, 0.5, 1, 0, 0},     /* parallel, outside, in the filter */
      {-1, 1 + 1e-9, 0.5, 1, 0, 0}, /* parallel, 1e-9 outside */
      {-1, 1 - 1e-9, 0.5, 1, 0, 0}, /* parallel, 1e-9 inside */
      {0.5, 0.5, -1, 0, 0, 1},      /* head on */
      {-1, 0.5, 1, 1, 0, 0},        /* in the top face plane */
      {-1, 0, 0, 1, 0, 0},          /* along the edge y = z = 0 */
  };
  for (size_t k = 0; k < sizeof rays / sizeof *rays; k++) {
    const double *o = rays[k], *d = rays[k] + 3;
    one_ray(&cs, s, c, &t, o, d, 6, 600, TOL);
    one_ray(&cs, sh, c0, &t0, o, d, 6, 600, TOL);
  }
  /* near-tangent rays across the rounded edge: x + y = c0 - delta */
  double x0 = edge_x0(r), cc = 2 * (1 + x0);
  double deltas[] = {1e-2, 1e-4, 1e-6, 1e-8, 1e-10, 1e-12, 0, -1e-12, -1e-6};
  double seps[16];
  int nsep = 0;
  for (size_t k = 0; k < sizeof deltas / sizeof *deltas; k++) {
    double ce = cc - deltas[k];
    double o[3] = {ce / 2 - 1, ce / 2 + 1, 0.5}, d[3] = {0.5, -0.5, 0};
    one_ray(&cs, s, c, &t, o, d, 4, 400, TOL);
    sray R = {&t, NULL, 0.5, {o[0], o[1], o[2]}, {d[0], d[1], d[2]}, 0};
    sroot rr[8];
    int nr = sray_roots(&R, 0, 4, NULL, 0, 400, rr, 8);
    if (nr == 2 && rr[0].kind && rr[1].kind)
      seps[nsep++] = (rr[1].t - rr[0].t) * vlen(d);
  }
  /* two crossings 1e-6 apart: sep ~ k sqrt(delta); choose delta from the
   * 1e-4 ray's separation */
  if (nsep >= 2) {
    double k = seps[1] / sqrt(1e-4), want = 1e-6;
    double delta = (want / k) * (want / k);
    for (int rep = 0; rep < 3; rep++) {
      double ce = cc - delta;
      double o[3] = {ce / 2 - 1, ce / 2 + 1, 0.5}, d[3] = {0.5, -0.5, 0};
      sray R = {&t, NULL, 0.5, {o[0], o[1], o[2]}, {d[0], d[1], d[2]}, 0};
      sroot rr[8];
      int nr = sray_roots(&R, 0, 4, NULL, 0, 400, rr, 8);
      double sep = nr == 2 ? (rr[1].t - rr[0].t) * vlen(d) : 0;
      if (sep > 0) delta *= (want / sep) * (want / sep);
      if (rep == 2) {
        printf("# near-tangent edge ray: crossings %.3g apart\n", sep);
        int ok = one_ray(&cs, s, c, &t, o, d, 4, 400, TOL);
        CHECK("two crossings 1e-6 apart across a rounded edge: both found, "
              "to the tolerance", ok && fabs(sep - 1e-6) < 1e-8);
      }
    }
  }
  /* grazing rays at random points of the 0.5 surface near edges and
   * corners: perpendicular to the gradient, tilted by 1e-9 .. 1e-2 */
  for (int j = 0; j < 80; j++) {
    double p[3];
    for (int i = 0; i < 3; i++) p[i] = urand() < 0.5 ? 0.95 + 0.05 * urand() : urand();
    /* move p onto the surface along (p - centre) by reference bisection */
    double dc[3] = {p[0] - 0.5, p[1] - 0.5, p[2] - 0.5}, l = vlen(dc);
    for (int i = 0; i < 3; i++) dc[i] /= l;
    double oc[3] = {0.5, 0.5, 0.5};
    sray R = {&t, NULL, 0.5, {oc[0], oc[1], oc[2]}, {dc[0], dc[1], dc[2]}, 0};
    double ts = sray_bisect(&R, 0, 1, sray_f(&R, 0), sray_f(&R, 1));
    for (int i = 0; i < 3; i++) p[i] = oc[i] + ts * dc[i];
    /* gradient by central differences of the reference */
    double g[3];
    for (int i = 0; i < 3; i++) {
      double e[3] = {0, 0, 0};
      e[i] = 1;
      sray Ri = {&t, NULL, 0.5, {p[0], p[1], p[2]}, {e[0], e[1], e[2]}, 0};
      g[i] = (sray_f(&Ri, 1e-9) - sray_f(&Ri, -1e-9)) / 2e-9;
    }
    double u[3];
    unit_dir(u);
    double gl = vlen(g), ug = (u[0] * g[0] + u[1] * g[1] + u[2] * g[2]) / (gl * gl);
    for (int i = 0; i < 3; i++) u[i] -= ug * g[i];
    double ul = vlen(u), tilt = pow(10, -9 + 7 * urand());
    for (int i = 0; i < 3; i++) u[i] = u[i] / ul + tilt * g[i] / gl * (j % 2 ? 1 : -1);
    ul = vlen(u);
    double o[3], d[3];
    for (int i = 0; i < 3; i++) d[i] = u[i] / ul, o[i] = p[i] - 1.5 * d[i];
    one_ray(&cs, s, c, &t, o, d, 3, 600, TOL);
  }
  ray_ctx_free(c);
  ray_ctx_free(c0);
  scene_free(s);
  scene_free(sh);
  stree_free(&t);
  stree_free(&t0);
  sc_report(&cs, "MPFR cap fraction, golden-section dips", "1e-12 + 8 eps A/|f'|");
  printf("# near-tangent separations:");
  for (int i = 0; i < nsep; i++) printf(" %.3g", seps[i]);
  printf("\n");
}

/* ---- Figure 15b: overlapping Sums ---- */
static void test_figure15b(void) {
  const char *src =
      "Rounded 0.1 (Sum (Sum (Shift (0, 0, 0) UnitCube) (Shift (0.95, 0, 0) "
      "UnitCube)) (Sum (Shift (0, 0, 0.95) UnitCube) (Shift (0.95, 0, 0.95) "
      "UnitCube)))";
  char warn[2000];
  Scene *s = stab_compile_warn(src, warn, sizeof warn);
  CHECK("Figure 15b: the overlapping Sum is warned about, at its Rounded",
        s && s->ill_formed && strstr(warn, "<stab>:1:1: warning") &&
            strstr(warn, "Figure 15b"));
  stree t = {.n = 0};
  double off[4][2] = {{0, 0}, {0.95, 0}, {0, 0.95}, {0.95, 0.95}};
  int b[4];
  for (int i = 0; i < 4; i++) {
    double lo[3] = {off[i][0], 0, off[i][1]}, hi[3] = {off[i][0] + 1, 1, off[i][1] + 1};
    b[i] = st_box(&t, lo, hi, 0.1);
  }
  int ab = st_op(&t, SR_SUM, b[0], b[1]), cd = st_op(&t, SR_SUM, b[2], b[3]);
  st_op(&t, SR_SUM, ab, cd);
  stree_ready(&t);
  scase cs = {.name = "Figure 15b: four overlapping summed cubes (density up to 4)",
              .work_cap = WORK_CAP};
  RayCtx *c = ray_ctx_new(s, TOL);
  for (int j = 0; s && j < 60; j++) {
    double q[3] = {0.8 + 0.35 * urand(), 0.8 + 0.4 * urand(), 0.8 + 0.35 * urand()};
    double du[3], o[3], d[3];
    unit_dir(du);
    if (j % 4 == 0) { du[0] = 0; du[1] = 1; du[2] = 0; } /* down a seam */
    aim(q, du, 1, o, d);
    one_ray(&cs, s, c, &t, o, d, 6, 600, TOL);
  }
  ray_ctx_free(c);
  scene_free(s);
  stree_free(&t);
  sc_report(&cs, "MPFR cap fractions summed", "1e-12 + 8 eps A/|f'|");
  /* touching parts (Figure 11's obj6) are not ill-formed */
  s = stab_compile_warn("Rounded 0.1 (Sum UnitCube (Shift (1, 0, 0) UnitCube))",
                        warn, sizeof warn);
  CHECK("touching summed cubes: no warning", s && warn[0] == 0);
  scene_free(s);
}

/* A ray that runs within rounding of the 0.5 level for a long stretch:
 * a halfspace smoothed with radius 5.9e15 summed with a cube smoothed with
 * radius 125, from a point where the density is 0.5 - 9e-16 (found by
 * fuzz_probes: it took 7.8 million segments, 2.9 s, before the budget).
 * The search must stop within its budget (lg.h, LG_MAX_SEGMENTS per
 * interval searched), say which object it left undecided, and still
 * return finite, paired crossings. */
static void test_budget(void) {
  Scene *s = stab_compile(
      "Rounded 125 (Sum (Difference (RoundedHalfspace 5887875975479296 "
      "((-4, -4, -4), -4)) UnitCube) UnitCube)");
  if (!s) { CHECK("budget: the scene compiles", 0); return; }
  RayCtx *c = ray_ctx_new(s, TOL);
  double o[3] = {-4, -4, -4}, d[3] = {-4, -4, -4}, t[64];
  int n = stab_scene_roots(s, c, o, d, 0, INFINITY, t, 64);
  int finite = 1;
  for (int i = 0; i < n; i++) finite &= isfinite(t[i]);
  long segs = c->stats.lg.segments;
  printf("# summary budget: %d crossings, %ld segments, %ld left undecided\n",
         n, segs, c->stats.lg.overflows);
  CHECK("budget: crossings finite and paired", n >= 0 && n % 2 == 0 && finite);
  CHECK("budget: segments within the budget of the intervals searched",
        segs <= 4L * (LG_MAX_SEGMENTS + LG_STACK));
  CHECK("budget: the undecided segments are counted",
        c->stats.lg.overflows > 0);
  CHECK("budget: the object left undecided is named",
        c->unresolved_node >= 0 && s->nodes[c->unresolved_node].kind == SC_ROUNDED);
  ray_ctx_free(c);
  scene_free(s);
}

/* The OuterBounds probe warns about Figure 15b only where summed parts
 * overlap with volume, as the renderer does: not for parts that touch. */
static int probe_warns(const char *text) {
  fflush(stdout);
  fflush(stderr);
  int saved_err = dup(2), saved_out = dup(1);
  FILE *tmp = tmpfile(), *null = fopen("/dev/null", "w");
  dup2(fileno(tmp), 2);
  dup2(fileno(null), 1);
  RunStatus st = interp_run_string(stab_I, "<probe>", text, MODE_SCRIPT);
  fflush(stdout);
  fflush(stderr);
  dup2(saved_err, 2);
  dup2(saved_out, 1);
  close(saved_err);
  close(saved_out);
  fclose(null);
  rewind(tmp);
  char buf[4096];
  size_t k = fread(buf, 1, sizeof buf - 1, tmp);
  buf[k] = 0;
  fclose(tmp);
  return st != RUN_OK ? -1 : strstr(buf, "Figure 15b") != NULL;
}

static void test_bounds_warning(void) {
  CHECK("OuterBounds: no Figure 15b warning for summed cubes that touch",
        probe_warns("OuterBounds 0.1 0.5 (Sum UnitCube (Shift (1, 0, 0) UnitCube))\n") == 0);
  CHECK("OuterBounds: a Figure 15b warning for summed cubes that overlap",
        probe_warns("OuterBounds 0.1 0.5 (Sum UnitCube (Shift (0.5, 0, 0) UnitCube))\n") == 1);
}

int main(void) {
  char base;
  stab_init("stab-rounded", &base);
  test_radii();
  test_far();
  test_grazing();
  test_figure15b();
  test_budget();
  test_bounds_warning();
  CHECK_DONE();
}
