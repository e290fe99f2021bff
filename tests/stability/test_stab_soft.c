/* test_stab_soft.c: numerical stability of soft objects (Wyvill and
 * Trotman) through the scene-level ray API and the kernel soft_roots,
 * against the MPFR field of stab.h (eq. (1) from the distance to each key;
 * no polynomial in t).
 *
 * Cases (issue 6): keys that nearly cancel (same centre, and a dipole of a
 * positive and a negative key), clustered and multiple polynomial roots
 * (tangent rays, a neck between two keys crossed twice 1e-6 apart), keys
 * at 1e6 from the ray origin, 1e5 keys, magic near 0 and near the field's
 * maximum.  Work per ray: intervals + polynomial solves + BVH nodes
 * (soft_stats). */
#include "stab.h"

#define TOL 1e-12

static long soft_work(const RayCtx *c) {
  return c->stats.soft.intervals + c->stats.soft.poly.solves + c->stats.soft.nodes;
}

static uint64_t rng = 4242;
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

/* qcs text of a soft object. */
static char *soft_src(const ssoft *S) {
  size_t cap = 64 + (size_t)S->nkeys * 100;
  char *b = malloc(cap);
  size_t n = (size_t)snprintf(b, cap, "SoftObject %.17g [", S->magic);
  for (int k = 0; k < S->nkeys; k++) {
    const skey *K = &S->keys[k];
    n += (size_t)snprintf(b + n, cap - n, "%sKey (%.17g, %.17g, %.17g) %.17g (%.17g)",
                          k ? ", " : "", K->c[0], K->c[1], K->c[2], K->R, K->w);
  }
  snprintf(b + n, cap - n, "]");
  return b;
}

/* One ray, scene level and kernel level, against the reference on
 * [t0, t1] (the scene is searched on [0, inf)). */
static void one_ray(scase *cs, const Scene *s, RayCtx *c, ssoft *S,
                    const double o[3], const double d[3], double t0, double t1,
                    int nsamp) {
  double got[STAB_MAXR];
  long w0 = soft_work(c);
  int ng = stab_scene_roots(s, c, o, d, 0, INFINITY, got, STAB_MAXR);
  sc_work(cs, soft_work(c) - w0);
  soft_select(S, o, d);
  sray R = {NULL, S, S->magic, {o[0], o[1], o[2]}, {d[0], d[1], d[2]}, 0};
  double *brk = malloc(sizeof(double) * (size_t)(3 * S->nact + 1));
  int nb = soft_breaks(S, o, d, brk);
  sroot rr[STAB_MAXR];
  int nr = sray_roots(&R, t0, t1, brk, nb, nsamp, rr, STAB_MAXR);
  free(brk);
  if (ng < 0) {
    cs->rays++;
    cs->missed++;
    sc_note(cs, "ray_spans failed");
    return;
  }
  int ok = sc_compare(cs, got, ng, rr, nr, TOL, vlen(d));
  /* the kernel: every crossing, touches omitted */
  const ScNode *nd = &s->nodes[s->root];
  double kt[STAB_MAXR];
  int nk = nd->kind == SC_SOFT ? soft_roots(nd->soft, o, d, 0, INFINITY, kt,
                                            STAB_MAXR, c->soft, NULL) : -1;
  if (nk != ng || (nk > 0 && memcmp(kt, got, sizeof *kt * (size_t)nk))) {
    cs->missed++;
    ok = 0;
    sc_note(cs, "ray %ld: soft_roots gives %d crossings, the scene %d", cs->rays,
            nk, ng);
  }
  /* normals and field at the crossings: finite */
  for (int i = 0; i < ng; i++) {
    double p[3] = {o[0] + got[i] * d[0], o[1] + got[i] * d[1], o[2] + got[i] * d[2]};
    double g[3], f = soft_field_grad(nd->soft, p, g);
    if (!isfinite(f) || !isfinite(g[0]) || !isfinite(g[1]) || !isfinite(g[2])) {
      cs->nonfinite++;
      ok = 0;
    }
  }
  if (!ok && getenv("STAB_VERBOSE")) {
    printf("#   ray o = (%.17g, %.17g, %.17g) d = (%.17g, %.17g, %.17g)\n", o[0],
           o[1], o[2], d[0], d[1], d[2]);
    for (int i = 0; i < ng; i++) printf("#     got %.17g\n", got[i]);
    for (int i = 0; i < nr; i++)
      printf("#     ref %.17g kind %d allow %.3g slope %.3g cond %.3g [%.17g, %.17g]\n",
             rr[i].t, rr[i].kind, rr[i].allow, rr[i].slope, rr[i].cond, rr[i].lo, rr[i].hi);
  }
}

/* Rays at a soft object: from 3 units away through points near target. */
static void run_case(const char *name, ssoft *S, const double tgt[3],
                     double spread, int nrays, long cap, const double *lens,
                     int nlens, const double (*fixed)[6], int nfixed) {
  scase cs = {.name = name, .work_cap = cap};
  char *src = soft_src(S);
  Scene *s = stab_compile(src);
  if (!s) {
    printf("# %s\n", stab_error);
    CHECK(name, 0);
    free(src);
    return;
  }
  RayCtx *c = ray_ctx_new(s, TOL);
  for (int j = 0; j < nfixed; j++) {
    const double *o = fixed[j], *d = fixed[j] + 3;
    double l = vlen(d);
    one_ray(&cs, s, c, S, o, d, 0, 6 / l, 2000);
  }
  for (int j = 0; j < nrays; j++) {
    double q[3], du[3], o[3], d[3];
    for (int i = 0; i < 3; i++) q[i] = tgt[i] + spread * (2 * urand() - 1);
    unit_dir(du);
    double len = lens ? lens[j % nlens] : 1;
    for (int i = 0; i < 3; i++) d[i] = du[i] * len, o[i] = q[i] - 3 * du[i];
    one_ray(&cs, s, c, S, o, d, 0, 6 / len, 2000);
  }
  ray_ctx_free(c);
  scene_free(s);
  free(src);
  sc_report(&cs, "MPFR eq. (1)", "1e-12 + 8 eps A/|f'|");
}

static void test_cancel(void) {
  /* same centre: (W + 1) - W = 1: a sphere of radius R/2 for magic 0.5 */
  static const double Ws[] = {1e3, 1e6};
  for (int k = 0; k < 2; k++) {
    skey keys[2] = {{{0, 0, 0}, 1, Ws[k] + 1}, {{0, 0, 0}, 1, -Ws[k]}};
    ssoft S = {keys, 2, 0.5, NULL, 0, NULL, NULL, 0};
    char name[120];
    snprintf(name, sizeof name, "nearly cancelling keys on one centre, "
             "w = %g + 1 and -%g", Ws[k], Ws[k]);
    double tgt[3] = {0, 0, 0};
    run_case(name, &S, tgt, 0.6, 40, 200, NULL, 0, NULL, 0);
    free(S.act); free(S.te);
  }
  /* a dipole: +W at 0 and -W at delta along x, with a unit key beside */
  skey keys[3] = {{{0, 0, 0}, 1, 1e4}, {{1e-5, 0, 0}, 1, -1e4},
                  {{0.3, 0, 0}, 1, 1}};
  ssoft S = {keys, 3, 0.5, NULL, 0, NULL, NULL, 0};
  double tgt[3] = {0.2, 0, 0};
  run_case("a dipole of keys +-1e4, 1e-5 apart, beside a unit key", &S, tgt,
           0.7, 60, 200, NULL, 0, NULL, 0);
  free(S.act); free(S.te);
}

/* The field of two keys at (+-a, 0, 0) at the origin: 2 C(a^2/R^2). */
static double two_key_mid(double a) {
  double x = a * a;
  return 2 * (1 + x * (-22.0 / 9 + x * (17.0 / 9 - x * 4.0 / 9)));
}

static void test_roots_clusters(void) {
  /* tangent and near-tangent rays to one key's surface (r = R/2 for
   * magic 0.5, w = 1): offsets 0, +-1e-16 .. 1e-4 from the tangent line */
  skey one[1] = {{{0, 0, 0}, 1, 1}};
  ssoft S1 = {one, 1, 0.5, NULL, 0, NULL, NULL, 0};
  double fixed[24][6];
  int nf = 0;
  static const double offs[] = {0, 1e-16, 1e-12, 1e-9, 1e-6, 1e-4,
                                -1e-16, -1e-12, -1e-9, -1e-6, -1e-4};
  for (size_t k = 0; k < sizeof offs / sizeof *offs; k++) {
    double y = 0.5 + offs[k];
    double f[6] = {-2, y, 0, 1, 0, 0};
    memcpy(fixed[nf++], f, sizeof f);
  }
  /* the crossings 1e-6 apart: half-chord 5e-7 at radius 0.5 */
  double y6 = sqrt(0.25 - 2.5e-13);
  double f6[6] = {-2, y6, 0, 1, 0, 0};
  memcpy(fixed[nf++], f6, sizeof f6);
  double tgt[3] = {0, 0, 0};
  run_case("tangent and near-tangent rays at one key (double roots, pairs "
           "1e-6 apart)", &S1, tgt, 0.6, 20, 200, NULL, 0,
           (const double (*)[6])fixed, nf);
  free(S1.act); free(S1.te);

  /* a neck between two keys at (+-0.6, 0, 0), R = 1: along the x axis
   * the field has a minimum 2 C(0.36) at the origin; magic just above it
   * gives two crossings about 1e-6 apart there, magic equal to it a
   * double root, and rays along the axis cross 4 times in a cluster */
  double fmid = two_key_mid(0.6);
  static const double dm[] = {0, 1e-13, 1e-10, 1e-8, -1e-13};
  for (size_t k = 0; k < sizeof dm / sizeof *dm; k++) {
    skey two[2] = {{{-0.6, 0, 0}, 1, 1}, {{0.6, 0, 0}, 1, 1}};
    ssoft S2 = {two, 2, fmid + dm[k], NULL, 0, NULL, NULL, 0};
    double fx[3][6] = {{-2, 0, 0, 1, 0, 0}, {-2, 1e-7, 0, 1, 0, 0},
                       {-2, 0, 1e-4, 1, 0, 1e-9}};
    char name[160];
    snprintf(name, sizeof name, "neck between two keys, magic = minimum "
             "%+g (clustered roots)", dm[k]);
    run_case(name, &S2, tgt, 0.3, 10, 300, NULL, 0,
             (const double (*)[6])fx, 3);
    free(S2.act); free(S2.te);
  }
}

static void test_far(void) {
  /* ten keys near (1e6, 0, 0); rays from the origin and from nearby, with
   * direction lengths 1e-6 .. 1e6 */
  skey keys[10];
  for (int k = 0; k < 10; k++) {
    keys[k].c[0] = 1e6 + 0.3 * k;
    keys[k].c[1] = 0.2 * sin(k);
    keys[k].c[2] = 0.2 * cos(k);
    keys[k].R = 0.5;
    keys[k].w = 1;
  }
  ssoft S = {keys, 10, 0.5, NULL, 0, NULL, NULL, 0};
  char *src = soft_src(&S);
  Scene *s = stab_compile(src);
  scase cs = {.name = "ten keys at 1e6 from the ray origin, |d| = 1e-6 .. 1e6",
              .work_cap = 400};
  RayCtx *c = ray_ctx_new(s, TOL);
  static const double lens[] = {1e-6, 1e-3, 1, 1e3, 1e6};
  for (int j = 0; j < 30; j++) {
    double q[3] = {1e6 + 1.35 + 1.5 * (2 * urand() - 1), 0.4 * (2 * urand() - 1),
                   0.4 * (2 * urand() - 1)};
    double l = vlen(q), len = lens[j % 5], o[3] = {0, 0, 0}, d[3];
    for (int i = 0; i < 3; i++) d[i] = q[i] / l * len;
    if (j % 2) { /* or from 3 units away */
      double du[3];
      unit_dir(du);
      for (int i = 0; i < 3; i++) d[i] = du[i] * len, o[i] = q[i] - 3 * du[i];
      l = 3;
    }
    one_ray(&cs, s, c, &S, o, d, (l - 3) / len, (l + 3) / len, 3000);
  }
  ray_ctx_free(c);
  scene_free(s);
  free(src);
  free(S.act); free(S.te);
  sc_report(&cs, "MPFR eq. (1)", "1e-12 + 8 eps A/|f'| (A ~ S = 1e6)");
}

static void test_many(void) {
  /* 1e5 keys by the R2 sequence in a 20 x 20 x 20 box, R = 0.6 */
  int n = 100000;
  skey *keys = malloc(sizeof *keys * (size_t)n);
  const double g = 1.2207440846057596;
  for (int k = 0; k < n; k++) {
    keys[k].c[0] = 20 * fmod(0.5 + (k + 1) / g, 1);
    keys[k].c[1] = 20 * fmod(0.5 + (k + 1) / (g * g), 1);
    keys[k].c[2] = 20 * fmod(0.5 + (k + 1) / (g * g * g), 1);
    keys[k].R = 0.6;
    keys[k].w = k % 7 == 0 ? -0.5 : 1;
  }
  ssoft S = {keys, n, 0.5, NULL, 0, NULL, NULL, 0};
  double tgt[3] = {10, 10, 10};
  scase cs = {.name = "1e5 keys (1 in 7 negative), 12 rays through the cloud",
              .work_cap = 20000};
  char *src = soft_src(&S);
  Scene *s = stab_compile(src);
  RayCtx *c = s ? ray_ctx_new(s, TOL) : NULL;
  for (int j = 0; s && j < 12; j++) {
    double q[3], du[3], o[3], d[3];
    for (int i = 0; i < 3; i++) q[i] = tgt[i] + 9 * (2 * urand() - 1);
    unit_dir(du);
    for (int i = 0; i < 3; i++) d[i] = du[i], o[i] = q[i] - 40 * du[i];
    one_ray(&cs, s, c, &S, o, d, 0, 80, 8000);
  }
  CHECK("1e5 keys compile", s != NULL);
  ray_ctx_free(c);
  scene_free(s);
  free(src);
  free(S.act); free(S.te);
  free(keys);
  sc_report(&cs, "MPFR eq. (1), keys the ray meets", "1e-12 + 8 eps A/|f'|");
}

static void test_magic(void) {
  double tgt[3] = {0, 0, 0};
  /* magic near 0: the surface hugs the keys' bounds, where C has a double
   * zero; near the maximum 1 of a unit key: a tiny sphere */
  static const double mags[] = {1e-6, 1e-12, 1e-300, 1 - 1e-9, 1 - 1e-12,
                                1 - 1e-15};
  for (size_t k = 0; k < sizeof mags / sizeof *mags; k++) {
    skey keys[2] = {{{0, 0, 0}, 1, 1}, {{0.7, 0.2, 0}, 0.8, 0.9}};
    ssoft S = {keys, mags[k] < 0.5 ? 2 : 1, mags[k], NULL, 0, NULL, NULL, 0};
    double fx[4][6] = {{-2, 0, 0, 1, 0, 0}, {0, -2, 0, 0, 1, 0},
                       {-2, 1e-7, 0, 1, 0, 0}, {-2, 0.3, 0.1, 1, 0, 0}};
    char name[160];
    snprintf(name, sizeof name, "magic %.17g (%s)", mags[k],
             mags[k] < 0.5 ? "near 0, two keys" : "near the maximum 1 of one key");
    run_case(name, &S, tgt, mags[k] < 0.5 ? 1 : 1e-6, 20, 200, NULL, 0,
             (const double (*)[6])fx, 4);
    if (mags[k] < 1e-20) {
      char *src = soft_src(&S), warn[2000];
      Scene *s = stab_compile_warn(src, warn, sizeof warn);
      CHECK("magic 1e-300: a warning names the SoftObject (surface placed "
            "approximately)", s && strstr(warn, "<stab>:1:1: warning: magic"));
      scene_free(s);
      free(src);
    }
    free(S.act); free(S.te);
  }
}

int main(void) {
  char base;
  stab_init("stab-soft", &base);
  test_cancel();
  test_roots_clusters();
  test_far();
  test_magic();
  test_many();
  CHECK_DONE();
}
