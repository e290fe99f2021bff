/* tradeoff.c: error against run time, for the root tolerance and for the
 * quasi-convolution itself. See tradeoff.h for the job and the ownership
 * rules. */
#include "study/tradeoff.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "lang/interp.h"
#include "render/camera.h"
#include "render/mesh.h"
#include "render/render.h"
#include "scene/scene.h"
#include "scene/ray.h"
#include "bind/render_lang.h"

static double now_seconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ------------------------------------------------------------------ */
/* 1. The tolerance ladder                                             */

static double rung_tol(int i) { return pow(10.0, -2.0 - i); }

/* Render at tol, best of reps; the image of the last run is returned. */
static Image *render_rung(const Scene *s, const RenderSettings *base,
                          double tol, int reps, TradeoffRow *row, char *err,
                          size_t errlen) {
  RenderSettings rs = *base;
  rs.tol = tol;
  Image *im = NULL;
  row->tol = tol;
  row->seconds = INFINITY;
  row->worst = 0;
  row->spp = 0;
  for (int k = 0; k < reps; k++) {
    RenderReport rep;
    img_free(im);
    im = render_scene(s, &rs, &rep, &qcs_interrupted, err, errlen);
    if (!im) {
      if (rep.interrupted) snprintf(err, errlen, "tradeoff interrupted");
      return NULL;
    }
    if (rep.seconds < row->seconds) row->seconds = rep.seconds;
    if (rep.seconds > row->worst) row->worst = rep.seconds;
    row->evals = rep.evals;
    row->steps = rep.steps;
  }
  return im;
}

/* The hit distances of a fixed sample of primary rays (one through each
   pixel centre, the render's own camera: render/camera.h) in double
   precision: the float Z plane cannot resolve errors below ~1e-7 of the
   distance. NAN where the ray misses or starts inside. Returns 0, or -1
   on no memory (or a camera the render itself would have refused). */
static int sample_hits(const Scene *s, const RenderSettings *rs, double tol,
                       double *z) {
  double lo[3], hi[3];
  char err[200];
  Camera cam;
  int has_box = camera_scene_box(s, lo, hi);
  if (has_box < 0 || camera_setup(&cam, rs, has_box, lo, hi, err, sizeof err))
    return -1;
  RayCtx *c = ray_ctx_new(s, tol);
  if (!c) return -1;
  for (int y = 0; y < rs->height; y++)
    for (int x = 0; x < rs->width; x++) {
      double d[3];
      camera_ray(&cam, x + 0.5, y + 0.5, d);
      ray_reset(c);
      csg_span *sp;
      int n = ray_spans(s, s->root, cam.eye, d, 0, INFINITY, c, &sp);
      double hit = NAN;
      if (n > 0 && sp[0].t0 > 0) hit = sp[0].t0;
      z[(size_t)y * (size_t)rs->width + (size_t)x] = hit;
    }
  if (c->failed) {
    ray_ctx_free(c);
    return -1;
  }
  ray_ctx_free(c);
  return 0;
}

/* Hit-distance errors of the sample against the reference's. */
static void compare_hits(const double *z, const double *zr, size_t n,
                         TradeoffRow *row) {
  double sum2 = 0, mx = 0;
  long both = 0;
  for (size_t i = 0; i < n; i++) {
    if (isnan(z[i]) || isnan(zr[i])) continue;
    double dz = fabs(z[i] - zr[i]);
    if (dz > 10.0 * row->tol + 1e-9 * (1.0 + fabs(zr[i]))) continue;
    both++;
    sum2 += dz * dz;
    if (dz > mx) mx = dz;
  }
  row->max_dz = mx;
  row->rms_dz = both ? sqrt(sum2 / (double)both) : 0;
  row->both = both;
}

static void compare_rung(const Image *a, const Image *ref, TradeoffRow *row) {
  size_t n = (size_t)a->width * (size_t)a->height;
  long changed = 0;
  const double cos_max = cos(10.0 * M_PI / 180.0);
  for (size_t i = 0; i < n; i++) {
    double za = a->z[i], zr = ref->z[i];
    int ha = isfinite(za), hr = isfinite(zr);
    if (ha != hr) {
      changed++;
      continue;
    }
    if (!ha) continue;
    const float *na = a->n + 3 * i, *nr = ref->n + 3 * i;
    double dot = (double)na[0] * nr[0] + (double)na[1] * nr[1] +
                 (double)na[2] * nr[2];
    double la = sqrt((double)na[0] * na[0] + (double)na[1] * na[1] +
                     (double)na[2] * na[2]);
    double lr = sqrt((double)nr[0] * nr[0] + (double)nr[1] * nr[1] +
                     (double)nr[2] * nr[2]);
    double dz = fabs(za - zr);
    if ((la > 0 && lr > 0 && dot < cos_max * la * lr) ||
        dz > 10.0 * row->tol + 1e-6 * (1.0 + fabs(zr))) {
      changed++;
      continue;
    }
  }
  row->changed = changed;
  double share;
  img_compare(a, ref, &row->rms_rgb, &share, 1.0 / 255.0);
}

/* The truth about cost: the spread of the best times over the ladder
   against the run-to-run noise, the largest spread between the repeats of
   one rung. */
static void cost_line(FILE *out, const TradeoffRow *rows, int n, int reps) {
  double lo = INFINITY, hi = 0, noise = 0;
  int ilo = 0, ihi = 0;
  for (int i = 0; i < n; i++) {
    if (rows[i].seconds < lo) lo = rows[i].seconds, ilo = i;
    if (rows[i].seconds > hi) hi = rows[i].seconds, ihi = i;
    if (rows[i].seconds > 0)
      noise = fmax(noise, (rows[i].worst - rows[i].seconds) / rows[i].seconds);
  }
  if (!(lo > 0)) return;
  double spread = 100.0 * (hi - lo) / lo;
  noise *= 100.0;
  if (reps < 2)
    fprintf(out, "\ntime varies by %.0f%% over the ladder; with one run per "
            "rung the run-to-run noise\nis not measured (--repeats 3 "
            "measures it).\n", spread);
  else if (spread <= noise)
    fprintf(out, "\ntime varies by %.0f%% over the ladder, within run-to-run "
            "noise of %.0f%% (the largest\nspread between the %d repeats of "
            "one rung): the tolerance costs almost nothing here.\n",
            spread, noise, reps);
  else
    fprintf(out, "\ntime varies by %.0f%% over the ladder (fastest %.0e, "
            "slowest %.0e), beyond run-to-run\nnoise of %.0f%% (the largest "
            "spread between the %d repeats of one rung): the tolerance\n"
            "costs measurable time here.\n", spread, rows[ilo].tol,
            rows[ihi].tol, noise, reps);
}

int tradeoff_scene(const Scene *s, const RenderSettings *base_in,
                   const TradeoffOptions *o, const char *name,
                   TradeoffRow *rows, char *err, size_t errlen) {
  RenderSettings base = *base_in;
  if (o->width) base.width = o->width, base.height = o->height;
  if (o->threads) base.threads = o->threads;
  base.aovs = IMG_Z | IMG_N;
  base.progress = NULL;
  int reps = o->repeats > 0 ? o->repeats : 3;
  FILE *out = o->out ? o->out : stdout;
  const char *svg = o->svg ? o->svg : "tradeoff.svg";

  /* The reference first: the tightest rung. */
  Image *ref = render_rung(s, &base, rung_tol(TRADEOFF_RUNGS - 1), reps,
                           &rows[TRADEOFF_RUNGS - 1], err, errlen);
  if (!ref) return -1;
  size_t npix = (size_t)base.width * (size_t)base.height;
  double *zref = malloc(npix * sizeof *zref), *z = malloc(npix * sizeof *z);
  if (!zref || !z ||
      sample_hits(s, &base, rung_tol(TRADEOFF_RUNGS - 1), zref)) {
    free(zref);
    free(z);
    img_free(ref);
    snprintf(err, errlen, "out of memory");
    return -1;
  }
  TradeoffRow *rr = &rows[TRADEOFF_RUNGS - 1];
  rr->max_dz = rr->rms_dz = rr->rms_rgb = 0;
  rr->changed = 0;
  rr->both = 0;
  for (size_t i = 0; i < (size_t)ref->width * (size_t)ref->height; i++)
    rr->both += isfinite(ref->z[i]) != 0;
  for (int i = 0; i < TRADEOFF_RUNGS - 1; i++) {
    Image *im = render_rung(s, &base, rung_tol(i), reps, &rows[i], err, errlen);
    if (!im || sample_hits(s, &base, rung_tol(i), z)) {
      img_free(im);
      img_free(ref);
      free(zref);
      free(z);
      if (im) snprintf(err, errlen, "out of memory");
      return -1;
    }
    compare_rung(im, ref, &rows[i]);
    compare_hits(z, zref, npix, &rows[i]);
    img_free(im);
  }
  img_free(ref);
  free(zref);
  free(z);

  fprintf(out,
          "tradeoff of %s: %dx%d, %d sample%s/pixel, each rung rendered %d "
          "times (best wall time kept)\n"
          "errors against the 1e-12 rung. dZ: hit distance of the primary "
          "ray through each pixel centre,\ntraced again in double precision "
          "(the float Z plane cannot resolve it), over rays hitting the\n"
          "same surface in both (|dZ| <= 10 tol). RMS RGB over all pixels. "
          "Changed pixels (from the Z and N planes): "
          "hit vs miss, normal turned > 10 deg,\nor Z moved > 10 tol.\n\n",
          name, base.width, base.height, base.spp, base.spp == 1 ? "" : "s",
          reps);
  if (!(s->flags & SCENE_HAS_ROUNDED))
    fprintf(out, "note: this scene has no Rounded object. The root tolerance "
            "only steers the density\nroot search (Figure 9): sharp planes "
            "are solved directly and soft objects' sextics\nto machine "
            "precision, so every rung traces the same surfaces and every "
            "error below is 0.\n\n");
  fprintf(out, "| tol | time s | evals | steps | max dZ | RMS dZ | RMS RGB "
               "| changed px |\n|---|---|---|---|---|---|---|---|\n");
  for (int i = 0; i < TRADEOFF_RUNGS; i++) {
    const TradeoffRow *w = &rows[i];
    if (i == TRADEOFF_RUNGS - 1)
      fprintf(out, "| %.0e | %.4f | %ld | %ld | ref | ref | ref | ref |\n",
              w->tol, w->seconds, w->evals, w->steps);
    else
      fprintf(out, "| %.0e | %.4f | %ld | %ld | %.2e | %.2e | %.2e | %ld |\n",
              w->tol, w->seconds, w->evals, w->steps, w->max_dz, w->rms_dz,
              w->rms_rgb, w->changed);
  }
  cost_line(out, rows, TRADEOFF_RUNGS, reps);
  if (svg[0]) {
    char title[300];
    snprintf(title, sizeof title, "%s, %dx%d: hit-distance error against time",
             name, base.width, base.height);
    if (tradeoff_svg(rows, TRADEOFF_RUNGS - 1, title, svg, err, errlen))
      return -1;
    fprintf(out, "\nplot written to %s\n", svg);
  }
  fflush(out);
  return 0;
}

/* ---- the samples-per-pixel ladder ---- */

int tradeoff_spp(const Scene *s, const RenderSettings *base_in,
                 const TradeoffOptions *o, const char *name,
                 TradeoffRow *rows, char *err, size_t errlen) {
  RenderSettings base = *base_in;
  int capped = 0, sw = base.width, sh = base.height;
  if (o->width) base.width = o->width, base.height = o->height;
  else if (base.width > TRADEOFF_SPP_WIDTH) {
    capped = 1;
    base.height = (int)lround((double)base.height * TRADEOFF_SPP_WIDTH /
                              (double)base.width);
    if (base.height < 1) base.height = 1;
    base.width = TRADEOFF_SPP_WIDTH;
  }
  if (o->threads) base.threads = o->threads;
  base.progress = NULL;
  int reps = o->repeats > 0 ? o->repeats : 3;
  FILE *out = o->out ? o->out : stdout;
  const char *svg = o->svg ? o->svg : "tradeoff.svg";
  const int n = TRADEOFF_SPP_RUNGS;

  base.spp = TRADEOFF_SPP_REF;
  Image *ref = render_rung(s, &base, base.tol, 1, &rows[n], err, errlen);
  if (!ref) return -1;
  rows[n].spp = TRADEOFF_SPP_REF;
  rows[n].rms_rgb = 0;
  for (int i = 0; i < n; i++) {
    base.spp = 1 << (2 * i); /* 1, 4, 16, 64 */
    Image *im = render_rung(s, &base, base.tol, reps, &rows[i], err, errlen);
    if (!im) {
      img_free(ref);
      return -1;
    }
    rows[i].spp = base.spp;
    double share;
    img_compare(im, ref, &rows[i].rms_rgb, &share, 1.0 / 255.0);
    img_free(im);
  }
  img_free(ref);

  fprintf(out,
          "samples-per-pixel tradeoff of %s: %dx%d", name, base.width,
          base.height);
  if (capped)
    fprintf(out, " (the script's %dx%d capped to %d wide: the %d-sample "
            "reference is costly;\n--size WxH to change)", sw, sh,
            TRADEOFF_SPP_WIDTH, TRADEOFF_SPP_REF);
  fprintf(out, ", root tolerance %.0e.\neach rung rendered %d times (best "
          "wall time kept), the %d-sample reference once.\nRMS RGB: linear "
          "RGB difference from the reference over all pixels and channels."
          "\n\n| samples/px | time s | RMS RGB |\n|---|---|---|\n",
          base.tol, reps, TRADEOFF_SPP_REF);
  for (int i = 0; i <= n; i++) {
    if (i == n)
      fprintf(out, "| %d | %.4f | ref |\n", rows[i].spp, rows[i].seconds);
    else
      fprintf(out, "| %d | %.4f | %.2e |\n", rows[i].spp, rows[i].seconds,
              rows[i].rms_rgb);
  }
  if (svg[0]) {
    char title[300];
    snprintf(title, sizeof title, "%s, %dx%d: image error against time",
             name, base.width, base.height);
    if (tradeoff_svg(rows, n, title, svg, err, errlen)) return -1;
    fprintf(out, "\nplot written to %s\n", svg);
  }
  fflush(out);
  return 0;
}

/* ------------------------------------------------------------------ */
/* 4. The mesh-tolerance ladder                                        */

/* The bounded parts of node into parts[]: the node if its box is finite,
   else those of a union's children; an unbounded part that is not a
   union (a floor) is counted in *left. */
static void bounded_parts(const Scene *s, int node, int *parts, int *n,
                          int max, int *left) {
  double lo[3], hi[3];
  if (render_node_box(s, node, lo, hi) && isfinite(hi[0] - lo[0]) &&
      isfinite(hi[1] - lo[1]) && isfinite(hi[2] - lo[2])) {
    if (*n < max) parts[(*n)++] = node;
    return;
  }
  if (s->nodes[node].kind == SC_UNION) {
    bounded_parts(s, s->nodes[node].a, parts, n, max, left);
    bounded_parts(s, s->nodes[node].b, parts, n, max, left);
    return;
  }
  ++*left;
}

typedef struct MeshErr {
  double max, sum2;
  long n, unresolved;
} MeshErr;

/* The distance from p along the unit vector u to the nearest crossing of
   node's surface within L either way; -1 if there is none. */
static double normal_dist(const Scene *s, int node, const double p[3],
                          const double u[3], double L, RayCtx *c) {
  double o[3] = {p[0] - L * u[0], p[1] - L * u[1], p[2] - L * u[2]};
  csg_span *sp;
  ray_reset(c);
  int ns = ray_spans(s, node, o, u, 0, 2 * L, c, &sp);
  double best = -1;
  for (int i = 0; i < ns; i++) {
    double e[2] = {sp[i].t0, sp[i].t1};
    for (int k = 0; k < 2; k++)
      if (e[k] > 0 && e[k] < 2 * L && (best < 0 || fabs(e[k] - L) < best))
        best = fabs(e[k] - L);
  }
  return best;
}

/* The sampled distance of mesh m to node's surface (see tradeoff.h). */
static void mesh_error(const Scene *s, int node, const Mesh *m, double L,
                       RayCtx *c, MeshErr *e) {
  size_t stride = m->nt > TRADEOFF_MESH_SAMPLES
                      ? (m->nt + TRADEOFF_MESH_SAMPLES - 1) /
                            TRADEOFF_MESH_SAMPLES
                      : 1;
  for (size_t t = 0; t < m->nt; t += stride) {
    const double *A = m->v + 3 * m->t[3 * t], *B = m->v + 3 * m->t[3 * t + 1],
                 *C = m->v + 3 * m->t[3 * t + 2];
    double ab[3], ac[3], u[3];
    for (int k = 0; k < 3; k++) ab[k] = B[k] - A[k], ac[k] = C[k] - A[k];
    u[0] = ab[1] * ac[2] - ab[2] * ac[1];
    u[1] = ab[2] * ac[0] - ab[0] * ac[2];
    u[2] = ab[0] * ac[1] - ab[1] * ac[0];
    double ul = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    if (!(ul > 0)) continue;
    for (int k = 0; k < 3; k++) u[k] /= ul;
    double pts[4][3];
    for (int k = 0; k < 3; k++) {
      pts[0][k] = (A[k] + B[k] + C[k]) / 3;
      pts[1][k] = 0.5 * (A[k] + B[k]);
      pts[2][k] = 0.5 * (B[k] + C[k]);
      pts[3][k] = 0.5 * (C[k] + A[k]);
    }
    /* three directions near the axes but in no plane of a box: a line
       through a point of a sharp edge then crosses there, not along a
       face */
    static const double axes[3][3] = {
        {0.9415, 0.2957, 0.1614}, {0.1542, 0.9232, -0.3519},
        {-0.2130, 0.1429, 0.9665}};
    for (int q = 0; q < 4; q++) {
      /* the nearest crossing along the normal and three directions: at
         least the point's distance to the surface, and near it where the
         mesh cuts a sharp edge (along the normal alone it is far) */
      double dd = normal_dist(s, node, pts[q], u, L, c);
      for (int a = 0; a < 3; a++) {
        double w[3], wl = sqrt(axes[a][0] * axes[a][0] +
                               axes[a][1] * axes[a][1] +
                               axes[a][2] * axes[a][2]);
        for (int k = 0; k < 3; k++) w[k] = axes[a][k] / wl;
        double da = normal_dist(s, node, pts[q], w, L, c);
        if (da >= 0 && (dd < 0 || da < dd)) dd = da;
      }
      if (dd < 0) {
        e->unresolved++;
        continue;
      }
      e->max = fmax(e->max, dd);
      e->sum2 += dd * dd;
      e->n++;
    }
  }
}

int tradeoff_mesh(const Scene *s, const TradeoffOptions *o, const char *name,
                  TradeoffRow *rows, char *err, size_t errlen) {
  FILE *out = o->out ? o->out : stdout;
  const char *svg = o->svg ? o->svg : "tradeoff.svg";
  int reps = o->repeats > 0 ? o->repeats : 1;
  int parts[64], np = 0, left = 0;
  bounded_parts(s, s->root, parts, &np, 64, &left);
  if (np == 0) {
    snprintf(err, errlen, "tradeoff --mesh: %s has no bounded part to mesh",
             name);
    return -1;
  }
  double size = 0;
  for (int i = 0; i < np; i++) {
    double lo[3], hi[3];
    render_node_box(s, parts[i], lo, hi);
    for (int k = 0; k < 3; k++) size = fmax(size, hi[k] - lo[k]);
  }
  RayCtx *c = ray_ctx_new(s, 1e-10 * fmax(size, 1));
  if (!c) {
    snprintf(err, errlen, "out of memory");
    return -1;
  }
  for (int r = 0; r < TRADEOFF_MESH_RUNGS; r++) {
    TradeoffRow *row = &rows[r];
    memset(row, 0, sizeof *row);
    row->mesh = 1;
    row->tol = size / (10.0 * (1 << r));
    MeshErr e = {0, 0, 0, 0};
    for (int i = 0; i < np; i++) {
      MeshSettings ms;
      memset(&ms, 0, sizeof ms);
      ms.tol = row->tol;
      ms.max_triangles = 20000000;
      double best = INFINITY;
      for (int k = 0; k < reps; k++) {
        Mesh *m = NULL;
        MeshReport mr;
        int bad;
        if (mesh_scene(s, parts[i], &ms, &m, &mr, &bad, err, errlen)) {
          ray_ctx_free(c);
          return -1;
        }
        best = fmin(best, mr.seconds);
        if (k == reps - 1) {
          row->triangles += mr.triangles;
          row->certified = fmax(row->certified, mr.certified);
          mesh_error(s, parts[i], m, 4 * row->tol, c, &e);
        }
        mesh_free(m);
      }
      row->seconds += best;
    }
    row->max_dz = e.max;
    row->rms_dz = e.n ? sqrt(e.sum2 / (double)e.n) : 0;
    row->changed = e.unresolved;
    row->both = e.n;
  }
  ray_ctx_free(c);

  fprintf(out, "mesh-tolerance tradeoff of %s: %d bounded part%s, size %.4g",
          name, np, np == 1 ? "" : "s", size);
  if (left)
    fprintf(out, " (%d unbounded part%s left out: a floor?)", left,
            left == 1 ? "" : "s");
  fprintf(out, ".\neach rung meshed %d time%s (best wall time kept). "
          "certified: the mesher's proven bound on\nthe distance of every "
          "mesh point to the surface. sampled: from the centre and edge\n"
          "midpoints of up to %d triangles a part to the nearest crossing "
          "of the surface\nalong the triangle's normal or 3 fixed lines "
          "(exact ray spans; at least the\ndistance to the surface), max and "
          "RMS over the points.\n\n"
          "| tolerance | triangles | time s | certified | sampled max | "
          "sampled RMS | points |\n|---|---|---|---|---|---|---|\n",
          reps, reps == 1 ? "" : "s", TRADEOFF_MESH_SAMPLES);
  for (int r = 0; r < TRADEOFF_MESH_RUNGS; r++) {
    fprintf(out, "| %.3g | %zu | %.4f | %.3g | %.3g | %.3g | %ld", rows[r].tol,
            rows[r].triangles, rows[r].seconds, rows[r].certified,
            rows[r].max_dz, rows[r].rms_dz, rows[r].both);
    if (rows[r].changed)
      fprintf(out, " (%ld beyond 4 tol)", rows[r].changed);
    fputs(" |\n", out);
  }
  if (rows[0].seconds > 0 && rows[0].triangles > 0)
    fprintf(out, "\nhalving the tolerance multiplied the triangles by %.2g "
            "and the time by %.2g\n(from the first rung to the last, per "
            "step: the mesh is uniform, not adaptive).\n",
            pow((double)rows[TRADEOFF_MESH_RUNGS - 1].triangles /
                    (double)rows[0].triangles,
                1.0 / (TRADEOFF_MESH_RUNGS - 1)),
            pow(rows[TRADEOFF_MESH_RUNGS - 1].seconds / rows[0].seconds,
                1.0 / (TRADEOFF_MESH_RUNGS - 1)));
  if (svg[0]) {
    char title[300];
    snprintf(title, sizeof title, "%s: mesh error against time", name);
    if (tradeoff_svg(rows, TRADEOFF_MESH_RUNGS, title, svg, err, errlen))
      return -1;
    fprintf(out, "\nplot written to %s\n", svg);
  }
  fflush(out);
  return 0;
}

/* ---- the plot ---- */

static void svg_escape(FILE *f, const char *s) {
  for (; *s; s++) {
    if (*s == '<') fputs("&lt;", f);
    else if (*s == '>') fputs("&gt;", f);
    else if (*s == '&') fputs("&amp;", f);
    else fputc(*s, f);
  }
}

int tradeoff_svg(const TradeoffRow *rows, int n, const char *title,
                 const char *path, char *err, size_t errlen) {
  double tmin = INFINITY, tmax = 0, emin = INFINITY, emax = 0;
  const int spp = n > 0 && rows[0].spp > 0;
  const int mesh = n > 0 && !spp && rows[0].mesh;
#define ERR(i, k) (spp ? (k ? 0.0 : rows[i].rms_rgb) : \
                   mesh ? (k ? rows[i].certified : rows[i].max_dz) : \
                   (k ? rows[i].rms_dz : rows[i].max_dz))
  for (int i = 0; i < n; i++) {
    if (rows[i].seconds > 0) {
      tmin = fmin(tmin, rows[i].seconds);
      tmax = fmax(tmax, rows[i].seconds);
    }
    double e[2] = {ERR(i, 0), ERR(i, 1)};
    for (int k = 0; k < 2; k++)
      if (e[k] > 0) emin = fmin(emin, e[k]), emax = fmax(emax, e[k]);
  }
  if (!(tmax > 0)) tmin = 1e-3, tmax = 1;
  if (!(emax > 0)) emin = 1e-16, emax = 1;
  double x0 = floor(log10(tmin)), x1 = ceil(log10(tmax));
  double y0 = floor(log10(emin)), y1 = ceil(log10(emax));
  if (x1 <= x0) x1 = x0 + 1;
  if (y1 <= y0) y1 = y0 + 1;
  const double W = 720, H = 480, L = 90, R = 30, T = 50, B = 60;
  const double pw = W - L - R, ph = H - T - B;
#define PX(t) (L + (log10(t) - x0) / (x1 - x0) * pw)
#define PY(e) (T + (y1 - log10(e)) / (y1 - y0) * ph)
  char tmp[1100];
  snprintf(tmp, sizeof tmp, "%s.tmp", path);
  FILE *f = fopen(tmp, "w");
  if (!f) {
    snprintf(err, errlen, "cannot write %s", path);
    return -1;
  }
  fprintf(f,
          "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" "
          "height=\"%.0f\" viewBox=\"0 0 %.0f %.0f\" font-family=\"sans-serif\" "
          "font-size=\"12\">\n<rect width=\"100%%\" height=\"100%%\" "
          "fill=\"white\"/>\n<text x=\"%.0f\" y=\"24\" text-anchor=\"middle\" "
          "font-size=\"14\">",
          W, H, W, H, W / 2);
  svg_escape(f, title);
  fputs("</text>\n", f);
  /* Grid and ticks: decades, with 2 and 5 marks on the time axis. */
  for (double d = x0; d <= x1 + 1e-9; d++) {
    for (int m = 1; m <= 5; m += (m == 1 ? 1 : 3)) {
      double t = m * pow(10, d);
      if (log10(t) > x1 + 1e-9) break;
      double x = PX(t);
      fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" "
                 "stroke=\"#%s\"/>\n", x, T, x, T + ph, m == 1 ? "ccc" : "eee");
      if (m == 1 || x1 - x0 <= 2)
        fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">%g</text>\n",
                x, T + ph + 16, t);
    }
  }
  for (double d = y0; d <= y1 + 1e-9; d++) {
    double y = PY(pow(10, d));
    fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" "
               "stroke=\"#ccc\"/>\n<text x=\"%.1f\" y=\"%.1f\" "
               "text-anchor=\"end\">1e%d</text>\n",
            L, y, L + pw, y, L - 6, y + 4, (int)d);
  }
  fprintf(f, "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" "
             "fill=\"none\" stroke=\"black\"/>\n", L, T, pw, ph);
  fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">wall time "
             "of the %s, seconds (log)</text>\n", L + pw / 2, H - 18,
          mesh ? "mesh" : "render");
  if (mesh)
    fprintf(f, "<text transform=\"translate(22 %.1f) rotate(-90)\" "
               "text-anchor=\"middle\">distance of the mesh to the surface, "
               "scene units (log)</text>\n", T + ph / 2);
  else if (spp)
    fprintf(f, "<text transform=\"translate(22 %.1f) rotate(-90)\" "
               "text-anchor=\"middle\">RMS RGB error against %d samples/"
               "pixel (log)</text>\n", T + ph / 2, TRADEOFF_SPP_REF);
  else
    fprintf(f, "<text transform=\"translate(22 %.1f) rotate(-90)\" "
               "text-anchor=\"middle\">hit-distance error against tol "
               "1e-12, scene units (log)</text>\n", T + ph / 2);
  /* The two series. */
  const char *colour[2] = {"#c0392b", "#2e6db4"};
  for (int k = 0; k < (spp ? 1 : 2); k++) {
    fprintf(f, "<polyline fill=\"none\" stroke=\"%s\" points=\"", colour[k]);
    for (int i = 0; i < n; i++) {
      double e = ERR(i, k);
      if (e > 0 && rows[i].seconds > 0)
        fprintf(f, "%.1f,%.1f ", PX(rows[i].seconds), PY(e));
    }
    fputs("\"/>\n", f);
    for (int i = 0; i < n; i++) {
      double e = ERR(i, k);
      if (!(e > 0 && rows[i].seconds > 0)) continue;
      double x = PX(rows[i].seconds), y = PY(e);
      if (k == 0)
        fprintf(f, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"4\" fill=\"%s\"/>\n",
                x, y, colour[k]);
      else
        fprintf(f, "<rect x=\"%.1f\" y=\"%.1f\" width=\"7\" height=\"7\" "
                   "fill=\"%s\"/>\n", x - 3.5, y - 3.5, colour[k]);
      if (spp)
        fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" font-size=\"10\" "
                   "fill=\"%s\">%d spp</text>\n", x + 6, y - 5, colour[k],
                rows[i].spp);
      else if (mesh && k == 0) {
        int right = x > L + pw - 160; /* keep the label inside the frame */
        fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" font-size=\"10\" "
                   "fill=\"%s\" text-anchor=\"%s\">tol %.2g, %zu triangles"
                   "</text>\n", right ? x - 6 : x + 6, y + 14, colour[k],
                right ? "end" : "start", rows[i].tol, rows[i].triangles);
      } else if (mesh)
        ;
      else
        fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" font-size=\"10\" "
                   "fill=\"%s\">%.0e</text>\n", x + 6, y + (k ? 12 : -5),
                colour[k], rows[i].tol);
    }
  }
  /* Legend. */
  if (mesh) {
    fprintf(f, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"4\" fill=\"%s\"/>"
               "<text x=\"%.1f\" y=\"%.1f\">sampled maximum distance</text>\n"
               "<rect x=\"%.1f\" y=\"%.1f\" width=\"7\" height=\"7\" "
               "fill=\"%s\"/><text x=\"%.1f\" y=\"%.1f\">certified bound"
               "</text>\n",
            L + 16, T + 16, colour[0], L + 26, T + 20, L + 12.5, T + 32.5,
            colour[1], L + 26, T + 40);
  } else if (spp) {
    fprintf(f, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"4\" fill=\"%s\"/>"
               "<text x=\"%.1f\" y=\"%.1f\">RMS RGB error</text>\n"
               "<text x=\"%.1f\" y=\"%.1f\" font-size=\"10\">points "
               "labelled with samples per pixel</text>\n",
            L + pw - 200, T + 16, colour[0], L + pw - 190, T + 20,
            L + pw - 200, T + 38);
  } else {
  fprintf(f, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"4\" fill=\"%s\"/>"
             "<text x=\"%.1f\" y=\"%.1f\">maximum error</text>\n",
          L + pw - 150, T + 16, colour[0], L + pw - 140, T + 20);
  fprintf(f, "<rect x=\"%.1f\" y=\"%.1f\" width=\"7\" height=\"7\" fill=\"%s\"/>"
             "<text x=\"%.1f\" y=\"%.1f\">RMS error</text>\n",
          L + pw - 153.5, T + 32.5, colour[1], L + pw - 140, T + 40);
  fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" font-size=\"10\">points labelled "
             "with the root tolerance</text>\n", L + pw - 150, T + 58);
  }
  fputs("</svg>\n", f);
#undef PX
#undef PY
#undef ERR
  if (fclose(f) != 0 || rename(tmp, path) != 0) {
    remove(tmp);
    snprintf(err, errlen, "cannot write %s", path);
    return -1;
  }
  return 0;
}

/* ---- capture ---- */

typedef struct Job {
  const TradeoffOptions *opt;
  const char *name;
  int done, failed;
} Job;

static int capture(void *ctx, const Scene *s, const RenderSettings *rs,
                   const char *path, char *err, size_t errlen) {
  Job *j = ctx;
  if (j->done) return 0; /* only the first render */
  j->done = 1;
  TradeoffRow rows[TRADEOFF_RUNGS];
  memset(rows, 0, sizeof rows);
  if (j->opt->mesh_ladder
          ? tradeoff_mesh(s, j->opt, j->name, rows, err, errlen)
      : j->opt->spp_ladder
          ? tradeoff_spp(s, rs, j->opt, j->name, rows, err, errlen)
          : tradeoff_scene(s, rs, j->opt, j->name, rows, err, errlen)) {
    j->failed = 1;
    return -1;
  }
  return 0;
}

int tradeoff_file(Interp *I, const char *path, const TradeoffOptions *o) {
  Job j = {o, path, 0, 0};
  RenderOverrides ov;
  memset(&ov, 0, sizeof ov);
  ov.capture = capture;
  ov.capture_ctx = &j;
  RenderOverrides *saved = render_get_overrides(I);
  render_set_overrides(I, &ov);
  int status = 0;
  if (interp_run_file(I, path) != RUN_OK) status = 1;
  else if (!j.done) {
    if (!interp_has_global(I, "scene")) {
      fprintf(stderr, "qcs: error: tradeoff %s: the script renders nothing "
              "and defines no `scene`\n", path);
      status = 1;
    } else if (interp_eval_print(I, "renderWith [] \"tradeoff.png\" scene") !=
               RUN_OK) {
      status = 1;
    }
  }
  render_set_overrides(I, saved);
  return status || j.failed;
}

/* ------------------------------------------------------------------ */
/* 2. The true convolution                                             */

/* ---- the report ---- */

typedef struct Obj {
  const char *name, *note;
  dt_tape *quasi;
  csg_tape *sharp;
  double r;
  long points, chords; /* true-field evaluations and the chords they cast */
  int nrays;
  double o[64][3], d[64][3]; /* rays (unit directions) starting outside */
} Obj;

static dt_tape *wedge_tape(double alpha_deg, double r) {
  double a = alpha_deg * M_PI / 180;
  double na[3] = {0, -1, 0}, nb[3] = {-sin(a), cos(a), 0};
  dt_builder *b = dt_builder_new();
  dt_builder_leaf(b, na, 0, r);
  dt_builder_leaf(b, nb, 0, r);
  dt_builder_op(b, DT_PRODUCT);
  return dt_builder_finish(b, NULL);
}

static void box_leaves(dt_builder *b, const double lo[3], const double hi[3],
                       double r) {
  for (int k = 0; k < 3; k++) {
    double n[3] = {0, 0, 0};
    n[k] = 1;
    dt_builder_leaf(b, n, hi[k], r);
    if (k) dt_builder_op(b, DT_PRODUCT);
    n[k] = -1;
    dt_builder_leaf(b, n, -lo[k], r);
    dt_builder_op(b, DT_PRODUCT);
  }
}

static dt_tape *cube_tape(double r) {
  dt_builder *b = dt_builder_new();
  double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  box_leaves(b, lo, hi, r);
  return dt_builder_finish(b, NULL);
}

/* figure12's obj4: Rounded r (Difference UnitCube box1). */
static dt_tape *obj4_tape(double r) {
  dt_builder *b = dt_builder_new();
  double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  double lo1[3] = {0.25, 0.8, 0.25}, hi1[3] = {0.75, 1.3, 0.75};
  box_leaves(b, lo, hi, r);
  box_leaves(b, lo1, hi1, r);
  dt_builder_op(b, DT_DIFF);
  return dt_builder_finish(b, NULL);
}

static void add_ray(Obj *ob, const double target[3], const double dir_out[3],
                    double back) {
  if (ob->nrays == 64) return;
  double l = sqrt(dir_out[0] * dir_out[0] + dir_out[1] * dir_out[1] +
                  dir_out[2] * dir_out[2]);
  for (int k = 0; k < 3; k++) {
    ob->d[ob->nrays][k] = -dir_out[k] / l;
    ob->o[ob->nrays][k] = target[k] + back * dir_out[k] / l;
  }
  ob->nrays++;
}

/* Rays in the z = 0 plane through the apex of a wedge of interior angle
   alpha, travelling into the wedge in 7 directions spread over its
   interior angle (so every one meets the rounded tip, however acute), and
   rays perpendicular to the face y = 0 where the wedge is at least 4r
   thick, 0.5r, r and 2r beyond that point. */
static void wedge_rays(Obj *ob, double alpha_deg) {
  double apex[3] = {0, 0, 0};
  double a = alpha_deg * M_PI / 180;
  for (int i = 1; i <= 7; i++) {
    double gamma = a * i / 8.0;
    double dir[3] = {-cos(gamma), -sin(gamma), 0}; /* outward: back along */
    add_ray(ob, apex, dir, 3 * ob->r);
  }
  double fr[3] = {0.5, 1, 2};
  double x0 = alpha_deg < 90 ? 4 * ob->r / tan(a) : 0;
  for (int i = 0; i < 3; i++) {
    double x = x0 + fr[i] * ob->r;
    /* a point on face y = 0 inside the wedge's face (x > 0) */
    double tgt[3] = {x, 0, 0}, dir[3] = {0, -1, 0};
    add_ray(ob, tgt, dir, 3 * ob->r);
  }
}

static void cube_edge_rays(Obj *ob) {
  double tgt[3] = {1, 1, 0.5};
  for (int i = 0; i < 9; i++) {
    double a = (5 + 10 * i) * M_PI / 180;
    double dir[3] = {cos(a), sin(a), 0};
    add_ray(ob, tgt, dir, 3 * ob->r);
  }
}

static void cube_corner_rays(Obj *ob) {
  double tgt[3] = {1, 1, 1};
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      double th = (15 + 30 * i) * M_PI / 180, ph = (15 + 30 * j) * M_PI / 180;
      double dir[3] = {sin(th) * cos(ph), sin(th) * sin(ph), cos(th)};
      add_ray(ob, tgt, dir, 3 * ob->r);
    }
  double diag[3] = {1, 1, 1};
  add_ray(ob, tgt, diag, 3 * ob->r);
}

/* From figure12's camera towards a 5 x 5 grid over the top of obj4 (the
   hole's rim and the cube's top edges) and its front corners. */
static void obj4_rays(Obj *ob) {
  double eye[3] = {2.25, 3.2, 5.0};
  for (int i = 0; i < 5; i++)
    for (int j = 0; j < 5; j++) {
      double tgt[3] = {0.05 + 0.225 * i, 1.0, 0.05 + 0.225 * j};
      double dir[3] = {eye[0] - tgt[0], eye[1] - tgt[1], eye[2] - tgt[2]};
      double l = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
      add_ray(ob, tgt, dir, l); /* from the eye */
    }
}

/* The first crossing of the quasi field's 0.5 level along the ray, by
   marching in steps of r/16 then bisecting. -1 if none within len. */
static double quasi_cross(const dt_tape *t, const double o[3],
                          const double d[3], double len, double r,
                          long *evals) {
  double step = r / 16, s0 = 0;
  for (double s = step; s <= len; s += step) {
    double p[3] = {o[0] + s * d[0], o[1] + s * d[1], o[2] + s * d[2]};
    (*evals)++;
    if (dt_density(t, p) >= 0.5) {
      double a = s0, b = s;
      while (b - a > 1e-12 * r) {
        double m = 0.5 * (a + b);
        double q[3] = {o[0] + m * d[0], o[1] + m * d[1], o[2] + m * d[2]};
        (*evals)++;
        if (dt_density(t, q) >= 0.5) b = m;
        else a = m;
      }
      return 0.5 * (a + b);
    }
    s0 = s;
  }
  return -1;
}

int conv_report(FILE *out) {
  const double tol = 1e-6; /* fraction accuracy of the true convolution */
  enum { NOBJ = 8 };
  static Obj objs[NOBJ];
  memset(objs, 0, sizeof objs);
  int n = 0;
  objs[n] = (Obj){"cube edge (90 deg)", "r = 0.1, unit cube", cube_tape(0.1),
                  NULL, 0.1, 0, 0, 0, {{0}}, {{0}}};
  cube_edge_rays(&objs[n++]);
  objs[n] = (Obj){"cube corner", "r = 0.1, unit cube", cube_tape(0.1), NULL,
                  0.1, 0, 0, 0, {{0}}, {{0}}};
  cube_corner_rays(&objs[n++]);
  objs[n] = (Obj){"cube corner", "r = 0.3, unit cube", cube_tape(0.3), NULL,
                  0.3, 0, 0, 0, {{0}}, {{0}}};
  cube_corner_rays(&objs[n++]);
  double angles[4] = {30, 90, 135, 180};
  const char *wnames[4] = {"wedge 30 deg (acute)", "wedge 90 deg",
                           "wedge 135 deg (obtuse)",
                           "halfspace twice (180 deg)"};
  for (int i = 0; i < 4; i++) {
    objs[n] = (Obj){wnames[i], "r = 1 (scale-free)", wedge_tape(angles[i], 1),
                    NULL, 1, 0, 0, 0, {{0}}, {{0}}};
    wedge_rays(&objs[n++], angles[i]);
  }
  objs[n] = (Obj){"figure12 obj4 (Difference)", "r = 0.07", obj4_tape(0.07),
                  NULL, 0.07, 0, 0, 0, {{0}}, {{0}}};
  obj4_rays(&objs[n++]);

  fprintf(out,
          "Quasi-convolution against the true convolution (fraction of the "
          "ball inside the sharp polyhedron,\nexact chord lengths integrated "
          "by nested adaptive Gauss-Kronrod 7-15, requested %.0e, verified to 1e-7\nin the fraction against the exact cube edge 1/4, corner 1/8 and halfspace cap).\n"
          "d = (quasi crossing - true crossing) / r along each ray, positive "
          "where the quasi surface lies inside the true one.\n\n",
          tol);
  fprintf(out, "| object | radius | rays | max abs d | RMS d | mean d | "
               "min d | max d | quasi us/eval | true us/eval |\n"
               "|---|---|---|---|---|---|---|---|---|---|\n");
  for (int i = 0; i < n; i++) {
    Obj *ob = &objs[i];
    ob->sharp = conv_sharp_of(ob->quasi);
    if (!ob->quasi || !ob->sharp) return -1;
    long qe = 0;
    double tq = 0, tt = 0;
    double mx = 0, sum2 = 0, sum = 0, dmin = INFINITY, dmax = -INFINITY;
    int used = 0;
    for (int k = 0; k < ob->nrays; k++) {
      double len = 6 * ob->r + 10;
      double t0 = now_seconds();
      double sq = quasi_cross(ob->quasi, ob->o[k], ob->d[k], len, ob->r, &qe);
      tq += now_seconds() - t0;
      if (sq < 0) continue;
      t0 = now_seconds();
      double st = conv_crossing(ob->sharp, ob->r, ob->o[k], ob->d[k], sq,
                                  tol, &ob->points, &ob->chords);
      tt += now_seconds() - t0;
      if (st < 0) continue;
      double dd = (sq - st) / ob->r;
      used++;
      sum += dd;
      sum2 += dd * dd;
      mx = fmax(mx, fabs(dd));
      dmin = fmin(dmin, dd);
      dmax = fmax(dmax, dd);
    }
    fprintf(out, "| %s | %s | %d | %.4f | %.4f | %+.4f | %+.4f | %+.4f | "
                 "%.3f | %.0f (%.0f chords) |\n",
            ob->name, ob->note, used, mx, used ? sqrt(sum2 / used) : 0,
            used ? sum / used : 0, dmin, dmax, qe ? 1e6 * tq / (double)qe : 0,
            ob->points ? 1e6 * tt / (double)ob->points : 0,
            ob->points ? (double)ob->chords / (double)ob->points : 0);
    fflush(out);
  }
  for (int i = 0; i < n; i++) {
    dt_tape_free(objs[i].quasi);
    csg_tape_free(objs[i].sharp);
  }
  return 0;
}
