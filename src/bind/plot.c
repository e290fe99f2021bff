/* plot.c: pictures for teaching. See plot.h.
 *
 * The SVG is written by hand: a plot area with a frame, ticks at 1, 2 or
 * 5 times a power of ten, labels, a title and a legend, and the data
 * drawn inside a clip path. The text is built in memory (open_memstream)
 * and written atomically (img_write_bytes). */
#include "bind/plot.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bind/compile.h"
#include "lang/builtins.h"
#include "core/bounds.h"
#include "core/conv.h"
#include "core/csg.h"
#include "core/lg.h"
#include "core/soft.h"
#include "lang/eval.h"
#include "lang/print.h"
#include "render/image.h"
#include "scene/ray.h"

/* ---- SVG ---------------------------------------------------------------- */

typedef struct Svg {
  FILE *f;
  char *buf;
  size_t len;
  double W, H;
  double px0, px1, py0, py1; /* plot area: left, right, top, bottom */
  double x0, x1, y0, y1;     /* data ranges */
  int clip;                  /* clip paths defined so far */
} Svg;

static double sx(const Svg *s, double x) {
  return s->px0 + (x - s->x0) / (s->x1 - s->x0) * (s->px1 - s->px0);
}
static double sy(const Svg *s, double y) {
  return s->py1 - (y - s->y0) / (s->y1 - s->y0) * (s->py1 - s->py0);
}

static void svg_text_esc(FILE *f, const char *t) {
  for (; *t; t++) {
    if (*t == '<') fputs("&lt;", f);
    else if (*t == '>') fputs("&gt;", f);
    else if (*t == '&') fputs("&amp;", f);
    else fputc(*t, f);
  }
}

/* A number as the probes print it (shortest round trip), for data-*. */
static void svg_num(FILE *f, double x) {
  char b[40];
  format_real(b, x);
  fputs(b, f);
}

static int svg_open(Svg *s, double W, double H) {
  memset(s, 0, sizeof *s);
  s->f = open_memstream(&s->buf, &s->len);
  if (!s->f) return -1;
  s->W = W;
  s->H = H;
  fprintf(s->f,
          "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
          "<svg xmlns=\"http://www.w3.org/2000/svg\" "
          "xmlns:xlink=\"http://www.w3.org/1999/xlink\" width=\"%.0f\" "
          "height=\"%.0f\" viewBox=\"0 0 %.0f %.0f\" "
          "font-family=\"DejaVu Sans, Helvetica, Arial, sans-serif\" "
          "font-size=\"12\">\n"
          "<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n",
          W, H, W, H);
  return 0;
}

/* Free the buffer without writing (an error unwinds, or after writing). */
static void svg_discard(void *p) {
  Svg *s = p;
  if (s->f) fclose(s->f);
  s->f = NULL;
  free(s->buf);
  s->buf = NULL;
}

static void svg_close(Interp *I, Svg *s, const char *path, Pos pos) {
  fputs("</svg>\n", s->f);
  fclose(s->f);
  s->f = NULL;
  char err[400];
  int rc = img_write_bytes(path, s->buf, s->len, err, sizeof err);
  free(s->buf);
  s->buf = NULL;
  if (rc != 0) qcs_error(pos, "%s", err);
}

/* Ticks: a step of 1, 2 or 5 times a power of ten, about n ticks. */
static double tick_step(double lo, double hi, int n) {
  double raw = (hi - lo) / n;
  double p = pow(10, floor(log10(raw)));
  double m = raw / p;
  return (m < 1.5 ? 1 : m < 3.5 ? 2 : m < 7.5 ? 5 : 10) * p;
}

static void tick_label(char *b, double v, double step) {
  if (fabs(v) < step * 1e-9) v = 0;
  format_real_digits(b, v, 6);
}

/* Frame, ticks, labels, title; opens the clipped data group. */
static void svg_axes(Svg *s, const char *title, const char *xlabel,
                     const char *ylabel) {
  FILE *f = s->f;
  int id = ++s->clip;
  fprintf(f, "<defs><clipPath id=\"plot%d\"><rect x=\"%.1f\" y=\"%.1f\" "
          "width=\"%.1f\" height=\"%.1f\"/></clipPath></defs>\n", id, s->px0,
          s->py0, s->px1 - s->px0, s->py1 - s->py0);
  fprintf(f, "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" "
          "fill=\"none\" stroke=\"black\"/>\n", s->px0, s->py0,
          s->px1 - s->px0, s->py1 - s->py0);
  char b[40];
  double st = tick_step(s->x0, s->x1, 8);
  for (double v = ceil(s->x0 / st) * st; v <= s->x1 + st * 1e-9; v += st) {
    double x = sx(s, v);
    tick_label(b, v, st);
    fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" "
            "stroke=\"black\"/><text x=\"%.1f\" y=\"%.1f\" "
            "text-anchor=\"middle\">%s</text>\n", x, s->py1, x, s->py1 + 5,
            x, s->py1 + 18, b);
  }
  st = tick_step(s->y0, s->y1, 6);
  for (double v = ceil(s->y0 / st) * st; v <= s->y1 + st * 1e-9; v += st) {
    double y = sy(s, v);
    tick_label(b, v, st);
    fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" "
            "stroke=\"black\"/><text x=\"%.1f\" y=\"%.1f\" "
            "text-anchor=\"end\">%s</text>\n", s->px0 - 5, y, s->px0, y,
            s->px0 - 8, y + 4, b);
  }
  fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">",
          0.5 * (s->px0 + s->px1), s->py1 + 36);
  svg_text_esc(f, xlabel);
  fprintf(f, "</text>\n<text transform=\"translate(%.1f %.1f) rotate(-90)\" "
          "text-anchor=\"middle\">", s->px0 - 48, 0.5 * (s->py0 + s->py1));
  svg_text_esc(f, ylabel);
  fprintf(f, "</text>\n<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\" "
          "font-size=\"14\" font-weight=\"bold\">", 0.5 * (s->px0 + s->px1),
          s->py0 - 12);
  svg_text_esc(f, title);
  fprintf(f, "</text>\n<g clip-path=\"url(#plot%d)\">\n", id);
}

static void svg_end_data(Svg *s) { fputs("</g>\n", s->f); }

/* A horizontal line across the plot at y, with a label at its right end. */
static void svg_hline(Svg *s, double y, const char *style) {
  fprintf(s->f, "<line x1=\"%.1f\" y1=\"%.2f\" x2=\"%.1f\" y2=\"%.2f\" "
          "%s/>\n", s->px0, sy(s, y), s->px1, sy(s, y), style);
}

/* A polyline through (x[i], y[i]); class names it, and with data set the
   points also go into data-x / data-y in full precision. */
static void svg_curve(Svg *s, int n, const double *x, const double *y,
                      const char *cls, const char *style, int data) {
  FILE *f = s->f;
  fprintf(f, "<polyline class=\"%s\" fill=\"none\" %s points=\"", cls, style);
  for (int i = 0; i < n; i++)
    fprintf(f, "%s%.2f,%.2f", i ? " " : "", sx(s, x[i]), sy(s, y[i]));
  fputc('"', f);
  if (data) {
    fputs(" data-x=\"", f);
    for (int i = 0; i < n; i++) { if (i) fputc(' ', f); svg_num(f, x[i]); }
    fputs("\" data-y=\"", f);
    for (int i = 0; i < n; i++) { if (i) fputc(' ', f); svg_num(f, y[i]); }
    fputc('"', f);
  }
  fputs("/>\n", f);
}

typedef struct LegendItem {
  const char *style; /* attributes of the swatch */
  int box;           /* a filled box, else a line */
  const char *text;
} LegendItem;

/* The legend below the plot from y: items in rows within the width. */
static void svg_legend(Svg *s, double y, const LegendItem *it, int n) {
  FILE *f = s->f;
  double x = s->px0, w = s->px1;
  for (int i = 0; i < n; i++) {
    double tw = 7.0 * (double)strlen(it[i].text) + 40;
    if (x + tw > w && x > s->px0) {
      x = s->px0;
      y += 18;
    }
    if (it[i].box)
      fprintf(f, "<rect x=\"%.1f\" y=\"%.1f\" width=\"22\" height=\"10\" "
              "%s/>\n", x, y - 9, it[i].style);
    else
      fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" "
              "%s/>\n", x, y - 4, x + 22, y - 4, it[i].style);
    fprintf(f, "<text x=\"%.1f\" y=\"%.1f\">", x + 28, y);
    svg_text_esc(f, it[i].text);
    fputs("</text>\n", f);
    x += tw;
  }
}

/* ---- arguments ------------------------------------------------------ */

static void get_vec(Interp *I, Value *v, Pos pos, const char *what,
                    double p[3]) {
  force_vec3(I, v, pos, what, p);
  if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2]))
    qcs_error(pos, "%s must be finite", what);
}

static const char *get_path(Interp *I, Value *v, Pos pos, const char *ext) {
  const char *path = force_str(I, v, pos, "the file name");
  size_t n = strlen(path), e = strlen(ext);
  if (n <= e || strcmp(path + n - e, ext) != 0)
    qcs_error(pos, "the file name must end in %s, not '%s'", ext, path);
  return path;
}

static void free_scene_cb(void *p) { scene_free(p); }
static void free_ctx_cb(void *p) { ray_ctx_free(p); }
static void free_csg_cb(void *p) { csg_tape_free(p); }
static void free_tape_cb(void *p) { dt_tape_free(p); }

/* ---- plotRay ------------------------------------------------------- */

typedef struct RayLog {
  lg_trace_event *lg;
  soft_trace_event *soft;
  size_t nlg, caplg, nsoft, capsoft;
} RayLog;

static void log_lg(void *ctx, const lg_trace_event *ev) {
  RayLog *t = ctx;
  if (t->nlg == t->caplg) {
    size_t cap = t->caplg ? 2 * t->caplg : 64;
    lg_trace_event *n = realloc(t->lg, cap * sizeof *n);
    if (!n) return;
    t->lg = n;
    t->caplg = cap;
  }
  t->lg[t->nlg++] = *ev;
}

static void log_soft(void *ctx, const soft_trace_event *ev) {
  RayLog *t = ctx;
  if (t->nsoft == t->capsoft) {
    size_t cap = t->capsoft ? 2 * t->capsoft : 64;
    soft_trace_event *n = realloc(t->soft, cap * sizeof *n);
    if (!n) return;
    t->soft = n;
    t->capsoft = cap;
  }
  t->soft[t->nsoft++] = *ev;
}

static void free_log_cb(void *p) {
  RayLog *t = p;
  free(t->lg);
  free(t->soft);
}

#define RAY_SAMPLES 400
#define MAX_SPANS 64

static const char *const seg_colour[] = {
    [LG_SEG_EXCLUDED] = "#9e9e9e", [LG_SEG_FLAT] = "#bdbdbd",
    [LG_SEG_NO_ROOT] = "#1f77b4",  [LG_SEG_ROOT] = "#2ca02c",
    [LG_SEG_SPLIT] = "#ff7f0e",    [LG_SEG_TINY] = "#9467bd",
    [LG_SEG_PLANE] = "#17becf",    [LG_SEG_CONCAVE] = "#8c564b",
};

/* The spans of a sharp bound along the ray, as bars in a row at y. */
static void bound_row(Svg *s, const csg_tape *b, const double o[3],
                      const double d[3], double y, const char *fill,
                      const char *name) {
  csg_span sp[MAX_SPANS], scratch[256];
  int n = b ? csg_ray_spans(b, o, d, 0, INFINITY, sp, MAX_SPANS, scratch, 256)
            : 0;
  fprintf(s->f, "<g class=\"%s\">\n", name);
  for (int i = 0; i < n; i++) {
    double a = fmax(sp[i].t0, s->x0), c = fmin(sp[i].t1, s->x1);
    if (!(c > a)) continue;
    fprintf(s->f, "<rect x=\"%.2f\" y=\"%.1f\" width=\"%.2f\" height=\"8\" "
            "fill=\"%s\" data-t0=\"", sx(s, a), y, sx(s, c) - sx(s, a), fill);
    svg_num(s->f, sp[i].t0);
    fputs("\" data-t1=\"", s->f);
    svg_num(s->f, sp[i].t1);
    fputs("\"/>\n", s->f);
  }
  fputs("</g>\n", s->f);
}

/* The cone of a segment: |rho(t) - rho(t0)| <= L (t - t0) from the left
   end and likewise from the right, intersected: a diamond, clamped to the
   plot's density range (a steep cone would leave it). */
static void lg_cone(Svg *s, const lg_trace_event *e) {
  if (!isfinite(e->L)) return;
  double r0 = e->f0 + 0.5, r1 = e->f1 + 0.5, L = e->L;
  const char *col = e->decision >= 0 && e->decision <= LG_SEG_CONCAVE
                        ? seg_colour[e->decision] : "black";
  int leaf = e->decision != LG_SEG_SPLIT;
  enum { K = 24 };
  fprintf(s->f, "<polygon class=\"cone\" points=\"");
  for (int pass = 0; pass < 2; pass++)
    for (int k = 0; k <= K; k++) {
      double t = pass == 0 ? e->t0 + (e->t1 - e->t0) * k / K
                           : e->t1 - (e->t1 - e->t0) * k / K;
      double y = pass == 0 ? fmin(r0 + L * (t - e->t0), r1 + L * (e->t1 - t))
                           : fmax(r0 - L * (t - e->t0), r1 - L * (e->t1 - t));
      y = fmin(fmax(y, s->y0), s->y1);
      fprintf(s->f, "%.2f,%.2f ", sx(s, t), sy(s, y));
    }
  fprintf(s->f, "\" fill=\"%s\" fill-opacity=\"%s\" stroke=\"%s\" "
          "stroke-width=\"1\"%s/>\n", col, leaf ? "0.18" : "0", col,
          leaf ? "" : " stroke-dasharray=\"4 3\"");
}

/* plotRay "ray.svg" obj o d */
static Value *pl_ray(Interp *I, Value **args, Pos pos) {
  const char *path = get_path(I, args[0], pos, ".svg");
  double o[3], d[3];
  get_vec(I, args[2], pos, "the ray origin", o);
  get_vec(I, args[3], pos, "the ray direction", d);
  if (d[0] == 0 && d[1] == 0 && d[2] == 0)
    qcs_error(pos, "the ray direction cannot be zero");
  Scene *sc = compile_scene(I, args[1], pos);
  ErrCleanup cu_scene, cu_ctx, cu_log, cu_svg;
  err_defer(&cu_scene, free_scene_cb, sc);
  const ScNode *node = &sc->nodes[sc->root];
  if (node->kind != SC_ROUNDED && node->kind != SC_SOFT)
    qcs_error(pos, "plotRay needs one Rounded object or one SoftObject "
              "(plot the parts of a CSG object one by one)");
  int soft = node->kind == SC_SOFT;
  RayCtx *c = ray_ctx_new(sc, 1e-10);
  if (!c) qcs_error(pos, "out of memory");
  err_defer(&cu_ctx, free_ctx_cb, c);
  RayLog log = {0};
  err_defer(&cu_log, free_log_cb, &log);
  lg_hook hook = {log_lg, &log};
  soft_hook shook = {log_soft, &log};
  c->hook = &hook;
  c->soft_hook = &shook;
  csg_span *sp;
  int nsp = ray_spans(sc, sc->root, o, d, 0, INFINITY, c, &sp);
  if (nsp < 0) qcs_error(pos, "out of memory tracing the ray");
  double roots[2 * MAX_SPANS];
  int nroots = 0;
  for (int i = 0; i < nsp && nroots < 2 * MAX_SPANS - 1; i++) {
    if (sp[i].id0 >= 0 && sp[i].t0 >= 0) roots[nroots++] = sp[i].t0;
    if (sp[i].id1 >= 0 && isfinite(sp[i].t1)) roots[nroots++] = sp[i].t1;
  }

  /* The t range: what the search looked at, padded; else [0, 2]. */
  double ta = INFINITY, tb = -INFINITY;
  for (size_t i = 0; i < log.nlg; i++) {
    ta = fmin(ta, log.lg[i].t0);
    tb = fmax(tb, log.lg[i].t1);
  }
  for (size_t i = 0; i < log.nsoft; i++) {
    if (!isfinite(log.soft[i].t1)) continue;
    ta = fmin(ta, log.soft[i].t0);
    tb = fmax(tb, log.soft[i].t1);
  }
  if (!(ta < tb)) { ta = 0; tb = 2; }
  double pad = 0.15 * (tb - ta);
  ta = fmax(0, ta - pad);
  tb += pad;

  /* The curve: the same kernels as Density and Field. */
  double ts[RAY_SAMPLES + 1], ys[RAY_SAMPLES + 1], ymax = soft ? 0 : 1;
  for (int i = 0; i <= RAY_SAMPLES; i++) {
    double t = ta + (tb - ta) * i / RAY_SAMPLES;
    double p[3] = {o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]};
    ts[i] = t;
    ys[i] = soft ? soft_field(node->soft, p) : dt_density(node->tape, p);
    if (ys[i] > ymax) ymax = ys[i];
  }
  double level = soft ? soft_magic(node->soft) : 0.5;
  int maxdepth = 0;
  for (size_t i = 0; i < log.nlg; i++)
    if (log.lg[i].depth > maxdepth) maxdepth = log.lg[i].depth;
  if (maxdepth > 24) maxdepth = 24;

  double plot_h = 300, strip = soft ? 48 : 14.0 * (maxdepth + 1) + 30;
  double H = 70 + plot_h + 50 + strip + 110;
  Svg s;
  if (svg_open(&s, 820, H) != 0) qcs_error(pos, "out of memory");
  err_defer(&cu_svg, svg_discard, &s);
  s.px0 = 80; s.px1 = 800; s.py0 = 70; s.py1 = s.py0 + plot_h;
  s.x0 = ta; s.x1 = tb;
  if (soft) {
    double lo = 0;
    for (int i = 0; i <= RAY_SAMPLES; i++) if (ys[i] < lo) lo = ys[i];
    s.y1 = 1.1 * fmax(ymax, level);
    s.y0 = lo - 0.05 * (s.y1 - lo);
  } else {
    s.y0 = -0.05;
    s.y1 = 1.1;
  }
  FILE *f = s.f;
  svg_axes(&s, soft ? "Soft object: the field along the ray (Wyvill and "
                      "Trotman)"
                    : "Rounded object: density along the ray and the root "
                      "search (Figure 9)",
           "t along o + t d", soft ? "field" : "density");
  if (soft) {
    for (size_t i = 0; i < log.nsoft; i++) {
      const soft_trace_event *e = &log.soft[i];
      if (e->decision == SOFT_IV_EMPTY || !isfinite(e->t1)) continue;
      const char *col = e->decision == SOFT_IV_BOUND || e->decision == SOFT_IV_COEFF
                            ? "#9e9e9e" : "#2ca02c";
      double lo = fmax(e->flo, s.y0), hi = fmin(e->fhi, s.y1);
      fprintf(f, "<rect class=\"interval\" x=\"%.2f\" y=\"%.2f\" "
              "width=\"%.2f\" height=\"%.2f\" fill=\"%s\" "
              "fill-opacity=\"0.15\" stroke=\"%s\"/>\n", sx(&s, e->t0),
              sy(&s, hi), sx(&s, e->t1) - sx(&s, e->t0),
              sy(&s, lo) - sy(&s, hi), col, col);
    }
  } else {
    /* outer and inner bounds as shaded stretches */
    csg_span b[MAX_SPANS], scratch[256];
    int nb = node->outer ? csg_ray_spans(node->outer, o, d, 0, INFINITY, b,
                                         MAX_SPANS, scratch, 256) : 0;
    for (int i = 0; i < nb; i++)
      fprintf(f, "<rect x=\"%.2f\" y=\"%.1f\" width=\"%.2f\" height=\"%.1f\" "
              "fill=\"#fff3c4\"/>\n", sx(&s, fmax(b[i].t0, ta)), s.py0,
              sx(&s, fmin(b[i].t1, tb)) - sx(&s, fmax(b[i].t0, ta)),
              s.py1 - s.py0);
    nb = node->inner ? csg_ray_spans(node->inner, o, d, 0, INFINITY, b,
                                     MAX_SPANS, scratch, 256) : 0;
    for (int i = 0; i < nb; i++)
      fprintf(f, "<rect x=\"%.2f\" y=\"%.1f\" width=\"%.2f\" height=\"%.1f\" "
              "fill=\"#d6e9ff\"/>\n", sx(&s, fmax(b[i].t0, ta)), s.py0,
              sx(&s, fmin(b[i].t1, tb)) - sx(&s, fmax(b[i].t0, ta)),
              s.py1 - s.py0);
    for (size_t i = 0; i < log.nlg; i++) lg_cone(&s, &log.lg[i]);
  }
  svg_hline(&s, level, "stroke=\"#d62728\" stroke-dasharray=\"6 4\"");
  svg_curve(&s, RAY_SAMPLES + 1, ts, ys, soft ? "field" : "density",
            "stroke=\"black\" stroke-width=\"2\"", 1);
  for (int i = 0; i < nroots; i++)
    if (roots[i] >= ta && roots[i] <= tb)
      fprintf(f, "<circle class=\"root\" cx=\"%.2f\" cy=\"%.2f\" r=\"4.5\" "
              "fill=\"#d62728\" data-t=\"%.17g\"/>\n", sx(&s, roots[i]),
              sy(&s, level), roots[i]);
  svg_end_data(&s);

  double y = s.py1 + 50;
  if (!soft) {
    /* the bounds and the segments of Figure 9, one row per depth */
    fprintf(f, "<text x=\"%.1f\" y=\"%.1f\">bounds and segments of the "
            "search, one row per depth of splitting:</text>\n", s.px0, y);
    y += 8;
    bound_row(&s, node->outer, o, d, y, "#f2c94c", "outer");
    fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"end\">outer</text>\n",
            s.px0 - 4, y + 8);
    y += 12;
    bound_row(&s, node->inner, o, d, y, "#6fa8dc", "inner");
    fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"end\">inner</text>\n",
            s.px0 - 4, y + 8);
    y += 14;
    for (size_t i = 0; i < log.nlg; i++) {
      const lg_trace_event *e = &log.lg[i];
      if (e->depth > maxdepth) continue;
      double yy = y + 14.0 * e->depth;
      const char *col = e->decision >= 0 && e->decision <= LG_SEG_CONCAVE
                            ? seg_colour[e->decision] : "black";
      fprintf(f, "<rect class=\"segment\" x=\"%.2f\" y=\"%.1f\" "
              "width=\"%.2f\" height=\"10\" fill=\"%s\" stroke=\"white\" "
              "data-t0=\"%.17g\" data-t1=\"%.17g\" data-L=\"%.17g\" "
              "data-G=\"%.17g\" data-decision=\"%d\"/>\n",
              sx(&s, e->t0), yy, sx(&s, e->t1) - sx(&s, e->t0), col, e->t0,
              e->t1, e->L, e->G, e->decision);
    }
    for (int k = 0; k <= maxdepth; k++)
      fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"end\">d=%d</text>\n",
              s.px0 - 4, y + 14.0 * k + 9, k);
    y += 14.0 * (maxdepth + 1) + 24;
    static const LegendItem items[] = {
        {"stroke=\"black\" stroke-width=\"2\"", 0, "density"},
        {"stroke=\"#d62728\" stroke-dasharray=\"6 4\"", 0, "0.5 level"},
        {"fill=\"#d62728\"", 1, "root"},
        {"fill=\"#fff3c4\"", 1, "inside the outer bound"},
        {"fill=\"#d6e9ff\"", 1, "inside the inner bound"},
        {"fill=\"#ff7f0e\"", 1, "split: eq. (6) fails"},
        {"fill=\"#2ca02c\"", 1, "accepted: one root"},
        {"fill=\"#1f77b4\"", 1, "accepted: no root"},
        {"fill=\"#9e9e9e\"", 1, "discarded: range misses 0.5"},
        {"fill=\"#9467bd\"", 1, "shorter than the tolerance"},
        {"fill=\"#17becf\"", 1, "one leaf live: its plane"},
        {"fill=\"#8c564b\"", 1, "a product: log-concave, decided whole"},
        {"fill=\"none\" stroke=\"#ff7f0e\" stroke-dasharray=\"4 3\"", 1,
         "LG cone: |rho(t) - rho(end)| <= L |t - end|"},
    };
    svg_legend(&s, y, items, (int)(sizeof items / sizeof *items));
  } else {
    /* the intervals again as a row of bars, each with the iterations
       spent solving eq. (4) on it */
    fprintf(f, "<text x=\"%.1f\" y=\"%.1f\">intervals between key "
            "bounds, with the Laguerre iterations (+ Newton/bisection "
            "steps) spent on each:</text>\n", s.px0, y);
    y += 8;
    for (size_t i = 0; i < log.nsoft; i++) {
      const soft_trace_event *e = &log.soft[i];
      if (!isfinite(e->t1) || e->t1 <= ta || e->t0 >= tb) continue;
      double x0 = sx(&s, fmax(e->t0, ta)), x1 = sx(&s, fmin(e->t1, tb));
      const char *col = e->decision == SOFT_IV_EMPTY ? "#ffffff"
                        : e->decision < SOFT_IV_QUICK ? "#9e9e9e"
                                                      : "#2ca02c";
      char label[48] = "";
      if (e->decision >= SOFT_IV_QUICK) {
        if (e->bsteps) snprintf(label, sizeof label, "%ld+%ld", e->lsteps,
                                e->bsteps);
        else snprintf(label, sizeof label, "%ld", e->lsteps);
      }
      fprintf(f, "<rect class=\"soft-interval\" x=\"%.2f\" y=\"%.1f\" "
              "width=\"%.2f\" height=\"16\" fill=\"%s\" "
              "fill-opacity=\"0.5\" stroke=\"#555\" data-t0=\"%.17g\" "
              "data-t1=\"%.17g\" data-decision=\"%d\" data-laguerre=\"%ld\" "
              "data-bracket=\"%ld\"/>\n", x0, y, x1 - x0, col, e->t0, e->t1,
              e->decision, e->lsteps, e->bsteps);
      if (*label && x1 - x0 >= 7.0 * (double)strlen(label))
        fprintf(f, "<text x=\"%.2f\" y=\"%.1f\" text-anchor=\"middle\" "
                "font-size=\"11\">%s</text>\n", 0.5 * (x0 + x1), y + 12,
                label);
    }
    y += 16 + 24;
    static const LegendItem items[] = {
        {"stroke=\"black\" stroke-width=\"2\"", 0, "field"},
        {"stroke=\"#d62728\" stroke-dasharray=\"6 4\"", 0, "magic"},
        {"fill=\"#d62728\"", 1, "root"},
        {"fill=\"#2ca02c\" fill-opacity=\"0.3\" stroke=\"#2ca02c\"", 1,
         "interval solved by eq. (4) (box: field range)"},
        {"fill=\"#9e9e9e\" fill-opacity=\"0.3\" stroke=\"#9e9e9e\"", 1,
         "interval settled by its range"},
    };
    svg_legend(&s, y, items, (int)(sizeof items / sizeof *items));
  }
  err_release(&cu_svg);
  svg_close(I, &s, path, pos);
  err_release(&cu_log);
  free_log_cb(&log);
  err_release(&cu_ctx);
  ray_ctx_free(c);
  err_release(&cu_scene);
  scene_free(sc);
  return val_str(path);
}

/* ---- plotDisplacement ------------------------------------------------ */

static Value *pl_displacement(Interp *I, Value **args, Pos pos) {
  const char *path = get_path(I, args[0], pos, ".svg");
  enum { N = 200 };
  double t[N + 1], D[N + 1];
  for (int i = 0; i <= N; i++) {
    t[i] = (double)i / N;
    D[i] = dt_displacement(1, t[i]);
  }
  Svg s;
  if (svg_open(&s, 720, 470) != 0) qcs_error(pos, "out of memory");
  ErrCleanup cu;
  err_defer(&cu, svg_discard, &s);
  s.px0 = 80; s.px1 = 700; s.py0 = 50; s.py1 = 380;
  s.x0 = 0; s.x1 = 1; s.y0 = -1.1; s.y1 = 1.1;
  svg_axes(&s, "eq. (5): where the t-isosurface of a smoothed halfspace lies",
           "density level t", "offset from the plane, in units of r");
  svg_hline(&s, 0, "stroke=\"#999\"");
  svg_curve(&s, N + 1, t, D, "displacement",
            "stroke=\"black\" stroke-width=\"2\"", 1);
  static const double mark[] = {0.25, 0.5, 0.75};
  for (int i = 0; i < 3; i++) {
    double Dm = dt_displacement(1, mark[i]);
    char b[40];
    format_real_digits(b, Dm, 4);
    fprintf(s.f, "<circle cx=\"%.2f\" cy=\"%.2f\" r=\"4\" fill=\"#d62728\"/>"
            "<text x=\"%.2f\" y=\"%.2f\">t = %g: %s r</text>\n",
            sx(&s, mark[i]), sy(&s, Dm), sx(&s, mark[i]) + 8,
            sy(&s, Dm) - 8, mark[i], b);
  }
  svg_end_data(&s);
  static const LegendItem items[] = {
      {"stroke=\"black\" stroke-width=\"2\"", 0,
       "Displacement 1 t (outward positive; the 0.5 surface is the plane)"},
      {"fill=\"#d62728\"", 1, "t = 0.25, 0.5, 0.75"},
  };
  svg_legend(&s, 440, items, 2);
  err_release(&cu);
  svg_close(I, &s, path, pos);
  return val_str(path);
}

/* ---- plotField -------------------------------------------------------- */

/* Wyvill and Trotman eq. (1), in the paper's own expanded form. */
static double wyvill_c(double r) {
  if (r >= 1) return 0;
  double r2 = r * r;
  return 1 - 22.0 / 9 * r2 + 17.0 / 9 * r2 * r2 - 4.0 / 9 * r2 * r2 * r2;
}

static Value *pl_field(Interp *I, Value **args, Pos pos) {
  const char *path = get_path(I, args[0], pos, ".svg");
  double o[3], d[3];
  get_vec(I, args[2], pos, "the line's origin", o);
  get_vec(I, args[3], pos, "the line's direction", d);
  if (d[0] == 0 && d[1] == 0 && d[2] == 0)
    qcs_error(pos, "the line's direction cannot be zero");
  Scene *sc = compile_scene(I, args[1], pos);
  ErrCleanup cu_scene, cu_svg;
  err_defer(&cu_scene, free_scene_cb, sc);
  const ScNode *node = &sc->nodes[sc->root];
  if (node->kind != SC_SOFT)
    qcs_error(pos, "plotField needs a SoftObject");
  enum { N = 300 };
  double r[N + 1], C[N + 1], t[N + 1], F[N + 1];
  for (int i = 0; i <= N; i++) {
    r[i] = 1.2 * i / N;
    C[i] = wyvill_c(r[i]);
  }
  /* the line over the object's box, or t in [-2, 2] */
  double lo[3], hi[3], ta = -2, tb = 2;
  if (soft_bounds(node->soft, lo, hi)) {
    double a = -INFINITY, b = INFINITY;
    for (int k = 0; k < 3; k++) {
      if (d[k] == 0) continue;
      double u = (lo[k] - o[k]) / d[k], v = (hi[k] - o[k]) / d[k];
      a = fmax(a, fmin(u, v));
      b = fmin(b, fmax(u, v));
    }
    if (a < b && isfinite(a) && isfinite(b)) {
      double pad = 0.1 * (b - a);
      ta = a - pad;
      tb = b + pad;
    }
  }
  double fmax_ = soft_magic(node->soft), fmin_ = 0;
  for (int i = 0; i <= N; i++) {
    t[i] = ta + (tb - ta) * i / N;
    double p[3] = {o[0] + t[i] * d[0], o[1] + t[i] * d[1], o[2] + t[i] * d[2]};
    F[i] = soft_field(node->soft, p);
    fmax_ = fmax(fmax_, F[i]);
    fmin_ = fmin(fmin_, F[i]);
  }
  Svg s;
  if (svg_open(&s, 900, 440) != 0) qcs_error(pos, "out of memory");
  err_defer(&cu_svg, svg_discard, &s);
  s.px0 = 70; s.px1 = 400; s.py0 = 50; s.py1 = 340;
  s.x0 = 0; s.x1 = 1.2; s.y0 = -0.05; s.y1 = 1.1;
  svg_axes(&s, "Wyvill's C(r), R = 1", "r / R", "C");
  svg_hline(&s, 0.5, "stroke=\"#999\" stroke-dasharray=\"2 3\"");
  svg_curve(&s, N + 1, r, C, "wyvill", "stroke=\"black\" stroke-width=\"2\"",
            1);
  fprintf(s.f, "<circle cx=\"%.2f\" cy=\"%.2f\" r=\"4\" fill=\"#d62728\"/>\n",
          sx(&s, 0.5), sy(&s, wyvill_c(0.5)));
  svg_end_data(&s);
  s.px0 = 520; s.px1 = 880;
  s.x0 = ta; s.x1 = tb;
  s.y0 = fmin_ - 0.05 * (fmax_ - fmin_);
  s.y1 = fmax_ + 0.1 * (fmax_ - fmin_);
  svg_axes(&s, "the field along o + t d", "t", "field");
  svg_hline(&s, soft_magic(node->soft),
            "stroke=\"#d62728\" stroke-dasharray=\"6 4\"");
  svg_curve(&s, N + 1, t, F, "field", "stroke=\"black\" stroke-width=\"2\"",
            1);
  svg_end_data(&s);
  static const LegendItem items[] = {
      {"stroke=\"black\" stroke-width=\"2\"", 0,
       "left: C(r) = 1 - 22/9 r^2 + 17/9 r^4 - 4/9 r^6"},
      {"fill=\"#d62728\"", 1, "C(1/2) = 1/2"},
      {"stroke=\"black\" stroke-width=\"2\"", 0,
       "right: the sum of w C(r/R) over the keys (Field)"},
      {"stroke=\"#d62728\" stroke-dasharray=\"6 4\"", 0, "magic"},
  };
  s.px0 = 70;
  s.px1 = 880;
  svg_legend(&s, 400, items, 4);
  err_release(&cu_svg);
  svg_close(I, &s, path, pos);
  err_release(&cu_scene);
  scene_free(sc);
  return val_str(path);
}

/* ---- plotConvolution ------------------------------------------------- */

/* The first crossing of density 0.5 along o + t d in [ta, tb] from n + 1
   samples y[] at t[]: the first sign change, bisected on the density. */
static double quasi_crossing(const dt_tape *tp, const double o[3],
                             const double d[3], const double *t,
                             const double *y, int n) {
  for (int i = 0; i < n; i++) {
    if ((y[i] >= 0.5) == (y[i + 1] >= 0.5)) continue;
    double a = t[i], b = t[i + 1];
    int above_a = y[i] >= 0.5;
    for (int k = 0; k < 80 && b - a > 0; k++) {
      double m = 0.5 * (a + b);
      double p[3] = {o[0] + m * d[0], o[1] + m * d[1], o[2] + m * d[2]};
      if ((dt_density(tp, p) >= 0.5) == above_a) a = m;
      else b = m;
    }
    return 0.5 * (a + b);
  }
  return NAN;
}

/* plotConvolution "f.svg" r tree o d: Lobb's Figure 5 along a ray, the
   quasi-convolution (Density) against the true convolution (TrueDensity)
   near where the ray meets the sharp polyhedron, with both 0.5
   crossings. */
#define CONV_TOL 1e-6 /* TrueDensity's */
static Value *pl_convolution(Interp *I, Value **args, Pos pos) {
  const char *path = get_path(I, args[0], pos, ".svg");
  double r = force_num(I, args[1], pos, "the radius"), o[3], d[3];
  if (!isfinite(r) || r <= 0)
    qcs_error(pos, "plotConvolution needs a radius > 0, not %g", r);
  get_vec(I, args[3], pos, "the ray origin", o);
  get_vec(I, args[4], pos, "the ray direction", d);
  double dl = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  if (!(dl > 0)) qcs_error(pos, "the ray direction cannot be zero");
  dt_tape *tp = compile_density_tape(I, args[2], r, pos);
  ErrCleanup cu_tape, cu_csg, cu_svg;
  err_defer(&cu_tape, free_tape_cb, tp);
  csg_tape *sharp = conv_sharp_of(tp);
  if (!sharp) qcs_error(pos, "out of memory");
  err_defer(&cu_csg, free_csg_cb, sharp);
  csg_span sp[MAX_SPANS], scratch[256];
  int ns = csg_ray_spans(sharp, o, d, 0, INFINITY, sp, MAX_SPANS, scratch,
                         256);
  double ts = ns <= 0 ? NAN : sp[0].t0 > 0 ? sp[0].t0 : sp[0].t1;
  if (!isfinite(ts)) /* the sharp surface */
    qcs_error(pos, "plotConvolution: the ray does not cross the sharp "
              "polyhedron's surface");
  double half = 2.5 * r / dl, ta = fmax(0, ts - half), tb = ts + half;
  enum { NQ = 200, NT = 32 };
  double tq[NQ + 1], yq[NQ + 1], tt[NT + 1], yt[NT + 1];
  for (int i = 0; i <= NQ; i++) {
    tq[i] = ta + (tb - ta) * i / NQ;
    double p[3] = {o[0] + tq[i] * d[0], o[1] + tq[i] * d[1],
                   o[2] + tq[i] * d[2]};
    yq[i] = dt_density(tp, p);
  }
  for (int i = 0; i <= NT; i++) {
    eval_check(I, pos);
    tt[i] = ta + (tb - ta) * i / NT;
    double p[3] = {o[0] + tt[i] * d[0], o[1] + tt[i] * d[1],
                   o[2] + tt[i] * d[2]};
    yt[i] = conv_fraction(sharp, p, r, CONV_TOL, NULL);
  }
  double cq = quasi_crossing(tp, o, d, tq, yq, NQ);
  double ct = conv_crossing(sharp, r, o, d, isfinite(cq) ? cq : ts, CONV_TOL,
                            NULL, NULL);
  if (ct < 0) ct = NAN;

  Svg s;
  if (svg_open(&s, 760, 650) != 0) qcs_error(pos, "out of memory");
  err_defer(&cu_svg, svg_discard, &s);
  s.px0 = 80; s.px1 = 740; s.py0 = 50; s.py1 = 330;
  s.x0 = ta; s.x1 = tb; s.y0 = -0.05; s.y1 = 1.1;
  double ymax = 1;
  for (int i = 0; i <= NQ; i++) ymax = fmax(ymax, yq[i]);
  s.y1 = 1.1 * ymax;
  svg_axes(&s, "Figure 5: quasi- against true convolution along the ray",
           "t along o + t d", "density");
  FILE *f = s.f;
  fprintf(f, "<line class=\"sharp\" x1=\"%.2f\" y1=\"%.1f\" x2=\"%.2f\" "
          "y2=\"%.1f\" stroke=\"#777\" stroke-width=\"1.5\" data-t=\"%.17g\"/>\n",
          sx(&s, ts), s.py0, sx(&s, ts), s.py1, ts);
  svg_hline(&s, 0.5, "stroke=\"#d62728\" stroke-dasharray=\"6 4\"");
  /* the true curve under the quasi one: where they agree, black shows */
  svg_curve(&s, NT + 1, tt, yt, "true",
            "stroke=\"#1f77b4\" stroke-width=\"2\" stroke-dasharray=\"7 4\"",
            1);
  for (int i = 0; i <= NT; i++)
    fprintf(f, "<circle cx=\"%.2f\" cy=\"%.2f\" r=\"2.5\" fill=\"#1f77b4\"/>\n",
            sx(&s, tt[i]), sy(&s, yt[i]));
  svg_curve(&s, NQ + 1, tq, yq, "quasi", "stroke=\"black\" stroke-width=\"2\"",
            1);
  if (isfinite(cq))
    fprintf(f, "<circle class=\"cross-quasi\" cx=\"%.2f\" cy=\"%.2f\" r=\"5\" "
            "fill=\"black\" data-t=\"%.17g\"/>\n", sx(&s, cq), sy(&s, 0.5), cq);
  if (isfinite(ct))
    fprintf(f, "<circle class=\"cross-true\" cx=\"%.2f\" cy=\"%.2f\" r=\"5\" "
            "fill=\"none\" stroke=\"#1f77b4\" stroke-width=\"2\" "
            "data-t=\"%.17g\"/>\n", sx(&s, ct), sy(&s, 0.5), ct);
  svg_end_data(&s);
  /* below: the difference, which the eye cannot read off the curves */
  double dq[NT + 1], dmax = 0;
  for (int i = 0; i <= NT; i++) {
    double p[3] = {o[0] + tt[i] * d[0], o[1] + tt[i] * d[1],
                   o[2] + tt[i] * d[2]};
    dq[i] = dt_density(tp, p) - yt[i];
    dmax = fmax(dmax, fabs(dq[i]));
  }
  if (!(dmax > 0)) dmax = 1e-3;
  s.py0 = 390; s.py1 = 520;
  s.y0 = -1.15 * dmax; s.y1 = 1.15 * dmax;
  svg_axes(&s, "", "t along o + t d", "quasi - true");
  svg_hline(&s, 0, "stroke=\"#999\"");
  fprintf(f, "<line x1=\"%.2f\" y1=\"%.1f\" x2=\"%.2f\" y2=\"%.1f\" "
          "stroke=\"#777\" stroke-width=\"1.5\"/>\n", sx(&s, ts), s.py0,
          sx(&s, ts), s.py1);
  svg_curve(&s, NT + 1, tt, dq, "difference",
            "stroke=\"#9467bd\" stroke-width=\"2\"", 1);
  svg_end_data(&s);
  char note[160] = "";
  if (isfinite(cq) && isfinite(ct)) {
    char b[40];
    format_real_digits(b, (cq - ct) * dl / r, 3);
    snprintf(note, sizeof note, "0.5 crossings: quasi - true = %s r along the "
             "ray (> 0: the quasi surface is met later)", b);
  } else {
    snprintf(note, sizeof note, "no 0.5 crossing of %s in this window",
             isfinite(cq) ? "the true convolution" : "the quasi-convolution");
  }
  fprintf(f, "<text x=\"%.1f\" y=\"%.1f\">", s.px0, s.py1 + 62);
  svg_text_esc(f, note);
  fputs("</text>\n", f);
  static const LegendItem items[] = {
      {"stroke=\"black\" stroke-width=\"2\"", 0, "quasi: Density (eq. 2 combined)"},
      {"stroke=\"#1f77b4\" stroke-width=\"2\" stroke-dasharray=\"7 4\"", 0,
       "true: TrueDensity (ball fraction)"},
      {"stroke=\"#777\" stroke-width=\"1.5\"", 0, "sharp surface"},
      {"stroke=\"#d62728\" stroke-dasharray=\"6 4\"", 0, "0.5 level"},
      {"stroke=\"#9467bd\" stroke-width=\"2\"", 0,
       "below: Density - TrueDensity"},
  };
  svg_legend(&s, s.py1 + 88, items, 5);
  err_release(&cu_svg);
  svg_close(I, &s, path, pos);
  err_release(&cu_csg);
  csg_tape_free(sharp);
  err_release(&cu_tape);
  dt_tape_free(tp);
  return val_str(path);
}

/* ---- plotSlice -------------------------------------------------------- */

static void at(const double c[3], const double u[3], const double v[3],
               double a, double b, double p[3]) {
  for (int k = 0; k < 3; k++) p[k] = c[k] + a * u[k] + b * v[k];
}

/* The point on the grid edge from (a0, b0) to (a1, b1) where the density
   crosses level (it does: the ends straddle it), by bisection. */
static void edge_root(const dt_tape *t, const double c[3], const double u[3],
                      const double v[3], double a0, double b0, double a1,
                      double b1, double level, double *a, double *b) {
  double p[3], lo = 0, hi = 1;
  at(c, u, v, a0, b0, p);
  int below0 = dt_density(t, p) < level;
  for (int i = 0; i < 60; i++) {
    double m = 0.5 * (lo + hi);
    at(c, u, v, a0 + m * (a1 - a0), b0 + m * (b1 - b0), p);
    if ((dt_density(t, p) < level) == below0) lo = m;
    else hi = m;
  }
  double m = 0.5 * (lo + hi);
  *a = a0 + m * (a1 - a0);
  *b = b0 + m * (b1 - b0);
}

int plot_isoline(const dt_tape *t, const double c[3], const double u[3],
                 const double v[3], int nx, int ny, double level,
                 double *ab, int max) {
  int n = 0;
  double *val = malloc((size_t)(nx + 1) * (size_t)(ny + 1) * sizeof *val);
  if (!val) return 0;
#define A(i) (-1 + 2.0 * (i) / nx)
#define B(j) (-1 + 2.0 * (j) / ny)
#define V(i, j) val[(size_t)(j) * (size_t)(nx + 1) + (size_t)(i)]
  for (int j = 0; j <= ny; j++)
    for (int i = 0; i <= nx; i++) {
      double p[3];
      at(c, u, v, A(i), B(j), p);
      V(i, j) = dt_density(t, p);
    }
  for (int j = 0; j < ny; j++)
    for (int i = 0; i < nx; i++) {
      /* corners 0..3 counter-clockwise; edges 0: 0-1, 1: 1-2, 2: 2-3,
         3: 3-0; a crossing on every edge whose ends straddle level */
      int ci[4] = {i, i + 1, i + 1, i}, cj[4] = {j, j, j + 1, j + 1};
      double pa[4], pb[4];
      int ne = 0;
      for (int e = 0; e < 4; e++) {
        int k0 = e, k1 = (e + 1) % 4;
        int s0 = V(ci[k0], cj[k0]) < level, s1 = V(ci[k1], cj[k1]) < level;
        if (s0 == s1) continue;
        edge_root(t, c, u, v, A(ci[k0]), B(cj[k0]), A(ci[k1]), B(cj[k1]),
                  level, &pa[ne], &pb[ne]);
        ne++;
      }
      for (int k = 0; k + 1 < ne && n + 2 <= max; k += 2) {
        ab[2 * n] = pa[k]; ab[2 * n + 1] = pb[k]; n++;
        ab[2 * n] = pa[k + 1]; ab[2 * n + 1] = pb[k + 1]; n++;
      }
    }
#undef A
#undef B
#undef V
  free(val);
  return n;
}

static void free_image_cb(void *p) { img_free(p); }
static void free_buf_cb(void *p) { free(*(void **)p); }

/* A colour map for density in [0, 1]: dark blue through white to red. */
static void cmap(double x, float rgb[3]) {
  x = fmin(fmax(x, 0), 1);
  double r, g, b;
  if (x < 0.5) { double u = x / 0.5; r = 0.05 + 0.95 * u; g = 0.15 + 0.85 * u; b = 0.45 + 0.55 * u; }
  else { double u = (x - 0.5) / 0.5; r = 1; g = 1 - 0.8 * u; b = 1 - 0.85 * u; }
  rgb[0] = (float)(r * r);  /* roughly linear light, img_write encodes sRGB */
  rgb[1] = (float)(g * g);
  rgb[2] = (float)(b * b);
}

static void put(Image *im, int x, int y, const float rgb[3]) {
  if (x < 0 || y < 0 || x >= im->width || y >= im->height) return;
  float *p = im->rgba + 4 * ((size_t)y * (size_t)im->width + (size_t)x);
  p[0] = rgb[0]; p[1] = rgb[1]; p[2] = rgb[2]; p[3] = 1;
}

/* plotSlice "slice.png" r tree (c, u, v) */
static Value *pl_slice(Interp *I, Value **args, Pos pos) {
  const char *path = get_path(I, args[0], pos, ".png");
  double r = force_num(I, args[1], pos, "the radius");
  if (!isfinite(r) || r < 0)
    qcs_error(pos, "the radius must be finite and >= 0, not %g", r);
  Value *pl = force(I, args[3]);
  if (pl->kind != V_TUPLE || pl->u.tup.n != 3)
    qcs_error(pos, "the plane piece is (centre, u, v): the points centre + "
              "a u + b v with a and b in [-1, 1]");
  double c[3], u[3], v[3];
  get_vec(I, pl->u.tup.items[0], pos, "the centre", c);
  get_vec(I, pl->u.tup.items[1], pos, "u", u);
  get_vec(I, pl->u.tup.items[2], pos, "v", v);
  double lu = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
  double lv = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (!(lu > 0) || !(lv > 0)) qcs_error(pos, "u and v cannot be zero");
  dt_tape *tape = compile_density_tape(I, args[2], r, pos);
  ErrCleanup cu_tape, cu_sharp, cu_outer, cu_inner, cu_img, cu_seg, cu_svg;
  err_defer(&cu_tape, free_tape_cb, tape);
  dt_tape *sharp = compile_density_tape(I, args[2], 0, pos);
  err_defer(&cu_sharp, free_tape_cb, sharp);
  int flags = 0;
  csg_tape *outer = bnd_outer(tape, 0.5, &flags);
  err_defer(&cu_outer, free_csg_cb, outer);
  csg_tape *inner = bnd_inner(tape, 0.5, &flags);
  err_defer(&cu_inner, free_csg_cb, inner);
  if (!outer || !inner) qcs_error(pos, "out of memory");
  int W = 600, H = (int)lround(600 * lv / lu);
  if (H < 100) H = 100;
  if (H > 1200) H = 1200;
  Image *im = img_new(W, H, 0);
  if (!im) qcs_error(pos, "out of memory");
  err_defer(&cu_img, free_image_cb, im);
  /* pixel centres: a = -1 + 2 (x + 0.5) / W, b = 1 - 2 (y + 0.5) / H */
  unsigned char *in_sharp = malloc((size_t)W * (size_t)H * 3);
  if (!in_sharp) qcs_error(pos, "out of memory");
  void *bufp = in_sharp;
  err_defer(&cu_seg, free_buf_cb, &bufp);
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++) {
      double p[3];
      at(c, u, v, -1 + 2 * (x + 0.5) / W, 1 - 2 * (y + 0.5) / H, p);
      float rgb[3];
      cmap(dt_density(tape, p), rgb);
      put(im, x, y, rgb);
      size_t k = (size_t)y * (size_t)W + (size_t)x;
      in_sharp[3 * k] = (unsigned char)(dt_density(sharp, p) > 0.5);
      in_sharp[3 * k + 1] = (unsigned char)csg_inside(outer, p);
      in_sharp[3 * k + 2] = (unsigned char)csg_inside(inner, p);
    }
  /* edges of the polyhedron, the outer and the inner bound: where the
     classification changes between neighbouring pixels */
  static const float line_col[3][3] = {
      {0.5f, 0, 0.5f}, {0.9f, 0.55f, 0}, {0, 0.5f, 0.1f}};
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++) {
      size_t k = (size_t)y * (size_t)W + (size_t)x;
      for (int m = 0; m < 3; m++) {
        int here = in_sharp[3 * k + (size_t)m];
        int right = x + 1 < W ? in_sharp[3 * (k + 1) + (size_t)m] : here;
        int down = y + 1 < H ? in_sharp[3 * (k + (size_t)W) + (size_t)m] : here;
        if (here != right || here != down) {
          int dashed = m > 0 && ((x + y) / 6) % 2;
          if (!dashed) put(im, x, y, line_col[m]);
        }
      }
    }
  /* isolines, exact on their grid edges, drawn as dots along segments */
  static const double levels[3] = {0.25, 0.5, 0.75};
  int maxv = 200000;
  double *ab = malloc((size_t)maxv * 2 * sizeof *ab);
  if (!ab) qcs_error(pos, "out of memory");
  free(in_sharp);
  bufp = ab;
  Svg s;
  if (svg_open(&s, 760, H + 150) != 0) qcs_error(pos, "out of memory");
  err_defer(&cu_svg, svg_discard, &s);
  for (int li = 0; li < 3; li++) {
    int n = plot_isoline(tape, c, u, v, W / 4, H / 4, levels[li], ab, maxv);
    float col[3] = {levels[li] == 0.5 ? 0.0f : 0.1f,
                    levels[li] == 0.5 ? 0.0f : 0.1f,
                    levels[li] == 0.5 ? 0.0f : 0.1f};
    for (int k = 0; k + 1 < n; k += 2) {
      double a0 = ab[2 * k], b0 = ab[2 * k + 1], a1 = ab[2 * k + 2],
             b1 = ab[2 * k + 3];
      for (int q = 0; q <= 8; q++) {
        double a = a0 + (a1 - a0) * q / 8, b = b0 + (b1 - b0) * q / 8;
        put(im, (int)floor((a + 1) * 0.5 * W), (int)floor((1 - b) * 0.5 * H),
            col);
      }
    }
  }
  char err[400];
  if (img_write(im, path, NULL, err, sizeof err) != 0)
    qcs_error(pos, "%s", err);

  /* The SVG beside it: the picture, axes in (a, b), legend. */
  size_t pl_len = strlen(path);
  char *svgpath = malloc(pl_len + 1);
  if (!svgpath) qcs_error(pos, "out of memory");
  memcpy(svgpath, path, pl_len - 4);
  strcpy(svgpath + pl_len - 4, ".svg");
  const char *base = strrchr(path, '/');
  base = base ? base + 1 : path;
  s.px0 = 80; s.px1 = 80 + 600; s.py0 = 50; s.py1 = 50 + H;
  s.x0 = -1; s.x1 = 1; s.y0 = -1; s.y1 = 1;
  fprintf(s.f, "<image x=\"%.1f\" y=\"%.1f\" width=\"%d\" height=\"%d\" "
          "xlink:href=\"", s.px0, s.py0, W, H);
  svg_text_esc(s.f, base);
  fputs("\" href=\"", s.f);
  svg_text_esc(s.f, base);
  fputs("\"/>\n", s.f);
  char title[200], b1[40], b2[40];
  format_real_digits(b1, r, 6);
  if (r > 0)
    snprintf(title, sizeof title, "Density over a plane (r = %s): eq. (2) "
             "combined, Figures 4 and 8", b1);
  else
    snprintf(title, sizeof title, "Density over a plane (each plane's own "
             "radius): Figures 4 and 8");
  svg_axes(&s, title, "a (centre + a u + b v)", "b");
  svg_end_data(&s);
  /* colour bar */
  for (int k = 0; k < 100; k++) {
    float rgb[3];
    cmap(k / 99.0, rgb);
    fprintf(s.f, "<rect x=\"%.1f\" y=\"%.1f\" width=\"16\" height=\"%.2f\" "
            "fill=\"rgb(%d,%d,%d)\"/>\n", s.px1 + 20,
            s.py1 - (k + 1) * (s.py1 - s.py0) / 100, (s.py1 - s.py0) / 100 + 1.5,
            img_srgb8(rgb[0]), img_srgb8(rgb[1]), img_srgb8(rgb[2]));
  }
  for (int k = 0; k <= 4; k++) {
    format_real_digits(b2, k / 4.0, 3);
    fprintf(s.f, "<text x=\"%.1f\" y=\"%.1f\">%s</text>\n", s.px1 + 40,
            s.py1 - k * (s.py1 - s.py0) / 4 + 4, b2);
  }
  static const LegendItem items[] = {
      {"stroke=\"black\" stroke-width=\"3\"", 0, "0.5 isoline (the surface)"},
      {"stroke=\"#555\" stroke-width=\"1\"", 0, "0.25 and 0.75 isolines"},
      {"stroke=\"#c000c0\" stroke-width=\"2\"", 0, "the sharp polyhedron's edges"},
      {"stroke=\"#e68c00\" stroke-width=\"2\" stroke-dasharray=\"6 6\"", 0,
       "outer bound (Figure 8)"},
      {"stroke=\"#00801a\" stroke-width=\"2\" stroke-dasharray=\"6 6\"", 0,
       "inner bound"},
  };
  svg_legend(&s, s.py1 + 60, items, 5);
  err_release(&cu_svg);
  fputs("</svg>\n", s.f);
  fclose(s.f);
  s.f = NULL;
  int rc = img_write_bytes(svgpath, s.buf, s.len, err, sizeof err);
  free(s.buf);
  free(svgpath);
  err_release(&cu_seg);
  free(ab);
  err_release(&cu_img);
  img_free(im);
  err_release(&cu_inner);
  csg_tape_free(inner);
  err_release(&cu_outer);
  csg_tape_free(outer);
  err_release(&cu_sharp);
  dt_tape_free(sharp);
  err_release(&cu_tape);
  dt_tape_free(tape);
  if (rc != 0) qcs_error(pos, "%s", err);
  return val_str(path);
}

#define PLOTS(X)                                                              \
  X("plotRay", 4, pl_ray,                                                     \
    "plotRay \"f.svg\" obj o d: density or field along the ray, the bounds, "  \
    "the Figure 9 segments and their LG cones, the roots; e.g. plotRay "      \
    "\"ray.svg\" (Rounded 0.1 UnitCube) (-1, 0.95, 0.5) (1, 0, 0)")            \
  X("plotSlice", 4, pl_slice,                                                 \
    "plotSlice \"f.png\" r tree (c, u, v): density over c + a u + b v as "     \
    "colour, isolines, edges, bounds (and f.svg with axes and legend); e.g. " \
    "plotSlice \"slice.png\" 0.1 UnitCube ((0.5, 0.5, 0.5), (0.8, 0, 0), "     \
    "(0, 0.8, 0))")                                                           \
  X("plotDisplacement", 1, pl_displacement,                                   \
    "plotDisplacement \"f.svg\": eq. (5), the isosurface offset against t; "  \
    "e.g. plotDisplacement \"d.svg\"")                                         \
  X("plotConvolution", 5, pl_convolution,                                     \
    "plotConvolution \"f.svg\" r tree o d: Figure 5, Density against "        \
    "TrueDensity along the ray near the sharp surface, with both 0.5 "        \
    "crossings; e.g. plotConvolution \"conv.svg\" 0.1 UnitCube (1.3, 1.3, "   \
    "1.3) (-1, -1, -1)")                                                      \
  X("plotField", 4, pl_field,                                                 \
    "plotField \"f.svg\" soft o d: Wyvill's C(r) and the field along a line; " \
    "e.g. plotField \"c.svg\" (SoftObject 0.5 [Key (0, 0, 0) 1 1]) "           \
    "(-2, 0, 0) (1, 0, 0)")

static const Builtin plots[] = {
#define X(name, arity, fn, doc) {name, arity, fn, doc},
    PLOTS(X)
#undef X
};

void plot_install(Interp *I) {
  for (size_t i = 0; i < sizeof plots / sizeof *plots; i++)
    builtin_define(I, &plots[i]);
}
