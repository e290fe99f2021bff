/* test_density.c: density tapes (eq. 2, Figure 4, Section 2.4, eq. 5)
 * against MPFR and long double references from ref_density.h, which share
 * no code with src/core/density.c. */
#include <float.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "core/density.h"
#include "ref_density.h"

static const double EPS = DBL_EPSILON;

/* The rounded unit cube of scenes/README.md, shifted by sh, radius r. */
static int unit_cube(rtree *t, double sh, double r) {
  double lo[3] = {sh, sh, sh}, hi[3] = {sh + 1, sh + 1, sh + 1};
  double rr[6] = {r, r, r, r, r, r};
  t->n = 0;
  return rt_box(t, lo, hi, rr);
}

static void test_paper_values(void) {
  rtree t;
  for (int k = 0; k < 2; k++) {
    double sh = k ? 1e6 : 0;   /* exact in double either way */
    int root = unit_cube(&t, sh, 0.07);
    dt_tape *tp = rt_tape(&t, root);
    double face[3] = {sh + 0.5, sh + 0.5, sh + 1};
    double edge[3] = {sh + 0.5, sh + 1, sh + 1};
    double corner[3] = {sh + 1, sh + 1, sh + 1};
    /* The paper's exact values (Section 2.3.1 (c),(d)); exact in double. */
    CHECK_NEAR(k ? "face 0.5 (shifted 1e6)" : "face 0.5",
               dt_density(tp, face), 0.5, 0);
    CHECK_NEAR(k ? "edge 0.25 (shifted 1e6)" : "edge 0.25",
               dt_density(tp, edge), 0.25, 0);
    CHECK_NEAR(k ? "corner 0.125 (shifted 1e6)" : "corner 0.125",
               dt_density(tp, corner), 0.125, 0);
    double g[3];
    double v = dt_density_grad(tp, corner, g);
    CHECK_NEAR("grad value = density at corner", v, 0.125, 0);
    /* d/dx of 0.5^3 product: 0.25 * (-3/4)/r on each axis, to 1e-15 rel. */
    for (int i = 0; i < 3; i++)
      CHECK_NEAR("corner gradient component", g[i], 0.25 * -0.75 / 0.07,
                 1e-15 * 0.25 * 0.75 / 0.07 * 4);
    CHECK_NEAR("M of the unit cube", dt_max(tp), 1, 0);
    dt_tape_free(tp);
  }
}

/* Random points against MPFR.  Tolerance: a leaf's alpha = s/r carries an
 * absolute error of at most ~4 eps (|n.p| + |d|)/r from double rounding,
 * so the density error is at most 0.75 * that per leaf times the number of
 * leaves (all other factors are <= 1 in magnitude, sums <= 4): we use
 * 8 * nleaves * eps * scale / rmin + 4 eps. */
static void test_random_points(void) {
  rng_t g = {12111};
  double worst = 0, worst_ratio = 0;
  int bad = 0;
  for (int sc = 0; sc < 60; sc++) {
    rtree t;
    int root = rt_random_scene(&t, &g);
    dt_tape *tp = rt_tape(&t, root);
    double rmin = 1;
    for (int i = 0; i < t.n; i++)
      if (t.nodes[i].op == R_LEAF && t.nodes[i].r < rmin) rmin = t.nodes[i].r;
    for (int k = 0; k < 40; k++) {
      double p[3] = {rng_range(&g, -1.3, 2.3), rng_range(&g, -1.3, 2.3),
                     rng_range(&g, -1.3, 2.3)};
      double got = dt_density(tp, p), want = ref_density(&t, root, p);
      double tol = 8 * tp->nleaves * EPS * 4 / rmin + 4 * EPS;
      double err = fabs(got - want);
      if (err > worst) worst = err;
      if (err / tol > worst_ratio) worst_ratio = err / tol;
      if (err > tol) bad++;
    }
    dt_tape_free(tp);
  }
  printf("# random points: max |density - mpfr| = %.3g (%.3g of tolerance)\n",
         worst, worst_ratio);
  CHECK("2400 random points match MPFR within the rounding bound", bad == 0);
}

/* MPFR central difference of the reference density along dir at q+s*dir,
 * step 2^-90 at 320 bits: the truncation error is below 1e-40. */
static double ref_deriv(const rtree *t, int root, const double q[3],
                        const double dir[3], double s) {
  mpfr_t p[3], a, b, tmp, h;
  mpfr_inits2(REF_PREC, p[0], p[1], p[2], a, b, tmp, h, (mpfr_ptr)0);
  mpfr_set_ui_2exp(h, 1, -90, MPFR_RNDN);
  for (int sign = 0; sign < 2; sign++) {
    for (int i = 0; i < 3; i++) {
      mpfr_set_d(tmp, s, MPFR_RNDN);
      if (sign) mpfr_add(tmp, tmp, h, MPFR_RNDN);
      else mpfr_sub(tmp, tmp, h, MPFR_RNDN);
      mpfr_mul_d(tmp, tmp, dir[i], MPFR_RNDN);
      mpfr_add_d(p[i], tmp, q[i], MPFR_RNDN);
    }
    ref_eval(sign ? b : a, t, root, p);
  }
  mpfr_sub(a, b, a, MPFR_RNDN);
  mpfr_div(a, a, h, MPFR_RNDN);
  mpfr_div_ui(a, a, 2, MPFR_RNDN);
  double v = mpfr_get_d(a, MPFR_RNDN);
  mpfr_clears(p[0], p[1], p[2], a, b, tmp, h, (mpfr_ptr)0);
  return v;
}

/* Gradient and ray derivative against MPFR central differences.
 * Tolerance: 1e-9 relative to the sum of |leaf gradient| magnitudes
 * (bounded by nleaves * 0.75/rmin * |dir|), which covers the alpha
 * rounding of the previous test propagated through one differentiation
 * (condition ~ |alpha|/(1 - alpha^2) stays far below 1e6 at random
 * points). */
static void test_gradients(void) {
  rng_t g = {777};
  int bad_g = 0, bad_r = 0, n = 0;
  double worst = 0;
  for (int sc = 0; sc < 30; sc++) {
    rtree t;
    int root = rt_random_scene(&t, &g);
    dt_tape *tp = rt_tape(&t, root);
    double rmin = 1;
    for (int i = 0; i < t.n; i++)
      if (t.nodes[i].op == R_LEAF && t.nodes[i].r < rmin) rmin = t.nodes[i].r;
    for (int k = 0; k < 20; k++) {
      double p[3] = {rng_range(&g, -1.3, 2.3), rng_range(&g, -1.3, 2.3),
                     rng_range(&g, -1.3, 2.3)};
      double gr[3];
      dt_density_grad(tp, p, gr);
      double scale = tp->nleaves * 0.75 / rmin;
      for (int i = 0; i < 3; i++) {
        double e[3] = {0, 0, 0};
        e[i] = 1;
        double want = ref_deriv(&t, root, p, e, 0);
        double err = fabs(gr[i] - want) / scale;
        if (err > worst) worst = err;
        if (err > 1e-9) bad_g++;
      }
      /* Ray derivative with |dir| in {1e-3, 1, 1e3}. */
      double len = pow(10, 3.0 * (int)(rng_u64(&g) % 3) - 3);
      double dir[3] = {rng_range(&g, -1, 1), rng_range(&g, -1, 1),
                       rng_range(&g, -1, 1)};
      double dl = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
      for (int i = 0; i < 3; i++) dir[i] *= len / dl;
      double s = rng_range(&g, -1, 1) / len;
      double o[3] = {p[0] - s * dir[0], p[1] - s * dir[1], p[2] - s * dir[2]};
      double dv;
      dt_density_ray(tp, o, dir, s, &dv);
      double want = ref_deriv(&t, root, o, dir, s);
      if (fabs(dv - want) > 1e-9 * scale * len) bad_r++;
      n++;
    }
    dt_tape_free(tp);
  }
  printf("# gradients: max |grad - mpfr diff| / scale = %.3g\n", worst);
  CHECK("gradient matches MPFR central differences (1e-9 rel)", bad_g == 0);
  CHECK("ray derivative matches MPFR for |d| = 1e-3, 1, 1e3 (1e-9 rel)",
        bad_r == 0 && n == 600);
}

/* MPFR reference for eq. (5): bisect the cap fraction h^2(3r-h)/(4r^3)
 * (r = 1) for the cap height h in [0, 2] with 300 steps; the distance of
 * the isosurface from the plane is 1 - h. */
static void ref_displacement(mpfr_t x, double level) {
  mpfr_t lo, hi, mid, s, f;
  mpfr_inits2(REF_PREC, lo, hi, mid, s, f, (mpfr_ptr)0);
  mpfr_set_si(lo, -1, MPFR_RNDN);  /* distance s: density 1 at -1 */
  mpfr_set_si(hi, 1, MPFR_RNDN);
  for (int i = 0; i < 300; i++) {
    mpfr_add(mid, lo, hi, MPFR_RNDN);
    mpfr_div_2ui(mid, mid, 1, MPFR_RNDN);
    ref_cap(f, mid, 1.0);
    if (mpfr_cmp_d(f, level) > 0) mpfr_set(lo, mid, MPFR_RNDN);
    else mpfr_set(hi, mid, MPFR_RNDN);
  }
  mpfr_set(x, lo, MPFR_RNDN);
  mpfr_clears(lo, hi, mid, s, f, (mpfr_ptr)0);
}

static void test_displacement(void) {
  double levels[64];
  int nl = 0;
  levels[nl++] = 1e-300;
  levels[nl++] = 4.9e-324;
  levels[nl++] = 1e-15;
  levels[nl++] = 0.5 - 1e-15;
  levels[nl++] = 0.5;
  levels[nl++] = 0.5 + 1e-15;
  levels[nl++] = 1 - 1e-15;
  levels[nl++] = nextafter(1, 0);
  levels[nl++] = nextafter(0.5, 0);
  levels[nl++] = nextafter(0.5, 1);
  levels[nl++] = 0.25;
  levels[nl++] = 0.75;
  levels[nl++] = 1e-8;
  rng_t g = {4242};
  while (nl < 64) levels[nl++] = rng_unit(&g);
  double radii[] = {1e-9, 1e-3, 0.07, 1, 1e3};
  double worst_rho = 0, worst_x = 0;
  int bad_rho = 0, bad_x = 0, bad_sign = 0;
  mpfr_t xr, s, f;
  mpfr_inits2(REF_PREC, xr, s, f, (mpfr_ptr)0);
  for (int i = 0; i < nl; i++) {
    double lv = levels[i];
    ref_displacement(xr, lv);
    for (size_t k = 0; k < sizeof radii / sizeof *radii; k++) {
      double r = radii[k], x = dt_displacement(r, lv);
      /* density of the halfspace (radius r) at the returned distance,
       * by the MPFR cap formula: |rho - level| <= 1e-15 (brief: 1e-14). */
      mpfr_set_d(s, x, MPFR_RNDN);
      ref_cap(f, s, r);
      mpfr_sub_d(f, f, lv, MPFR_RNDN);
      double e = fabs(mpfr_get_d(f, MPFR_RNDN));
      if (e > worst_rho) worst_rho = e;
      if (e > 1e-15) bad_rho++;
      /* distance against the MPFR root: within 2 ulps of r (4.5e-16 r). */
      mpfr_mul_d(s, xr, r, MPFR_RNDN);
      double ex = fabs(x - mpfr_get_d(s, MPFR_RNDN)) / r;
      if (ex > worst_x) worst_x = ex;
      if (ex > 4.5e-16) bad_x++;
      if ((lv < 0.5 && !(x > 0)) || (lv > 0.5 && !(x < 0)) ||
          (lv == 0.5 && x != 0) || fabs(x) > r)
        bad_sign++;
    }
  }
  mpfr_clears(xr, s, f, (mpfr_ptr)0);
  printf("# displacement: max |rho(x) - t| = %.3g, max |x - x_mpfr|/r = %.3g\n",
         worst_rho, worst_x);
  CHECK("displacement: rho(x) = t to 1e-15 for t near 0, 0.5, 1 and random",
        bad_rho == 0);
  CHECK("displacement: x within 2 ulps of r of the MPFR root", bad_x == 0);
  CHECK("displacement: positive outward, exact 0 at 0.5, |x| <= r",
        bad_sign == 0);
  CHECK_NEAR("displacement t=0 is +r", dt_displacement(0.3, 0), 0.3, 0);
  CHECK_NEAR("displacement t=1 is -r", dt_displacement(0.3, 1), -0.3, 0);
  CHECK_NEAR("displacement r=0 is 0", dt_displacement(0, 0.3), 0, 0);
  int mono = 1;
  double prev = dt_displacement(1, 0);
  for (int i = 1; i <= 100000; i++) {
    double x = dt_displacement(1, i / 100000.0);
    if (x > prev) mono = 0;
    prev = x;
  }
  CHECK("displacement is non-increasing in t (1e5 steps)", mono);
}

/* Radii from 1e-9 to 1e3 with the geometry scaled alike (so the rounding
 * bound of test_random_points stays the same relative size). */
static void test_radius_scales(void) {
  rng_t g = {99};
  int bad = 0;
  for (int e = -9; e <= 3; e++) {
    double r = pow(10, e), S = r / 0.07;
    rtree t;
    double lo[3] = {0, 0, 0}, hi[3] = {S, S, S};
    double rr[6] = {r, r, r, r, r, r};
    t.n = 0;
    int root = rt_box(&t, lo, hi, rr);
    dt_tape *tp = rt_tape(&t, root);
    for (int k = 0; k < 50; k++) {
      double p[3] = {rng_range(&g, -0.1, 1.1) * S, rng_range(&g, -0.1, 1.1) * S,
                     rng_range(&g, -0.1, 1.1) * S};
      double got = dt_density(tp, p), want = ref_density(&t, root, p);
      if (fabs(got - want) > 6 * 8 * EPS * 2 / 0.07) bad++;
    }
    dt_tape_free(tp);
  }
  CHECK("radii 1e-9..1e3 (scaled cubes) match MPFR (1.5e-13)", bad == 0);
}

/* The scene shifted to 1e6: the alpha rounding bound grows with |p| = 1e6:
 * tolerance 6 leaves * 0.75 * 4 eps * 3e6 / r. */
static void test_shifted(void) {
  rng_t g = {31337};
  rtree t;
  int root = unit_cube(&t, 1e6, 0.07);
  dt_tape *tp = rt_tape(&t, root);
  int bad = 0;
  double tol = 6 * 0.75 * 4 * EPS * 3e6 / 0.07;
  for (int k = 0; k < 300; k++) {
    double p[3] = {1e6 + rng_range(&g, -0.1, 1.1), 1e6 + rng_range(&g, -0.1, 1.1),
                   1e6 + rng_range(&g, -0.1, 1.1)};
    if (fabs(dt_density(tp, p) - ref_density(&t, root, p)) > tol) bad++;
  }
  dt_tape_free(tp);
  CHECK("cube shifted to 1e6 matches MPFR (tol 2e-8 from |p| = 1e6)", bad == 0);
}

static void test_max_bound(void) {
  rtree t;
  t.n = 0;
  double rr[6] = {0.1, 0.1, 0.1, 0.1, 0.1, 0.1};
  double off[4][2] = {{0, 0}, {0.95, 0}, {0, 0.95}, {0.95, 0.95}};
  int k = -1, box[4];
  for (int i = 0; i < 4; i++) {
    double lo[3] = {off[i][0], 0, off[i][1]};
    double hi[3] = {off[i][0] + 1, 1, off[i][1] + 1};
    int b = box[i] = rt_box(&t, lo, hi, rr);
    k = k < 0 ? b : rt_op(&t, R_SUM, k, b);
  }
  dt_tape *tp = rt_tape(&t, k);
  CHECK_NEAR("Figure 15b: M of four summed cubes is 4", dt_max(tp), 4, 0);
  double p[3] = {0.975, 0.5, 0.975};
  /* The overlap is thinner than the filter, so the peak stays below 4
   * but above 1; tol 1e-14 against MPFR. */
  CHECK("Figure 15b: density exceeds 1 in the overlap", dt_density(tp, p) > 1);
  CHECK_NEAR("Figure 15b: overlap density matches MPFR", dt_density(tp, p),
             ref_density(&t, k, p), 1e-14);
  dt_tape_free(tp);
  int u = rt_op(&t, R_UNION, box[0], box[1]);
  tp = rt_tape(&t, u);
  CHECK_NEAR("density Union keeps M = 1", dt_max(tp), 1, 0);
  dt_tape_free(tp);
  int d = rt_op(&t, R_DIFF, box[0], box[1]);
  tp = rt_tape(&t, d);
  CHECK("Difference range is [-1, 1]", tp->lo == -1 && tp->hi == 1);
  dt_tape_free(tp);
}

static void test_builder_errors(void) {
  double z[3] = {0, 0, 0}, n[3] = {0, 2, 0}, inf[3] = {INFINITY, 0, 0};
  dt_builder *b = dt_builder_new();
  CHECK("zero normal rejected", dt_builder_leaf(b, z, 1, 0.1) == DT_EPLANE);
  CHECK("infinite normal rejected",
        dt_builder_leaf(b, inf, 1, 0.1) == DT_EPLANE);
  CHECK("NaN offset rejected", dt_builder_leaf(b, n, NAN, 0.1) == DT_EPLANE);
  CHECK("negative radius rejected",
        dt_builder_leaf(b, n, 1, -0.1) == DT_ERADIUS);
  CHECK("op without operands rejected", dt_builder_op(b, DT_SUM) == DT_EOP);
  CHECK("good leaf accepted", dt_builder_leaf(b, n, 2, 0.1) == DT_OK);
  CHECK("good leaf accepted (2)", dt_builder_leaf(b, n, 4, 0) == DT_OK);
  int err = 0;
  dt_tape *tp = dt_builder_finish(b, &err);
  CHECK("two trees left: unbalanced", !tp && err == DT_EUNBALANCED);
  b = dt_builder_new();
  dt_builder_leaf(b, n, 2, 0.1);   /* normalised: y < 1 */
  tp = dt_builder_finish(b, &err);
  CHECK("single leaf finishes", tp && err == DT_OK);
  double p[3] = {0, 1, 0};
  CHECK_NEAR("normal normalised at build: 0.5 on y = 1", dt_density(tp, p),
             0.5, 0);
  dt_tape_free(tp);
  CHECK("strerror names the error",
        strstr(dt_strerror(DT_EPLANE), "normal") != NULL);
}

static void test_sharp_leaves(void) {
  rtree t;
  double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  double rr[6] = {0, 0.1, 0, 0.1, 0, 0.1};
  t.n = 0;
  int root = rt_box(&t, lo, hi, rr);
  dt_tape *tp = rt_tape(&t, root);
  int bad = 0;
  rng_t g = {5};
  for (int k = 0; k < 500; k++) {
    double p[3] = {rng_range(&g, -0.2, 1.2), rng_range(&g, -0.2, 1.2),
                   rng_range(&g, -0.2, 1.2)};
    if (k == 0) { p[0] = 1; }   /* exactly on a sharp plane */
    double gr[3], v = dt_density_grad(tp, p, gr), dv;
    double d[3] = {1, 0, 0};
    double v2 = dt_density_ray(tp, p, d, 0, &dv);
    if (!isfinite(v) || !isfinite(gr[0]) || !isfinite(gr[1]) ||
        !isfinite(gr[2]) || !isfinite(dv) || v != v2 ||
        fabs(v - ref_density(&t, root, p)) > 1e-14)
      bad++;
  }
  dt_tape_free(tp);
  CHECK("r = 0 leaves: step density, finite gradients, matches MPFR", bad == 0);
  CHECK_NEAR("r = 0 on the plane is 0.5", dt_halfspace(0, 0), 0.5, 0);
}

/* A right-deep chain of 3000 slabs: Sethi-Ullman reordering keeps the
 * stack tiny; value vs long double (tol 1e-13: products of values <= 1). */
static void test_deep_chain(void) {
  dt_builder *b = dt_builder_new();
  double n[3] = {1, 0.5, 0}, m[3] = {-1, -0.5, 0};
  for (int i = 0; i < 1500; i++) {
    dt_builder_leaf(b, n, 1 + i * 1e-4, 0.2);
    dt_builder_leaf(b, m, 0.0, 0.2);
  }
  for (int i = 0; i < 2999; i++) dt_builder_op(b, DT_PRODUCT);
  int err;
  dt_tape *tp = dt_builder_finish(b, &err);
  CHECK("3000-leaf right-deep chain builds", tp && err == DT_OK);
  if (!tp) return;
  CHECK("chain needs few stack slots", tp->depth <= 13);
  double p[3] = {0.5, 0.1, 0};
  long double want = 1;
  long double len = sqrtl(1.25L);
  for (int i = 0; i < 1500; i++) {
    long double s1 = (0.5L + 0.05L - (1 + i * 1e-4L)) / len, s2 = -0.55L / len;
    long double h1 = 0.2L - s1, h2 = 0.2L - s2;
    long double f1 = h1 >= 0.4L ? 1 : h1 * h1 * (0.6L - h1) / (4 * 0.008L);
    long double f2 = h2 >= 0.4L ? 1 : h2 * h2 * (0.6L - h2) / (4 * 0.008L);
    want *= f1 * f2;
  }
  CHECK_NEAR("chain density vs long double (1e-13)", dt_density(tp, p),
             (double)want, 1e-13);
  dt_tape_free(tp);
}

/* Pruned views equal the full tape inside their segment (1e-15: folding
 * only drops exact identities 1*x, x+0, x-0 and 1+x-x). */
static void test_prune(void) {
  rng_t g = {2024};
  int bad = 0, shrunk = 0;
  for (int sc = 0; sc < 40; sc++) {
    rtree t;
    int root = rt_random_scene(&t, &g);
    dt_tape *tp = rt_tape(&t, root);
    dt_instr *buf = malloc((size_t)tp->ncode * sizeof *buf);
    for (int k = 0; k < 20; k++) {
      double o[3] = {rng_range(&g, -2, 2), rng_range(&g, -2, 2),
                     rng_range(&g, -2, 2)};
      double d[3] = {rng_range(&g, -1, 1), rng_range(&g, -1, 1),
                     rng_range(&g, -1, 1)};
      double s0 = rng_range(&g, 0, 3), s1 = s0 + rng_range(&g, 0, 0.5);
      dt_tape view;
      int nv = dt_prune_ray(tp, o, d, s0, s1, buf, &view);
      if (nv > tp->ncode || nv < 1) bad++;
      if (nv < tp->ncode) shrunk++;
      for (int j = 0; j <= 10; j++) {
        double s = s0 + (s1 - s0) * j / 10, d1, d2;
        double a = dt_density_ray(tp, o, d, s, &d1);
        double c = dt_density_ray(&view, o, d, s, &d2);
        if (fabs(a - c) > 1e-15 || fabs(d1 - d2) > 1e-12 * (1 + fabs(d1)))
          bad++;
      }
    }
    free(buf);
    dt_tape_free(tp);
  }
  CHECK("pruned views agree with the full tape on their segment", bad == 0);
  CHECK("pruning shortens most views", shrunk > 400);
}

/* dt_prune_class (the renderer's tiles): a tape cut to a region where
 * some leaves are constant, then pruned to a ray segment inside the
 * region, gives the very code (leaf for leaf, constant for constant) and
 * the very densities, to the bit, that pruning the whole tape to that
 * segment gives. The region is a longer stretch of the same ray; the
 * leaves' classes there come from the test's own long double distances
 * at its ends, kept a margin away from the filters' edges. */
static int same_code(const dt_tape *a, const dt_tape *b) {
  if (a->ncode != b->ncode) return 0;
  for (int i = 0; i < a->ncode; i++) {
    const dt_instr *x = &a->code[i], *y = &b->code[i];
    if (x->op != y->op) return 0;
    if (x->op == DT_CONST && x->c != y->c) return 0;
    if (x->op == DT_LEAF &&
        memcmp(&a->leaves[x->arg], &b->leaves[y->arg], sizeof(dt_leaf)))
      return 0;
  }
  return 1;
}

static void test_prune_class(void) {
  rng_t g = {77};
  int bad_code = 0, bad_value = 0, cut = 0, grouped = 0, segs = 0;
  int same_said = 0, bad_same = 0;
  for (int sc = 0; sc < 60; sc++) {
    dt_tape *tp;
    if (sc % 2) {
      rtree t;
      int root = rt_random_scene(&t, &g);
      tp = rt_tape(&t, root);
    } else { /* sums, differences and unions only: no product groups */
      dt_builder *b = dt_builder_new();
      int n = 3 + (int)rng_range(&g, 0, 10);
      for (int j = 0; j < n; j++) {
        double nn[3] = {rng_range(&g, -1, 1), rng_range(&g, -1, 1),
                        rng_range(&g, -1, 1)};
        dt_builder_leaf(b, nn, rng_range(&g, -1, 1), rng_range(&g, 0.05, 0.5));
        if (j) {
          static const dt_op ops[] = {DT_SUM, DT_DIFF, DT_UNION};
          dt_builder_op(b, ops[(int)rng_range(&g, 0, 2.999)]);
        }
      }
      tp = dt_builder_finish(b, NULL);
    }
    int np = tp->prog ? tp->prog->npcode : 1;
    dt_instr *buf = malloc((size_t)tp->ncode * sizeof *buf);
    dt_instr *pbuf = malloc((size_t)np * sizeof *pbuf);
    dt_instr *v1 = malloc((size_t)tp->ncode * sizeof *v1);
    dt_instr *v2 = malloc((size_t)tp->ncode * sizeof *v2);
    dt_leaf *lv = malloc((size_t)tp->nleaves * sizeof *lv);
    signed char *cls = malloc((size_t)tp->nleaves);
    int *lives = malloc((size_t)tp->nleaves * sizeof *lives);
    dt_ray_leaf *rl1 = malloc((size_t)tp->nleaves * sizeof *rl1);
    dt_ray_leaf *rl2 = malloc((size_t)tp->nleaves * sizeof *rl2);
    grouped += tp->prog != NULL;
    for (int k = 0; k < 20; k++) {
      double o[3] = {rng_range(&g, -2, 2), rng_range(&g, -2, 2),
                     rng_range(&g, -2, 2)};
      double d[3] = {rng_range(&g, -1, 1), rng_range(&g, -1, 1),
                     rng_range(&g, -1, 1)};
      double r0 = rng_range(&g, 0, 3), r1 = r0 + rng_range(&g, 0, 1.5);
      int live = 0;
      for (int j = 0; j < tp->nleaves; j++) {
        const dt_leaf *lf = &tp->leaves[j];
        long double e0 = -lf->d, e1 = -lf->d;
        for (int i = 0; i < 3; i++) {
          e0 += (long double)lf->n[i] * (o[i] + (long double)r0 * d[i]);
          e1 += (long double)lf->n[i] * (o[i] + (long double)r1 * d[i]);
        }
        long double lo = e0 < e1 ? e0 : e1, hi = e0 < e1 ? e1 : e0;
        long double m = 1e-9L;
        cls[j] = lo > lf->r + m ? 0 : hi < -lf->r - m ? 1 : -1;
        live += cls[j] < 0;
      }
      dt_prune_prog pg;
      dt_tape tile;
      dt_prune_class(tp, cls, buf, lv, pbuf, &pg, lives, &tile);
      if (live < tp->nleaves) cut++;
      for (int q = 0; q < 3; q++) {
        double s0 = rng_range(&g, r0, r1), s1 = rng_range(&g, s0, r1);
        dt_tape a, b;
        dt_prune_ray(tp, o, d, s0, s1, v1, &a);
        dt_prune_ray(&tile, o, d, s0, s1, v2, &b);
        segs++;
        if (!same_code(&a, &b)) bad_code++;
        for (int j = 0; j <= 8; j++) {
          double s = s0 + (s1 - s0) * j / 8, d1, d2;
          double x = dt_density_ray(&a, o, d, s, &d1);
          double y = dt_density_ray(&b, o, d, s, &d2);
          if (memcmp(&x, &y, sizeof x) || memcmp(&d1, &d2, sizeof d1))
            bad_value++;
        }
        /* the same through the leaf tables, the cut tape's filled only
           for its live leaves (the rest NaN: read, they would show) */
        for (int j = 0; j < tp->nleaves; j++) rl2[j].base = rl2[j].nd = NAN;
        dt_ray_leaves(tp, o, d, rl1);
        dt_ray_leaves(&tile, o, d, rl2);
        dt_prune_rl(tp, rl1, s0, s1, v1, &a);
        dt_prune_rl(&tile, rl2, s0, s1, v2, &b);
        if (!same_code(&a, &b)) bad_code++;
        /* dt_prune_rl_same: when it says nothing folds, pruning gives the
           tape's own code (the whole tape, the cut one with its groups,
           and a segment's view cut again to a part of its segment) */
        {
          double u0 = rng_range(&g, s0, s1), u1 = rng_range(&g, u0, s1);
          const dt_tape *from[3] = {tp, &tile, &b};
          const dt_ray_leaf *rls[3] = {rl1, rl2, rl2};
          for (int f = 0; f < 3; f++) {
            double x0 = f == 2 ? u0 : s0, x1 = f == 2 ? u1 : s1;
            dt_instr *w = malloc((size_t)tp->ncode * sizeof *w);
            dt_tape c;
            dt_prune_rl(from[f], rls[f], x0, x1, w, &c);
            if (dt_prune_rl_same(from[f], rls[f], x0, x1)) {
              same_said++;
              if (!same_code(&c, from[f])) bad_same++;
            }
            free(w);
          }
        }
        for (int j = 0; j <= 8; j++) {
          double s = s0 + (s1 - s0) * j / 8, d1, d2;
          double x = dt_density_rl(&a, rl1, s, &d1);
          double y = dt_density_rl(&b, rl2, s, &d2);
          if (memcmp(&x, &y, sizeof x) || memcmp(&d1, &d2, sizeof d1))
            bad_value++;
        }
      }
    }
    free(buf);
    free(pbuf);
    free(v1);
    free(v2);
    free(lv);
    free(cls);
    free(lives);
    free(rl1);
    free(rl2);
    dt_tape_free(tp);
  }
  if (getenv("QCS_TEST_VERBOSE"))
    printf("# prune_class: %d segments, %d cuts, %d grouped tapes\n", segs,
           cut, grouped);
  CHECK("a tape cut to a region, then to a segment in it: the segment's "
        "code, leaf for leaf", bad_code == 0);
  CHECK("... and its densities and derivatives, bit for bit",
        bad_value == 0);
  CHECK("the regions cut leaves, in tapes with and without groups",
        cut > 300 && grouped > 0 && grouped < 60);
  if (getenv("QCS_TEST_VERBOSE"))
    printf("# prune_rl_same: %d of %d prunes said to keep the code\n",
           same_said, 3 * segs);
  CHECK("dt_prune_rl_same: where it says nothing folds, the pruned code is "
        "the tape's own, instruction for instruction",
        bad_same == 0 && same_said > 100);
}


/* dt_envelope and dt_envelope_clear (the shadow ray's self-test, render.c).
 * The reference is the tape's own leaves (its doubles n, d and inv_r, the
 * density the tracer defines) evaluated in MPFR with the cap formula, the
 * tree walked from the tape's code: a claim "clear" must leave the solid's
 * density at or below 0.5 at every point of the ray tried, exactly. */
static double ref_tape_ray(const dt_tape *t, const double o[3],
                           const double dir[3], double s) {
  mpfr_t st[DT_STACK_MAX], p[3], dist, a, tmp;
  for (int i = 0; i < DT_STACK_MAX; i++) mpfr_init2(st[i], REF_PREC);
  mpfr_inits2(REF_PREC, p[0], p[1], p[2], dist, a, tmp, (mpfr_ptr)0);
  for (int i = 0; i < 3; i++) {
    mpfr_set_d(tmp, dir[i], MPFR_RNDN);
    mpfr_mul_d(tmp, tmp, s, MPFR_RNDN);
    mpfr_add_d(p[i], tmp, o[i], MPFR_RNDN);
  }
  int sp = 0;
  for (int i = 0; i < t->ncode; i++) {
    const dt_instr *in = &t->code[i];
    if (in->op == DT_LEAF) {
      const dt_leaf *lf = &t->leaves[in->arg];
      mpfr_set_zero(dist, 1);
      for (int k = 0; k < 3; k++) {
        mpfr_set_d(tmp, lf->n[k], MPFR_RNDN);
        mpfr_fma(dist, tmp, p[k], dist, MPFR_RNDN);
      }
      mpfr_sub_d(dist, dist, lf->d, MPFR_RNDN);
      if (lf->r <= 0) {
        int c = mpfr_sgn(dist);
        mpfr_set_d(st[sp], c < 0 ? 1.0 : (c > 0 ? 0.0 : 0.5), MPFR_RNDN);
      } else {
        /* the cap fraction in a = dist * inv_r: h/r = 1 - a */
        mpfr_mul_d(a, dist, lf->inv_r, MPFR_RNDN);
        mpfr_ui_sub(tmp, 1, a, MPFR_RNDN);            /* h/r */
        if (mpfr_sgn(tmp) <= 0) mpfr_set_zero(st[sp], 1);
        else if (mpfr_cmp_ui(tmp, 2) >= 0) mpfr_set_ui(st[sp], 1, MPFR_RNDN);
        else {                        /* (h/r)^2 (3 - h/r) / 4 */
          mpfr_ui_sub(a, 3, tmp, MPFR_RNDN);
          mpfr_mul(a, a, tmp, MPFR_RNDN);
          mpfr_mul(a, a, tmp, MPFR_RNDN);
          mpfr_div_ui(st[sp], a, 4, MPFR_RNDN);
        }
      }
      sp++;
    } else {
      sp--;
      /* the tape's ops as the reference tree's (y - x: a swap) */
      int op = in->op == DT_SUM ? R_SUM : in->op == DT_PRODUCT ? R_PROD
             : in->op == DT_DIFF || in->op == DT_RDIFF ? R_DIFF : R_UNION;
      if (in->op == DT_RDIFF) ref_op(st[sp - 1], op, st[sp], st[sp - 1], tmp);
      else ref_op(st[sp - 1], op, st[sp - 1], st[sp], tmp);
    }
  }
  /* the sign of rho - 0.5, exactly: +1 inside, 0 on, -1 outside */
  double r = (double)mpfr_cmp_d(st[0], 0.5);
  for (int i = 0; i < DT_STACK_MAX; i++) mpfr_clear(st[i]);
  mpfr_clears(p[0], p[1], p[2], dist, a, tmp, (mpfr_ptr)0);
  return r;
}

static void test_envelope(void) {
  /* what dt_envelope keeps: a box's six leaves; a box minus a box, the
     first box's; none for a sum, a union, or a product with a factor
     that may exceed 1 or go negative */
  static const double lo1[3] = {0, 0, 0}, hi1[3] = {1, 1, 1};
  static const double lo2[3] = {0.25, 0.8, 0.25}, hi2[3] = {0.75, 1.3, 0.75};
  static const double lo3[3] = {0.5, 0, 0}, hi3[3] = {2, 1, 1};
  double r6[6] = {0.1, 0.1, 0.1, 0.1, 0.1, 0.1};
  struct { int op2, op3, want; const char *name; } kinds[] = {
    {-1, -1, 6, "a box: its six leaves"},
    {R_DIFF, -1, 6, "a box minus a box: the first box's six"},
    {R_SUM, -1, 0, "a sum: none"},
    {R_UNION, -1, 0, "a union: none"},
    {R_PROD, -1, 12, "a product of boxes: all twelve"},
    {R_PROD, R_SUM, 0, "a product with a sum (up to 2): none"},
    {R_PROD, R_DIFF, 0, "a product with a difference (down to -1): none"},
    {R_DIFF, R_PROD, 6, "a box minus a product: the first box's six"},
  };
  for (size_t k = 0; k < sizeof kinds / sizeof *kinds; k++) {
    rtree t = {.n = 0};
    int a = rt_box(&t, lo1, hi1, r6), root = a;
    if (kinds[k].op2 >= 0) {
      int b = rt_box(&t, lo2, hi2, r6);
      if (kinds[k].op3 >= 0) b = rt_op(&t, kinds[k].op3, b, rt_box(&t, lo3, hi3, r6));
      root = rt_op(&t, kinds[k].op2, a, b);
    }
    dt_tape *tp = rt_tape(&t, root);
    int env[64];
    int n = dt_envelope(tp, env);
    /* the leaves kept are the first box's (planes at 0 or 1) unless all */
    int first_box = 1;
    for (int i = 0; i < n; i++) {
      const dt_leaf *lf = &tp->leaves[env[i]];
      double off = fabs(lf->d);
      if (!(off == 0 || off == 1)) first_box = 0;
    }
    char name[160];
    snprintf(name, sizeof name, "envelope of %s (%d)", kinds[k].name, n);
    CHECK(name, n == kinds[k].want && (n == 12 || first_box));
    dt_tape_free(tp);
  }

  /* soundness on random objects: a rounded convex polytope, a box with a
     notch (a difference), far from the origin and with stiff radii; the
     ray starts just outside a surface point, in a random direction */
  rng_t g = {20261127};
  int tried = 0, clear = 0, bad = 0, entering = 0, entering_clear = 0;
  for (int it = 0; it < 1500; it++) {
    rtree t = {.n = 0};
    double scale = pow(10, rng_range(&g, -2, 2));
    double off = (it % 3 == 0) ? pow(10, rng_range(&g, 0, 6)) : 0;
    double rr = scale * pow(10, rng_range(&g, -6, -0.5));
    int kind = (int)(rng_u64(&g) % 3), root = -1;
    double c[3] = {off, -off * 0.5, off * 0.25};
    if (kind < 2) {
      double lo[3], hi[3], r[6];
      for (int j = 0; j < 3; j++) {
        lo[j] = c[j] - scale * rng_range(&g, 0.3, 1);
        hi[j] = c[j] + scale * rng_range(&g, 0.3, 1);
      }
      for (int j = 0; j < 6; j++) r[j] = rr * rng_range(&g, 0.5, 2);
      root = rt_box(&t, lo, hi, r);
      if (kind == 1) {   /* a notch through the top */
        double nlo[3] = {c[0] - 0.2 * scale, hi[1] - 0.3 * scale, c[2] - 0.2 * scale};
        double nhi[3] = {c[0] + 0.2 * scale, hi[1] + 0.3 * scale, c[2] + 0.2 * scale};
        root = rt_op(&t, R_DIFF, root, rt_box(&t, nlo, nhi, r));
      }
    } else {             /* 5 to 9 random planes around c */
      int np = 5 + (int)(rng_u64(&g) % 5);
      for (int j = 0; j < np; j++) {
        double n[3];
        for (int q = 0; q < 3; q++) n[q] = rng_range(&g, -1, 1);
        if (j < 3) { n[0] = n[1] = n[2] = 0; n[j] = 1; }
        double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        double d = (n[0] * c[0] + n[1] * c[1] + n[2] * c[2]) / len +
                   scale * rng_range(&g, 0.4, 1);
        for (int q = 0; q < 3; q++) n[q] /= len;
        int l = rt_leaf(&t, n[0], n[1], n[2], d, rr * rng_range(&g, 0.5, 2));
        root = root < 0 ? l : rt_op(&t, R_PROD, root, l);
      }
      /* close it below: -n for the first three */
      for (int j = 0; j < 3; j++) {
        double n[3] = {0, 0, 0};
        n[j] = -1;
        int l = rt_leaf(&t, n[0], n[1], n[2], -c[j] + scale * 0.5, rr);
        root = rt_op(&t, R_PROD, root, l);
      }
    }
    dt_tape *tp = rt_tape(&t, root);
    int env[64], n = dt_envelope(tp, env);
    if (n == 0) { dt_tape_free(tp); continue; }
    /* a surface point: bisection on the exact sign along a random line
       from the centre (inside) outwards */
    double u[3];
    for (int q = 0; q < 3; q++) u[q] = rng_range(&g, -1, 1);
    double ul = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    for (int q = 0; q < 3; q++) u[q] /= ul;
    if (ref_tape_ray(tp, c, u, 0) <= 0) { dt_tape_free(tp); continue; }
    double s0 = 0, s1 = 4 * scale;
    if (ref_tape_ray(tp, c, u, s1) > 0) { dt_tape_free(tp); continue; }
    for (int k = 0; k < 80; k++) {
      double m = 0.5 * (s0 + s1);
      if (ref_tape_ray(tp, c, u, m) > 0) s0 = m; else s1 = m;
    }
    /* just outside: s1, moved further by up to 1e-6 of the scale, or in
       one case of five by half to twice the scale (past every filter of
       the planes it is outside of: their factors are 0 there) */
    double o[3];
    double push = it % 5 == 1 ? scale * rng_range(&g, 0.5, 2)
                              : scale * pow(10, rng_range(&g, -14, -6));
    for (int q = 0; q < 3; q++) o[q] = c[q] + (s1 + push) * u[q];
    double d[3];
    int aim = it % 4 == 0 || it % 20 == 1;   /* some aimed at the centre */
    for (int q = 0; q < 3; q++)
      d[q] = aim ? c[q] - o[q] : rng_range(&g, -1, 1);
    double dl = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    for (int q = 0; q < 3; q++) d[q] /= dl;
    int says = dt_envelope_clear(tp, env, n, o, d);
    tried++;
    clear += says;
    /* the ray, densely: near its start on a log scale, then to 6 scales */
    int inside = 0;
    for (int k = 0; k <= 60 && !inside; k++) {
      double sk = k < 30 ? scale * pow(10, -15 + 0.5 * k) : 6 * scale * (k - 29) / 31.0;
      inside = ref_tape_ray(tp, o, d, sk) > 0;
    }
    if (aim) entering += inside, entering_clear += inside && says;
    if (says && inside) bad++;
    dt_tape_free(tp);
  }
  printf("# envelope: %d rays from surfaces, %d proven clear, %d of them "
         "entering the solid; %d aimed rays entering, %d called clear\n",
         tried, clear, bad, entering, entering_clear);
  CHECK("envelope: no ray called clear enters the solid (MPFR)", bad == 0);
  CHECK("envelope: a ray aimed into the solid is never called clear",
        entering > 100 && entering_clear == 0);
  CHECK("envelope: most rays leaving a surface are proven clear",
        clear > tried / 4);
}

int main(void) {
  check_prefix = "density";
  test_paper_values();
  test_random_points();
  test_gradients();
  test_displacement();
  test_radius_scales();
  test_shifted();
  test_max_bound();
  test_builder_errors();
  test_sharp_leaves();
  test_deep_chain();
  test_prune();
  test_prune_class();
  test_envelope();
  CHECK_DONE();
}
