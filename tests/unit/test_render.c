/* test_render.c: the tracer end to end, through the interpreter: small
 * renders of the canonical scenes against stored reference images, the
 * EXR read back through the OpenEXR library, shading checked against an
 * independent long double computation, determinism across thread counts,
 * the per-tile culling and pruning against the untiled tracer,
 * and an interrupted render leaving no file.
 *
 * Reference images live in tests/images/NAME.png (150 x 95). After a
 * deliberate change to the pictures, look at the new ones and refresh the
 * references with `make update-references`. QCS_UPDATE_REFERENCES=1 makes
 * this program write them instead of comparing. */
#include <gc.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "render/image.h"
#include "bind/bind.h"
#include "lang/interp.h"
#include "render/render.h"
#include "bind/render_lang.h"
#include "lang/value.h"

static Interp *I;
static char tmpdir[] = "/tmp/qcs-test-render-XXXXXX";

/* Render FILE (an example) with the given overrides; 0 on success. */
static int render_file(const char *file, const char *out, int w, int h,
                       int threads, int cost) {
  RenderOverrides o = {0};
  o.output = out;
  o.width = w;
  o.height = h;
  o.threads = threads;
  o.cost = cost;
  render_set_overrides(I, &o);
  int st = interp_run_file(I, file);
  render_set_overrides(I, NULL);
  return st == RUN_OK && o.renders > 0 ? 0 : -1;
}

static void reference_test(const char *name) {
  char ex[256], out[512], ref[256], err[300], label[300];
  snprintf(ex, sizeof ex, "examples/%s.qcs", name);
  snprintf(ref, sizeof ref, "tests/images/%s.png", name);
  snprintf(out, sizeof out, "%s/%s.png", tmpdir, name);
  snprintf(label, sizeof label, "reference image %s", name);
  if (access(ex, R_OK) != 0) {
    printf("skip render: %s: no %s yet\n", label, ex);
    return;
  }
  if (render_file(ex, out, 150, 95, 0, 0)) {
    CHECK(label, 0);
    return;
  }
  if (getenv("QCS_UPDATE_REFERENCES")) {
    Image *im = img_read_png(out, err, sizeof err);
    if (im && img_write(im, ref, NULL, err, sizeof err) == 0)
      printf("ok render: %s written\n", ref);
    img_free(im);
    return;
  }
  Image *a = img_read_png(out, err, sizeof err);
  Image *b = img_read_png(ref, err, sizeof err);
  if (!a || !b) {
    printf("FAIL render: %s: %s (make update-references makes it)\n", label, err);
    check_failed_count++;
  } else {
    double rms, share;
    int ok = img_compare(a, b, &rms, &share, 0.1) == 0;
    /* Tolerances: RMS 0.01 of full scale, and at most 0.5% of the pixels
       off by more than 0.1 (an edge moving by a pixel). */
    if (ok && rms <= 0.01 && share <= 0.005) {
      printf("ok render: %s (rms %.4f, %.2f%% pixels differ)\n", label, rms,
             100 * share);
    } else {
      printf("FAIL render: %s: rms %.4f, %.2f%% pixels differ by > 0.1\n",
             label, rms, 100 * share);
      check_failed_count++;
    }
  }
  img_free(a);
  img_free(b);
}

/* The floor pixel at (x, y) of figure12 lit by the light, computed in long
   double from the scene conventions: camera, plane y = 0, grey 0.5,
   ambient 0.15, Lambert, Blinn-Phong 0.3 with exponent 32. */
static long double floor_radiance(int x, int y, int w, int h) {
  long double eye[3] = {2.25L, 3.2L, 5.0L}, at[3] = {2.25L, 0.5L, -0.4L};
  long double f[3], r[3], u[3], up[3] = {0, 1, 0};
  long double fl = 0;
  for (int i = 0; i < 3; i++) f[i] = at[i] - eye[i], fl += f[i] * f[i];
  fl = sqrtl(fl);
  for (int i = 0; i < 3; i++) f[i] /= fl;
  r[0] = f[1] * up[2] - f[2] * up[1];
  r[1] = f[2] * up[0] - f[0] * up[2];
  r[2] = f[0] * up[1] - f[1] * up[0];
  long double rl = sqrtl(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
  for (int i = 0; i < 3; i++) r[i] /= rl;
  u[0] = r[1] * f[2] - r[2] * f[1];
  u[1] = r[2] * f[0] - r[0] * f[2];
  u[2] = r[0] * f[1] - r[1] * f[0];
  long double th = tanl(35.0L * 3.14159265358979323846L / 360);
  long double px = (2 * (x + 0.5L) / w - 1) * th * w / h;
  long double py = (1 - 2 * (y + 0.5L) / h) * th;
  long double d[3], dl = 0;
  for (int i = 0; i < 3; i++) d[i] = f[i] + px * r[i] + py * u[i], dl += d[i] * d[i];
  dl = sqrtl(dl);
  for (int i = 0; i < 3; i++) d[i] /= dl;
  long double t = -eye[1] / d[1];
  long double p[3], L[3], ll = 0, light[3] = {-3, 8, 6};
  for (int i = 0; i < 3; i++) p[i] = eye[i] + t * d[i];
  for (int i = 0; i < 3; i++) L[i] = light[i] - p[i], ll += L[i] * L[i];
  ll = sqrtl(ll);
  for (int i = 0; i < 3; i++) L[i] /= ll;
  long double H[3], hl = 0;
  for (int i = 0; i < 3; i++) H[i] = L[i] - d[i], hl += H[i] * H[i];
  hl = sqrtl(hl);
  long double ndh = H[1] / hl;
  return 0.5L * 0.15L + 0.5L * L[1] + 0.3L * powl(ndh, 32);
}

static void exr_test(void) {
  char out[512], err[300];
  snprintf(out, sizeof out, "%s/figure12.exr", tmpdir);
  int w = 120, h = 76;
  if (render_file("examples/figure12.qcs", out, w, h, 0, 1)) {
    CHECK("render: figure12 to EXR", 0);
    return;
  }
  Image *im = img_read_exr(out, err, sizeof err);
  CHECK("exr: reads back through OpenEXR", im != NULL);
  if (!im) return;
  CHECK("exr: size", im->width == w && im->height == h);
  CHECK("exr: Z, N and cost channels", (im->flags & (IMG_Z | IMG_N | IMG_COST)) ==
                                           (IMG_Z | IMG_N | IMG_COST));
  int sky = 0, hits = 0, unit = 0, cost = 0, floor_ok = 0, floor_n = 0;
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) {
      size_t k = img_index(im, x, y);
      float *c = &im->rgba[4 * k];
      if (isinf(im->z[k])) {
        /* The sky: the background colour, to half precision (2^-11). */
        if (fabsf(c[0] - 0.55f) < 1e-3f && fabsf(c[1] - 0.65f) < 1e-3f &&
            fabsf(c[2] - 0.85f) < 1e-3f)
          sky++;
        continue;
      }
      hits++;
      float *n = &im->n[3 * k];
      if (fabsf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2] - 1) < 1e-4f) unit++;
      if (im->cost[k] >= 0) cost++;
      /* Floor pixels (normal straight up, well below the objects). */
      if (y > h - 8 && n[1] > 0.9999f) {
        long double want = floor_radiance(x, y, w, h);
        floor_n++;
        /* Half precision colour: relative 2^-11; the floor may be in a
           shadow only where the objects are, not in the bottom rows. */
        if (fabsl(c[0] - want) <= 1e-3L * want + 1e-6L) floor_ok++;
      }
    }
  int sky_total = w * h - hits;
  /* (figure12 looks down at its floor: there may be no sky at all.) */
  CHECK("exr: every sky pixel has the background colour", sky == sky_total);
  CHECK("exr: every hit has a unit normal", hits > 0 && unit == hits);
  CHECK("exr: cost channel is a count", cost == hits);
  CHECK("exr: floor shading matches a long double computation",
        floor_n > 0 && floor_ok == floor_n);
  img_free(im);
}

static void determinism_test(void) {
  char a[512], b[512], err[300];
  snprintf(a, sizeof a, "%s/t1.exr", tmpdir);
  snprintf(b, sizeof b, "%s/t3.exr", tmpdir);
  int ra = render_file("examples/figure12.qcs", a, 97, 61, 1, 1);
  int rb = render_file("examples/figure12.qcs", b, 97, 61, 3, 1);
  Image *ia = ra ? NULL : img_read_exr(a, err, sizeof err);
  Image *ib = rb ? NULL : img_read_exr(b, err, sizeof err);
  int same = ia && ib;
  if (same) {
    size_t n = (size_t)ia->width * ia->height;
    same = !memcmp(ia->rgba, ib->rgba, n * 4 * sizeof(float)) &&
           !memcmp(ia->z, ib->z, n * sizeof(float)) &&
           !memcmp(ia->n, ib->n, n * 3 * sizeof(float)) &&
           !memcmp(ia->cost, ib->cost, n * sizeof(float));
  }
  CHECK("render: 1 and 3 threads give the same image, bit for bit", same);
  img_free(ia);
  img_free(ib);
}

/* The tolerance in force: the requested one near the origin; what doubles
   resolve (4e-16 |x|) when the eye or the scene is far from it. */
static RenderReport tol_rep;
static int tol_capture(void *ctx, const struct Scene *s,
                       const struct RenderSettings *rs, const char *path,
                       char *err, size_t errlen) {
  (void)ctx; (void)path;
  RenderSettings r = *rs;
  r.width = 24;
  r.height = 16;
  r.threads = 1;
  r.progress = NULL;
  Image *im = render_scene(s, &r, &tol_rep, NULL, err, errlen);
  if (!im) return -1;
  img_free(im);
  return 0;
}

static void tolerance_test(void) {
  static const double far[] = {0, 1e6, 1e9};
  for (int i = 0; i < 3; i++) {
    char src[512], name[96];
    snprintf(src, sizeof src,
             "renderWith [Camera (%.17g, 2, 3) (%.17g, 0.5, 0.5) 40] "
             "\"x.png\" (Shift (%.17g, 0, 0) (Rounded 0.1 UnitCube))\n",
             far[i] + 2, far[i] + 0.5, far[i]);
    RenderOverrides o = {0};
    o.capture = tol_capture;
    render_set_overrides(I, &o);
    memset(&tol_rep, 0, sizeof tol_rep);
    int st = interp_run_string(I, "<tol>", src, MODE_SCRIPT);
    render_set_overrides(I, NULL);
    /* The largest coordinate is the eye's, X + 2, or a conservative bound
       of the cube (X + 1.1 padded by at most a few units at X = 1e9). */
    long double want = 4e-16L * (far[i] + 2), want_hi = 4e-16L * (far[i] + 10);
    if (want < 1e-9L) want = want_hi = 1e-9L;
    snprintf(name, sizeof name, "tolerance in force with the scene at %g", far[i]);
    if (getenv("QCS_TEST_VERBOSE"))
      printf("# st %d tol %g in force %.17g want %.17Lg primary %ld\n", st,
             tol_rep.tol, tol_rep.tol_in_force, want, tol_rep.primary);
    CHECK(name, st == RUN_OK && tol_rep.tol == 1e-9 &&
                    tol_rep.tol_in_force >= want * (1 - 1e-15L) &&
                    tol_rep.tol_in_force <= want_hi * (1 + 1e-15L) &&
                    tol_rep.primary == 24 * 16);
  }
}

/* Tiles: the per-tile culling and pruning (render.c, TileCull) against
   the untiled tracer (QCS_TILES=0): the same pixels, depths, normals and
   cost, bit for bit, and the same counts of rays, hits, density
   evaluations, segments and polishing steps (the root searches did the
   same work on the same views). A leaf the tile dropped that a ray needed
   would change a root or a count; a box culled wrongly, a hit. */
typedef struct TileCase {
  int width, height, spp, threads;
  int renders, same, counts_same;
  long primary, spared;
} TileCase;

/* The switch the two renders differ by: QCS_TILES, or QCS_ENVELOPE for
   the shadow rays' envelope test (envelope_examples_test). */
static const char *toggle = "QCS_TILES";

static Image *render_tiles(const struct Scene *s, const RenderSettings *rs,
                           int tiled, RenderReport *rep, char *err,
                           size_t errlen) {
  if (tiled) unsetenv(toggle);
  else setenv(toggle, "0", 1);
  Image *im = render_scene(s, rs, rep, NULL, err, errlen);
  unsetenv(toggle);
  return im;
}

static int tiles_capture(void *ctx, const struct Scene *s,
                         const struct RenderSettings *rs, const char *path,
                         char *err, size_t errlen) {
  (void)path;
  TileCase *tc = ctx;
  RenderSettings r = *rs;
  r.width = tc->width;
  r.height = tc->height;
  r.spp = tc->spp;
  r.threads = tc->threads;
  r.aovs = IMG_Z | IMG_N | IMG_COST;
  r.progress = NULL;
  RenderReport ra, rb;
  Image *a = render_tiles(s, &r, 0, &ra, err, errlen);
  Image *b = a ? render_tiles(s, &r, 1, &rb, err, errlen) : NULL;
  if (!a || !b) {
    img_free(a);
    return -1;
  }
  size_t n = (size_t)a->width * (size_t)a->height;
  int same = a->width == b->width && a->height == b->height &&
             !memcmp(a->rgba, b->rgba, n * 4 * sizeof(float)) &&
             !memcmp(a->z, b->z, n * sizeof(float)) &&
             !memcmp(a->n, b->n, n * 3 * sizeof(float)) &&
             !memcmp(a->cost, b->cost, n * sizeof(float));
  int counts = ra.primary == rb.primary && ra.shadow == rb.shadow &&
               ra.hits == rb.hits && ra.evals == rb.evals &&
               ra.segments == rb.segments && ra.steps == rb.steps &&
               ra.soft_solves == rb.soft_solves &&
               ra.max_ray_work == rb.max_ray_work;
  if (strcmp(toggle, "QCS_TILES")) {
    /* the envelope spares searches: the same rays and hits, no more
       work, and (tc->spared) how much less; the cost AOV counts it */
    counts = ra.primary == rb.primary && ra.shadow == rb.shadow &&
             ra.hits == rb.hits && rb.evals <= ra.evals &&
             rb.segments <= ra.segments;
    same = a->width == b->width && a->height == b->height &&
           !memcmp(a->rgba, b->rgba, n * 4 * sizeof(float)) &&
           !memcmp(a->z, b->z, n * sizeof(float)) &&
           !memcmp(a->n, b->n, n * 3 * sizeof(float));
    tc->spared += ra.segments - rb.segments;
  }
  if (getenv("QCS_TEST_VERBOSE"))
    printf("# tiles: %d same %d counts %d primary %ld shadow %ld evals %ld/%ld\n",
           tc->renders, same, counts, ra.primary, ra.shadow, ra.evals, rb.evals);
  tc->renders++;
  tc->same += same;
  tc->counts_same += counts;
  tc->primary += ra.primary;
  img_free(a);
  img_free(b);
  return 0;
}

static void tiles_run(TileCase *tc, const char *file, const char *src) {
  RenderOverrides o = {0};
  o.capture = tiles_capture;
  o.capture_ctx = tc;
  render_set_overrides(I, &o);
  int st = file ? interp_run_file(I, file)
                : interp_run_string(I, "<tiles>", src, MODE_SCRIPT);
  render_set_overrides(I, NULL);
  if (st != RUN_OK) tc->renders = -1000;
}

static void tiles_examples_test(void) {
  static const char *const scenes[] = {
      "figure12", "figure12-sharp", "figure13", "figure15a",
      "figure15b", "soft-cloud", "teapot", "mould", "staplers"};
  for (size_t i = 0; i < sizeof scenes / sizeof *scenes; i++) {
    char ex[256], name[300];
    snprintf(ex, sizeof ex, "examples/%s.qcs", scenes[i]);
    /* 150 x 95 on 2 threads (partial tiles at the edges), and figure12
       with 3 x 3 samples a pixel */
    for (int spp = 1; spp <= 9; spp += 8) {
      if (spp > 1 && i > 0) break;
      TileCase tc = {150, 95, spp, 2, 0, 0, 0, 0, 0};
      tiles_run(&tc, ex, NULL);
      snprintf(name, sizeof name, "tiles: %s (%d spp) tiled = untiled, "
               "bit for bit", scenes[i], spp);
      CHECK(name, tc.renders >= 1 && tc.same == tc.renders &&
                      tc.primary == 150L * 95 * spp * tc.renders);
      snprintf(name, sizeof name, "tiles: %s (%d spp) the same rays and "
               "root-search work", scenes[i], spp);
      CHECK(name, tc.renders >= 1 && tc.counts_same == tc.renders);
    }
  }
}

/* The shadow rays' envelope test (render.c, dt_envelope_clear) against
   the full search (QCS_ENVELOPE=0): the same pixels, depths and normals,
   bit for bit, the same rays and hits, and no more root-search work; on
   figure15a (one rounded cuboid, every self-test provable) it must spare
   some. A clear the envelope gave wrongly would light a shadowed pixel. */
static void envelope_examples_test(void) {
  static const char *const scenes[] = {"figure12", "figure13", "figure15a",
                                       "figure15b", "staplers", "mould"};
  toggle = "QCS_ENVELOPE";
  for (size_t i = 0; i < sizeof scenes / sizeof *scenes; i++) {
    char ex[256], name[300];
    snprintf(ex, sizeof ex, "examples/%s.qcs", scenes[i]);
    TileCase tc = {150, 95, 1, 2, 0, 0, 0, 0, 0};
    tiles_run(&tc, ex, NULL);
    snprintf(name, sizeof name, "envelope: %s the same picture, rays and "
             "hits with and without it, no more work (%ld segments spared)",
             scenes[i], tc.spared);
    CHECK(name, tc.renders >= 1 && tc.same == tc.renders &&
                    tc.counts_same == tc.renders &&
                    (strcmp(scenes[i], "figure15a") || tc.spared > 0));
  }
  toggle = "QCS_TILES";
}

/* xorshift64*: the random scenes' numbers in [0, 1) */
static unsigned long long tile_rng = 0x9E3779B97F4A7C15ULL;
static double urand(void) {
  tile_rng ^= tile_rng >> 12;
  tile_rng ^= tile_rng << 25;
  tile_rng ^= tile_rng >> 27;
  return (double)((tile_rng * 2685821657736338717ULL) >> 11) * 0x1p-53;
}

/* A box: UnitCube scaled, turned and moved, as qcs source. */
static int rand_box(char *b, size_t n) {
  static const char *const ax[] = {"x", "y", "z"};
  return snprintf(b, n, "(Shift (%.3f, %.3f, %.3f) (Rotate \"%s\" %.1f "
                  "(Scale (%.3f, %.3f, %.3f) UnitCube)))",
                  4 * urand() - 2, 2 * urand() - 0.5, 4 * urand() - 2,
                  ax[(int)(3 * urand())], 360 * urand(), 0.3 + 1.5 * urand(),
                  0.3 + 1.5 * urand(), 0.3 + 1.5 * urand());
}

static void tiles_random_test(void) {
  int scenes = 24, ok = 0, counts = 0, ran = 0;
  for (int k = 0; k < scenes; k++) {
    char src[8192], b1[256], b2[256];
    size_t m = 0;
    int nobj = 2 + (int)(5 * urand());
    m += (size_t)snprintf(src + m, sizeof src - m, "scene = foldr1 Union [");
    for (int j = 0; j < nobj; j++) {
      rand_box(b1, sizeof b1);
      rand_box(b2, sizeof b2);
      double r = 0.02 + 0.3 * urand();
      int kind = (int)(6 * urand());
      const char *sep = j ? ", " : "";
      if (kind == 0)
        m += (size_t)snprintf(src + m, sizeof src - m, "%sRounded %.3f %s", sep, r, b1);
      else if (kind == 1)
        m += (size_t)snprintf(src + m, sizeof src - m, "%sRounded %.3f (Difference %s %s)", sep, r, b1, b2);
      else if (kind == 2)
        m += (size_t)snprintf(src + m, sizeof src - m, "%sSetDifference (Rounded %.3f %s) %s", sep, r, b1, b2);
      else if (kind == 3)
        m += (size_t)snprintf(src + m, sizeof src - m, "%sRounded %.3f (Sum %s %s)", sep, r, b1, b2);
      else if (kind == 4)
        m += (size_t)snprintf(src + m, sizeof src - m, "%sIntersection (Rounded %.3f %s) (Rounded %.3f %s)", sep, r, b1, 0.5 * r, b2);
      else
        m += (size_t)snprintf(src + m, sizeof src - m, "%s%s", sep, b1);
    }
    if (urand() < 0.6)
      m += (size_t)snprintf(src + m, sizeof src - m, ", Halfspace ((0, 1, 0), -0.5)");
    double th = 6.2831853 * urand(), ph = 0.2 + 1.1 * urand(), R = 5 + 6 * urand();
    m += (size_t)snprintf(src + m, sizeof src - m,
                          "];\nrenderWith [Camera (%.3f, %.3f, %.3f) (%.3f, %.3f, %.3f) %.1f, "
                          "Light (%.3f, %.3f, %.3f)] \"x.png\" scene\n",
                          R * cos(th) * cos(ph), R * sin(ph), R * sin(th) * cos(ph),
                          urand() - 0.5, urand(), urand() - 0.5, 20 + 50 * urand(),
                          12 * urand() - 6, 4 + 6 * urand(), 12 * urand() - 6);
    TileCase tc = {61 + (int)(40 * urand()), 37 + (int)(30 * urand()),
                   urand() < 0.3 ? 4 : 1, 2, 0, 0, 0, 0, 0};
    tiles_run(&tc, NULL, src);
    if (tc.renders == 1) ran++;
    if (tc.renders == 1 && tc.same == 1) ok++;
    else if (getenv("QCS_TEST_VERBOSE")) printf("# differs:\n%s", src);
    if (tc.renders == 1 && tc.counts_same == 1) counts++;
  }
  CHECK("tiles: 24 random rounded scenes render", ran == scenes);
  CHECK("tiles: 24 random rounded scenes tiled = untiled, bit for bit",
        ok == scenes);
  CHECK("tiles: 24 random rounded scenes, the same root-search work",
        counts == scenes);
}

static void interrupt_test(void) {
  char out[512];
  snprintf(out, sizeof out, "%s/interrupted.png", tmpdir);
  qcs_interrupted = 1; /* as if Ctrl-C came before the first tile */
  int r = render_file("examples/figure12.qcs", out, 150, 95, 2, 0);
  qcs_interrupted = 0;
  CHECK("render: an interrupted render fails", r != 0);
  CHECK("render: an interrupted render leaves no file", access(out, F_OK) != 0);
  /* Nor does it leave a temporary in the folder. */
  char cmd[600];
  snprintf(cmd, sizeof cmd, "ls -A %s | grep -q tmp", tmpdir);
  CHECK("render: no temporary file left behind", system(cmd) != 0);
}

int main(void) {
  check_prefix = "render";
  if (!mkdtemp(tmpdir)) return 1;
  I = bind_interp_new();
  char probe;
  interp_set_stack(I, &probe, 4u << 20);
  static const char *const scenes[] = {
      "figure12", "figure12-sharp", "figure13", "figure15a",
      "figure15b", "soft-cloud", "teapot", "mould", "staplers"};
  for (size_t i = 0; i < sizeof scenes / sizeof *scenes; i++)
    reference_test(scenes[i]);
  if (!getenv("QCS_UPDATE_REFERENCES")) {
    exr_test();
    tolerance_test();
    determinism_test();
    tiles_examples_test();
    envelope_examples_test();
    tiles_random_test();
    interrupt_test();
  }
  char cmd[600];
  snprintf(cmd, sizeof cmd, "rm -rf %s", tmpdir);
  if (system(cmd) != 0) return 1;
  CHECK_DONE();
}
