/* test_poly.c: poly.c against MPFR references.
 *
 * Polynomials are built from known roots, expanded in MPFR at 512 bits and
 * rounded once to double. The reference crossings are those of the ROUNDED
 * double polynomial (what the solver is given), located by evaluating it
 * exactly in MPFR (2048 bits) and bisecting down to adjacent doubles, from
 * sample points chosen from the construction (never from the solver). The
 * tolerance beside each root is the first-order forward error of a double
 * evaluation near it: 2 * gamma_2n * sum |c_i||r|^i / |p'(r)| + 4 ulp. */
#include "check.h"
#include "core/poly.h"

#include <float.h>
#include <mpfr.h>
#include <stdint.h>

static uint64_t rng_state = 12111;
static double rnd(void)  /* uniform in [0, 1), xorshift64* */
{
  rng_state ^= rng_state >> 12;
  rng_state ^= rng_state << 25;
  rng_state ^= rng_state >> 27;
  return (double)((rng_state * 2685821657736338717ULL) >> 11) * 0x1p-53;
}

/* Expand lead * prod (x - re[i]) * prod (x^2 - 2 u x + u^2 + v^2) in MPFR
 * and round the coefficients to double. Returns the degree. */
static int expand(double lead, const double *re, int nre, const double *cu,
                  const double *cv, int ncx, double *out)
{
  mpfr_t p[POLY_MAX_DEG + 1], t, s;
  for (int i = 0; i <= POLY_MAX_DEG; i++) mpfr_init2(p[i], 512), mpfr_set_zero(p[i], 1);
  mpfr_inits2(512, t, s, (mpfr_ptr)0);
  mpfr_set_d(p[0], lead, MPFR_RNDN);
  int n = 0;
  for (int k = 0; k < nre; k++) {  /* multiply by (x - r) */
    for (int i = n + 1; i >= 0; i--) {
      mpfr_mul_d(t, p[i], -re[k], MPFR_RNDN);
      if (i > 0) mpfr_add(t, t, p[i - 1], MPFR_RNDN);
      mpfr_set(p[i], t, MPFR_RNDN);
    }
    n++;
  }
  for (int k = 0; k < ncx; k++) {  /* multiply by x^2 - 2u x + (u^2 + v^2) */
    mpfr_t q0, q1;
    mpfr_inits2(512, q0, q1, (mpfr_ptr)0);
    mpfr_set_d(q1, cu[k], MPFR_RNDN);
    mpfr_mul_si(q1, q1, -2, MPFR_RNDN);
    mpfr_set_d(q0, cu[k], MPFR_RNDN);
    mpfr_sqr(q0, q0, MPFR_RNDN);
    mpfr_set_d(s, cv[k], MPFR_RNDN);
    mpfr_sqr(s, s, MPFR_RNDN);
    mpfr_add(q0, q0, s, MPFR_RNDN);
    for (int i = n + 2; i >= 0; i--) {
      mpfr_mul(t, p[i], q0, MPFR_RNDN);
      if (i >= 1) { mpfr_mul(s, p[i - 1], q1, MPFR_RNDN); mpfr_add(t, t, s, MPFR_RNDN); }
      if (i >= 2) mpfr_add(t, t, p[i - 2], MPFR_RNDN);
      mpfr_set(p[i], t, MPFR_RNDN);
    }
    n += 2;
    mpfr_clears(q0, q1, (mpfr_ptr)0);
  }
  for (int i = 0; i <= POLY_MAX_DEG; i++) {
    out[i] = i <= n ? mpfr_get_d(p[i], MPFR_RNDN) : 0;
    mpfr_clear(p[i]);
  }
  mpfr_clears(t, s, (mpfr_ptr)0);
  return n;
}

/* Exact value (2048 bits) of the double polynomial at x. */
static void mp_eval(mpfr_t y, const double *c, int n, double x)
{
  mpfr_set_d(y, c[n], MPFR_RNDN);
  for (int i = n - 1; i >= 0; i--) {
    mpfr_mul_d(y, y, x, MPFR_RNDN);
    mpfr_add_d(y, y, c[i], MPFR_RNDN);
  }
}

static int mp_pos(const double *c, int n, double x)
{
  mpfr_t y;
  mpfr_init2(y, 2048);
  mp_eval(y, c, n, x);
  int s = mpfr_sgn(y) > 0;
  mpfr_clear(y);
  return s;
}

/* Reference crossings of the double polynomial in (a, b): sign changes
 * between consecutive sample points, bisected to adjacent doubles. */
static int ref_crossings(const double *c, int n, double a, double b,
                         const double *hint, int nhint, int grid, double *out)
{
  double pts[4096];
  int np = 0;
  pts[np++] = a;
  for (int i = 1; i < grid; i++) pts[np++] = a + (b - a) * i / grid;
  for (int i = 0; i < nhint; i++) if (hint[i] > a && hint[i] < b) pts[np++] = hint[i];
  pts[np++] = b;
  for (int i = 1; i < np; i++) {  /* insertion sort */
    double t = pts[i];
    int j = i - 1;
    while (j >= 0 && pts[j] > t) { pts[j + 1] = pts[j]; j--; }
    pts[j + 1] = t;
  }
  int k = 0, sprev = mp_pos(c, n, pts[0]);
  for (int i = 1; i < np; i++) {
    int s = mp_pos(c, n, pts[i]);
    if (s != sprev) {
      double lo = pts[i - 1], hi = pts[i];
      for (;;) {
        double mid = lo + (hi - lo) / 2;
        if (mid <= lo || mid >= hi) break;
        if (mp_pos(c, n, mid) == sprev) lo = mid; else hi = mid;
      }
      out[k++] = 0.5 * (lo + hi);
    }
    sprev = s;
  }
  return k;
}

/* First-order bound on where a double evaluation can misplace the root r. */
static double root_tol(const double *c, int n, double r)
{
  long double s = 0, d = 0, xp = 1, xs = 1;
  for (int i = 0; i <= n; i++) {
    s += fabsl((long double)c[i]) * xp;
    if (i < n) d += (long double)(i + 1) * c[i + 1] * xs;
    xp *= fabsl((long double)r);
    xs *= (long double)r;
  }
  double gam = 2 * n * (DBL_EPSILON / 2) / (1 - 2 * n * (DBL_EPSILON / 2));
  double dd = fabs((double)d);
  double t = dd > 0 ? 2 * gam * (double)s / dd : INFINITY;
  return t + 4 * (nextafter(fabs(r), INFINITY) - fabs(r)) + DBL_MIN;
}

static int cmp_roots(const char *name, const double *c, int n, double a,
                     double b, const double *hint, int nhint, unsigned opts,
                     poly_stats *st)
{
  double ref[16], got[POLY_MAX_DEG];
  int nr = ref_crossings(c, n, a, b, hint, nhint, 2000, ref);
  int sa = poly_eval(c, n, a, NULL) > 0, sb = poly_eval(c, n, b, NULL) > 0;
  int ng = poly_crossings(c, n, a, b, sa, sb, opts, got, st);
  int ok = ng == nr;
  for (int i = 0; ok && i < ng; i++) {
    if (fabs(got[i] - ref[i]) > root_tol(c, n, ref[i])) ok = 0;
    if (i > 0 && !(got[i] > got[i - 1])) ok = 0;  /* ascending */
  }
  if (!ok) {
    printf("# %s: got %d:", name, ng);
    for (int i = 0; i < ng; i++) printf(" %.17g", got[i]);
    printf("  ref %d:", nr);
    for (int i = 0; i < nr; i++) printf(" %.17g(tol %.2g)", ref[i], root_tol(c, n, ref[i]));
    printf("\n# c:");
    for (int i = 0; i <= n; i++) printf(" %a", c[i]);
    printf(" a=%a b=%a opts=%u\n", a, b, opts);
  }
  return ok;
}

static void test_eval(void)
{
  /* Horner's running bound must hold against the exact value. */
  mpfr_t y, g;
  mpfr_inits2(2048, y, g, (mpfr_ptr)0);
  int bad = 0, dbad = 0;
  for (int k = 0; k < 2000; k++) {
    double c[7], x = (rnd() - 0.5) * 8, err, dp;
    for (int i = 0; i <= 6; i++) c[i] = (rnd() - 0.5) * pow(10, 6 * rnd() - 3);
    double v = poly_eval(c, 6, x, &err);
    mp_eval(y, c, 6, x);
    mpfr_sub_d(g, y, v, MPFR_RNDN);
    if (mpfr_cmpabs_ui(g, 0) != 0 && fabs(mpfr_get_d(g, MPFR_RNDN)) > err) bad++;
    double v2 = poly_eval_d(c, 6, x, &dp, NULL);
    double dc[6];
    poly_deriv(c, 6, dc);
    mp_eval(y, dc, 5, x);  /* dc is exact: i * c[i] for small i is exact */
    if (v2 != v || fabs(dp - mpfr_get_d(y, MPFR_RNDN)) > 1e-12 * (fabs(dp) + 1e-300) * 1e3) dbad++;
  }
  CHECK("horner error bound holds on 2000 random sextics (bound is rigorous)", bad == 0);
  /* tolerance: derivative by Horner vs exact p', 1e-9 relative */
  CHECK("poly_eval_d value equals poly_eval; derivative within 1e-9 rel", dbad == 0);

  /* Taylor shift: p(x0 + u) from the shifted coefficients, vs exact p. */
  int sbad = 0;
  for (int k = 0; k < 500; k++) {
    double c[7], s[7], x0 = (rnd() - 0.5) * 4, u = (rnd() - 0.5) * 2;
    for (int i = 0; i <= 6; i++) c[i] = rnd() - 0.5;
    poly_shift(c, 6, x0, s);
    double v = poly_eval(s, 6, u, NULL);
    double sc = 0;
    for (int i = 0; i <= 6; i++) sc += fabs(c[i]) * pow(fabs(x0) + fabs(u), i);
    mpfr_set_d(g, x0, MPFR_RNDN);
    mpfr_add_d(g, g, u, MPFR_RNDN);
    mpfr_set_d(y, c[6], MPFR_RNDN);
    for (int i = 5; i >= 0; i--) { mpfr_mul(y, y, g, MPFR_RNDN); mpfr_add_d(y, y, c[i], MPFR_RNDN); }
    /* tolerance: 64 eps * sum |c_i| (|x0|+|u|)^i (shift + evaluation) */
    if (fabs(v - mpfr_get_d(y, MPFR_RNDN)) > 64 * DBL_EPSILON * sc) sbad++;
  }
  CHECK("poly_shift: p(x0+u) within 64 eps * sum|c||x|^i on 500 cases", sbad == 0);
  mpfr_clears(y, g, (mpfr_ptr)0);

  double c[7] = {1, 2, 0, 0, 0, 0, 0};
  CHECK("poly_degree drops zero leading coefficients", poly_degree(c, 6) == 1);
}

static void test_known(void)
{
  static const struct { const char *name; double a, b; int nre; double re[6];
                        int ncx; double cu[3], cv[3]; double lead; } cases[] = {
    {"wilkinson 1..6 on [0,7]", 0, 7, 6, {1, 2, 3, 4, 5, 6}, 0, {0}, {0}, 1},
    {"wilkinson 1..6 on [2.5,5.5]", 2.5, 5.5, 6, {1, 2, 3, 4, 5, 6}, 0, {0}, {0}, 1},
    {"wilkinson-like 10..15 on [9,16]", 9, 16, 6, {10, 11, 12, 13, 14, 15}, 0, {0}, {0}, 1},
    {"tight 1.0..1.5 step 0.1", 0.5, 2, 6, {1, 1.1, 1.2, 1.3, 1.4, 1.5}, 0, {0}, {0}, 1},
    {"spread roots", -5, 10, 6, {-3, -0.5, 0.1, 2, 2.5, 9}, 0, {0}, {0}, -0.25},
    {"clustered 1e-6 apart", 0, 5, 6, {1, 1 + 1e-6, 2, 3, 3 + 1e-6, 4}, 0, {0}, {0}, 1},
    {"three clustered 1e-6 apart", 0, 5, 6, {2, 2 + 1e-6, 2 + 2e-6, 0.5, 3, 4.5}, 0, {0}, {0}, 3},
    {"complex pairs + reals", -3, 3, 2, {-1, 0.7}, 2, {0.5, -2}, {1e-2, 1}, 1},
    {"three complex pairs", -3, 3, 0, {0}, 3, {0.5, -1, 1}, {0.3, 1e-3, 2}, 1},
    {"near-real pair 1e-4", -3, 3, 4, {-2, -1, 1, 2}, 1, {0.3}, {1e-4}, 1},
    {"cubic", -2, 2, 3, {-1, 0.25, 1.5}, 0, {0}, {0}, 2},
    {"tiny scale", -1e-3, 1e-3, 4, {-5e-4, -1e-4, 2e-4, 7e-4}, 0, {0}, {0}, 1},
    {"huge scale", -1e4, 1e4, 5, {-8e3, -1e3, 2e3, 3e3, 9e3}, 0, {0}, {0}, 1e-9},
  };
  for (unsigned k = 0; k < sizeof cases / sizeof cases[0]; k++) {
    double c[7], hint[16];
    int n = expand(cases[k].lead, cases[k].re, cases[k].nre, cases[k].cu,
                   cases[k].cv, cases[k].ncx, c);
    /* hints: midpoints between consecutive known real roots */
    double r[6];
    int nh = 0;
    for (int i = 0; i < cases[k].nre; i++) r[i] = cases[k].re[i];
    for (int i = 1; i < cases[k].nre; i++) {
      double t = r[i]; int j = i - 1;
      while (j >= 0 && r[j] > t) { r[j + 1] = r[j]; j--; }
      r[j + 1] = t;
    }
    for (int i = 0; i + 1 < cases[k].nre; i++) hint[nh++] = 0.5 * (r[i] + r[i + 1]);
    char name[160];
    poly_stats st = {0};
    snprintf(name, sizeof name, "roots (laguerre): %s", cases[k].name);
    CHECK(name, cmp_roots(name, c, n, cases[k].a, cases[k].b, hint, nh, 0, &st));
    snprintf(name, sizeof name, "roots (cascade only): %s", cases[k].name);
    CHECK(name, cmp_roots(name, c, n, cases[k].a, cases[k].b, hint, nh,
                          POLY_CASCADE_ONLY, &st));
  }
}

/* Roots of even multiplicity: touches are not reported; rounding may split
 * one into a pair of crossings, which must then both lie near it. */
static void test_multiple(void)
{
  double re[6] = {1, 1, 2, 3, -1, -1}, c[7], got[6];
  int n = expand(1, re, 6, NULL, NULL, 0, c);
  poly_stats st = {0};
  int ng = poly_roots(c, n, -2, 4, got, &st);
  int near1 = 0, nearm1 = 0, other = 0;
  for (int i = 0; i < ng; i++) {
    if (fabs(got[i] - 1) < 1e-6) near1++;        /* sqrt(eps)*10 */
    else if (fabs(got[i] + 1) < 1e-6) nearm1++;
    else if (fabs(got[i] - 2) < 1e-12 || fabs(got[i] - 3) < 1e-12) other++;
  }
  CHECK("double roots: crossings at 2 and 3 (tol 1e-12)", other == 2);
  CHECK("double roots: even count within 1e-6 of each touch", near1 % 2 == 0 && nearm1 % 2 == 0
        && near1 + nearm1 + other == ng);
  CHECK("double roots: the cascade fallback ran", st.fallbacks > 0);

  double re3[6] = {1.5, 1.5, 1.5, -1, 4, 0.25};
  n = expand(1, re3, 6, NULL, NULL, 0, c);
  ng = poly_roots(c, n, -2, 5, got, &st);
  int n15 = 0, rest = 0;
  for (int i = 0; i < ng; i++) {
    if (fabs(got[i] - 1.5) < 1e-4) n15++;   /* eps^(1/3) * 100 */
    else if (fabs(got[i] + 1) < 1e-12 || fabs(got[i] - 4) < 1e-12 || fabs(got[i] - 0.25) < 1e-12) rest++;
  }
  CHECK("triple root: odd number of crossings within 1e-4", n15 % 2 == 1 && rest == 3 && ng == n15 + rest);

  double re6[6] = {0.5, 0.5, 0.5, 0.5, 0.5, 0.5};
  n = expand(1, re6, 6, NULL, NULL, 0, c);
  ng = poly_roots(c, n, 0, 1, got, &st);
  int ok = ng >= 0 && ng % 2 == 0;
  for (int i = 0; i < ng; i++) ok = ok && fabs(got[i] - 0.5) < 0.01;  /* eps^(1/6)*5 */
  CHECK("sextuple root (x-0.5)^6: even crossings, all within 1e-2", ok);
  double re5[5] = {0.5, 0.5, 0.5, 0.5, 0.5};
  n = expand(-2, re5, 5, NULL, NULL, 0, c);
  ng = poly_roots(c, n, 0, 1, got, &st);
  ok = ng % 2 == 1;
  for (int i = 0; i < ng; i++) ok = ok && fabs(got[i] - 0.5) < 0.01;  /* eps^(1/5)*5 */
  CHECK("quintuple root: odd crossings, all within 1e-2", ok);
}

/* Random sextics: never miss a sign change. At 4000 sample points where the
 * exact value clears the double evaluation error, the parity of reported
 * crossings between consecutive samples must match the exact sign change;
 * where all roots are at least 1e-3 apart, the roots must match too. */
static void test_random(void)
{
  int parity_bad = 0, match_bad = 0, tested = 0;
  poly_stats st = {0};
  for (int k = 0; k < 400; k++) {
    double re[6], cu[3], cv[3], c[7], got[6];
    int ncx = (int)(rnd() * 3.99), nre = 6 - 2 * ncx;
    if (k % 7 == 0 && nre >= 1) nre--;  /* odd degree too */
    for (int i = 0; i < nre; i++) re[i] = (rnd() - 0.5) * 4;
    if (k % 5 == 0 && nre >= 2) re[1] = re[0] + 1e-5 * (rnd() + 0.01);  /* near-pairs */
    for (int i = 0; i < ncx; i++) { cu[i] = (rnd() - 0.5) * 4; cv[i] = pow(10, -6 * rnd()); }
    int n = expand(rnd() + 0.5, re, nre, cu, cv, ncx, c);
    double a = (rnd() - 0.5) * 4 - 0.5, b = a + 0.1 + rnd() * 4;
    int sa = poly_eval(c, n, a, NULL) > 0, sb = poly_eval(c, n, b, NULL) > 0;
    unsigned opts = k & 1 ? POLY_CASCADE_ONLY : 0;
    int ng = poly_crossings(c, n, a, b, sa, sb, opts, got, &st);
    int cur = sa, gi = 0, cnt = 0;
    for (int i = 1; i <= 4000; i++) {
      double x = a + (b - a) * i / 4000, err;
      double v = poly_eval(c, n, x, &err);
      while (gi < ng && got[gi] <= x) { gi++; cnt++; }
      if (fabs(v) <= 2 * err && i < 4000) continue;  /* undecided sample */
      int s = i < 4000 ? mp_pos(c, n, x) : sb;
      if ((cnt & 1) != (s != cur)) parity_bad++;
      cur = s;
      cnt = 0;
    }
    /* root match where the real roots are well separated */
    int sep = 1;
    for (int i = 0; i < nre; i++)
      for (int j = i + 1; j < nre; j++) if (fabs(re[i] - re[j]) < 1e-3) sep = 0;
    for (int i = 0; i < ncx; i++) if (cv[i] < 1e-3) sep = 0;
    if (sep) {
      tested++;
      double hint[16];
      int nh = 0;
      for (int i = 0; i < nre; i++) {
        hint[nh++] = re[i] - 4e-4;
        hint[nh++] = re[i] + 4e-4;
      }
      char name[64];
      snprintf(name, sizeof name, "random %d", k);
      st.solves--;  /* cmp_roots solves again */
      if (!cmp_roots(name, c, n, a, b, hint, nh, opts, &st)) match_bad++;
    }
  }
  CHECK("random sextics: crossing parity matches exact signs at 4000 samples (400 polys)", parity_bad == 0);
  CHECK("random separated sextics: roots match MPFR reference within root_tol", match_bad == 0 && tested > 50);
  CHECK("random sextics: both laguerre and fallback paths exercised", st.laguerre > 0 && st.fallbacks > 0);
  printf("# poly stats: solves %ld quick %ld laguerre %ld fallbacks %ld\n",
         st.solves, st.quick, st.laguerre, st.fallbacks);
}

/* Imposed end states: crossings consistent with them. */
static void test_imposed(void)
{
  double c[3] = {-1, 0, 1}, got[6];  /* x^2 - 1 */
  int n = poly_crossings(c, 2, 1, 3, 1, 1, 0, got, NULL);
  CHECK("imposed: root on the left end counted by the left neighbour only", n == 0);
  n = poly_crossings(c, 2, -0.5, 1, 0, 1, 0, got, NULL);
  CHECK("imposed: root at right end reported once, at the end (tol 1e-15)", n == 1 && fabs(got[0] - 1) < 1e-15);
  n = poly_crossings(c, 2, 0.5, 3, 1, 1, 0, got, NULL);
  CHECK("imposed: state disagreeing at a puts a crossing pair in (a,b)", n == 0 || n == 2);
  double k[1] = {2};
  n = poly_crossings(k, 0, 0, 1, 0, 1, 0, got, NULL);
  CHECK("constant with imposed states: crossing at the disagreeing end", n == 1 && got[0] == 0);
  double lin[2] = {-1, 4};
  n = poly_roots(lin, 1, 0, 1, got, NULL);
  CHECK_NEAR("linear root (tol 1 ulp)", n == 1 ? got[0] : -1, 0.25, 1e-16);
}

/* The iteration counters a soft-object Trace prints: Laguerre finds each of
 * the n roots of the deflated polynomials and polishes each on p, so an
 * accepted solve takes at least 2n iterations (and at most the 80 of each
 * call's limit), no Newton step; the cascade takes no Laguerre iteration
 * and at least one bracket step per crossing; a solve settled by the range
 * bound takes none. */
static void test_steps(void)
{
  double re[6] = {1, 2, 3, 4, 5, 6}, c[7], got[6];
  int n = expand(1, re, 6, NULL, NULL, 0, c);
  poly_stats st = {0};
  int k = poly_crossings(c, n, 0, 7, 1, 1, 0, got, &st);
  CHECK("steps: Laguerre settles wilkinson 1..6 with 6 crossings",
        k == 6 && st.laguerre == 1 && st.fallbacks == 0);
  CHECK("steps: Laguerre takes 2n..160n iterations, no bracket step",
        st.laguerre_steps >= 12 && st.laguerre_steps <= 160 * 6 &&
        st.bracket_steps == 0);
  poly_stats sc = {0};
  k = poly_crossings(c, n, 0, 7, 1, 1, POLY_CASCADE_ONLY, got, &sc);
  CHECK("steps: the cascade takes no Laguerre iteration, >= 1 step a root",
        k == 6 && sc.laguerre_steps == 0 && sc.bracket_steps >= 6);
  poly_stats sq = {0};
  double far[3] = {2, 0, 1};  /* x^2 + 2 > 0 */
  k = poly_crossings(far, 2, -1, 1, 1, 1, 0, got, &sq);
  CHECK("steps: a solve settled by its range takes no iteration",
        k == 0 && sq.quick == 1 && sq.laguerre_steps == 0 &&
        sq.bracket_steps == 0);
  poly_stats sl = {0};
  double lin[2] = {-1, 4};
  k = poly_crossings(lin, 1, 0, 1, 0, 1, 0, got, &sl);
  CHECK("steps: a monotone p is bracketed, no Laguerre iteration",
        k == 1 && sl.laguerre_steps == 0 && sl.bracket_steps >= 1);
}

int main(void)
{
  check_prefix = "poly";
  test_eval();
  test_known();
  test_multiple();
  test_random();
  test_imposed();
  test_steps();
  CHECK_DONE();
}
