/* test_soft.c: soft.c against independent references.
 *
 * The field reference evaluates eq. (1) in the paper's own form, from the
 * distance r (or the full 4x4 quadratic form u'Mu) at each point: in MPFR
 * at 256 bits for point tests, in long double for ray tests. It never
 * builds a polynomial in t. Ray crossings are found by dense sampling of
 * that field along the ray (spacing DT) and long double bisection of each
 * sign change. A ray is "ambiguous" when the sampled g = field - magic has
 * a discrete local extremum with |g| below the largest dip that could hide
 * between two samples (M DT^2, M a bound on |g''|); for those only the
 * well-conditioned reference crossings are required, not the count. */
#include "check.h"
#include "core/soft.h"

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

/* A test key: the soft_key plus what the test knows about its shape from
 * construction: a bounding sphere and its smallest semi-axis. */
typedef struct {
  soft_key k;
  double bc[3], brad, emin;
} tkey;

static tkey sphere_key(double x, double y, double z, double R, double w)
{
  tkey t;
  memset(&t, 0, sizeof t);
  t.k.kind = SOFT_SPHERE;
  t.k.c[0] = x; t.k.c[1] = y; t.k.c[2] = z;
  t.k.R = R; t.k.w = w;
  t.bc[0] = x; t.bc[1] = y; t.bc[2] = z;
  t.brad = R; t.emin = R;
  return t;
}

/* Ellipsoid key: centre c, semi-axes R*ax[i] along a random rotation.
 * M = [[A, -A c], [-c'A, c'A c]] with A = Rot diag(1/ax^2) Rot'. */
static tkey quadric_key(const double c[3], const double ax[3], double R, double w)
{
  tkey t;
  memset(&t, 0, sizeof t);
  double q[4] = {rnd() - 0.5, rnd() - 0.5, rnd() - 0.5, rnd() - 0.5}, n = 0;
  for (int i = 0; i < 4; i++) n += q[i] * q[i];
  n = sqrt(n);
  for (int i = 0; i < 4; i++) q[i] /= n;
  double a = q[0], b = q[1], cc = q[2], d = q[3];
  double rot[3][3] = {
    {a*a + b*b - cc*cc - d*d, 2*(b*cc - a*d), 2*(b*d + a*cc)},
    {2*(b*cc + a*d), a*a - b*b + cc*cc - d*d, 2*(cc*d - a*b)},
    {2*(b*d - a*cc), 2*(cc*d + a*b), a*a - b*b - cc*cc + d*d}};
  double A[3][3];
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      A[i][j] = 0;
      for (int k = 0; k < 3; k++) A[i][j] += rot[i][k] * rot[j][k] / (ax[k] * ax[k]);
    }
  t.k.kind = SOFT_QUADRIC;
  double Ac[3], cAc = 0;
  for (int i = 0; i < 3; i++) {
    Ac[i] = A[i][0] * c[0] + A[i][1] * c[1] + A[i][2] * c[2];
    cAc += c[i] * Ac[i];
  }
  for (int i = 0; i < 3; i++) {
    for (int j = 0; j < 3; j++) t.k.m[i][j] = A[i][j];
    t.k.m[i][3] = t.k.m[3][i] = -Ac[i];
  }
  t.k.m[3][3] = cAc;
  t.k.R = R; t.k.w = w;
  double amax = fmax(ax[0], fmax(ax[1], ax[2])), amin = fmin(ax[0], fmin(ax[1], ax[2]));
  for (int i = 0; i < 3; i++) t.bc[i] = c[i];
  t.brad = R * amax * 1.001;
  t.emin = R * amin;
  return t;
}

static soft_obj *build(const tkey *tk, int n, double magic)
{
  soft_key keys[256];
  for (int i = 0; i < n; i++) keys[i] = tk[i].k;
  soft_obj *o;
  size_t bad;
  if (soft_build(keys, n, magic, &o, &bad) != SOFT_OK) return NULL;
  return o;
}

/* ---- references ---------------------------------------------------------- */

/* eq. (1) in MPFR from the distance / the full quadratic form. */
static void mp_field(mpfr_t f, const tkey *tk, int n, const double p[3])
{
  mpfr_t s, t, u, x2, R2;
  mpfr_inits2(256, s, t, u, x2, R2, (mpfr_ptr)0);
  mpfr_set_zero(f, 1);
  for (int j = 0; j < n; j++) {
    const soft_key *k = &tk[j].k;
    mpfr_set_zero(s, 1);
    if (k->kind == SOFT_SPHERE) {
      for (int i = 0; i < 3; i++) {
        mpfr_set_d(t, p[i], MPFR_RNDN);
        mpfr_sub_d(t, t, k->c[i], MPFR_RNDN);
        mpfr_sqr(t, t, MPFR_RNDN);
        mpfr_add(s, s, t, MPFR_RNDN);
      }
    } else {
      double uu[4] = {p[0], p[1], p[2], 1};
      for (int a = 0; a < 4; a++)
        for (int b = 0; b < 4; b++) {
          mpfr_set_d(t, uu[a], MPFR_RNDN);
          mpfr_mul_d(t, t, uu[b], MPFR_RNDN);
          mpfr_mul_d(t, t, k->m[a][b], MPFR_RNDN);
          mpfr_add(s, s, t, MPFR_RNDN);
        }
    }
    mpfr_set_d(R2, k->R, MPFR_RNDN);
    mpfr_sqr(R2, R2, MPFR_RNDN);
    mpfr_div(x2, s, R2, MPFR_RNDN);  /* (r/R)^2 */
    if (mpfr_cmp_ui(x2, 1) >= 0) continue;
    /* -4/9 x^6 + 17/9 x^4 - 22/9 x^2 + 1 */
    mpfr_pow_ui(t, x2, 3, MPFR_RNDN);
    mpfr_mul_si(t, t, -4, MPFR_RNDN);
    mpfr_sqr(u, x2, MPFR_RNDN);
    mpfr_mul_ui(u, u, 17, MPFR_RNDN);
    mpfr_add(t, t, u, MPFR_RNDN);
    mpfr_mul_ui(u, x2, 22, MPFR_RNDN);
    mpfr_sub(t, t, u, MPFR_RNDN);
    mpfr_div_ui(t, t, 9, MPFR_RNDN);
    mpfr_add_ui(t, t, 1, MPFR_RNDN);
    mpfr_mul_d(t, t, k->w, MPFR_RNDN);
    mpfr_add(f, f, t, MPFR_RNDN);
  }
  mpfr_clears(s, t, u, x2, R2, (mpfr_ptr)0);
}

/* The same in long double at the point o + tau dn (dn unit). */
static long double ld_field(const tkey *tk, int n, const long double o[3],
                            const long double dn[3], long double tau)
{
  long double f = 0, x[3];
  for (int i = 0; i < 3; i++) x[i] = o[i] + tau * dn[i];
  for (int j = 0; j < n; j++) {
    const soft_key *k = &tk[j].k;
    long double s = 0;
    if (k->kind == SOFT_SPHERE) {
      long double r2 = 0;
      for (int i = 0; i < 3; i++) r2 += (x[i] - k->c[i]) * (x[i] - k->c[i]);
      long double q = sqrtl(r2) / k->R;  /* r/R */
      if (q >= 1) continue;
      f += k->w * (-4.0L / 9 * powl(q, 6) + 17.0L / 9 * powl(q, 4) - 22.0L / 9 * q * q + 1);
      continue;
    }
    long double uu[4] = {x[0], x[1], x[2], 1};
    for (int a = 0; a < 4; a++)
      for (int b = 0; b < 4; b++) s += (long double)k->m[a][b] * uu[a] * uu[b];
    s /= (long double)k->R * k->R;
    if (s >= 1) continue;
    f += k->w * (-4.0L / 9 * s * s * s + 17.0L / 9 * s * s - 22.0L / 9 * s + 1);
  }
  return f;
}

typedef struct {
  double tau[512];   /* crossings, in length along the unit direction */
  double slope[512]; /* |dg/dtau| there */
  int n, ambiguous;
} ref_t;

/* Dense sign-change search of g = field - magic on [ta, tb] (length units). */
static void ref_roots(const tkey *tk, int n, double magic, const double o[3],
                      const double d[3], double ta, double tb, double dt,
                      ref_t *ref)
{
  long double lo_[3], dn[3], len = 0;
  for (int i = 0; i < 3; i++) len += (long double)d[i] * d[i];
  len = sqrtl(len);
  for (int i = 0; i < 3; i++) { lo_[i] = o[i]; dn[i] = d[i] / len; }
  /* clip to the keys' bounding spheres: outside, g = -magic */
  double kmin = INFINITY, kmax = -INFINITY, M = 0;
  for (int j = 0; j < n; j++) {
    long double b = 0, c2 = 0;
    for (int i = 0; i < 3; i++) {
      long double p = lo_[i] - tk[j].bc[i];
      b += p * dn[i];
      c2 += p * p;
    }
    long double disc = b * b - (c2 - (long double)tk[j].brad * tk[j].brad);
    if (disc < 0) continue;
    kmin = fmin(kmin, (double)(-b - sqrtl(disc)));
    kmax = fmax(kmax, (double)(-b + sqrtl(disc)));
    M += fabs(tk[j].k.w) * 20 / (tk[j].emin * tk[j].emin);
  }
  ref->n = 0;
  ref->ambiguous = 0;
  double a = fmax(ta, kmin - dt), b = fmin(tb, kmax + dt);
  if (!(a < b)) return;
  double delta = 2 * M * dt * dt;  /* largest hidden dip: M dt^2 / 2, x4 */
  int ns = (int)ceil((b - a) / dt);
  long double gprev2 = 0, gprev = 0;
  for (int i = 0; i <= ns; i++) {
    long double t = a + (long double)(b - a) * i / ns;
    long double g = ld_field(tk, n, lo_, dn, t) - magic;
    if (i >= 2 && fabsl(gprev) <= delta && (gprev - gprev2) * (g - gprev) < 0)
      ref->ambiguous = 1;
    if (i >= 1 && (g > 0) != (gprev > 0) && ref->n < 512) {
      long double lo = a + (long double)(b - a) * (i - 1) / ns, hi = t;
      int slo = gprev > 0;
      for (int it = 0; it < 80; it++) {
        long double mid = 0.5L * (lo + hi);
        if ((ld_field(tk, n, lo_, dn, mid) - magic > 0) == slo) lo = mid; else hi = mid;
      }
      long double r = 0.5L * (lo + hi), e = 1e-7L;
      ref->tau[ref->n] = (double)r;
      ref->slope[ref->n] = (double)fabsl((ld_field(tk, n, lo_, dn, r + e) -
                                          ld_field(tk, n, lo_, dn, r - e)) / (2 * e));
      ref->n++;
    }
    gprev2 = gprev;
    gprev = g;
  }
}

/* ---- comparing -------------------------------------------------------------- */

typedef struct {
  int rays, ambiguous, bad_count, bad_pos, bad_order, bad_ret;
  double worst;  /* largest |error| / tolerance seen */
} tally;

/* Compare soft_roots with the reference on one ray. Tolerance for a
 * crossing with reference slope g' (length units):
 *   tol = (2e-15 * W + 4e-16 * D) / |g'| + 2e-15 * (1 + D)
 * W = sum |w| (rounding of the sextic's coefficients), D = distance from
 * the origin to the keys plus |tau| (rounding of the key offsets). Only
 * crossings with |g'| >= 1e-4 are held to it (the rest are near-tangent). */
static void compare_ray(const tkey *tk, int n, const soft_obj *obj, double magic,
                        const double o[3], const double d[3], double t0,
                        double t1, double dt, soft_scratch *s, soft_stats *st,
                        tally *ty)
{
  double dl = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  ref_t ref;
  ref_roots(tk, n, magic, o, d, t0 * dl, t1 * dl, dt, &ref);
  double got[512];
  int ng = soft_roots(obj, o, d, t0, t1, got, 512, s, st);
  ty->rays++;
  if (ng < 0) { ty->bad_ret++; return; }
  for (int i = 1; i < ng; i++) if (!(got[i] > got[i - 1])) ty->bad_order++;
  for (int i = 0; i < ng; i++) if (!(got[i] > t0 && got[i] < t1)) ty->bad_order++;
  double W = 0, D = sqrt(o[0] * o[0] + o[1] * o[1] + o[2] * o[2]);
  for (int j = 0; j < n; j++) {
    W += fabs(tk[j].k.w);
    double e = 0;
    for (int i = 0; i < 3; i++) e += (o[i] - tk[j].bc[i]) * (o[i] - tk[j].bc[i]);
    D = fmax(D, sqrt(e));
  }
  if (ref.ambiguous) ty->ambiguous++;
  else if (ng != ref.n) {
    ty->bad_count++;
    printf("# count: got %d ref %d\n", ng, ref.n);
    return;
  }
  /* every well-conditioned reference crossing has a computed one nearby */
  for (int i = 0; i < ref.n; i++) {
    if (ref.slope[i] < 1e-4) continue;
    double tol = (2e-15 * W + 4e-16 * (D + fabs(ref.tau[i]))) / ref.slope[i] +
                 2e-15 * (1 + D + fabs(ref.tau[i]));
    double best = INFINITY;
    for (int j = 0; j < ng; j++) best = fmin(best, fabs(got[j] * dl - ref.tau[i]));
    if (best > tol) {
      ty->bad_pos++;
      printf("# position: ref %.17g slope %.3g err %.3g tol %.3g\n", ref.tau[i], ref.slope[i], best, tol);
    }
    if (best / tol > ty->worst) ty->worst = best / tol;
  }
}

static void report(const char *what, const tally *ty)
{
  char name[200];
  snprintf(name, sizeof name, "%s: %d rays (%d ambiguous) count matches dense reference", what, ty->rays, ty->ambiguous);
  CHECK(name, ty->bad_count == 0 && ty->bad_ret == 0 && ty->rays > 0);
  snprintf(name, sizeof name, "%s: crossings within tolerance (worst err/tol %.3g)", what, ty->worst);
  CHECK(name, ty->bad_pos == 0);
  snprintf(name, sizeof name, "%s: crossings strictly ascending, inside (t0, t1)", what);
  CHECK(name, ty->bad_order == 0);
}

static void random_dir(double d[3])
{
  double n;
  do {
    for (int i = 0; i < 3; i++) d[i] = 2 * rnd() - 1;
    n = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
  } while (n > 1 || n < 1e-3);
  n = sqrt(n);
  for (int i = 0; i < 3; i++) d[i] /= n;
}

/* A random ray passing near a point of the cloud box [-1.5, 1.5]^3 + off. */
static void aim_ray(const double off[3], double span, double o[3], double d[3])
{
  double target[3];
  random_dir(d);
  for (int i = 0; i < 3; i++) target[i] = off[i] + (rnd() - 0.5) * span;
  for (int i = 0; i < 3; i++) o[i] = target[i] - 6 * d[i];
}

/* ---- tests ------------------------------------------------------------------- */

static void test_build(void)
{
  soft_key k[3];
  memset(k, 0, sizeof k);
  for (int i = 0; i < 3; i++) { k[i].kind = SOFT_SPHERE; k[i].R = 1; k[i].w = 1; }
  soft_obj *o;
  size_t bad;
  k[1].R = 0;
  CHECK("build: R = 0 rejected with the key's index", soft_build(k, 3, 0.5, &o, &bad) == SOFT_ERR_RADIUS && bad == 1 && !o);
  k[1].R = 1;
  k[2].c[1] = NAN;
  CHECK("build: NaN centre rejected", soft_build(k, 3, 0.5, &o, &bad) == SOFT_ERR_NONFINITE && bad == 2);
  k[2].c[1] = 0;
  k[0].w = INFINITY;
  CHECK("build: infinite weight rejected", soft_build(k, 3, 0.5, &o, &bad) == SOFT_ERR_NONFINITE && bad == 0);
  k[0].w = 1;
  CHECK("build: magic <= 0 rejected", soft_build(k, 3, 0, &o, &bad) == SOFT_ERR_MAGIC);
  k[2].kind = SOFT_QUADRIC;  /* cylinder x^2 + y^2: 3x3 block singular */
  k[2].m[0][0] = k[2].m[1][1] = 1;
  CHECK("build: cylinder quadric rejected as unbounded", soft_build(k, 3, 0.5, &o, &bad) == SOFT_ERR_UNBOUNDED && bad == 2);
  k[2].m[2][2] = 4;
  int err = soft_build(k, 3, 0.5, &o, &bad);
  CHECK("build: ellipsoid quadric accepted", err == SOFT_OK && o && soft_nkeys(o) == 3);
  double lo[3], hi[3];
  /* ellipsoid x^2 + y^2 + 4 z^2 < 1: z half-extent 0.5 (tol 1e-9) */
  if (o) {
    soft_bounds(o, lo, hi);
    CHECK_NEAR("bounds: z extent of ellipsoid key and unit spheres", hi[2], 1, 1e-9);
    soft_free(o);
  }
  k[2].w = -5;  /* negative keys only subtract: not in the box */
  k[1].c[0] = 10;
  err = soft_build(k, 3, 0.5, &o, &bad);
  if (err == SOFT_OK) {
    soft_bounds(o, lo, hi);
    CHECK_NEAR("bounds: union of positive keys only, hi x (tol 1e-12)", hi[0], 11, 1e-12);
    CHECK_NEAR("bounds: union of positive keys only, lo x (tol 1e-12)", lo[0], -1, 1e-12);
    soft_free(o);
  }
  CHECK("strerror names errors", strstr(soft_strerror(SOFT_ERR_UNBOUNDED), "bounded") != NULL);
}

static int make_cloud(tkey *tk, int n, const double off[3], int negatives,
                      int quadrics)
{
  for (int j = 0; j < n; j++) {
    double c[3] = {off[0] + (rnd() - 0.5) * 2.4, off[1] + (rnd() - 0.5) * 2.4,
                   off[2] + (rnd() - 0.5) * 2.4};
    double R = 0.4 + 0.5 * rnd(), w = 0.5 + rnd();
    if (negatives && rnd() < 0.3) w = -w;
    if (quadrics && rnd() < 0.4) {
      double ax[3] = {0.5 + rnd(), 0.5 + rnd(), 0.5 + rnd()};
      tk[j] = quadric_key(c, ax, R, w);
    } else {
      tk[j] = sphere_key(c[0], c[1], c[2], R, w);
    }
  }
  return n;
}

static void test_field(void)
{
  tkey tk[40];
  double off[3] = {0, 0, 0};
  make_cloud(tk, 40, off, 1, 1);
  soft_obj *o = build(tk, 40, 0.5);
  CHECK("field: mixed cloud builds", o != NULL);
  if (!o) return;
  mpfr_t f, fp, fm;
  mpfr_inits2(256, f, fp, fm, (mpfr_ptr)0);
  double W = 0;
  for (int j = 0; j < 40; j++) W += fabs(tk[j].k.w);
  int fbad = 0, gbad = 0;
  double worst = 0;
  for (int i = 0; i < 2000; i++) {
    double p[3] = {(rnd() - 0.5) * 4, (rnd() - 0.5) * 4, (rnd() - 0.5) * 4}, g[3];
    double v = soft_field(o, p), v2 = soft_field_grad(o, p, g);
    mp_field(f, tk, 40, p);
    double ref = mpfr_get_d(f, MPFR_RNDN);
    /* tolerance: 1e-14 * sum |w| (a few roundings per key) */
    if (fabs(v - ref) > 1e-14 * W || v2 != v) fbad++;
    worst = fmax(worst, fabs(v - ref) / W);
    for (int a = 0; a < 3; a++) {
      /* central difference of the MPFR field, h = 1e-6: truncation
       * h^2 |f'''| / 6 < 1e-9 W here, so tolerance 1e-7 * sum |w| */
      double pp[3] = {p[0], p[1], p[2]};
      pp[a] = p[a] + 1e-6;
      mp_field(fp, tk, 40, pp);
      pp[a] = p[a] - 1e-6;
      mp_field(fm, tk, 40, pp);
      mpfr_sub(fp, fp, fm, MPFR_RNDN);
      double dref = mpfr_get_d(fp, MPFR_RNDN) / ((p[a] + 1e-6) - (p[a] - 1e-6));
      if (fabs(g[a] - dref) > 1e-7 * W) gbad++;
    }
  }
  mpfr_clears(f, fp, fm, (mpfr_ptr)0);
  char name[160];
  snprintf(name, sizeof name, "field vs MPFR at 2000 points, 40 mixed keys (tol 1e-14 sum|w|; worst %.2g)", worst);
  CHECK(name, fbad == 0);
  CHECK("gradient vs MPFR central difference (tol 1e-7 sum|w|)", gbad == 0);
  /* bounds: no inside point outside the box */
  double lo[3], hi[3];
  soft_bounds(o, lo, hi);
  int out = 0;
  for (int i = 0; i < 20000; i++) {
    double p[3] = {(rnd() - 0.5) * 6, (rnd() - 0.5) * 6, (rnd() - 0.5) * 6};
    if (soft_field(o, p) > 0.5)
      for (int a = 0; a < 3; a++) if (p[a] < lo[a] || p[a] > hi[a]) out++;
  }
  CHECK("bounds: every sampled inside point lies in soft_bounds", out == 0);
  soft_free(o);
}

/* The gradient in long double from the definition: sum of w dC/ds grad s
 * with C(s) = 1 - 22/9 s + 17/9 s^2 - 4/9 s^3, s = |x - c|^2 / R^2 (grad s
 * = 2 (x - c) / R^2) or u'Mu / R^2 (grad s = 2 (M u)_xyz / R^2, M
 * symmetric as built). */
static void ld_grad(const tkey *tk, int n, const double p[3], long double g[3])
{
  g[0] = g[1] = g[2] = 0;
  for (int j = 0; j < n; j++) {
    const soft_key *k = &tk[j].k;
    long double s = 0, gs[3], R2 = (long double)k->R * k->R;
    if (k->kind == SOFT_SPHERE) {
      for (int i = 0; i < 3; i++) {
        long double d = (long double)p[i] - k->c[i];
        s += d * d;
        gs[i] = 2 * d / R2;
      }
      s /= R2;
    } else {
      long double uu[4] = {p[0], p[1], p[2], 1}, mu[4] = {0, 0, 0, 0};
      for (int a = 0; a < 4; a++)
        for (int b = 0; b < 4; b++) mu[a] += (long double)k->m[a][b] * uu[b];
      for (int a = 0; a < 4; a++) s += uu[a] * mu[a];
      s /= R2;
      for (int i = 0; i < 3; i++) gs[i] = 2 * mu[i] / R2;
    }
    if (s >= 1) continue;
    long double dc = -22.0L / 9 + 34.0L / 9 * s - 12.0L / 9 * s * s;
    for (int i = 0; i < 3; i++) g[i] += k->w * dc * gs[i];
  }
}

/* soft_field_box and soft_grad_box (the mesher's cell proofs) hold the
 * field (MPFR) and the gradient (long double, from the definition) at
 * the corners and random points of 600 random boxes of sides 1e-3 to 1
 * over a cloud of spheres, ellipsoids and negative keys. */
static void test_box_bounds(void)
{
  tkey tk[40];
  double off[3] = {0, 0, 0};
  make_cloud(tk, 40, off, 1, 1);
  soft_obj *o = build(tk, 40, 0.5);
  CHECK("box bounds: the cloud builds", o != NULL);
  if (!o) return;
  mpfr_t f;
  mpfr_init2(f, 256);
  int fbad = 0, gbad = 0, pts = 0;
  double width = 0;
  for (int b = 0; b < 600; b++) {
    double side = pow(10, -3 * rnd()), lo[3], hi[3], fl, fh, gl[3], gh[3];
    for (int a = 0; a < 3; a++) {
      lo[a] = (rnd() - 0.5) * 3.2;
      hi[a] = lo[a] + side * (0.5 + rnd());
    }
    soft_field_box(o, lo, hi, &fl, &fh);
    soft_grad_box(o, lo, hi, gl, gh);
    for (int a = 0; a < 3; a++) width = fmax(width, (gh[a] - gl[a]) / side);
    for (int q = 0; q < 24; q++, pts++) {
      double p[3];
      for (int a = 0; a < 3; a++)
        p[a] = q < 8 ? (q >> a & 1 ? hi[a] : lo[a]) : lo[a] + rnd() * (hi[a] - lo[a]);
      mp_field(f, tk, 40, p);
      double v = mpfr_get_d(f, MPFR_RNDN);
      if (v < fl || v > fh) fbad++;
      long double g[3];
      ld_grad(tk, 40, p, g);
      for (int a = 0; a < 3; a++)
        if (g[a] < gl[a] || g[a] > gh[a]) gbad++;
    }
  }
  mpfr_clear(f);
  char name[200];
  snprintf(name, sizeof name, "soft_field_box holds the field (MPFR) at %d points of 600 boxes", pts);
  CHECK(name, fbad == 0);
  snprintf(name, sizeof name, "soft_grad_box holds the gradient (long double) at %d points of 600 boxes", pts);
  CHECK(name, gbad == 0);
  /* not vacuous: a small box's gradient range is narrow */
  double lo[3] = {0.1, 0.2, 0.3}, hi[3] = {0.101, 0.201, 0.301}, gl[3], gh[3];
  soft_grad_box(o, lo, hi, gl, gh);
  long double g[3];
  ld_grad(tk, 40, lo, g);
  double gw = 0, gn = 0;
  for (int a = 0; a < 3; a++) {
    gw = fmax(gw, gh[a] - gl[a]);
    gn += (double)(g[a] * g[a]);
  }
  snprintf(name, sizeof name, "soft_grad_box over a 0.001 box: width %.3g against |grad| %.3g", gw, sqrt(gn));
  CHECK(name, gw < 0.05 * sqrt(gn));
  soft_free(o);
}

/* soft_surface_bounds is conservative: no point with field >= magic lies
 * outside it, over clouds of mixed keys (spheres, ellipsoids, negative
 * weights), dense and sparse, and magic from 0.05 to 2. */
static void test_surface_bounds(void)
{
  soft_key one = {0};
  one.kind = SOFT_SPHERE;
  one.R = 2;
  one.w = 1;
  soft_obj *o;
  size_t bad;
  double lo[3], hi[3];
  int ok = soft_build(&one, 1, 0.5, &o, &bad) == SOFT_OK &&
           soft_surface_bounds(o, lo, hi);
  /* C(1/4) = 1/2: the surface is at r = R / 2 */
  CHECK("surface bounds: a lone key of weight 1, magic 0.5: radius R / 2",
        ok && fabs(hi[0] - 1) < 1e-6 && fabs(lo[2] + 1) < 1e-6);
  if (o) soft_free(o);
  static const double magics[] = {0.05, 0.3, 0.5, 1, 2};
  int out = 0, inside = 0;
  double shrink = 0;
  for (int trial = 0; trial < 20; trial++) {
    tkey tk[40];
    double off[3] = {0, 0, 0};
    int nk = trial % 2 ? 40 : 10; /* dense or sparse */
    make_cloud(tk, nk, off, trial % 3 != 0, 1);
    double magic = magics[trial % 5];
    o = build(tk, nk, magic);
    if (!o) { out++; continue; }
    double blo[3], bhi[3];
    if (soft_bounds(o, blo, bhi)) {
      int has = soft_surface_bounds(o, lo, hi);
      double vb = 1, vs = 1;
      for (int a = 0; a < 3; a++) {
        vb *= bhi[a] - blo[a];
        vs *= has ? hi[a] - lo[a] : 0;
      }
      shrink += vs / vb;
      for (int i = 0; i < 20000; i++) {
        double p[3];
        for (int a = 0; a < 3; a++) p[a] = blo[a] + rnd() * (bhi[a] - blo[a]);
        if (soft_field(o, p) >= magic) {
          inside++;
          for (int a = 0; a < 3; a++)
            if (!has || p[a] < lo[a] || p[a] > hi[a]) { out++; break; }
        }
      }
    }
    soft_free(o);
  }
  char name[200];
  snprintf(name, sizeof name, "surface bounds: all of %d sampled points with "
           "field >= magic inside (20 clouds; mean volume %.2f of soft_bounds')",
           inside, shrink / 20);
  CHECK(name, out == 0 && inside > 1000);
}

static void cloud_rays(const char *what, tkey *tk, int n, double magic,
                       const double off[3], int nrays, double dscale)
{
  soft_obj *o = build(tk, n, magic);
  if (!o) { CHECK(what, 0); return; }
  soft_scratch *s = soft_scratch_new(n);
  soft_stats st;
  memset(&st, 0, sizeof st);
  tally ty;
  memset(&ty, 0, sizeof ty);
  for (int r = 0; r < nrays; r++) {
    double or_[3], d[3];
    aim_ray(off, 3, or_, d);
    for (int i = 0; i < 3; i++) d[i] *= dscale;
    compare_ray(tk, n, o, magic, or_, d, 0, INFINITY, 2e-3, s, &st, &ty);
  }
  report(what, &ty);
  printf("# %s: keys/ray %.1f intervals/ray %.1f solves %ld laguerre %ld fallbacks %ld\n", what,
         (double)st.keys / st.rays, (double)st.intervals / st.rays, st.poly.solves,
         st.poly.laguerre, st.poly.fallbacks);
  soft_scratch_free(s);
  soft_free(o);
}

static void test_clouds(void)
{
  tkey tk[64];
  double off[3] = {0, 0, 0};
  make_cloud(tk, 20, off, 0, 0);
  cloud_rays("random rays, 20 positive spheres", tk, 20, 0.5, off, 150, 1);
  make_cloud(tk, 24, off, 1, 0);
  cloud_rays("random rays, 24 spheres incl. negative", tk, 24, 0.5, off, 150, 1);
  make_cloud(tk, 24, off, 1, 1);
  cloud_rays("random rays, 24 mixed spheres/quadrics incl. negative", tk, 24, 0.5, off, 150, 1);
  make_cloud(tk, 20, off, 1, 1);
  cloud_rays("direction length 1e-3", tk, 20, 0.5, off, 60, 1e-3);
  cloud_rays("direction length 1e3", tk, 20, 0.5, off, 60, 1e3);
  cloud_rays("magic 1e-6", tk, 20, 1e-6, off, 60, 1);

  /* keys at 1e6 from the origin, rays from near the origin (spheres: the
   * long double reference keeps r exact enough there) */
  double far[3] = {1e6, -1e6, 1e6};
  make_cloud(tk, 20, far, 1, 0);
  soft_obj *o = build(tk, 20, 0.5);
  soft_scratch *s = soft_scratch_new(20);
  tally ty;
  memset(&ty, 0, sizeof ty);
  for (int r = 0; r < 40; r++) {
    double org[3] = {rnd(), rnd(), rnd()}, tg[3], d[3];
    for (int i = 0; i < 3; i++) tg[i] = far[i] + (rnd() - 0.5) * 3;
    for (int i = 0; i < 3; i++) d[i] = tg[i] - org[i];  /* |d| ~ 1.7e6 */
    compare_ray(tk, 20, o, 0.5, org, d, 0, INFINITY, 2e-3, s, NULL, &ty);
  }
  report("keys at 1e6 from the ray origin", &ty);
  soft_scratch_free(s);
  soft_free(o);
}

/* Rays parallel to an axis, their other direction components +0 or -0
 * (the key BVH's slab test takes a box's near and far sides by the
 * direction's signs, -0 included), through a lattice of equal keys whose
 * bounds, and so the BVH's boxes, share face planes; some rays run in
 * those planes (a key's bound's face, a lattice plane). Checked against
 * the dense long-double reference. */
static void test_axis_rays(void)
{
  tkey tk[64];
  int n = 0;
  for (int i = 0; i < 4; i++)
    for (int j = 0; j < 4; j++)
      for (int k = 0; k < 4; k++)
        tk[n++] = sphere_key(0.5 * i - 0.75, 0.5 * j - 0.75, 0.5 * k - 0.75,
                             0.5, (i + j + k) % 3 ? 0.6 : 0.9);
  soft_obj *o = build(tk, n, 0.5);
  soft_scratch *s = soft_scratch_new((size_t)n);
  tally ty;
  memset(&ty, 0, sizeof ty);
  int faces = 0;
  for (int axis = 0; axis < 3; axis++)
    for (int sg = -1; sg <= 1; sg += 2)
      for (int zs = 0; zs < 2; zs++)
        for (int r = 0; r < 8; r++) {
          double d[3], org[3], tg[3];
          for (int i = 0; i < 3; i++) {
            d[i] = zs ? -0.0 : 0.0;
            /* r < 4: in lattice planes or on bound faces (0.25 + 0.5 m,
               -0.75 + 0.5 m); else anywhere in the lattice's box */
            tg[i] = r < 4 ? -0.75 + 0.25 * (double)((r + 3 * i) % 7)
                          : (rnd() - 0.5) * 2.2;
          }
          d[axis] = sg;
          faces += r < 4;
          for (int i = 0; i < 3; i++) org[i] = tg[i] - 4 * d[i];
          compare_ray(tk, n, o, 0.5, org, d, 0, INFINITY, 2e-3, s, NULL, &ty);
        }
  report("axis-parallel rays (other components +0 and -0) through a lattice", &ty);
  CHECK("axis-parallel rays: some run in the bounds' face planes", faces == 48);
  soft_scratch_free(s);
  soft_free(o);
}

static void test_helix(void)
{
  tkey tk[50];
  for (int k = 0; k < 50; k++)
    tk[k] = sphere_key(cos(0.45 * k), sin(0.45 * k), 0.08 * k - 2, 0.6, 1);
  double off[3] = {0, 0, 0};
  soft_obj *o = build(tk, 50, 0.5);
  soft_scratch *s = soft_scratch_new(50);
  tally ty;
  memset(&ty, 0, sizeof ty);
  for (int r = 0; r < 150; r++) {
    double org[3], d[3];
    aim_ray(off, 3, org, d);
    compare_ray(tk, 50, o, 0.5, org, d, 0, INFINITY, 2e-3, s, NULL, &ty);
  }
  /* rays along the helix axis cross many keys */
  for (int r = 0; r < 20; r++) {
    double org[3] = {(rnd() - 0.5) * 0.5, (rnd() - 0.5) * 0.5, -4}, d[3] = {0.05 * (rnd() - 0.5), 0.05 * (rnd() - 0.5), 1};
    compare_ray(tk, 50, o, 0.5, org, d, 0, INFINITY, 2e-3, s, NULL, &ty);
  }
  report("fifty keys on a helix", &ty);
  soft_scratch_free(s);
  soft_free(o);
}

/* Near the field's maximum: one key (max 1 at its centre) and a pair. */
static void test_magic_extremes(void)
{
  tkey tk[3];
  tk[0] = sphere_key(0.1, -0.2, 0.3, 0.6, 1);
  double magic = 1 - 1e-6;
  soft_obj *o = build(tk, 1, magic);
  soft_scratch *s = soft_scratch_new(4);
  double out[8];
  double org[3] = {0.1 - 2, -0.2, 0.3}, d[3] = {1, 0, 0};
  int n = soft_roots(o, org, d, 0, INFINITY, out, 8, s, NULL);
  /* reference: C(x^2) = magic for the paper's cubic, solved by long double
   * bisection on the distance x = r/R */
  long double lo = 0, hi = 1;
  for (int i = 0; i < 100; i++) {
    long double m = 0.5L * (lo + hi), q = m;
    long double cv = -4.0L / 9 * powl(q, 6) + 17.0L / 9 * powl(q, 4) - 22.0L / 9 * q * q + 1;
    if (cv > magic) lo = m; else hi = m;
  }
  double rr = (double)(0.6L * lo);
  /* tolerance: the crossing is flat (g' ~ 3e-3): 1e-13 / g' ~ 1e-10 */
  CHECK("magic 1 - 1e-6, single key: two crossings", n == 2);
  if (n == 2) {
    CHECK_NEAR("magic 1 - 1e-6: entry at centre - r (tol 1e-10)", out[0], 2 - rr, 1e-10);
    CHECK_NEAR("magic 1 - 1e-6: exit at centre + r (tol 1e-10)", out[1], 2 + rr, 1e-10);
  }
  /* a ray missing the tiny sphere by a hair: no crossing */
  double org2[3] = {0.1 - 2, -0.2 + 1.5 * rr, 0.3};
  n = soft_roots(o, org2, d, 0, INFINITY, out, 8, s, NULL);
  CHECK("magic 1 - 1e-6: ray at 1.5 r misses", n == 0);
  soft_free(o);

  /* two overlapping keys, magic just below their joint maximum */
  tk[0] = sphere_key(0, 0, 0, 0.6, 1);
  tk[1] = sphere_key(0.3, 0, 0, 0.6, 1);
  double off[3] = {0.15, 0, 0};
  /* the maximum lies on the x axis between the two, by symmetry at 0.15 */
  long double o3[3] = {0.15L, 0, 0}, d3[3] = {1, 0, 0};
  double fmaxv = (double)ld_field(tk, 2, o3, d3, 0);
  tally ty;
  memset(&ty, 0, sizeof ty);
  o = build(tk, 2, fmaxv * (1 - 1e-4));
  for (int r = 0; r < 60; r++) {
    double ro[3], dd[3];
    random_dir(dd);
    for (int i = 0; i < 3; i++) ro[i] = off[i] + (rnd() - 0.5) * 0.05 - 3 * dd[i];
    compare_ray(tk, 2, o, fmaxv * (1 - 1e-4), ro, dd, 0, INFINITY, 2e-4, s, NULL, &ty);
  }
  report("magic 1e-4 below the maximum of two keys", &ty);
  soft_free(o);

  /* positive and negative keys that nearly cancel: w = 1 and -1, 1e-3 apart */
  tk[0] = sphere_key(0, 0, 0, 0.6, 1);
  tk[1] = sphere_key(1e-3, 0, 0, 0.6, -1);
  tk[2] = sphere_key(-0.2, 0.1, 0, 0.5, 1e-3);
  memset(&ty, 0, sizeof ty);
  o = build(tk, 3, 5e-4);
  for (int r = 0; r < 60; r++) {
    double ro[3], dd[3];
    random_dir(dd);
    for (int i = 0; i < 3; i++) ro[i] = (rnd() - 0.5) * 0.6 - 3 * dd[i];
    compare_ray(tk, 3, o, 5e-4, ro, dd, 0, INFINITY, 1e-3, s, NULL, &ty);
  }
  report("nearly cancelling +1/-1 keys, magic 5e-4", &ty);
  soft_free(o);
  soft_scratch_free(s);
}

/* A crossing exactly at a bound event: key B's sphere of influence starts
 * where key A's surface is, so the root sits on an interval boundary. */
static void test_boundary_root(void)
{
  long double lo = 0, hi = 1;
  for (int i = 0; i < 100; i++) {
    long double m = 0.5L * (lo + hi);
    long double cv = -4.0L / 9 * powl(m, 6) + 17.0L / 9 * powl(m, 4) - 22.0L / 9 * m * m + 1;
    if (cv > 0.5L) lo = m; else hi = m;
  }
  double rs = (double)lo;  /* A (R = 1) crosses 0.5 at r = rs */
  tkey tk[2] = {sphere_key(0, 0, 0, 1, 1), sphere_key(rs + 0.7, 0, 0, 0.7, 1)};
  soft_obj *o = build(tk, 2, 0.5);
  soft_scratch *s = soft_scratch_new(2);
  double out[16], org[3] = {-3, 0, 0}, d[3] = {1, 0, 0};
  int n = soft_roots(o, org, d, 0, INFINITY, out, 16, s, NULL);
  int near = 0;
  for (int i = 0; i < n; i++) if (fabs(out[i] - 3 - rs) < 1e-9) near++;
  tally ty;
  memset(&ty, 0, sizeof ty);
  compare_ray(tk, 2, o, 0.5, org, d, 0, INFINITY, 1e-3, s, NULL, &ty);
  report("root on an interval boundary", &ty);
  /* the field is C1 there and decreasing through magic: one crossing, and
   * then B's own surface is entered and left */
  CHECK("root on an interval boundary reported exactly once (tol 1e-9)", near == 1);
  soft_free(o);
  soft_scratch_free(s);
}

/* Tangent rays: a ray at distance y from a lone key's centre meets its
 * sphere of radius r* (C = magic) where x = +-sqrt(r*^2 - y^2). Grazing
 * rays give nearly double roots, which the polynomial solver must resolve
 * (or, exactly tangent, may drop as a touch). */
static void test_tangent(void)
{
  long double lo = 0, hi = 1;
  for (int i = 0; i < 100; i++) {
    long double m = 0.5L * (lo + hi);
    long double cv = -4.0L / 9 * powl(m, 6) + 17.0L / 9 * powl(m, 4) - 22.0L / 9 * m * m + 1;
    if (cv > 0.5L) lo = m; else hi = m;
  }
  long double rs = lo;
  tkey tk[1] = {sphere_key(0, 0, 0, 1, 1)};
  soft_obj *o = build(tk, 1, 0.5);
  soft_scratch *s = soft_scratch_new(1);
  soft_stats st;
  memset(&st, 0, sizeof st);
  static const double eps[] = {-1e-3, -1e-6, -1e-9, -1e-12, 0, 1e-12, 1e-9, 1e-6};
  int bad = 0;
  for (unsigned k = 0; k < sizeof eps / sizeof eps[0]; k++) {
    double y = (double)(rs * (1 + eps[k])), out[8];
    double org[3] = {-3, y, 0}, d[3] = {1, 0, 0};
    int n = soft_roots(o, org, d, 0, INFINITY, out, 8, s, &st);
    long double disc = rs * rs - (long double)y * y;
    if (eps[k] > 0) { if (n != 0) bad++; continue; }
    if (eps[k] == 0) {  /* touch: dropped, or a pair within 1e-7 of x = 0 */
      if (!(n == 0 || (n == 2 && fabs(out[0] - 3) < 1e-7 && fabs(out[1] - 3) < 1e-7))) bad++;
      continue;
    }
    double x = (double)sqrtl(disc);
    /* tolerance: rounding 1e-16 of the field over the slope |C'| x / r* */
    double tol = 1e-15 / x + 1e-15;
    if (n != 2 || fabs(out[0] - (3 - x)) > tol || fabs(out[1] - (3 + x)) > tol) {
      bad++;
      printf("# tangent eps %g: n %d (%.17g %.17g) want +-%.17g tol %g\n", eps[k], n,
             n > 0 ? out[0] - 3 : 0, n > 1 ? out[1] - 3 : 0, x, tol);
    }
  }
  CHECK("grazing rays: pairs resolved down to 1e-12 of tangency, none beyond", bad == 0);
  CHECK("grazing rays exercise the cascade fallback", st.poly.fallbacks > 0);
  soft_scratch_free(s);
  soft_free(o);
}

/* The keys of examples/soft-cloud.qcs with n = N (R = 0.6, w = 1, the R2
 * sequence over a cube of edge 0.5 N^(1/3)), calloc'd. */
static soft_key *cloud_keys(int N)
{
  soft_key *keys = calloc(N, sizeof *keys);
  double L = 0.5 * cbrt((double)N);
  for (int k = 0; k < N; k++) {
    keys[k].kind = SOFT_SPHERE;
    keys[k].c[0] = L * fmod(0.5 + k * 0.8191725134, 1.0);
    keys[k].c[1] = L * fmod(0.5 + k * 0.6710436067, 1.0);
    keys[k].c[2] = L * fmod(0.5 + k * 0.5497004779, 1.0);
    keys[k].R = 0.6;
    keys[k].w = 1;
  }
  return keys;
}

/* The first 125 of keys moved onto a 5 x 5 x 5 lattice of spacing 0.7
 * (keys in rows: bound events tie). */
static void lattice_keys(soft_key *keys)
{
  for (int k = 0; k < 125; k++) {
    keys[k].c[0] = 0.7 * (k % 5);
    keys[k].c[1] = 0.7 * (k / 5 % 5);
    keys[k].c[2] = 0.7 * (k / 25);
  }
}

/* Spatial index: cost follows the keys near the ray, and maxout / t0 / t1. */
static void test_index_and_limits(void)
{
  int N = 20000;
  soft_key *keys = cloud_keys(N);
  double L = 0.5 * cbrt((double)N);
  soft_obj *o;
  size_t bad;
  CHECK("soft-cloud 20000 builds", soft_build(keys, N, 0.5, &o, &bad) == SOFT_OK);
  soft_scratch *s = soft_scratch_new(N);
  soft_stats st;
  memset(&st, 0, sizeof st);
  double org[3] = {-1, L / 2, L / 2}, d[3] = {1, 0.01, 0.02}, all[4096], first[4];
  int na = soft_roots(o, org, d, 0, INFINITY, all, 4096, s, &st);
  /* a straight line through the box meets about L * pi R^2 * density keys */
  CHECK("index: a ray through the cloud touches < 2% of the keys", na > 0 && st.keys < N / 50);
  int nf = soft_roots(o, org, d, 0, INFINITY, first, 1, s, NULL);
  CHECK("maxout 1 returns the nearest crossing", nf == 1 && first[0] == all[0]);
  /* clipping: rays through the cloud until one has >= 4 crossings */
  int tried = 0, clip_ok = 0, state_ok = 0;
  for (int r = 0; r < 200 && !tried; r++) {
    double ro[3] = {-1, L * (0.2 + 0.6 * rnd()), L * (0.2 + 0.6 * rnd())};
    double rd[3] = {1, 0.2 * (rnd() - 0.5), 0.2 * (rnd() - 0.5)};
    na = soft_roots(o, ro, rd, 0, INFINITY, all, 4096, s, NULL);
    if (na < 4) continue;
    tried = 1;
    double t0 = 0.5 * (all[1] + all[2]), t1 = 0.5 * (all[na - 2] + all[na - 1]), part[4096];
    int np = soft_roots(o, ro, rd, t0, t1, part, 4096, s, NULL);
    clip_ok = np == na - 3;
    for (int i = 0; clip_ok && i < np; i++) clip_ok = fabs(part[i] - all[i + 2]) < 1e-9;  /* tol 1e-9 */
    double p[3];
    for (int i = 0; i < 3; i++) p[i] = ro[i] + t0 * rd[i];
    state_ok = soft_field(o, p) > 0.5;  /* between crossings 1 and 2: outside */
    state_ok = !state_ok;
  }
  CHECK("t0/t1 clip the crossings (tol 1e-9)", tried && clip_ok);
  CHECK("state at t0 from soft_field agrees with crossing parity", tried && state_ok);
  soft_scratch *small = soft_scratch_new(10);
  CHECK("scratch too small is an error", soft_roots(o, org, d, 0, INFINITY, all, 4, small, NULL) == -1);
  double z[3] = {0, 0, 0};
  CHECK("zero direction is an error", soft_roots(o, org, z, 0, INFINITY, all, 4, s, NULL) == -1);
  soft_scratch_free(small);
  soft_scratch_free(s);
  soft_free(o);
  free(keys);
}

/* soft_any (shadow rays) against soft_roots with maxout 1, the general
 * path, on one object: camera-like rays, and shadow-like rays from points
 * on, just off and just inside the surface towards a light, clipped at it.
 * The answers must agree on every ray (1, 0 or -1), and the point
 * soft_any gives must lie in (t0, t1], at or past the general path's
 * crossing. Counts into *same, *hits, *rays; returns rays that differ. */
static long any_rays(const soft_obj *o, const double lo[3], const double hi[3],
                     int nrays, soft_scratch *s, soft_stats *sa,
                     soft_stats *sr, long *hits, long *rays)
{
  long bad = 0;
  double mid[3], span = 0;
  for (int i = 0; i < 3; i++) {
    mid[i] = 0.5 * (lo[i] + hi[i]);
    span = fmax(span, hi[i] - lo[i]);
  }
  for (int r = 0; r < nrays; r++) {
    double org[3], d[3], t1 = INFINITY;
    aim_ray(mid, span, org, d);
    for (int i = 0; i < 3; i++) org[i] = mid[i] + (org[i] - mid[i]) * span;
    double th, tr[2];
    int nr = soft_roots(o, org, d, 0, INFINITY, tr, 1, s, sr);
    int na = soft_any(o, org, d, 0, INFINITY, &th, s, sa);
    ++*rays;
    if (na != nr || (nr == 1 && !(th >= tr[0] && th > 0))) bad++;
    if (nr != 1) continue;
    ++*hits;
    /* shadow rays from the hit: towards a light, from the point, from
     * eps off along the normal either way, t1 at the light or at
     * infinity, and a t0 > 0 */
    double p[3], g[3], light[3];
    for (int i = 0; i < 3; i++) p[i] = org[i] + tr[0] * d[i];
    soft_field_grad(o, p, g);
    double gl = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
    if (!(gl > 0)) gl = 1;
    random_dir(light);
    for (int i = 0; i < 3; i++) light[i] = mid[i] + light[i] * 2 * span;
    static const double offs[5] = {0, 1e-9, -1e-9, 1e-6, -1e-3};
    for (int k = 0; k < 5; k++) {
      double so[3], L[3];
      for (int i = 0; i < 3; i++) so[i] = p[i] - offs[k] * g[i] / gl;
      for (int i = 0; i < 3; i++) L[i] = light[i] - so[i];
      double dist = sqrt(L[0] * L[0] + L[1] * L[1] + L[2] * L[2]);
      for (int i = 0; i < 3; i++) L[i] /= dist;
      double ts[3][2] = {{0, dist}, {0, t1}, {1e-7, 0.5 * dist}};
      for (int q = 0; q < 3; q++) {
        nr = soft_roots(o, so, L, ts[q][0], ts[q][1], tr, 1, s, sr);
        na = soft_any(o, so, L, ts[q][0], ts[q][1], &th, s, sa);
        ++*rays;
        if (nr == 1) ++*hits;
        if (na != nr || (nr == 1 && !(th >= tr[0] && th > ts[q][0] &&
                                      th <= ts[q][1])))
          bad++;
      }
    }
  }
  return bad;
}

static void test_any(void)
{
  long bad = 0, hits = 0, rays = 0;
  soft_stats sa, sr;
  memset(&sa, 0, sizeof sa);
  memset(&sr, 0, sizeof sr);
  /* soft-cloud with 3000 keys (the canonical scene's keys) */
  int N = 3000;
  soft_key *keys = cloud_keys(N);
  soft_obj *o;
  size_t bad_key;
  soft_scratch *s = soft_scratch_new(N);
  if (soft_build(keys, N, 0.5, &o, &bad_key) == SOFT_OK) {
    double lo[3], hi[3];
    soft_bounds(o, lo, hi);
    bad += any_rays(o, lo, hi, 8000, s, &sa, &sr, &hits, &rays);
    soft_free(o);
  } else {
    bad++;
  }
  /* a lattice of equal keys (ties between bound events), and random
   * clouds with negative and quadric keys at several magics */
  lattice_keys(keys);
  if (soft_build(keys, 125, 0.5, &o, &bad_key) == SOFT_OK) {
    double lo[3], hi[3];
    soft_bounds(o, lo, hi);
    bad += any_rays(o, lo, hi, 3000, s, &sa, &sr, &hits, &rays);
    soft_free(o);
  } else {
    bad++;
  }
  static const double magics[4] = {0.5, 1e-6, 0.9, 2};
  for (int c = 0; c < 12; c++) {
    tkey tk[40];
    double off[3] = {0, 0, 0}, lo[3], hi[3];
    make_cloud(tk, 40, off, c % 3 != 0, c % 2);
    soft_obj *oc = build(tk, 40, magics[c % 4]);
    if (!oc) { bad++; continue; }
    if (soft_bounds(oc, lo, hi))
      bad += any_rays(oc, lo, hi, 1200, s, &sa, &sr, &hits, &rays);
    soft_free(oc);
  }
  soft_scratch_free(s);
  free(keys);
  char name[200];
  snprintf(name, sizeof name, "soft_any gives soft_roots' (maxout 1) answer "
           "on all of %ld rays (%ld hits), with a point at or past its crossing",
           rays, hits);
  printf("# soft_any: %ld rays differ\n", bad);
  CHECK(name, bad == 0 && hits > 5000 && rays - hits > 5000);
  snprintf(name, sizeof name, "soft_any solves fewer polynomials (%ld against %ld)",
           sa.poly.solves, sr.poly.solves);
  CHECK(name, sa.poly.solves < sr.poly.solves);
}

/* The key test's quick miss against plain key tests (soft_scratch_plain):
 * every crossing, bit for bit, and the same keys met, on rays through the
 * soft-cloud keys (3000), a lattice, and random clouds with quadric and
 * negative keys; rays from outside, from inside, and shadow rays from
 * surface points, long directions and rays at 1e6. */
static long quick_rays(const soft_obj *o, const double lo[3], const double hi[3],
                       int nrays, double dscale, soft_scratch *s, soft_scratch *p,
                       long *roots)
{
  long bad = 0;
  double mid[3], span = 0;
  for (int i = 0; i < 3; i++) {
    mid[i] = 0.5 * (lo[i] + hi[i]);
    span = fmax(span, hi[i] - lo[i]);
  }
  for (int r = 0; r < nrays; r++) {
    double org[3], d[3], a[64], b[64];
    aim_ray(mid, span, org, d);
    if (r % 3 == 0)  /* from inside the cloud's box */
      for (int i = 0; i < 3; i++) org[i] = mid[i] + (rnd() - 0.5) * span;
    else
      for (int i = 0; i < 3; i++) org[i] = mid[i] + (org[i] - mid[i]) * span;
    if (r % 5 == 4) {  /* along an axis, at a multiple of 0.7 off it */
      int ax = r / 5 % 3;
      for (int i = 0; i < 3; i++) {
        d[i] = i == ax ? 1 : 0;
        org[i] = i == ax ? lo[i] - 1 : 0.7 * floor(rnd() * 5);
      }
    }
    for (int i = 0; i < 3; i++) d[i] *= dscale;
    soft_stats sa, sb;
    memset(&sa, 0, sizeof sa);
    memset(&sb, 0, sizeof sb);
    int na = soft_roots(o, org, d, 0, INFINITY, a, 64, s, &sa);
    int nb = soft_roots(o, org, d, 0, INFINITY, b, 64, p, &sb);
    if (na != nb || sa.keys != sb.keys || sa.intervals != sb.intervals ||
        (na > 0 && memcmp(a, b, (size_t)na * sizeof *a) != 0)) bad++;
    if (na > 0) {
      *roots += na;
      /* a shadow ray from the first crossing, as the renderer casts it */
      double q[3], g[3], L[3];
      for (int i = 0; i < 3; i++) q[i] = org[i] + a[0] * d[i];
      soft_field_grad(o, q, g);
      random_dir(L);
      int sha = soft_any(o, q, L, 1e-9, 10 * span, NULL, s, NULL);
      int shb = soft_any(o, q, L, 1e-9, 10 * span, NULL, p, NULL);
      if (sha != shb) bad++;
    }
  }
  return bad;
}

static void test_quick_miss(void)
{
  long bad = 0, roots = 0;
  int N = 3000;
  soft_key *keys = cloud_keys(N);
  soft_scratch *s = soft_scratch_new(N), *p = soft_scratch_new(N);
  soft_scratch_plain(p, 1);
  soft_obj *o;
  size_t bad_key;
  double lo[3], hi[3];
  if (soft_build(keys, N, 0.5, &o, &bad_key) == SOFT_OK && soft_bounds(o, lo, hi)) {
    bad += quick_rays(o, lo, hi, 8000, 1, s, p, &roots);
    bad += quick_rays(o, lo, hi, 500, 1e3, s, p, &roots);
    bad += quick_rays(o, lo, hi, 500, 1e-3, s, p, &roots);
    soft_free(o);
  } else {
    bad++;
  }
  lattice_keys(keys);
  if (soft_build(keys, 125, 0.5, &o, &bad_key) == SOFT_OK && soft_bounds(o, lo, hi)) {
    bad += quick_rays(o, lo, hi, 2000, 1, s, p, &roots);
    soft_free(o);
  } else {
    bad++;
  }
  for (int c = 0; c < 12; c++) {
    tkey tk[40];
    double off[3] = {c % 4 == 3 ? 1e6 : 0, 0, 0};
    make_cloud(tk, 40, off, c % 3 != 0, c % 2);
    soft_obj *oc = build(tk, 40, c % 4 == 1 ? 1e-6 : 0.5);
    if (!oc) { bad++; continue; }
    if (soft_bounds(oc, lo, hi))
      bad += quick_rays(oc, lo, hi, 1500, 1, s, p, &roots);
    soft_free(oc);
  }
  soft_scratch_free(s);
  soft_scratch_free(p);
  free(keys);
  char name[200];
  snprintf(name, sizeof name, "the key test's quick miss: the same crossings "
           "bit for bit, keys and intervals as plain key tests (%ld crossings)",
           roots);
  printf("# quick miss: %ld rays differ\n", bad);
  CHECK(name, bad == 0 && roots > 10000);
}

int main(void)
{
  check_prefix = "soft";
  test_build();
  test_field();
  test_surface_bounds();
  test_box_bounds();
  test_clouds();
  test_axis_rays();
  test_helix();
  test_magic_extremes();
  test_boundary_root();
  test_tangent();
  test_index_and_limits();
  test_any();
  test_quick_miss();
  CHECK_DONE();
}
