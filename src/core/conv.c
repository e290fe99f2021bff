/* conv.c: the true convolution by nested adaptive Gauss-Kronrod quadrature
 * over the chords of the ball (see conv.h). */
#include "core/conv.h"

#include <math.h>
#include <string.h>

csg_tape *conv_sharp_of(const dt_tape *t) {
  csg_builder *b = csg_builder_new();
  if (!b) return NULL;
  int rc = 0;
  for (int i = 0; i < t->ncode && !rc; i++) {
    const dt_instr *c = &t->code[i];
    switch (c->op) {
    case DT_LEAF:
      rc = csg_builder_plane(b, t->leaves[c->arg].n, t->leaves[c->arg].d);
      break;
    case DT_CONST:
      rc = csg_builder_const(b, c->c > 0.5 ? CSG_ALL : CSG_EMPTY);
      break;
    case DT_SUM:
    case DT_UNION: rc = csg_builder_op(b, CSG_UNION); break;
    case DT_PRODUCT: rc = csg_builder_op(b, CSG_INTER); break;
    case DT_DIFF: rc = csg_builder_op(b, CSG_DIFF); break;
    case DT_RDIFF: rc = csg_builder_op(b, CSG_RDIFF); break;
    default: rc = -1;
    }
  }
  if (rc) {
    csg_builder_free(b);
    return NULL;
  }
  return csg_builder_finish(b, NULL);
}

typedef struct Chords {
  const csg_tape *t;
  double p[3], r;
  double u[3], e1[3], e2[3]; /* chord direction and the disc's axes */
  long evals;
} Chords;

/* Inside length of the chord at (a, b) of the disc. */
static double chord_len(Chords *C, double a, double b) {
  double h2 = C->r * C->r - a * a - b * b;
  if (h2 <= 0) return 0;
  double h = sqrt(h2);
  double o[3];
  for (int k = 0; k < 3; k++)
    o[k] = C->p[k] + a * C->e1[k] + b * C->e2[k] - h * C->u[k];
  csg_span sp[64];
  C->evals++;
  int n = csg_ray_spans(C->t, o, C->u, 0, 2 * h, sp, 64, NULL, 0);
  double L = 0;
  for (int i = 0; i < n; i++) {
    double t0 = fmax(sp[i].t0, 0), t1 = fmin(sp[i].t1, 2 * h);
    if (t1 > t0) L += t1 - t0;
  }
  return L;
}

/* Gauss-Kronrod 7-15 nodes and weights on [-1, 1]. */
static const double gk_x[8] = {
    0.991455371120812639206854697526329, 0.949107912342758524526189684047851,
    0.864864423359769072789712788640926, 0.741531185599394439863864773280788,
    0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
    0.207784955007898467600689403773245, 0.0};
static const double gk_wk[8] = {
    0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
    0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
    0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
    0.204432940075298892414161999234649, 0.209482141084727828012999174891714};
static const double gk_wg[4] = {
    0.129484966168869693270611432679082, 0.279705391489276667901467771423780,
    0.381830050505118944950369775488975, 0.417959183673469387755102040816327};

typedef double (*Fn)(void *ctx, double x);

static double gk15(Fn f, void *ctx, double a, double b, double *errest) {
  double c = 0.5 * (a + b), h = 0.5 * (b - a);
  double fc = f(ctx, c);
  double k = fc * gk_wk[7], g = fc * gk_wg[3];
  for (int i = 0; i < 7; i++) {
    double f1 = f(ctx, c - h * gk_x[i]), f2 = f(ctx, c + h * gk_x[i]);
    k += gk_wk[i] * (f1 + f2);
    if (i % 2 == 1) g += gk_wg[i / 2] * (f1 + f2);
  }
  *errest = fabs((k - g) * h);
  return k * h;
}

static double adapt(Fn f, void *ctx, double a, double b, double tol,
                    double whole, int depth) {
  double e, v = gk15(f, ctx, a, b, &e);
  if (e <= tol || depth >= 30 || b - a < 1e-7 * whole) return v;
  double m = 0.5 * (a + b);
  return adapt(f, ctx, a, m, 0.5 * tol, whole, depth + 1) +
         adapt(f, ctx, m, b, 0.5 * tol, whole, depth + 1);
}

typedef struct Inner {
  Chords *C;
  double b, w; /* the chord row b = r sin(theta), half-width w */
  double tol;
} Inner;

/* a = w sin(phi): smooth at the disc's rim. */
static double inner_fn(void *ctx, double phi) {
  Inner *in = ctx;
  return chord_len(in->C, in->w * sin(phi), in->b) * in->w * cos(phi);
}

static double outer_fn(void *ctx, double theta) {
  Inner *in = ctx;
  Inner row = *in;
  row.b = in->C->r * sin(theta);
  row.w = in->C->r * cos(theta);
  if (row.w <= 0) return 0;
  double v = adapt(inner_fn, &row, -M_PI / 2, M_PI / 2, in->tol, M_PI, 0);
  return v * in->C->r * cos(theta);
}

double conv_fraction(const csg_tape *t, const double p[3], double r,
                     double tol, long *evals) {
  if (csg_is_empty(t)) return 0;
  if (csg_is_all(t)) return 1;
  Chords C;
  memset(&C, 0, sizeof C);
  C.t = t;
  C.r = r;
  memcpy(C.p, p, sizeof C.p);
  /* A direction parallel to no face of the test objects, so the chord
     length is continuous over the disc (kinks only). */
  double u[3] = {0.3141592653, 0.5772156649, 0.7536512486};
  double lu = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
  for (int k = 0; k < 3; k++) C.u[k] = u[k] / lu;
  double e1[3] = {C.u[1], -C.u[0], 0};
  double l1 = sqrt(e1[0] * e1[0] + e1[1] * e1[1]);
  for (int k = 0; k < 3; k++) C.e1[k] = e1[k] / l1;
  C.e2[0] = C.u[1] * C.e1[2] - C.u[2] * C.e1[1];
  C.e2[1] = C.u[2] * C.e1[0] - C.u[0] * C.e1[2];
  C.e2[2] = C.u[0] * C.e1[1] - C.u[1] * C.e1[0];
  double V = 4.0 / 3.0 * M_PI * r * r * r;
  Inner in = {&C, 0, 0, 0};
  /* Outer error tol*V/2; each inner integral to a hundredth of
     tol*V/(2*pi*r): their errors, weighted by r cos(theta) over pi, add
     up to at most tol*V/200, small enough not to look like a kink to the
     outer rule's error estimate. */
  in.tol = 0.005 * tol * V / (M_PI * r);
  double v = adapt(outer_fn, &in, -M_PI / 2, M_PI / 2, 0.5 * tol * V, M_PI, 0);
  if (evals) *evals += C.evals;
  return v / V;
}


typedef struct Along {
  const csg_tape *t;
  const double *o, *d;
  double r, tol;
  long *points, *chords;
} Along;

static double along(const Along *A, double s) {
  double p[3] = {A->o[0] + s * A->d[0], A->o[1] + s * A->d[1],
                 A->o[2] + s * A->d[2]};
  if (A->points) ++*A->points;
  return conv_fraction(A->t, p, A->r, A->tol, A->chords) - 0.5;
}

double conv_crossing(const csg_tape *t, double r, const double o[3],
                     const double d[3], double guess, double tol,
                     long *points, long *chords) {
  Along A = {t, o, d, r, tol, points, chords};
  double dl = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  if (!(dl > 0) || !(r > 0)) return -1;
  double step = r / 8 / dl, a = guess, fa = along(&A, a);
  double b = a, fb = fa;
  int dirn = fa < 0 ? 1 : -1;
  for (int k = 0; k < 16; k++) {
    b = a + dirn * step;
    if (b < 0) return -1;
    fb = along(&A, b);
    if ((fa < 0) != (fb < 0)) break;
    a = b;
    fa = fb;
  }
  if ((fa < 0) == (fb < 0)) return -1;
  int side = 0;
  for (int it = 0; it < 60 && fabs(b - a) > 1e-7 * r / dl; it++) {
    double c = (a * fb - b * fa) / (fb - fa);
    double fc = along(&A, c);
    if ((fc < 0) == (fb < 0)) {
      b = c;
      fb = fc;
      if (side == -1) fa *= 0.5;
      side = -1;
    } else {
      a = c;
      fa = fc;
      if (side == 1) fb *= 0.5;
      side = 1;
    }
    if (fc == 0) return c;
  }
  return 0.5 * (a + b);
}
