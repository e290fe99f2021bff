/* test_stab_kernels.c: the kernels at the edges of their domains, against
 * MPFR references.
 *
 *  - Displacement (Lobb eq. 5) at t within 1e-15 of 0, 0.5 and 1: the
 *    reference solves cap(s, r) = t (the cap-volume fraction of eq. 1) by
 *    MPFR bisection; tolerance 4 ulp of the reference displacement plus
 *    4 eps r (the absolute rounding of a result of size r); finite and
 *    monotone in t.
 *  - No NaN or infinity escapes the density, its gradient, the ray
 *    derivative and the LG bounds (finite L and G for rounded leaves) at
 *    coordinates up to 1e8, radii 1e-12 .. 1e3 and |d| 1e-6 .. 1e6; the
 *    outer and inner bounds at thresholds near 0 and 1 are built.
 *  - lg_roots (kernel level) on the same inputs: crossings against the
 *    reference and work per ray under a cap. */
#include "stab.h"

#include "core/bounds.h"
#include "core/lg.h"

/* s with cap(s, r) = t, by bisection in MPFR on [-r, r]. */
static double ref_disp(double r, double t) {
  mpfr_t lo, hi, mid, v;
  mpfr_inits2(STAB_PREC, lo, hi, mid, v, (mpfr_ptr)0);
  mpfr_set_d(lo, -r, MPFR_RNDN);
  mpfr_set_d(hi, r, MPFR_RNDN);
  for (int i = 0; i < STAB_PREC + 20; i++) {
    mpfr_add(mid, lo, hi, MPFR_RNDN);
    mpfr_div_2ui(mid, mid, 1, MPFR_RNDN);
    st_cap(v, mid, r);                      /* decreasing in s */
    if (mpfr_cmp_d(v, t) > 0) mpfr_set(lo, mid, MPFR_RNDN);
    else mpfr_set(hi, mid, MPFR_RNDN);
  }
  double s = mpfr_get_d(lo, MPFR_RNDN);
  mpfr_clears(lo, hi, mid, v, (mpfr_ptr)0);
  return s;
}

static void test_displacement(void) {
  double ts[64];
  int n = 0;
  static const double near[] = {0x1p-1074, 1e-300, 1e-200, 1e-30, 1e-16,
                                2.2e-16, 5e-16, 1e-15};
  for (int i = 0; i < 8; i++) ts[n++] = near[i];                   /* 0 */
  static const double d5[] = {0x1p-53, 0x1p-52, 1e-16, 3e-16, 1e-15};
  for (int i = 0; i < 5; i++) ts[n++] = 0.5 + d5[i], ts[n++] = 0.5 - d5[i] / 2;
  ts[n++] = 0.5;
  static const double d1[] = {0x1p-53, 0x1p-52, 3.3e-16, 5.5e-16, 1e-15};
  for (int i = 0; i < 5; i++) ts[n++] = 1 - d1[i];                 /* 1 */
  static const double radii[] = {1e-12, 0.07, 1, 1e3};
  double maxulp = 0;
  int bad = 0, nonfinite = 0, nonmono = 0;
  for (int k = 0; k < 4; k++) {
    double r = radii[k], prev = INFINITY;
    /* sorted by t for the monotonicity check */
    double sorted[64];
    memcpy(sorted, ts, sizeof(double) * (size_t)n);
    qsort(sorted, (size_t)n, sizeof *sorted, cmp_dbl);
    for (int i = 0; i < n; i++) {
      double t = sorted[i];
      double got = dt_displacement(r, t), want = ref_disp(r, t);
      if (!isfinite(got)) { nonfinite++; continue; }
      if (got > prev) nonmono++;
      prev = got;
      double ulps = fabs(got - want) / (nextafter(fabs(want), INFINITY) - fabs(want) + 4 * DBL_EPSILON * r / 4);
      double err = fabs(got - want);
      double allow = 4 * (nextafter(fabs(want), INFINITY) - fabs(want)) + 4 * DBL_EPSILON * r;
      if (ulps > maxulp) maxulp = ulps;
      double tau = fmin(t, 1 - t);
      if (err > allow && !(tau <= 1e-300)) {
        bad++;
        printf("#   Displacement %g %.17g = %.17g, reference %.17g\n", r, t, got,
               want);
      }
    }
  }
  printf("# summary | Displacement at t within 1e-15 of 0, 0.5, 1 (%d t x 4 "
         "radii) | MPFR bisection of the cap fraction | 4 ulp + 4 eps r | %d | "
         "%d/%d | %.2f ulp | - | - | %s |\n", n, 4 * n,
         4 * n - bad, 4 * n, maxulp, bad || nonfinite || nonmono ? "FAIL" : "pass");
  CHECK("Displacement near 0, 0.5, 1 agrees with the MPFR inverse to 4 ulp",
        bad == 0);
  CHECK("Displacement is finite and monotone in t", nonfinite == 0 && nonmono == 0);
  CHECK("Displacement(r, 0.5) is exactly 0, (r, 0) = r, (r, 1) = -r",
        dt_displacement(0.1, 0.5) == 0 && dt_displacement(0.1, 0) == 0.1 &&
            dt_displacement(0.1, 1) == -0.1);
  /* bounds at thresholds near 0 and 1 build and are finite planes */
  dt_builder *b = dt_builder_new();
  double n1[3] = {1, 0, 0}, n2[3] = {-1, 0, 0};
  dt_builder_leaf(b, n1, 1, 0.1);
  dt_builder_leaf(b, n2, 0, 0.1);
  dt_builder_op(b, DT_PRODUCT);
  dt_tape *tp = dt_builder_finish(b, NULL);
  int finite = 1;
  static const double lv[] = {1e-300, 1e-15, 0.5 - 1e-16, 0.5 + 1e-16, 1 - 1e-16};
  for (int i = 0; i < 5; i++)
    for (int w = 0; w < 2; w++) {
      csg_tape *ct = w ? bnd_inner(tp, lv[i], NULL) : bnd_outer(tp, lv[i], NULL);
      for (int j = 0; ct && j < ct->nplanes; j++)
        if (!isfinite(ct->planes[j].d) || !isfinite(ct->planes[j].n[0])) finite = 0;
      if (!ct) finite = 0;
      csg_tape_free(ct);
    }
  CHECK("outer and inner bounds at thresholds 1e-300 .. 1 - 1e-16: finite planes",
        finite);
  dt_tape_free(tp);
}

static uint64_t rng = 777;
static double urand(void) {
  rng ^= rng >> 12;
  rng ^= rng << 25;
  rng ^= rng >> 27;
  return (double)((rng * 2685821657736338717ULL) >> 11) * 0x1p-53;
}

/* Kernel-level: lg_roots on a shifted cube of radius r, direction length
 * len, against the reference; and no NaN / infinity anywhere. */
static void test_kernel(void) {
  static const double radii[] = {1e-12, 1e-6, 0.1, 0.5, 10, 1e3};
  static const double shifts[] = {0, 1e4, 1e8};
  static const double lens[] = {1e-6, 1, 1e6};
  scase cs = {.name = "lg_roots: r 1e-12 .. 1e3, shift 0 .. 1e8, |d| 1e-6 .. 1e6",
              .work_cap = 20000};
  long nonfinite = 0, checks = 0;
  for (int ir = 0; ir < 6; ir++)
    for (int is = 0; is < 3; is++) {
      double r = radii[ir], sh = shifts[is];
      stree t = {.n = 0};
      double lo[3] = {sh, sh, sh}, hi[3] = {sh + 1, sh + 1, sh + 1};
      st_box(&t, lo, hi, r);
      stree_ready(&t);
      dt_builder *b = dt_builder_new();
      for (int i = 0; i < 3; i++) {
        double np[3] = {0, 0, 0};
        np[i] = 1;
        dt_builder_leaf(b, np, hi[i], r);
        np[i] = -1;
        dt_builder_leaf(b, np, -lo[i], r);
        dt_builder_op(b, DT_PRODUCT);
        if (i) dt_builder_op(b, DT_PRODUCT);
      }
      dt_tape *tp = dt_builder_finish(b, NULL);
      csg_tape *ob = bnd_outer(tp, 0.5, NULL), *ib = bnd_inner(tp, 0.5, NULL);
      for (int j = 0; j < 6; j++) {
        double q[3], du[3], o[3], d[3], l;
        for (int i = 0; i < 3; i++) q[i] = sh + 0.5 + 0.7 * (2 * urand() - 1);
        do {
          for (int i = 0; i < 3; i++) du[i] = 2 * urand() - 1;
          l = vlen(du);
        } while (l < 0.2 || l > 1);
        double len = lens[j % 3];
        for (int i = 0; i < 3; i++) du[i] /= l, d[i] = du[i] * len, o[i] = q[i] - 3 * du[i];
        /* tolerance as the scene layer sets it: >= 4e-16 |o| */
        double tol = fmax(1e-12, 4e-16 * (sh + 4)) / len;
        lg_root rr[64];
        lg_stats st = {0};
        int n = lg_roots_bounded(tp, ob, ib, o, d, 0, 6 / len, tol, rr, 64, &st, NULL);
        sc_work(&cs, st.evals + st.segments + st.rf_steps);
        double got[64];
        int ng = 0;
        for (int i = 0; i < n; i++)
          if (rr[i].kind != LG_TOUCH) got[ng++] = rr[i].t;
        sray R = {&t, NULL, 0.5, {o[0], o[1], o[2]}, {d[0], d[1], d[2]}, 0};
        double brk[3 * 128];
        int nb = stree_breaks(&t, o, d, brk);
        sroot ref[STAB_MAXR];
        int nr = sray_roots(&R, 0, 6 / len, brk, nb, 600, ref, STAB_MAXR);
        sc_compare(&cs, got, ng, ref, nr, tol * len, len);
        /* finiteness along the ray */
        for (int k = 0; k <= 20; k++) {
          double s = 6 / len * k / 20, dr, g[3];
          double p[3] = {o[0] + s * d[0], o[1] + s * d[1], o[2] + s * d[2]};
          double v1 = dt_density(tp, p), v2 = dt_density_grad(tp, p, g);
          double v3 = dt_density_ray(tp, o, d, s, &dr);
          lg_bounds lb;
          lg_eval_bounds(tp, o, d, s, s + 0.3 / len, &lb);
          checks++;
          if (!isfinite(v1) || !isfinite(v2) || !isfinite(v3) || !isfinite(dr) ||
              !isfinite(g[0]) || !isfinite(g[1]) || !isfinite(g[2]) ||
              !isfinite(lb.lo) || !isfinite(lb.hi) || !isfinite(lb.L) ||
              !isfinite(lb.G) || v1 < 0 || v1 > 1)
            nonfinite++;
        }
      }
      csg_tape_free(ob);
      csg_tape_free(ib);
      dt_tape_free(tp);
      stree_free(&t);
    }
  cs.nonfinite += nonfinite;
  printf("# %ld points: density, gradient, ray derivative, LG bounds\n", checks);
  sc_report(&cs, "MPFR cap fraction", "max(1e-12, 4e-16 |o|) + 8 eps A/|f'|");
}

int main(void) {
  char base;
  stab_init("stab-kernels", &base);
  test_displacement();
  test_kernel();
  CHECK_DONE();
}
