/* test_mesh.c: the mesher (render/mesh.h) on every object kind, checked
 * independently of its own bookkeeping: closure and orientation by
 * counting directed edges here (not with mesh_check), the Euler
 * characteristic and the components against the known topology, the
 * signed volume (outward orientation), the distance of triangle points
 * from the surface by point classification at +-tol, and the distance of
 * surface points (crossings of random rays, scene/ray.h) from the mesh by
 * brute force over the triangles. Bad input: every error before the work,
 * and no file left behind. */
#include <gc.h>
#include <gmp.h>
#include <unistd.h>

#include "check.h"
#include "bind/bind.h"
#include "bind/compile.h"
#include "lang/eval.h"
#include "lang/interp.h"
#include "lang/parse.h"
#include "render/mesh.h"
#include "render/mesh_check.h"
#include "render/mesh_cover.h"
#include "render/mesh_float.h"
#include "render/render.h"
#include "scene/ray.h"

static Interp *I;

/* A source holding a copy of text (kept: values point into it). */
static Src *src_of(const char *name, const char *text) {
  Src *src = calloc(1, sizeof *src);
  size_t n = strlen(text) + 1;
  char *copy = malloc(n);
  memcpy(copy, text, n);
  src->name = name;
  src->text = copy;
  return src;
}

static Scene *compile(const char *text) {
  Src *src = src_of("<test>", text);
  ErrFrame f;
  Scene *volatile s = NULL;
  if (ERR_TRY(f)) {
    Expr *e = parse_expression(I, src);
    Value *v = eval(I, e, NULL);
    s = compile_scene(I, v, pos_none);
    err_pop(&f);
  } else {
    err_pop(&f);
    printf("# compile error: %s\n", err_info()->msg);
  }
  return s;
}

static unsigned long long rng = 88172645463325252ull;
static double urand(void) {
  rng ^= rng << 13;
  rng ^= rng >> 7;
  rng ^= rng << 17;
  return (double)(rng >> 11) / 9007199254740992.0;
}

static int cmp(const void *x, const void *y) {
  unsigned long long a = *(const unsigned long long *)x,
                     b = *(const unsigned long long *)y;
  return a < b ? -1 : a > b;
}

/* Independent edge counting: every directed edge once, its reverse once. */
static int closed_oriented(const Mesh *m, long *euler) {
  size_t ne = 3 * m->nt;
  unsigned long long *e = malloc(ne * sizeof *e);
  for (size_t i = 0; i < m->nt; i++)
    for (int k = 0; k < 3; k++) {
      unsigned long long a = (unsigned)m->t[3 * i + k],
                         b = (unsigned)m->t[3 * i + (k + 1) % 3];
      e[3 * i + k] = a << 32 | b;
    }
  qsort(e, ne, sizeof *e, cmp);
  int ok = 1;
  for (size_t i = 0; i + 1 < ne; i++)
    if (e[i] == e[i + 1]) ok = 0; /* a directed edge twice */
  for (size_t i = 0; i < ne && ok; i++) {
    unsigned long long r = (e[i] & 0xffffffffull) << 32 | e[i] >> 32;
    if (!bsearch(&r, e, ne, sizeof *e, cmp)) ok = 0;
  }
  char *used = calloc(m->nv, 1);
  long nv = 0;
  for (size_t i = 0; i < 3 * m->nt; i++)
    if (!used[m->t[i]]) used[m->t[i]] = 1, nv++;
  *euler = nv - (long)(ne / 2) + (long)m->nt;
  free(used);
  free(e);
  return ok;
}

static double volume(const Mesh *m) {
  double v = 0;
  for (size_t i = 0; i < m->nt; i++) {
    const double *a = m->v + 3 * m->t[3 * i], *b = m->v + 3 * m->t[3 * i + 1],
                 *c = m->v + 3 * m->t[3 * i + 2];
    v += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
         a[2] * (b[0] * c[1] - b[1] * c[0]);
  }
  return v / 6;
}

/* Squared distance from p to triangle abc (Ericson's closest point). */
static double d2_tri(const double p[3], const double *a, const double *b,
                     const double *c) {
  double ab[3], ac[3], ap[3], q[3];
  for (int i = 0; i < 3; i++) ab[i] = b[i] - a[i], ac[i] = c[i] - a[i], ap[i] = p[i] - a[i];
  double d1 = vec3_dot(ab, ap), d2 = vec3_dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) { memcpy(q, a, sizeof q); goto out; }
  double bp[3];
  for (int i = 0; i < 3; i++) bp[i] = p[i] - b[i];
  double d3 = vec3_dot(ab, bp), d4 = vec3_dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) { memcpy(q, b, sizeof q); goto out; }
  double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    double v = d1 / (d1 - d3);
    for (int i = 0; i < 3; i++) q[i] = a[i] + v * ab[i];
    goto out;
  }
  double cp[3];
  for (int i = 0; i < 3; i++) cp[i] = p[i] - c[i];
  double d5 = vec3_dot(ab, cp), d6 = vec3_dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) { memcpy(q, c, sizeof q); goto out; }
  double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    double w = d2 / (d2 - d6);
    for (int i = 0; i < 3; i++) q[i] = a[i] + w * ac[i];
    goto out;
  }
  double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    for (int i = 0; i < 3; i++) q[i] = b[i] + w * (c[i] - b[i]);
    goto out;
  }
  {
    double den = 1 / (va + vb + vc), v = vb * den, w = vc * den;
    for (int i = 0; i < 3; i++) q[i] = a[i] + ab[i] * v + ac[i] * w;
  }
out:;
  double d = 0;
  for (int i = 0; i < 3; i++) d += (p[i] - q[i]) * (p[i] - q[i]);
  return d;
}

/* A uniformly random point p of a random triangle of m, and the triangle's
   normal nn (|nn| = twice its area, returned; 0 for a sliver). */
static double triangle_point(const Mesh *m, double p[3], double nn[3]) {
  size_t i = (size_t)(urand() * (double)m->nt);
  const double *a = m->v + 3 * m->t[3 * i], *b = m->v + 3 * m->t[3 * i + 1],
               *c = m->v + 3 * m->t[3 * i + 2];
  double u = urand(), v = urand(), ab[3], ac[3];
  if (u + v > 1) u = 1 - u, v = 1 - v;
  for (int j = 0; j < 3; j++) {
    p[j] = a[j] + u * (b[j] - a[j]) + v * (c[j] - a[j]);
    ab[j] = b[j] - a[j];
    ac[j] = c[j] - a[j];
  }
  vec3_cross(ab, ac, nn);
  return sqrt(vec3_dot(nn, nn));
}

/* Triangle points: is there a sign change within distance e (along the
   triangle's normal, the axes, and the diagonals of the cube about the
   point: in a concave wedge of 72 degrees, at a prism glued to a wider
   one, the normal and axes can all end inside), or does the exact ray
   span along the normal begin or end within e (a face 1e-12 from the
   next part's, both sides of it inside)? Either proves the surface
   within e. Returns the number of failures. */
static long mesh_to_surface(const Scene *s, const Mesh *m, double e, int n) {
  long bad = 0;
  RayCtx *c = ray_ctx_new(s, 1e-9);
  for (int k = 0; k < n; k++) {
    double p[3], nn[3], l = triangle_point(m, p, nn);
    if (!(l > 0)) continue;
    static const double more[13][3] = {
        {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0}, {1, -1, 0}, {0, 1, 1},
        {0, 1, -1}, {1, 0, 1}, {1, 0, -1}, {1, 1, 1}, {1, 1, -1}, {1, -1, 1},
        {-1, 1, 1}};
    double dirs[14][3] = {{nn[0] / l, nn[1] / l, nn[2] / l}};
    int nd = 14;
    for (int d = 0; d < 13; d++) {
      double len = sqrt(vec3_dot(more[d], more[d]));
      for (int j = 0; j < 3; j++) dirs[d + 1][j] = more[d][j] / len;
    }
    int in0 = scene_inside(s, s->root, p), change = 0;
    for (int d = 0; d < nd && !change; d++)
      for (int sg = -1; sg <= 1; sg += 2) {
        double q[3];
        for (int j = 0; j < 3; j++) q[j] = p[j] + sg * 0.999 * e * dirs[d][j];
        if (scene_inside(s, s->root, q) != in0) change = 1;
      }
    if (!change && c) {
      double o[3];
      csg_span *sp;
      for (int j = 0; j < 3; j++) o[j] = p[j] - 0.999 * e * dirs[0][j];
      ray_reset(c);
      int ns = ray_spans(s, s->root, o, dirs[0], 0, 2 * 0.999 * e, c, &sp);
      for (int q = 0; q < ns && !change; q++)
        change = (sp[q].t0 > 0 && sp[q].t0 < 2 * 0.999 * e) ||
                 (sp[q].t1 > 0 && sp[q].t1 < 2 * 0.999 * e);
    }
    if (!change) bad++;
  }
  ray_ctx_free(c);
  return bad;
}

/* The farthest from the mesh (brute force) of the surface's crossings of
   o + t d for t in (0, tmax), by the exact ray spans; -1 if none. */
static double crossings_far(const Scene *s, const Mesh *m, RayCtx *c,
                            const double o[3], const double d[3], double tmax) {
  csg_span *sp;
  ray_reset(c);
  int n = ray_spans(s, s->root, o, d, 0, tmax, c, &sp);
  double worst = -1;
  for (int q = 0; q < n; q++)
    for (int x = 0; x < 2; x++) {
      double tt = x ? sp[q].t1 : sp[q].t0, p[3], best = 1e300;
      if (!(tt > 0 && tt < tmax)) continue;
      for (int j = 0; j < 3; j++) p[j] = o[j] + tt * d[j];
      for (size_t i = 0; i < m->nt; i++)
        best = fmin(best, d2_tri(p, m->v + 3 * m->t[3 * i], m->v + 3 * m->t[3 * i + 1],
                                 m->v + 3 * m->t[3 * i + 2]));
      worst = fmax(worst, sqrt(best));
    }
  return worst;
}

/* crossings_far over n lines, line i from o[i] along d[i] to tmax: the
   largest (-1 if no line crosses the surface), and in *hit how many
   lines cross it. */
static double lines_far(const Scene *s, const Mesh *m, const double (*o)[3],
                        const double (*d)[3], int n, double tmax, int *hit) {
  RayCtx *c = ray_ctx_new(s, 1e-9);
  double worst = -1;
  *hit = 0;
  for (int i = 0; i < n; i++) {
    double f = crossings_far(s, m, c, o[i], d[i], tmax);
    *hit += f >= 0;
    worst = fmax(worst, f);
  }
  ray_ctx_free(c);
  return worst;
}

/* Surface points (crossings of random rays through the box) against the
   mesh: the largest distance found. */
static double surface_to_mesh(const Scene *s, const Mesh *m, int nrays) {
  RayCtx *c = ray_ctx_new(s, 1e-9);
  double worst = 0, lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  for (size_t i = 0; i < 3 * m->nv; i++) {
    if (m->v[i] < lo[i % 3]) lo[i % 3] = m->v[i];
    if (m->v[i] > hi[i % 3]) hi[i % 3] = m->v[i];
  }
  for (int r = 0; r < nrays; r++) {
    double o[3], t[3], d[3];
    for (int j = 0; j < 3; j++) {
      o[j] = lo[j] + (hi[j] - lo[j]) * (urand() * 3 - 1);
      t[j] = lo[j] + (hi[j] - lo[j]) * urand();
      d[j] = t[j] - o[j];
    }
    worst = fmax(worst, crossings_far(s, m, c, o, d, 4));
  }
  ray_ctx_free(c);
  return worst;
}

/* ---- the cover proof (mesh_cover.h) on a sphere ------------------------- */

/* The squared distance from p to triangle abc in long double, by another
   route than the library's: the foot on the plane if it falls inside (the
   three edge orientations agree), else the nearest of the three sides. */
static long double ld_seg_d2(const long double p[3], const long double a[3],
                             const long double b[3]) {
  long double ab[3], ap[3], t = 0, l = 0, d = 0;
  for (int i = 0; i < 3; i++) {
    ab[i] = b[i] - a[i];
    ap[i] = p[i] - a[i];
    t += ab[i] * ap[i];
    l += ab[i] * ab[i];
  }
  t = l > 0 ? t / l : 0;
  if (t < 0) t = 0;
  if (t > 1) t = 1;
  for (int i = 0; i < 3; i++) {
    long double x = ap[i] - t * ab[i];
    d += x * x;
  }
  return d;
}

static long double ld_tri_d2(const double *pd, const double *ad, const double *bd,
                             const double *cd) {
  long double p[3], v[3][3], n[3], nn = 0, h = 0;
  for (int i = 0; i < 3; i++) {
    p[i] = pd[i];
    v[0][i] = ad[i];
    v[1][i] = bd[i];
    v[2][i] = cd[i];
  }
  for (int i = 0; i < 3; i++) {
    int j = (i + 1) % 3, k = (i + 2) % 3;
    n[i] = (v[1][j] - v[0][j]) * (v[2][k] - v[0][k]) - (v[1][k] - v[0][k]) * (v[2][j] - v[0][j]);
    nn += n[i] * n[i];
  }
  if (nn > 0) {
    for (int i = 0; i < 3; i++) h += n[i] * (p[i] - v[0][i]);
    long double f[3];
    for (int i = 0; i < 3; i++) f[i] = p[i] - h / nn * n[i];
    int pos = 0, neg = 0;
    for (int e = 0; e < 3; e++) {
      const long double *a = v[e], *b = v[(e + 1) % 3];
      long double c[3], o = 0;
      for (int i = 0; i < 3; i++) {
        int j = (i + 1) % 3, k = (i + 2) % 3;
        c[i] = (b[j] - a[j]) * (f[k] - a[k]) - (b[k] - a[k]) * (f[j] - a[j]);
        o += c[i] * n[i];
      }
      pos += o >= 0;
      neg += o <= 0;
    }
    if (pos == 3 || neg == 3) return h * h / nn;
  }
  long double d = ld_seg_d2(p, v[0], v[1]), d1 = ld_seg_d2(p, v[1], v[2]),
              d2 = ld_seg_d2(p, v[2], v[0]);
  return d < d1 ? (d < d2 ? d : d2) : (d1 < d2 ? d1 : d2);
}

/* The octahedron split k times, its vertices pushed onto the sphere of
   radius R about the origin; outward. */
static Mesh *icosphere(int k, double R) {
  size_t nt = 8, cap = 8;
  for (int i = 0; i < k; i++) cap *= 4;
  double *tri = malloc(9 * cap * sizeof *tri), *nx = malloc(9 * cap * sizeof *nx);
  static const double P[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  static const int F[8][3] = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                              {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  for (int f = 0; f < 8; f++)
    for (int v = 0; v < 3; v++) memcpy(tri + 9 * f + 3 * v, P[F[f][v]], sizeof P[0]);
  for (int r = 0; r < k; r++) {
    size_t w = 0;
    for (size_t t = 0; t < nt; t++) {
      double *a = tri + 9 * t, *b = a + 3, *c = a + 6, m[3][3];
      for (int i = 0; i < 3; i++) {
        m[0][i] = 0.5 * (a[i] + b[i]);
        m[1][i] = 0.5 * (b[i] + c[i]);
        m[2][i] = 0.5 * (c[i] + a[i]);
      }
      for (int q = 0; q < 3; q++) {
        double l = sqrt(vec3_dot(m[q], m[q]));
        for (int i = 0; i < 3; i++) m[q][i] /= l;
      }
      const double *out[4][3] = {{a, m[0], m[2]}, {m[0], b, m[1]}, {m[2], m[1], c}, {m[0], m[1], m[2]}};
      for (int o = 0; o < 4; o++, w++)
        for (int v = 0; v < 3; v++) memcpy(nx + 9 * w + 3 * v, out[o][v], 3 * sizeof(double));
    }
    double *x = tri;
    tri = nx;
    nx = x;
    nt = w;
  }
  Mesh *m = calloc(1, sizeof *m);
  m->nt = nt;
  m->nv = 3 * nt; /* unshared vertices: the proof needs no topology */
  m->v = malloc(9 * nt * sizeof *m->v);
  m->t = malloc(3 * nt * sizeof *m->t);
  for (size_t i = 0; i < 9 * nt; i++) m->v[i] = R * tri[i];
  for (size_t i = 0; i < 3 * nt; i++) m->t[i] = (int)i;
  free(tri);
  free(nx);
  return m;
}

/* The sphere of radius *R about the origin over a closed box: 0 when the
   box is wholly inside or outside it (with a relative margin for the
   rounding of the squares), else 1. */
/* The least and largest |p|^2 over the box, as computed. */
static void box_r2(const double lo[3], const double hi[3], double *near,
                   double *far) {
  *near = *far = 0;
  for (int i = 0; i < 3; i++) {
    double c = lo[i] > 0 ? lo[i] : hi[i] < 0 ? hi[i] : 0;
    double f = fmax(fabs(lo[i]), fabs(hi[i]));
    *near += c * c;
    *far += f * f;
  }
}

static int sphere_class(void *ctx, const double lo[3], const double hi[3]) {
  double R = *(double *)ctx, near, far;
  box_r2(lo, hi, &near, &far);
  return !(far < R * R * (1 - 1e-12) || near > R * R * (1 + 1e-12));
}

/* Boxes of side a over [-L, L]^3. */
static double *box_grid(double L, double a, size_t *n) {
  int k = (int)ceil(2 * L / a);
  double *b = malloc(6 * (size_t)k * k * k * sizeof *b);
  size_t w = 0;
  for (int i = 0; i < k; i++)
    for (int j = 0; j < k; j++)
      for (int l = 0; l < k; l++, w++) {
        int q[3] = {i, j, l};
        for (int x = 0; x < 3; x++) {
          b[6 * w + x] = -L + a * q[x];
          b[6 * w + 3 + x] = -L + a * (q[x] + 1);
        }
      }
  *n = w;
  return b;
}

/* The sag of a mesh of the sphere of radius R (cover_sphere): the
   largest distance from the sphere's point over a triangle's centroid to
   that triangle. */
static double sphere_sag(const Mesh *m, double R) {
  double sag = 0;
  for (size_t t = 0; t < m->nt; t++) {
    const double *a = m->v + 9 * t;
    double c[3];
    for (int i = 0; i < 3; i++) c[i] = (a[i] + a[3 + i] + a[6 + i]) / 3;
    double l = sqrt(vec3_dot(c, c));
    for (int i = 0; i < 3; i++) c[i] *= R / l;
    sag = fmax(sag, sqrt((double)ld_tri_d2(c, a, a + 3, a + 6)));
  }
  return sag;
}

/* mesh_cover on a sphere meshed by a split octahedron: the nearest
   triangles through its hierarchy equal brute force in long double by
   another formula; the whole sphere proven within e when e is above the
   mesh's true sag (computed here: the sphere's farthest points from the
   mesh are the triangles' circumcentres pushed out, whose distance to
   their own triangle bounds it), not proven when e is below half the sag,
   and not proven where a cap of triangles is cut away, at the cap. */
static void cover_sphere(void) {
  char buf[300];
  double R = 1;
  Mesh *m = icosphere(4, R);
  /* the nearest triangle: hierarchy against brute force */
  size_t np = 400;
  double *p = malloc(3 * np * sizeof *p), *d = malloc(np * sizeof *d);
  for (size_t i = 0; i < 3 * np; i++) p[i] = urand() * 2.6 - 1.3;
  CHECK("cover: nearest triangles computed", mesh_cover_nearest(m, p, np, d) == 0);
  double worst = 0;
  for (size_t i = 0; i < np; i++) {
    long double best = 1e300L;
    for (size_t t = 0; t < m->nt; t++) {
      long double q = ld_tri_d2(p + 3 * i, m->v + 3 * m->t[3 * t], m->v + 3 * m->t[3 * t + 1],
                                m->v + 3 * m->t[3 * t + 2]);
      if (q < best) best = q;
    }
    worst = fmax(worst, fabs(d[i] - (double)sqrtl(best)));
  }
  snprintf(buf, sizeof buf, "cover: the hierarchy's nearest distances equal brute force "
           "in long double on %zu points (worst difference %.3g)", np, worst);
  CHECK(buf, worst <= 1e-12);
  /* the sag: for each triangle, the sphere point on the ray through its
     circumcentre... bounded above by the largest distance from the sphere
     point along the triangle's centroid direction to the triangle, and
     below by it; taken as the largest over triangles of that distance */
  double sag = sphere_sag(m, R);
  size_t nb;
  double *bx = box_grid(1.25, 0.1, &nb);
  void *ctx[2] = {&R, &R};
  MeshCover mc;
  unsigned char *bad = malloc(nb);
  double e = 4 * sag;
  CHECK("cover: the proof ran", mesh_cover(m, bx, nb, e, 1e-12, sphere_class, ctx, 2, NULL, bad, &mc) == 0);
  snprintf(buf, sizeof buf, "cover: the sphere (sag %.3g) proven within %.3g of %zu "
           "triangles (%ld boxes, %ld not proven)", sag, e, m->nt, mc.boxes, mc.unproven);
  CHECK(buf, mc.unproven == 0 && mc.bound <= e);
  e = 0.5 * sag;
  mesh_cover(m, bx, nb, e, 1e-12, sphere_class, ctx, 2, NULL, bad, &mc);
  snprintf(buf, sizeof buf, "cover: not proven within half the sag (%.3g): %ld boxes not",
           e, mc.unproven);
  CHECK(buf, mc.unproven > 0);
  /* a cap cut away: every triangle with a vertex above z = 0.9 */
  size_t w = 0;
  for (size_t t = 0; t < m->nt; t++) {
    const double *a = m->v + 9 * t;
    if (a[2] > 0.9 || a[5] > 0.9 || a[8] > 0.9) continue;
    memmove(m->v + 9 * w, a, 9 * sizeof *a);
    w++;
  }
  m->nt = w;
  m->nv = 3 * w;
  e = 0.05; /* the cap's rim is at z = 0.9, its top 0.1 above */
  mesh_cover(m, bx, nb, e, 1e-12, sphere_class, ctx, 2, NULL, bad, &mc);
  snprintf(buf, sizeof buf, "cover: a cap cut away is found (%ld boxes not proven, "
           "the first near (%.3g, %.3g, %.3g))", mc.unproven, mc.at[0], mc.at[1], mc.at[2]);
  CHECK(buf, mc.unproven > 0 && mc.at[2] > 0.9);
  int outside = 0; /* every box not proven is at the cap */
  for (size_t i = 0; i < nb; i++) outside += bad[i] && bx[6 * i + 5] < 0.9;
  CHECK("cover: every box not proven is at the cap", outside == 0);
  free(bad);
  free(bx);
  free(p);
  free(d);
  mesh_free(m);
}

/* The sphere's field for the column proof, R^2 - |p|^2 (rising inward),
   with its range and gradient -2 p bounded exactly over boxes. */
static double sphere_value(void *ctx, int node, const double p[3]) {
  double R = *(double *)ctx;
  return R * R - vec3_dot(p, p);
}

static void sphere_range(void *ctx, int node, const double lo[3],
                         const double hi[3], double *l, double *h) {
  double R = *(double *)ctx, near, far;
  box_r2(lo, hi, &near, &far);
  *l = (R * R - far) - 1e-12 * (R * R + far);
  *h = (R * R - near) + 1e-12 * (R * R + near);
}

static int sphere_grad(void *ctx, int node, const double lo[3],
                       const double hi[3], const double *u, double *gmin,
                       double *wperp, double *gmax, double g0[3]) {
  double mid[3], rad = 0, al = 0, ah = 0, mu = 0;
  for (int i = 0; i < 3; i++) { /* d/dx_i = -2 x_i over [-2 hi, -2 lo] */
    mid[i] = -(lo[i] + hi[i]);
    rad += (hi[i] - lo[i]) * (hi[i] - lo[i]);
    if (u) {
      al += u[i] > 0 ? -2 * hi[i] * u[i] : -2 * lo[i] * u[i];
      ah += u[i] > 0 ? -2 * lo[i] * u[i] : -2 * hi[i] * u[i];
      mu += u[i] * mid[i];
    }
  }
  if (!u) {
    memcpy(g0, mid, sizeof mid);
    return 0;
  }
  for (int i = 0; i < 3; i++) mid[i] -= mu * u[i];
  *gmin = al - 1e-12 * fabs(al) - 1e-300;
  *gmax = fmax(fabs(al), fabs(ah)) * (1 + 1e-12);
  *wperp = (sqrt(vec3_dot(mid, mid)) + sqrt(rad)) * (1 + 1e-12);
  return 0;
}

/* Of the points of the sphere's upper half over a grid of x and y
   within L of c's, those farther than e from m (brute force in long
   double) into *nfar, and how many of them lie in a box not marked bad. */
static int far_unproven(const Mesh *m, const double *bx, size_t nb,
                        const unsigned char *bad, const double *cen, double L,
                        double zc, double e, int *nfar) {
  int far = 0, missed = 0;
  for (int a = 0; a < 60; a++)
    for (int b = 0; b < 60; b++) {
      double x = cen[0] + L * (a / 29.5 - 1), y = cen[1] + L * (b / 29.5 - 1), q[3];
      if (x * x + y * y > fmin(1 - zc * zc, 0.999)) continue;
      q[0] = x;
      q[1] = y;
      q[2] = sqrt(1 - x * x - y * y);
      long double best = 1e300L;
      for (size_t t = 0; t < m->nt; t++) {
        long double d2 = ld_tri_d2(q, m->v + 9 * t, m->v + 9 * t + 3, m->v + 9 * t + 6);
        if (d2 < best) best = d2;
      }
      if (sqrtl(best) <= 1.001L * e) continue;
      far++;
      for (size_t i = 0; i < nb; i++) {
        int in = 1;
        for (int k = 0; k < 3; k++) in &= q[k] >= bx[6 * i + k] && q[k] <= bx[6 * i + 3 + k];
        missed += in && !bad[i];
      }
    }
  *nfar = far;
  return missed;
}

/* cover_columns_sphere's cut: every triangle of m with a vertex above z
   = zc cut away, the rim's edges (used by one triangle) fanned to apex
   (their centroid if NULL): a closed mesh. Then every box holding a
   point of the sphere farther than e from the mesh (brute force in long
   double, on a grid over x and y within L of the apex) is not proven,
   and with the flat lid every box not proven is at the cap. */
static void cap_check(Mesh *m, const double *bx, size_t nb, const MeshField *fld,
                      void **ctx, double zc, const double *apex, double e,
                      double L) {
  char buf[300];
  MeshCover mc;
  unsigned char *bad = malloc(nb);
  size_t w = 0;
  for (size_t t = 0; t < m->nt; t++) {
    const double *a = m->v + 9 * t;
    if (a[2] > zc || a[5] > zc || a[8] > zc) continue;
    memmove(m->v + 9 * w, a, 9 * sizeof *a);
    w++;
  }
  size_t rim = 0, cap = w + 4096;
  double *v = malloc(9 * cap * sizeof *v), *edges = malloc(6 * 4096 * sizeof *edges), cen[3] = {0, 0, 0};
  memcpy(v, m->v, 9 * w * sizeof *v);
  for (size_t t = 0; t < w; t++)
    for (int k = 0; k < 3; k++) {
      const double *p = v + 9 * t + 3 * k, *q = v + 9 * t + 3 * ((k + 1) % 3);
      int twin = 0;
      for (size_t u = 0; u < w && !twin; u++)
        for (int j = 0; j < 3 && !twin; j++)
          twin = !memcmp(v + 9 * u + 3 * j, q, 3 * sizeof *q) &&
                 !memcmp(v + 9 * u + 3 * ((j + 1) % 3), p, 3 * sizeof *p);
      if (twin || rim == 4096) continue;
      memcpy(edges + 6 * rim, p, 3 * sizeof *p);
      memcpy(edges + 6 * rim + 3, q, 3 * sizeof *q);
      for (int i = 0; i < 3; i++) cen[i] += p[i];
      rim++;
    }
  for (int i = 0; i < 3; i++) cen[i] /= (double)rim;
  if (apex) memcpy(cen, apex, sizeof cen);
  for (size_t r = 0; r < rim; r++, w++) { /* (q, p, centre): the rim's twin */
    memcpy(v + 9 * w, edges + 6 * r + 3, 3 * sizeof *v);
    memcpy(v + 9 * w + 3, edges + 6 * r, 3 * sizeof *v);
    memcpy(v + 9 * w + 6, cen, 3 * sizeof *v);
  }
  free(m->v);
  free(m->t);
  m->v = v;
  m->nt = w;
  m->nv = 3 * w;
  m->t = malloc(3 * w * sizeof *m->t);
  for (size_t i = 0; i < 3 * w; i++) m->t[i] = (int)i;
  const char *how = apex ? "a cone" : "a flat lid";
  snprintf(buf, sizeof buf, "cover by columns: %s closes the cut at z = %.2g (%zu rim edges)",
           how, zc, rim);
  CHECK(buf, rim >= 16);
  mesh_cover(m, bx, nb, e, 1e-12, sphere_class, ctx, 2, fld, bad, &mc);
  snprintf(buf, sizeof buf, "cover by columns: a cap under %s is found (%ld boxes "
           "not proven, the first near (%.3g, %.3g, %.3g))", how, mc.unproven, mc.at[0],
           mc.at[1], mc.at[2]);
  CHECK(buf, mc.unproven > 0 && mc.at[2] > zc - 0.05);
  if (!apex) {
    int outside = 0;
    for (size_t i = 0; i < nb; i++) outside += bad[i] && bx[6 * i + 5] < zc;
    CHECK("cover by columns: every box not proven is at the cap", outside == 0);
  }
  int far, missed = far_unproven(m, bx, nb, bad, cen, L, zc, e, &far);
  snprintf(buf, sizeof buf, "cover by columns, %s: every box holding one of the cap's %d "
           "points farther than e from the mesh (brute force) is not proven (%d are)",
           how, far, missed);
  CHECK(buf, far > 100 && missed == 0);
  free(edges);
  free(bad);
}

/* A pit: the sphere's vertex nearest (0.3, 0.2, 0.93) pushed in by 0.3
   (every copy of it; the mesh stays closed). Columns beside it whose
   centre lines miss the pit see the pit's sides leave through their
   bottom faces; every box holding a point of the sphere farther than
   0.05 from the mesh must stay not proven. */
static void pit_check(Mesh *m, const double *bx, size_t nb, const MeshField *fld,
                      void **ctx) {
  char buf[300];
  double dir[3] = {0.3, 0.2, 0.93}, best = -1, pv[3] = {0, 0, 0};
  for (size_t i = 0; i < m->nv; i++) {
    double d = vec3_dot(m->v + 3 * i, dir);
    if (d > best) {
      best = d;
      memcpy(pv, m->v + 3 * i, sizeof pv);
    }
  }
  int moved = 0;
  for (size_t i = 0; i < m->nv; i++)
    if (!memcmp(m->v + 3 * i, pv, sizeof pv)) {
      for (int k = 0; k < 3; k++) m->v[3 * i + k] *= 0.7;
      moved++;
    }
  unsigned char *bad = malloc(nb);
  MeshCover mc;
  double e = 0.05;
  mesh_cover(m, bx, nb, e, 1e-12, sphere_class, ctx, 2, fld, bad, &mc);
  int far, missed = far_unproven(m, bx, nb, bad, pv, 0.15, 0, e, &far);
  snprintf(buf, sizeof buf, "cover by columns, a pit (%d copies of a vertex pushed in): "
           "every box holding one of its %d points farther than e from the mesh "
           "is not proven (%d are; %ld boxes not proven)", moved, far, missed, mc.unproven);
  CHECK(buf, moved >= 4 && far > 20 && missed == 0);
  free(bad);
}

/* The same proof by columns (MeshField), on boxes of the sphere as wide
   as 0.25 (many triangles each): proven within 4x the sag, by columns
   alone; not within half; and where a cap is cut away and closed again
   (cap_check), not proven wherever the sphere is farther than 0.05 from
   the mesh. */
static void cover_columns_sphere(void) {
  char buf[300];
  double R = 1;
  Mesh *m = icosphere(4, R);
  double sag = sphere_sag(m, R);
  size_t nb;
  double *bx = box_grid(1.25, 0.25, &nb);
  int *node = calloc(nb, sizeof *node);
  MeshField fld = {node, sphere_value, sphere_range, sphere_grad};
  void *ctx[2] = {&R, &R};
  MeshCover mc;
  unsigned char *bad = malloc(nb);
  double e = 4 * sag;
  mesh_cover(m, bx, nb, e, 1e-12, sphere_class, ctx, 2, &fld, bad, &mc);
  snprintf(buf, sizeof buf, "cover by columns: the sphere (sag %.3g) proven within %.3g "
           "(%ld of %zu boxes by %ld columns, %ld boxes of the box proof, %ld not proven)",
           sag, e, mc.col_boxes, nb, mc.columns, mc.boxes, mc.unproven);
  CHECK(buf, mc.unproven == 0 && mc.bound <= e && mc.col_boxes == (long)nb && mc.boxes == 0);
  e = 0.5 * sag;
  mesh_cover(m, bx, nb, e, 1e-12, sphere_class, ctx, 2, &fld, bad, &mc);
  snprintf(buf, sizeof buf, "cover by columns: not proven within half the sag (%.3g): "
           "%ld boxes not", e, mc.unproven);
  CHECK(buf, mc.unproven > 0);
  /* a cap cut away and closed flat (the rim fanned to its centre), and
     cut lower and closed by a cone to the sphere's top, whose sides leave
     the columns through their faces (its top at a column's centre) */
  cap_check(m, bx, nb, &fld, ctx, 0.9, NULL, 0.05, 0.5);
  Mesh *m2 = icosphere(4, R);
  double top[3] = {0.125, 0.125, sqrt(1 - 2 * 0.125 * 0.125)};
  cap_check(m2, bx, nb, &fld, ctx, 0, top, 0.02, 0.12);
  mesh_free(m2);
  m2 = icosphere(4, R);
  pit_check(m2, bx, nb, &fld, ctx);
  mesh_free(m2);
  free(bad);
  free(node);
  free(bx);
  mesh_free(m);
}

/* Where the cover proof gave up (rep->cover_at): the farthest from the
   mesh (brute force) of the surface's crossings of 13 lines through the
   place, within e / 4 of it (the exact ray spans); -1 if none crosses. */
static double cover_place(const Scene *s, const Mesh *m, const MeshReport *rep,
                          double e) {
  RayCtx *c = ray_ctx_new(s, 1e-9);
  double worst = -1;
  for (int k = 0; k < 13; k++) {
    int a = k < 3 ? k : 0;
    double d[3] = {0, 0, 0}, o[3];
    if (k < 3) d[a] = 1;
    else {
      d[0] = (k - 3) & 1 ? 1 : -1;
      d[1] = (k - 3) & 2 ? 1 : -1;
      d[2] = (k - 3) & 4 ? 1 : 0.5;
      if (k >= 11) d[k - 11] = 0.1;
    }
    double l = sqrt(vec3_dot(d, d));
    for (int j = 0; j < 3; j++) {
      d[j] *= 2 * e / l;
      o[j] = rep->cover_at[j] - 0.5 * d[j];
    }
    worst = fmax(worst, crossings_far(s, m, c, o, d, 1));
  }
  ray_ctx_free(c);
  return worst;
}

/* meshWith [Uniform] stays the uniform grid where the cover proof gives
   up (figure12's obj5: its flush contact's groove, closed): no round of
   splitting, every surface cell at the finest level (before, the forced
   cells split down to the octree's limit: obj5 at 0.015 ran for minutes). */
static void cover_uniform(void) {
  Scene *s = compile("Union (Rounded 0.07 UnitCube) (Rounded 0.07 (Shift "
                     "(0.25, 1, 0.25) (Scale (0.5, 0.5, 0.5) UnitCube)))");
  CHECK("cover, uniform: obj5 compiled", s != NULL);
  if (!s) return;
  MeshSettings ms = {0};
  ms.tol = 0.02;
  ms.uniform = 1;
  Mesh *m = NULL;
  MeshReport rep;
  int bad;
  char err[300], buf[300];
  int rc = mesh_scene(s, s->root, &ms, &m, &rep, &bad, err, sizeof err);
  snprintf(buf, sizeof buf, "cover, uniform: obj5 at 0.02 meshed (%ld cells not "
           "proven, %d rounds, deepest level %d of %d)", rep.cover_unproven,
           rep.cover_rounds, rep.deepest, rep.depth);
  CHECK(buf, rc == 0 && rep.cover_rounds == 0 && rep.deepest == rep.depth);
  mesh_free(m);
  scene_free(s);
}

/* A soft object is meshed adaptively (soft_grad_box proves cells smooth
   above the finest level): far fewer triangles than the uniform grid at
   the same tolerance, and still within it both ways (triangle points by
   point classification, surface points by random rays). */
static void soft_adaptive(void) {
  const char *src = "SoftObject 0.5 [Key (0, 0, 0) 1 1, Key (0.6, 0, 0) 1 1, "
                    "QuadricKey ((1, 0, 0, 0), (0, 4, 0, -1.2), (0, 0, 1, 0), "
                    "(0, -1.2, 0, 0.36)) 1 0.8]";
  Scene *s = compile(src);
  CHECK("soft adaptive: compiles", s != NULL);
  if (!s) return;
  double tol = 0.015;
  MeshSettings ms = {0};
  ms.tol = tol;
  Mesh *m = NULL, *u = NULL;
  MeshReport rep, urep;
  char err[300], buf[300];
  int bad;
  int rc = mesh_scene(s, s->root, &ms, &m, &rep, &bad, err, sizeof err);
  ms.uniform = 1;
  int urc = mesh_scene(s, s->root, &ms, &u, &urep, &bad, err, sizeof err);
  CHECK("soft adaptive: meshed, adaptive and uniform", rc == 0 && urc == 0);
  if (!rc && !urc) {
    snprintf(buf, sizeof buf, "soft adaptive: %ld cells proven smooth, %zu triangles "
             "against %zu uniform", rep.smooth, m->nt, u->nt);
    CHECK(buf, rep.smooth > 0 && 3 * m->nt < u->nt);
    long eu;
    CHECK("soft adaptive: closed and oriented", closed_oriented(m, &eu) && eu == 2);
    snprintf(buf, sizeof buf, "soft adaptive: certified %.3g <= tol", rep.certified);
    CHECK(buf, rep.certified <= tol);
    CHECK("soft adaptive: 3000 triangle points within tol of the surface",
          mesh_to_surface(s, m, tol, 3000) == 0);
    double w = surface_to_mesh(s, m, 300);
    snprintf(buf, sizeof buf, "soft adaptive: surface points within tol of the mesh (worst %.3g)", w);
    CHECK(buf, w <= tol);
  }
  mesh_free(m);
  mesh_free(u);
  scene_free(s);
}

/* src compiled and meshed at tol, checked to succeed; the scene (its
   mesh in *m, the report in *rep), or NULL with nothing left to free. */
static Scene *compile_mesh(const char *name, const char *src, double tol,
                           Mesh **m, MeshReport *rep) {
  char buf[600], err[400];
  Scene *s = compile(src);
  CHECK(name, s != NULL);
  if (!s) return NULL;
  MeshSettings ms = {0};
  ms.tol = tol;
  int bad;
  int rc = mesh_scene(s, s->root, &ms, m, rep, &bad, err, sizeof err);
  snprintf(buf, sizeof buf, "%s: meshed (%s)", name, rc ? err : "ok");
  CHECK(buf, rc == 0);
  if (rc) {
    scene_free(s);
    return NULL;
  }
  return s;
}

static void one(const char *name, const char *src, double tol, long euler,
                long comps, double vol, int check_surface) {
  char buf[600];
  Mesh *m;
  MeshReport rep;
  Scene *s = compile_mesh(name, src, tol, &m, &rep);
  if (!s) return;
  long eu;
  snprintf(buf, sizeof buf, "%s: closed and consistently oriented by edge counting", name);
  CHECK(buf, closed_oriented(m, &eu));
  snprintf(buf, sizeof buf, "%s: Euler characteristic %ld", name, euler);
  CHECK_NEAR(buf, (double)eu, (double)euler, 0);
  MeshCheck ck;
  snprintf(buf, sizeof buf, "%s: mesh_check agrees, %ld component(s)", name, comps);
  CHECK(buf, mesh_check(m, &ck) == 0 && ck.components == comps && ck.euler == eu);
  snprintf(buf, sizeof buf, "%s: certified error %.4g <= tolerance %.4g", name,
           rep.certified, tol);
  CHECK(buf, rep.certified <= tol);
  snprintf(buf, sizeof buf, "%s: the sharp cells were kept", name);
  CHECK(buf, !rep.sharp_off);
  double v = volume(m);
  snprintf(buf, sizeof buf, "%s: outward (signed volume %.4f > 0)", name, v);
  CHECK(buf, v > 0);
  if (vol > 0) {
    snprintf(buf, sizeof buf, "%s: volume %.4f near %.4f", name, v, vol);
    CHECK_NEAR(buf, v, vol, 0.05 * vol);
  }
  long far = mesh_to_surface(s, m, tol, 3000);
  snprintf(buf, sizeof buf, "%s: 3000 triangle points within tol of the surface", name);
  CHECK_NEAR(buf, (double)far, 0, 0);
  if (check_surface) {
    double w = surface_to_mesh(s, m, 40);
    snprintf(buf, sizeof buf, "%s: ray crossings within tol of the mesh (worst %.3g)", name, w);
    CHECK(buf, w <= tol);
  }
  printf("# %s: %zu triangles, %ld cells (%ld empty, %ld full, %ld meshed: "
         "%ld plane, %ld smooth, %ld sharp), certified %.4g, %.3f s\n", name,
         rep.triangles, rep.cells, rep.empty, rep.full, rep.leaves, rep.planar,
         rep.smooth, rep.sharp, rep.certified, rep.seconds);
  mesh_free(m);
  scene_free(s);
}


/* ---- thin parts: thinner than the finest cell ---------------------------- */

/* p is inside the mesh: the parity of the triangles a ray from p crosses
   (Moller-Trumbore, an oblique direction that no test face contains). */
static int mesh_contains(const Mesh *m, const double p[3]) {
  static const double d[3] = {0.5773, 0.6234, 0.5274};
  int n = 0;
  for (size_t i = 0; i < m->nt; i++) {
    const double *a = m->v + 3 * m->t[3 * i], *b = m->v + 3 * m->t[3 * i + 1],
                 *c = m->v + 3 * m->t[3 * i + 2];
    double e1[3], e2[3], pv[3], tv[3], qv[3];
    for (int j = 0; j < 3; j++) e1[j] = b[j] - a[j], e2[j] = c[j] - a[j], tv[j] = p[j] - a[j];
    vec3_cross(d, e2, pv);
    double det = vec3_dot(e1, pv);
    if (det == 0) continue;
    double u = vec3_dot(tv, pv) / det;
    if (u < 0 || u > 1) continue;
    vec3_cross(tv, e1, qv);
    double v = vec3_dot(d, qv) / det;
    if (v < 0 || u + v > 1) continue;
    if (vec3_dot(e2, qv) / det > 0) n++;
  }
  return n & 1;
}

/* An object with a part thinner than the finest cell (the tolerance's
   cell side, given by the report, is checked to exceed the part's
   thickness): meshed closed and oriented with the object's Euler
   characteristic and components (known by construction), and each of
   the np points, chosen in the thin part from its definition (and
   checked inside by point classification), inside the mesh by ray
   parity. With gap set the thin thing is air between two parts (a gap
   the mesh must not close): its points are outside both. */
static void thin(const char *name, const char *src, double tol, double thick,
                 long euler, long comps, const double (*pts)[3], int np,
                 int gap) {
  char buf[600];
  Mesh *m;
  MeshReport rep;
  Scene *s = compile_mesh(name, src, tol, &m, &rep);
  if (!s) return;
  snprintf(buf, sizeof buf, "%s: the part (%.3g thick) is thinner than the "
           "finest cell (%.3g)", name, thick, rep.h);
  CHECK(buf, thick < rep.h);
  long eu;
  MeshCheck ck;
  snprintf(buf, sizeof buf, "%s: closed, oriented (edge counting), Euler "
           "characteristic %ld, %ld component(s)", name, euler, comps);
  CHECK(buf, closed_oriented(m, &eu) && eu == euler && mesh_check(m, &ck) == 0 &&
                 ck.components == comps);
  if (eu != euler || ck.components != comps)
    printf("# %s: Euler characteristic %ld, %ld component(s)\n", name, eu,
           ck.components);
  snprintf(buf, sizeof buf, "%s: outward (signed volume > 0), sharp cells kept", name);
  CHECK(buf, volume(m) > 0 && !rep.sharp_off);
  int in = 0, inmesh = 0;
  for (int i = 0; i < np; i++) {
    in += scene_inside(s, s->root, pts[i]) == 1;
    inmesh += mesh_contains(m, pts[i]);
  }
  snprintf(buf, sizeof buf, "%s: %d points of the thin %s %s the object", name,
           np, gap ? "gap" : "part", gap ? "outside" : "inside");
  CHECK(buf, in == (gap ? 0 : np));
  snprintf(buf, sizeof buf, "%s: and %s the mesh (%d of %d inside)", name,
           gap ? "outside" : "inside", inmesh, np);
  CHECK(buf, inmesh == (gap ? 0 : np));
  snprintf(buf, sizeof buf, "%s: every cell proven one sheet (%ld cells with two "
           "surfaces not proven)", name, rep.two);
  CHECK(buf, rep.two == 0);
  printf("# %s: %zu triangles, %ld cells split below the finest level (side "
         "%.3g), down to depth %d\n", name, rep.triangles, rep.thin, rep.h,
         rep.deepest);
  mesh_free(m);
  scene_free(s);
}

/* 16 points in the middle plane x = 0.315 of a fin 0.03 thick from
   x = 0.3, on a 4 x 4 grid from height y0 up; their number. */
static int fin_points(double (*pts)[3], double y0) {
  int n = 0;
  for (int i = 0; i < 4; i++)
    for (int j = 0; j < 4; j++, n++) {
      pts[n][0] = 0.315;
      pts[n][1] = y0 + 0.1 * i;
      pts[n][2] = 0.2 + 0.2 * j;
    }
  return n;
}

static void thin_parts(void) {
  double pts[64][3];
  int n;
  /* a fin 0.03 thick on a rounded cube, one density tree */
  n = fin_points(pts, 1.1);
  thin("thin fin (rounded)", "Rounded 0.01 (DensityUnion UnitCube (Shift (0.3, 1, 0) "
       "(Scale (0.03, 0.5, 1) UnitCube)))", 0.1, 0.03, 2, 1, pts, n, 0);
  /* a rod 0.03 thick beside the block: two components */
  for (n = 0; n < 14; n++) {
    pts[n][0] = 2.015;
    pts[n][1] = 0.015;
    pts[n][2] = 0.1 * (n + 1);
  }
  thin("thin rod beside a block (rounded)", "Rounded 0.01 (DensityUnion UnitCube "
       "(Shift (2, 0, 0) (Scale (0.03, 0.03, 1.5) UnitCube)))", 0.1, 0.03, 4, 2, pts, n, 0);
  /* a slab 0.03 thick through an exact sphere (rounded with soft) */
  n = 0;
  for (int i = 0; i < 8; i++) {
    double a = 2 * 3.14159265358979 * i / 8;
    for (int r = 0; r < 3; r++, n++) {
      pts[n][0] = (0.6 + 0.15 * r) * cos(a);
      pts[n][1] = 0;
      pts[n][2] = (0.6 + 0.15 * r) * sin(a);
    }
  }
  thin("thin slab through a sphere (rounded and soft)", "Union (Sphere 0.5) (Rounded "
       "0.01 (Shift (-1, -0.015, -1) (Scale (2, 0.03, 2) UnitCube)))", 0.1, 0.03, 2,
       1, pts, n, 0);
  /* a soft key 0.05 across (its surface alone at magic 0.5 is the
     sphere of half its reach) beside a ball key: two components */
  n = 0;
  for (int i = 0; i < 7; i++, n++) {
    pts[n][0] = 1.2 + (i == 1 ? 0.015 : i == 2 ? -0.015 : 0);
    pts[n][1] = i == 3 ? 0.015 : i == 4 ? -0.015 : 0;
    pts[n][2] = i == 5 ? 0.015 : i == 6 ? -0.015 : 0;
  }
  thin("small soft key beside a ball key", "SoftObject 0.5 [Key (0, 0, 0) 1 1, "
       "Key (1.2, 0, 0) 0.05 1]", 0.1, 0.05, 4, 2, pts, n, 0);
  /* a sharp fin 0.03 thick on a rounded cube (sharp CSG with rounded) */
  n = fin_points(pts, 1.02);
  thin("thin sharp fin on a rounded cube", "Union (Rounded 0.05 UnitCube) (Sharp "
       "(Shift (0.3, 0.9, 0) (Scale (0.03, 0.6, 1) UnitCube)))", 0.1, 0.03, 2, 1, pts, n, 0);
  /* a sharp wall 0.02 thick left by a cube subtracted from a cube: its
     two planes face alike but one is subtracted, so they are not taken
     as nested (planes_nested) and the cells split, the wall kept */
  for (n = 0; n < 4; n++) {
    pts[n][0] = 0.01;
    pts[n][1] = 0.2 + 0.2 * n;
    pts[n][2] = 0.5;
  }
  thin("thin sharp wall (a cube minus a cube, their faces alike)", "SetDifference "
       "UnitCube (Shift (0.02, -0.5, -0.5) (Scale (2, 2, 2) UnitCube))", 0.1, 0.02,
       2, 1, pts, n, 0);
  /* thin parts and gaps bounded by two different rounded nodes, each
     alone one sheet in a cell: a cup whose walls and floor are 0.02
     thick (a rounded cube minus a rounded box), a gap 0.02 wide between
     two rounded cubes (a union the mesh must not close), a sliver 0.02
     thick where two rounded cubes overlap */
  n = 0;
  for (int i = 0; i < 2; i++)
    for (int j = 0; j < 2; j++) {
      double a = 0.3 + 0.3 * i, b = 0.3 + 0.3 * j;
      double w[5][3] = {{0.01, a, b}, {0.99, a, b}, {a, b, 0.01}, {a, b, 0.99},
                        {a, 0.01, b}};
      for (int k = 0; k < 5; k++, n++) memcpy(pts[n], w[k], sizeof w[k]);
    }
  thin("thin cup (a rounded cube minus a rounded box)", "SetDifference (Rounded "
       "0.01 UnitCube) (Rounded 0.01 (Shift (0.02, 0.02, 0.02) (Scale (0.96, 1.5, "
       "0.96) UnitCube)))", 0.1, 0.02, 2, 1, pts, n, 0);
  for (n = 0; n < 16; n++) {
    pts[n][0] = 1.01;
    pts[n][1] = 0.2 + 0.2 * (n % 4);
    pts[n][2] = 0.2 + 0.2 * (n / 4);
  }
  thin("thin gap between two rounded cubes (union)", "Union (Rounded 0.01 UnitCube) "
       "(Rounded 0.01 (Shift (1.02, 0, 0) UnitCube))", 0.1, 0.02, 4, 2, pts, n, 1);
  for (n = 0; n < 16; n++) pts[n][0] = 0.99;
  thin("thin sliver of two rounded cubes (intersection)", "Intersection (Rounded "
       "0.01 UnitCube) (Rounded 0.01 (Shift (0.98, 0, 0) UnitCube))", 0.1, 0.02, 2, 1,
       pts, n, 0);
}

/* ---- the exact predicates and the self-intersection check --------------- */

/* The reference: the 4x4 determinant |a 1; b 1; c 1; d 1| in GMP
   rationals (mpq_set_d is exact), by Laplace expansion along the column
   of ones, minors by the rule of Sarrus -- not the code's formula (3x3 of
   differences, first-row cofactors). Equal to det [a - d; b - d; c - d]
   (subtract row d from the others, expand along the last column). */
static int ref_orient3d(const double *a, const double *b, const double *c,
                        const double *d) {
  const double *r[4] = {a, b, c, d};
  mpq_t det, m, t, x[4][3];
  mpq_inits(det, m, t, NULL);
  for (int i = 0; i < 4; i++)
    for (int k = 0; k < 3; k++) {
      mpq_init(x[i][k]);
      mpq_set_d(x[i][k], r[i][k]);
    }
  for (int i = 0; i < 4; i++) { /* minor without row i, sign (-1)^(i+3) */
    int w[3], n = 0;
    for (int q = 0; q < 4; q++)
      if (q != i) w[n++] = q;
    mpq_set_ui(m, 0, 1);
    for (int p = 0; p < 3; p++) { /* Sarrus: three products up, three down */
      mpq_mul(t, x[w[0]][p], x[w[1]][(p + 1) % 3]);
      mpq_mul(t, t, x[w[2]][(p + 2) % 3]);
      mpq_add(m, m, t);
      mpq_mul(t, x[w[0]][p], x[w[1]][(p + 2) % 3]);
      mpq_mul(t, t, x[w[2]][(p + 1) % 3]);
      mpq_sub(m, m, t);
    }
    if ((i + 3) % 2) mpq_sub(det, det, m);
    else mpq_add(det, det, m);
  }
  int sg = mpq_sgn(det);
  for (int i = 0; i < 4; i++)
    for (int k = 0; k < 3; k++) mpq_clear(x[i][k]);
  mpq_clears(det, m, t, NULL);
  return sg;
}

/* |a_i a_j 1; b_i b_j 1; c_i c_j 1| in GMP rationals, by Sarrus. */
static int ref_orient2d(const double *a, const double *b, const double *c, int i,
                        int j) {
  double m[3][3] = {{a[i], a[j], 1}, {b[i], b[j], 1}, {c[i], c[j], 1}};
  mpq_t det, t, x[3][3];
  mpq_inits(det, t, NULL);
  for (int r = 0; r < 3; r++)
    for (int k = 0; k < 3; k++) {
      mpq_init(x[r][k]);
      mpq_set_d(x[r][k], m[r][k]);
    }
  for (int p = 0; p < 3; p++) {
    mpq_mul(t, x[0][p], x[1][(p + 1) % 3]);
    mpq_mul(t, t, x[2][(p + 2) % 3]);
    mpq_add(det, det, t);
    mpq_mul(t, x[0][p], x[1][(p + 2) % 3]);
    mpq_mul(t, t, x[2][(p + 1) % 3]);
    mpq_sub(det, det, t);
  }
  int sg = mpq_sgn(det);
  for (int r = 0; r < 3; r++)
    for (int k = 0; k < 3; k++) mpq_clear(x[r][k]);
  mpq_clears(det, t, NULL);
  return sg;
}

static unsigned long long prng = 0x9e3779b97f4a7c15ull;
static double prand(void) { /* its own stream: urand's is the property test's */
  prng ^= prng << 13;
  prng ^= prng >> 7;
  prng ^= prng << 17;
  return (double)(prng >> 11) / 9007199254740992.0;
}

/* Random points, and points made coplanar (collinear in 2-D) exactly on
   a dyadic grid, then nudged by an ulp or two: the signs against GMP. */
static void predicates(void) {
  long exact = 0, zero = 0, bad3 = 0, bad2 = 0, n = 0, badp = 0, exactp = 0;
  for (int k = 0; k < 30000; k++) {
    double p[4][3];
    int kind = k % 5;
    double sc = ldexp(1, (int)(prand() * 40) - 20); /* scales 2^-20 .. 2^20 */
    for (int i = 0; i < 4; i++)
      for (int a = 0; a < 3; a++) p[i][a] = (prand() - 0.5) * sc;
    if (kind >= 1) { /* d = a + s (b - a) + t (c - a), s, t small dyadic:
                        exact on a grid of 2^-10 */
      for (int i = 0; i < 3; i++)
        for (int a = 0; a < 3; a++)
          p[i][a] = ldexp(floor(p[i][a] / sc * 1024), -10) * sc;
      double s = floor(prand() * 8) / 4 - 1, t = floor(prand() * 8) / 4 - 1;
      for (int a = 0; a < 3; a++)
        p[3][a] = p[0][a] + s * (p[1][a] - p[0][a]) + t * (p[2][a] - p[0][a]);
    }
    if (kind >= 3) { /* one coordinate an ulp or two off the plane */
      int a = (int)(prand() * 3), i = (int)(prand() * 4);
      p[i][a] = nextafter(p[i][a], kind == 3 ? INFINITY : -INFINITY);
      if (prand() < 0.5) p[i][a] = nextafter(p[i][a], kind == 3 ? INFINITY : -INFINITY);
    }
    if (kind == 1 && k % 2) /* two places along z: a plane along it */
      for (int a = 0; a < 2; a++) p[2][a] = p[0][a], p[3][a] = p[1][a];
    int r = ref_orient3d(p[0], p[1], p[2], p[3]);
    zero += r == 0;
    bad3 += mesh_orient3d(p[0], p[1], p[2], p[3], &exact) != r;
    badp += mesh_orient3d_plane(p[0], p[1], p[2], p[3], &exactp) != r;
    int i = (int)(prand() * 3), j = (i + 1 + (int)(prand() * 2)) % 3;
    bad2 += mesh_orient2d(p[0], p[1], p[3], i, j, &exact) !=
            ref_orient2d(p[0], p[1], p[3], i, j);
    n++;
  }
  /* the extremes of the range: the filter steps aside, GMP decides */
  double tiny[4][3] = {{0, 0, 0}, {1e-310, 0, 0}, {0, 1e-310, 0}, {0, 0, 1e-310}};
  double huge[4][3] = {{0, 0, 0}, {1e300, 0, 0}, {0, 1e300, 0}, {0, 0, 1e300}};
  bad3 += mesh_orient3d(tiny[0], tiny[1], tiny[2], tiny[3], NULL) !=
          ref_orient3d(tiny[0], tiny[1], tiny[2], tiny[3]);
  bad3 += mesh_orient3d(huge[0], huge[1], huge[2], huge[3], NULL) !=
          ref_orient3d(huge[0], huge[1], huge[2], huge[3]);
  bad3 += ref_orient3d(tiny[0], tiny[1], tiny[2], tiny[3]) == 0;
  char buf[300];
  snprintf(buf, sizeof buf, "orient3d: %ld signs of %ld agree with GMP's 4x4 "
           "determinant (%ld exactly zero; %ld signs decided in exact arithmetic)",
           n - bad3, n, zero, exact);
  CHECK(buf, bad3 == 0 && zero > 1000 && exact > 1000);
  snprintf(buf, sizeof buf, "orient2d: %ld signs of %ld agree with GMP", n - bad2, n);
  CHECK(buf, bad2 == 0);
  badp += mesh_orient3d_plane(tiny[0], tiny[1], tiny[2], tiny[3], NULL) !=
          ref_orient3d(tiny[0], tiny[1], tiny[2], tiny[3]);
  badp += mesh_orient3d_plane(huge[0], huge[1], huge[2], huge[3], NULL) !=
          ref_orient3d(huge[0], huge[1], huge[2], huge[3]);
  snprintf(buf, sizeof buf, "orient3d by the plane made once (the check's fast "
           "path): %ld signs of %ld agree with GMP (%ld left to exact arithmetic)",
           n - badp, n, exactp);
  CHECK(buf, badp == 0 && exactp > 1000);
}

/* A random point on the dyadic grid of 2^-10 * sc. */
static void grid_pt(double *p, double sc) {
  for (int a = 0; a < 3; a++) p[a] = ldexp(floor((prand() - 0.5) * 1024), -10) * sc;
}

/* p = a + s (b - a) + t (c - a) with s, t small dyadic: exact, in the
   plane of a, b, c (on the grid of 2^-12 * sc). */
static void in_plane(double *p, const double *a, const double *b,
                     const double *c) {
  double s = floor(prand() * 12) / 4 - 1, t = floor(prand() * 12) / 4 - 1;
  for (int k = 0; k < 3; k++) p[k] = a[k] + s * (b[k] - a[k]) + t * (c[k] - a[k]);
}

/* One coordinate of p an ulp or two off. */
static void nudge(double *p) {
  int a = (int)(prand() * 3);
  double dir = prand() < 0.5 ? INFINITY : -INFINITY;
  p[a] = nextafter(p[a], dir);
  if (prand() < 0.5) p[a] = nextafter(p[a], dir);
}

/* The check's fast path (planes made once, coplanar neighbours first)
   against the general pair test on pairs made to be near-degenerate:
   on one edge (third vertices in one plane, folded onto each other or
   flat, or an ulp off it), on one vertex (both in one plane, or an ulp
   off), on nothing (coplanar, overlapping or not), on two lines along an
   axis (a rounded edge's strips), each in a few scales; a wrong sign or
   a wrong shortcut makes the two differ. */
static void fast_pairs(void) {
  long n = 0, differ = 0, met = 0, kinds[5] = {0};
  for (int k = 0; k < 40000; k++) {
    double v[6][3];
    int t[2][3];
    int kind = k % 5;
    double sc = ldexp(1, (int)(prand() * 20) - 10);
    for (int i = 0; i < 6; i++) grid_pt(v[i], sc);
    if (kind == 0) { /* one edge 0 1: B's third vertex in A's plane */
      in_plane(v[3], v[0], v[1], v[2]);
      t[0][0] = 0, t[0][1] = 1, t[0][2] = 2, t[1][0] = 1, t[1][1] = 0, t[1][2] = 3;
    } else if (kind == 1) { /* one vertex 0 */
      in_plane(v[3], v[0], v[1], v[2]);
      in_plane(v[4], v[0], v[1], v[2]);
      t[0][0] = 0, t[0][1] = 1, t[0][2] = 2, t[1][0] = 0, t[1][1] = 3, t[1][2] = 4;
    } else if (kind == 2) { /* nothing shared, one plane */
      for (int i = 3; i < 6; i++) in_plane(v[i], v[0], v[1], v[2]);
      t[0][0] = 0, t[0][1] = 1, t[0][2] = 2, t[1][0] = 3, t[1][1] = 4, t[1][2] = 5;
    } else { /* vertices on two lines along axis ax: a strip */
      int ax = (int)(prand() * 3);
      for (int i = 0; i < 6; i++) {
        const double *base = v[i % 2 ? 1 : 0];
        double x = v[i][ax];
        memcpy(v[i], base, sizeof v[i]);
        v[i][ax] = x;
      }
      if (kind == 3) /* one edge */
        t[0][0] = 0, t[0][1] = 1, t[0][2] = 2, t[1][0] = 1, t[1][1] = 2,
        t[1][2] = 3;
      else /* one vertex */
        t[0][0] = 0, t[0][1] = 1, t[0][2] = 2, t[1][0] = 2, t[1][1] = 3,
        t[1][2] = 5;
    }
    if (k % 3 == 1) nudge(v[3 + (int)(prand() * 3)]);
    if (k % 7 == 2) nudge(v[(int)(prand() * 3)]);
    Mesh m = {6, 2, &v[0][0], &t[0][0], NULL};
    int g = mesh_tri_pair(&m, 0, 1), f = mesh_tri_pair_fast(&m, 0, 1);
    if (g != f && differ < 5)
      printf("# fast path %d, general %d, kind %d, pair %ld\n", f, g, kind, n);
    differ += g != f;
    met += g;
    kinds[kind] += g;
    n++;
  }
  mesh_check_release();
  char buf[300];
  snprintf(buf, sizeof buf, "self-intersection check's fast path: %ld of %ld "
           "near-degenerate pairs as the general test has them (%ld meet: "
           "%ld on an edge, %ld on a vertex, %ld coplanar, %ld and %ld in strips)",
           n - differ, n, met, kinds[0], kinds[1], kinds[2], kinds[3], kinds[4]);
  /* both answers common in every kind, so neither answer is a default */
  int mixed = 1;
  for (int q = 0; q < 5; q++) mixed &= kinds[q] > 200 && kinds[q] < 7800;
  CHECK(buf, differ == 0 && mixed);
}

/* A mesh of the given vertices and triangles (no closure needed). */
static int pair_of(const double (*v)[3], int nv, const int (*t)[3], int nt) {
  Mesh m = {(size_t)nv, (size_t)nt, (double *)v, (int *)t, NULL};
  MeshSelfCheck c;
  int r = mesh_self_check(&m, &c);
  int p = mesh_tri_pair(&m, 0, 1);
  return r < 0 ? -1 : r != p ? -2 : r; /* the grid and the pair test agree */
}

/* Hand-built pairs of triangles, each answer from the construction. */
static void hand_meshes(void) {
  struct {
    const char *name;
    double v[6][3];
    int t[2][3];
    int want;
  } cs[] = {
    /* T1 in z = 0; T2 upright in x = 0.25, through T1's inside */
    {"crossing", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.25, 0.25, -1}, {0.25, 0.25, 1}, {0.25, -1, 0.5}},
     {{0, 1, 2}, {3, 4, 5}}, 1},
    /* the same T2 moved to x = 2: apart */
    {"apart", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {2, 0.25, -1}, {2, 0.25, 1}, {2, -1, 0.5}},
     {{0, 1, 2}, {3, 4, 5}}, 0},
    /* T2's corner (its own vertex) on T1's inside point (0.25, 0.25, 0) */
    {"touching at a vertex not shared", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.25, 0.25, 0}, {0.25, 0.25, 1}, {0.5, 0.5, 1}},
     {{0, 1, 2}, {3, 4, 5}}, 1},
    /* T2's corner at (2, 0, 0) on T1's edge line extended: apart */
    {"corner on an edge's line, outside", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {2, 0, 0}, {2, 0, 1}, {2, 1, 1}},
     {{0, 1, 2}, {3, 4, 5}}, 0},
    /* one shared vertex 0, T2 rising out of T1's plane away from it */
    {"one shared vertex, apart", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {-1, 0, 1}, {0, -1, 1}, {0, 0, 0}},
     {{0, 1, 2}, {0, 3, 4}}, 0},
    /* one shared vertex, T2 through T1: its edge from 0 goes down to
       (1, 1, -1), its other vertex (0.2, 0.2, 1) above: it crosses
       z = 0 along a segment from 0 into T1 */
    {"one shared vertex, crossing", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.2, 0.2, 1}, {0.3, 0.3, -1}, {0, 0, 0}},
     {{0, 1, 2}, {0, 3, 4}}, 1},
    /* one shared vertex, both in z = 0, angles 0..90 and 180..270 deg */
    {"one shared vertex, coplanar, apart", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}, {0, 0, 0}},
     {{0, 1, 2}, {0, 3, 4}}, 0},
    /* one shared vertex, both in z = 0, angles 0..90 and 45..135 deg */
    {"one shared vertex, coplanar, overlapping", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {-1, 1, 0}, {0, 0, 0}},
     {{0, 1, 2}, {0, 3, 4}}, 1},
    /* one shared vertex, coplanar, T2's side along T1's side 0 -> (1, 0) */
    {"one shared vertex, coplanar, sides along each other", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {2, 0, 0}, {1, -1, 0}, {0, 0, 0}},
     {{0, 1, 2}, {0, 4, 3}}, 1},
    /* shared edge 0-1, T2 bent down out of the plane: proper */
    {"shared edge, bent", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.5, -1, -0.5}, {0, 0, 0}, {0, 0, 0}},
     {{0, 1, 2}, {1, 0, 3}}, 0},
    /* shared edge 0-1, T2 in the plane on the other side: flat, proper */
    {"shared edge, flat", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.5, -1, 0}, {0, 0, 0}, {0, 0, 0}},
     {{0, 1, 2}, {1, 0, 3}}, 0},
    /* shared edge 0-1, T2 in the plane on the same side: folded */
    {"shared edge, folded onto each other", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.5, 2, 0}, {0, 0, 0}, {0, 0, 0}},
     {{0, 1, 2}, {1, 0, 3}}, 1},
    /* no shared vertex, both in z = 0, T2 over T1's corner region */
    {"coplanar overlap", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.2, 0.2, 0}, {2, 0.2, 0}, {0.2, 2, 0}},
     {{0, 1, 2}, {3, 4, 5}}, 1},
    /* no shared vertex, both in z = 0, T2 inside T1 */
    {"coplanar, one inside the other", {{0, 0, 0}, {4, 0, 0}, {0, 4, 0}, {0.5, 0.5, 0}, {1, 0.5, 0}, {0.5, 1, 0}},
     {{0, 1, 2}, {3, 4, 5}}, 1},
    /* no shared vertex, z = 0, T2 below y = 0 touching T1 along part of
       its edge (0.2 .. 0.8, 0, 0) */
    {"coplanar, touching along an edge (nothing shared)", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.2, 0, 0}, {0.8, 0, 0}, {0.5, -1, 0}},
     {{0, 1, 2}, {4, 3, 5}}, 1},
    /* no shared vertex, z = 0, T2 below y = -0.001: a gap */
    {"coplanar, a gap below the edge", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.2, -0.001, 0}, {0.8, -0.001, 0}, {0.5, -1, 0}},
     {{0, 1, 2}, {4, 3, 5}}, 0},
    /* shared edge 0-1 in z = 0, coplanar, opposite sides: touching only
       along the shared edge */
    {"coplanar, touching only along the shared edge", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.3, -2, 0}, {0, 0, 0}, {0, 0, 0}},
     {{0, 1, 2}, {1, 0, 3}}, 0},
    /* a zero-area triangle 0, 3, 1 along T2's... : T1 = (0, 3, 1) with 3
       the middle of the edge 0-1, T2 = (1, 0, 2) holding that edge: they
       meet in the edge only */
    {"zero-area triangle along the shared edge", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.5, 0, 0}, {0, 0, 0}, {0, 0, 0}},
     {{0, 3, 1}, {1, 0, 2}}, 0},
    /* a zero-area triangle (0, 1, 3) reaching from T2's vertex 0 through
       T2 to (0.5, 0.5, 0) inside it: T2 = (0, 4, 2) shares vertex 0 */
    {"zero-area triangle into a neighbour", {{0, 0, 0}, {0.25, 0.25, 0}, {0, 1, 0}, {0.5, 0.5, 0}, {1, 0, 0}, {0, 0, 0}},
     {{0, 1, 3}, {0, 4, 2}}, 1},
  };
  int n = (int)(sizeof cs / sizeof cs[0]);
  for (int k = 0; k < n; k++) {
    char buf[200];
    int got = pair_of(cs[k].v, 6, cs[k].t, 2);
    snprintf(buf, sizeof buf, "self-intersection check, %s: %s", cs[k].name,
             cs[k].want ? "found" : "none");
    if (got != cs[k].want) printf("# %s: got %d\n", cs[k].name, got);
    CHECK(buf, got == cs[k].want);
  }
  /* the same answers under an exact similarity (a power of two and a
     shift by a dyadic vector keep every predicate's sign) */
  int same = 0;
  for (int k = 0; k < n; k++) {
    double v[6][3];
    for (int i = 0; i < 6; i++)
      for (int a = 0; a < 3; a++) v[i][a] = ldexp(cs[k].v[i][a], -7) + 0.375 * (a + 1);
    same += pair_of((const double (*)[3])v, 6, cs[k].t, 2) == cs[k].want;
  }
  CHECK("self-intersection check: the same answers scaled by 2^-7 and shifted", same == n);
  /* a closed octahedron |x| + |y| + |z| <= 1: no pair meets; a second
     one shifted by (0.5, 0.3, 0.1) has its vertex (-0.5, 0.3, 0.1)
     inside the first (0.9 < 1) and the next one along an edge, (0.5,
     1.3, 0.1), outside (1.9): that edge crosses the first's surface */
  double oct[12][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  int ot[16][3] = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  Mesh m = {6, 8, &oct[0][0], &ot[0][0], NULL};
  MeshSelfCheck c;
  CHECK("octahedron: no self-intersection (28 pairs, all boxes overlap)",
        mesh_self_check(&m, &c) == 0 && c.pairs == 28);
  static const double shift[3] = {0.5, 0.3, 0.1};
  for (int i = 0; i < 6; i++)
    for (int a = 0; a < 3; a++) oct[6 + i][a] = oct[i][a] + shift[a];
  for (int f = 0; f < 8; f++)
    for (int q = 0; q < 3; q++) ot[8 + f][q] = ot[f][q] + 6;
  m.nv = 12, m.nt = 16;
  CHECK("two octahedra, one's edge leaving the other: found",
        mesh_self_check(&m, &c) == 1 && c.bad > 0);
  for (int i = 0; i < 6; i++) oct[6 + i][0] += 3; /* moved clear */
  CHECK("two octahedra apart: none", mesh_self_check(&m, &c) == 0);
  oct[4][2] = NAN;
  CHECK("a vertex not finite: refused", mesh_self_check(&m, &c) == -1);
}

/* ---- sharp cells kept: the scenes a longer run gave them up in ---------- */

/* Long-run scenes meshed at 0.03 (the property test's generator), each
   checked by check and then for what every mesh must be: closed and
   oriented by this file's edge counting with the Euler characteristic
   the report gives, free of self-intersections by the exact check, and
   certified within the tolerance. */
static void long_run_scenes(const char *what, const char *const *objs,
                            const int *num, size_t n,
                            void (*check)(const char *, const MeshReport *)) {
  for (size_t k = 0; k < n; k++) {
    char name[120], buf[400];
    snprintf(name, sizeof name, "long run scene %d (%s)", num[k], what);
    Mesh *m;
    MeshReport rep;
    Scene *s = compile_mesh(name, objs[k], 0.03, &m, &rep);
    if (!s) continue;
    check(name, &rep);
    long eu;
    MeshSelfCheck sc;
    snprintf(buf, sizeof buf, "%s: closed and oriented by edge counting, Euler "
             "characteristic %ld as the report says, no self-intersection, "
             "certified %.4g <= 0.03", name, rep.euler, rep.certified);
    CHECK(buf, closed_oriented(m, &eu) && eu == rep.euler &&
                   mesh_self_check(m, &sc) == 0 && rep.certified <= 0.03);
    mesh_free(m);
    scene_free(s);
  }
}

static void apart_check(const char *name, const MeshReport *rep) {
  char buf[400];
  snprintf(buf, sizeof buf, "%s: %ld sharp cells given up locally, %ld kept "
           "sharp, none given up whole", name, rep->sharp_apart, rep->sharp);
  CHECK(buf, !rep->sharp_off && rep->sharp_apart > 0 && rep->sharp_apart <= 16 &&
                 rep->sharp > 0);
}

/* Long-run scenes 255 and 875, where two sharp cells placed a crease
   point each its own way (a crack: 5 and 62 boundary edges) and the
   whole mesh was made again without sharp cells: now only the sharp
   cells about the crack are (MeshReport.sharp_apart, a few) and the
   others stay sharp. */
static void sharp_apart_kept(void) {
  static const char *objs[] = {
    /* 255 */ "Union (Union (Rounded 0.13706648229358767 (Rotate \"y\" 57.708 (Shift (-0.136, -0.328, 0.113) (Scale (0.847, 0.805, 0.620) UnitCube)))) (Rotate \"z\" 27.775 (Shift (0.125, 0.192, 0.026) (Scale (0.475, 0.426, 0.402) UnitCube)))) (SoftObject 0.5 [Key (-0.007, -0.146, -0.121) 0.568 1, Key (0.149, -0.425, -0.287) 0.538 1, Key (-0.143, -0.238, 0.327) 0.656 1, Key (0.368, 0.437, -0.243) 0.713 (-1)])",
    /* 875 */ "SetDifference (Union (Rounded 0.073151740419062791 (Rotate \"y\" 85.649 (Shift (-0.085, 0.318, 0.139) (Scale (0.392, 0.676, 0.845) UnitCube)))) (Rotate \"x\" 59.252 (Shift (0.263, 0.445, -0.450) (Scale (0.812, 0.680, 0.341) UnitCube)))) (SoftObject 0.5 [Key (0.216, -0.308, 0.487) 0.551 1, Key (0.042, -0.178, -0.163) 0.674 1, Key (0.340, -0.158, 0.485) 0.577 1, Key (0.241, -0.231, 0.161) 0.671 (-1)])"};
  static const int num[] = {255, 875};
  long_run_scenes("a crack between sharp cells", objs, num, 2, apart_check);
}

/* Long-run scene 575: box B's bottom face, a soft surface dipping
   through it and its side face leave an island of B about 0.002 across
   (x 0.2005 .. 0.2025, y 0.391 .. 0.394, z 0.349 .. 0.3525, by Roots).
   The first mesh's cells (0.0045) missed it and the proof that the
   surface lies within the tolerance of the mesh failed there (the
   island 0.18 from it); the round that splits those cells found it, 3
   components more, and was not kept for changing the topology. Now a
   round that proves every part is kept (MeshReport.cover_topo): the
   island's surface, every crossing of 121 lines through it by the exact
   ray spans, within the tolerance of the mesh by brute force. */
static void cover_island(void) {
  static const char *obj =
    "SetDifference (Union (Rounded 0.11596058744294679 (Rotate \"x\" 45.591 (Shift (0.234, -0.269, -0.349) (Scale (0.328, 0.701, 0.358) UnitCube)))) (Rotate \"y\" 30.408 (Shift (-0.004, 0.391, 0.403) (Scale (0.698, 0.474, 0.368) UnitCube)))) (SoftObject 0.5 [Key (0.479, 0.243, -0.367) 0.851 1, Key (0.120, -0.461, 0.338) 0.635 1, Key (0.449, 0.495, 0.351) 0.526 1, Key (-0.276, -0.455, -0.168) 0.524 (-1)])";
  Mesh *m;
  MeshReport rep;
  char buf[400];
  Scene *s = compile_mesh("long run scene 575 (an island)", obj, 0.03, &m, &rep);
  if (!s) return;
  snprintf(buf, sizeof buf, "scene 575: every part proven within the tolerance "
           "(%ld cells not), the topology changed from the first mesh's (%ld "
           "components, Euler %ld) to %ld and %ld", rep.cover_unproven,
           rep.first_components, rep.first_euler, rep.components, rep.euler);
  CHECK(buf, rep.cover_unproven == 0 && rep.cover_topo &&
                 rep.components > rep.first_components);
  double o[121][3], d[121][3];
  for (int i = 0, l = 0; i <= 10; i++)
    for (int k = 0; k <= 10; k++, l++) {
      o[l][0] = 0.2005 + 0.0002 * i, o[l][1] = 0.38, o[l][2] = 0.349 + 0.00035 * k;
      d[l][0] = 0, d[l][1] = 0.02, d[l][2] = 0;
    }
  int hit;
  double worst = lines_far(s, m, (const double (*)[3])o, (const double (*)[3])d,
                           121, 1, &hit);
  snprintf(buf, sizeof buf, "scene 575: the island's surface within 0.03 of the "
           "mesh (%d of 121 lines cross it; worst %.3g)", hit, worst);
  CHECK(buf, hit >= 10 && worst >= 0 && worst <= 0.03);
  mesh_free(m);
  scene_free(s);
}

/* figure12's obj5 at 0.01: the groove under the rounded box's edge (it
   rests flush on the rounded cube) narrows to nothing, the first mesh
   closes it where it is thinner than the cells, and 741 cells beside the
   cells with two surfaces were not proven (the surface deep in the groove
   0.022 from the mesh). Those many are split in one round (a groove),
   kept because it proves every part and keeps the topology. Checked here
   by the exact ray spans of 44 vertical lines through the groove (both
   of its surfaces, up to the contact's edge at x = 0.32) against the
   mesh by brute force, and by edge counting: one part, genus 0. */
static void cover_groove(void) {
  static const char *obj =
    "Union (Rounded 0.07 UnitCube) (Rounded 0.07 (Shift (0.25, 1, 0.25) "
    "(Scale (0.5, 0.5, 0.5) UnitCube)))";
  Mesh *m;
  MeshReport rep;
  char buf[400];
  Scene *s = compile_mesh("figure12 obj5 at 0.01 (the groove)", obj, 0.01, &m, &rep);
  if (!s) return;
  long eu;
  int ok = closed_oriented(m, &eu);
  snprintf(buf, sizeof buf, "obj5 at 0.01: every part proven within the "
           "tolerance (%ld cells not) by a groove round (%d), kept with the "
           "first mesh's topology; closed and oriented, Euler %ld (2)",
           rep.cover_unproven, rep.cover_wide, eu);
  CHECK(buf, rep.cover_unproven == 0 && rep.cover_wide == 2 && !rep.cover_topo &&
                 !rep.cover_kept && ok && eu == 2 && rep.components == 1);
  double o[44][3], d[44][3];
  for (int i = 0, l = 0; i < 11; i++)
    for (int k = 0; k < 4; k++, l++) {
      /* down through the groove along the box's edge x = 0.25 .. 0.32
         (z = 0.4 .. 0.6) and, turned, along z = 0.25 .. 0.32 */
      double u = 0.29 + 0.0029 * i, w = k & 1 ? 0.6 : 0.4;
      o[l][0] = k < 2 ? u : w, o[l][1] = 1.05, o[l][2] = k < 2 ? w : u;
      d[l][0] = 0, d[l][1] = -0.1, d[l][2] = 0;
    }
  int hit;
  double worst = lines_far(s, m, (const double (*)[3])o, (const double (*)[3])d,
                           44, 1, &hit);
  snprintf(buf, sizeof buf, "obj5 at 0.01: the groove's surface within 0.01 of "
           "the mesh (%d of 44 lines cross it; worst %.3g)", hit, worst);
  CHECK(buf, hit == 44 && worst >= 0 && worst <= 0.01);
  mesh_free(m);
  scene_free(s);
}

/* A floor under a Bounds box whose low face lies in the floor's plane
   (qcs -o part.stl --bounds X0,0,Z0,... on a scene with a floor): the
   floor's solid y < 0 has no point in the box, and is taken out of every
   cell's class (clip_forced). Before, every cell on that face was
   undecided and the surface-to-mesh proof failed along all of it. The
   rounded cube standing on the floor is then all there is: its surface,
   by the exact ray spans of 60 lines across it at heights from 0.001 up
   (through its rounded side edges), within the tolerance of the mesh by brute
   force. */
static void bounds_floor(void) {
  const char *obj = "Union (Rounded 0.1 UnitCube) (Halfspace ((0, 1, 0), 0))";
  char buf[600], err[400];
  Scene *s = compile(obj);
  CHECK("bounds on a floor: compiled", s != NULL);
  if (!s) return;
  MeshSettings ms = {0};
  ms.tol = 0.02;
  ms.has_bounds = 1;
  double lo[3] = {-0.5, 0, -0.5}, hi[3] = {1.5, 1.5, 1.5};
  memcpy(ms.lo, lo, sizeof lo);
  memcpy(ms.hi, hi, sizeof hi);
  Mesh *m;
  MeshReport rep;
  int bad, rc = mesh_scene(s, s->root, &ms, &m, &rep, &bad, err, sizeof err);
  snprintf(buf, sizeof buf, "bounds on a floor: meshed (%s)", rc ? err : "ok");
  CHECK(buf, rc == 0);
  if (rc) {
    scene_free(s);
    return;
  }
  long eu;
  int ok = closed_oriented(m, &eu);
  snprintf(buf, sizeof buf, "bounds on a floor: every part proven within the "
           "tolerance (%ld cells not); closed and oriented, Euler %ld (2), %ld "
           "components (1)", rep.cover_unproven, eu, rep.components);
  CHECK(buf, rep.cover_unproven == 0 && ok && eu == 2 && rep.components == 1);
  static const double ys[] = {0.001, 0.003, 0.01, 0.03, 0.1, 0.5};
  double o[60][3], d[60][3];
  for (int i = 0, l = 0; i < 6; i++)
    for (int k = 0; k < 10; k++, l++) {
      /* away from the edges' rounding (0.1 wide): every line crosses;
         along x, and along z every other one */
      double z = 0.15 + 0.07 * k;
      o[l][0] = k & 1 ? z : -0.4, o[l][1] = ys[i], o[l][2] = k & 1 ? -0.4 : z;
      d[l][0] = k & 1 ? 0 : 1, d[l][1] = 0, d[l][2] = k & 1 ? 1 : 0;
    }
  int hit;
  double worst = lines_far(s, m, (const double (*)[3])o, (const double (*)[3])d,
                           60, 1.8, &hit);
  snprintf(buf, sizeof buf, "bounds on a floor: the cube's surface within 0.02 "
           "of the mesh (%d of 60 lines cross it; worst %.3g)", hit, worst);
  CHECK(buf, hit == 60 && worst >= 0 && worst <= 0.02);
  mesh_free(m);
  scene_free(s);
  /* A sharp cube standing on the floor, the box's low face in the
     floor's plane: no solid lies below that face (solid_misses: the
     cube's box, padded for rounding, reaches 2e-9 below it), so it
     clips nothing and the cube is one sharp cell, 12 triangles, as
     without the floor; before, the clip there kept every cell on the
     face at the finest level (13794 triangles). */
  s = compile("Union UnitCube (Halfspace ((0, 1, 0), 0))");
  CHECK("bounds on a floor, sharp: compiled", s != NULL);
  if (!s) return;
  rc = mesh_scene(s, s->root, &ms, &m, &rep, &bad, err, sizeof err);
  snprintf(buf, sizeof buf, "bounds on a floor, sharp: meshed (%s)", rc ? err : "ok");
  CHECK(buf, rc == 0);
  if (!rc) {
    ok = closed_oriented(m, &eu);
    snprintf(buf, sizeof buf, "bounds on a floor, sharp: the cube alone, %zu "
             "triangles (12), Euler %ld (2), %ld cells not proven",
             m->nt, eu, rep.cover_unproven);
    CHECK(buf, m->nt == 12 && ok && eu == 2 && rep.cover_unproven == 0);
    mesh_free(m);
  }
  /* The same with a slab of the floor, the box from y = -0.2: the box's
     sides and bottom cut the floor, and a full cell cut by one face is
     a plane cell (walk's clip_plane), not split to the finest level:
     15134 triangles, 71924 before. The volume against the exact 1.8
     (the cube and the 2 x 0.2 x 2 slab). */
  ms.lo[1] = -0.2;
  rc = mesh_scene(s, s->root, &ms, &m, &rep, &bad, err, sizeof err);
  snprintf(buf, sizeof buf, "bounds on a floor's slab: meshed (%s)", rc ? err : "ok");
  CHECK(buf, rc == 0);
  if (!rc) {
    ok = closed_oriented(m, &eu);
    double v = volume(m);
    snprintf(buf, sizeof buf, "bounds on a floor's slab: one part, Euler %ld "
             "(2), %ld cells not proven, %zu triangles (< 20000), %ld plane "
             "cells, volume %.6f (1.8)", eu, rep.cover_unproven, m->nt,
             rep.planar, v);
    CHECK(buf, ok && eu == 2 && rep.components == 1 && rep.cover_unproven == 0 &&
                   m->nt < 20000 && fabs(v - 1.8) <= 0.002);
    mesh_free(m);
  }
  scene_free(s);
}

/* The kit's round parts (n-gon prisms): a rounded plate with a 50-sided
   hole (at its rim some 36 of the hole's faces are live in a cell, more
   than the gradient bound keeps: the rest as a remainder, where before
   no bound was found and the rim split to the octree's limit, "thinner
   than the finest cell"; a rounded cone's apex, all 50), and prisms of more than 64 planes, whose box
   the renderer found by intersecting two unbounded halves (no box: the
   mesher refused them as unbounded). The prism's box against its
   vertices, its volume against the n-gon's area, n/2 sin(2 pi/n) r^2 h,
   in long double. */
/* Each split cell's rounded tapes and bound solids pruned for its
   children (prune_cell, csg_prune_box) leave every proof as it was: the
   same cells, the same triangles, the same vertices to the bit, as with
   the pruning off (QCS_MESH_NOPRUNE). */
static void pruned_same(void) {
  static const struct { const char *name, *src; double tol; } objs[] = {
    {"a rounded plate with a 50-sided hole", "Rounded 0.04 (Difference (Box (0, 0, 0) "
     "(1, 0.18, 1)) (Shift (0.5, -0.5, 0.5) (Cylinder 0.1 1)))", 0.02},
    {"a rounded gear-like disc", "Rounded 0.025 (Difference (CylinderWith [Sides 72] "
     "1.18 0.3) (foldTree DensityUnion (Ring 12 0.7 (Shift (0, -0.5, 0) "
     "(Cylinder 0.12 1.5)))))", 0.06},
    {"a rounded box flush on a rounded cube (figure12 obj5)", "Union (Rounded 0.1 "
     "UnitCube) (Rounded 0.1 (Shift (0.25, 1, 0.25) (Scale (0.5, 0.5, 0.5) UnitCube)))",
     0.01},
    {"a rounded cube minus a sharp one, and soft keys", "Union (SetDifference (Rounded "
     "0.15 UnitCube) (Shift (0.5, 0.5, 0.5) UnitCube)) (SoftObject 0.5 [Key (1.2, 0.5, "
     "0.5) 0.5 1])", 0.02},
  };
  for (size_t k = 0; k < sizeof objs / sizeof *objs; k++) {
    Mesh *a = NULL, *b = NULL;
    MeshReport ra, rb;
    char buf[400];
    Scene *s = compile_mesh(objs[k].name, objs[k].src, objs[k].tol, &a, &ra);
    if (!s) continue;
    scene_free(s);
    setenv("QCS_MESH_NOPRUNE", "1", 1);
    snprintf(buf, sizeof buf, "%s, not pruned", objs[k].name);
    s = compile_mesh(buf, objs[k].src, objs[k].tol, &b, &rb);
    unsetenv("QCS_MESH_NOPRUNE");
    if (s) {
      snprintf(buf, sizeof buf, "pruned tapes: %s: the same %ld cells, %zu triangles "
               "and vertices to the bit as unpruned", objs[k].name, ra.cells, a->nt);
      CHECK(buf, ra.cells == rb.cells && a->nt == b->nt && a->nv == b->nv &&
                     !memcmp(a->v, b->v, 3 * a->nv * sizeof *a->v) &&
                     !memcmp(a->t, b->t, 3 * a->nt * sizeof *a->t));
      printf("# %s: %.2f s pruned, %.2f s not\n", objs[k].name, ra.seconds, rb.seconds);
      scene_free(s);
      mesh_free(b);
    }
    mesh_free(a);
  }
}

/* A dome cut flat by a halfspace where it rests on a rounded table top
   (examples/table.qcs): at the dome's rim the top's plane and the cut's
   are one plane with their insides apart, T + (S . H) with H = not T, and
   the object is T + S there (complement_pairs): one sheet, proven. The
   top's tape holds the legs' and the hole's facets, whose infinite
   planes pass through the rim's cells; folded over each cell (node_plane)
   they are constants, and the top is one plane there. Before: 484 cells
   with two surfaces not proven, 392 not proven within the tolerance. */
static void flush_dome(void) {
  Mesh *m;
  MeshReport rep;
  char buf[400];
  Scene *s = compile_mesh("a dome cut flat, resting on a rounded table",
      "Union (Rounded 0.03 (Sum (Difference (Box (0, 0.9, 0) (2, 1, 1)) (Shift "
      "(1.35, 0.5, 0.5) (Cylinder 0.25 1))) (SumAll (Grid (2, 1, 2) (1.7, 0, 0.7) "
      "(Shift (0.15, 0, 0.15) (Cylinder 0.06 0.9)))))) (Intersection (Shift (0.6, "
      "1.0, 0.5) (Sphere 0.2)) (Halfspace ((0, -1, 0), -1.0)))", 0.0212, &m, &rep);
  if (!s) return;
  snprintf(buf, sizeof buf, "a dome on a table: no cells with two surfaces not "
           "proven one sheet (%ld), every part proven within the tolerance (%ld "
           "cells not)", rep.two, rep.cover_unproven);
  CHECK(buf, rep.two == 0 && rep.cover_unproven == 0);
  snprintf(buf, sizeof buf, "a dome on a table: one component of genus 1 (%ld, "
           "Euler %ld)", rep.components, rep.euler);
  CHECK(buf, rep.components == 1 && rep.euler == 0);
  mesh_free(m);
  scene_free(s);
}

/* A prism of many sides meshed exactly at its rims: near a rim the
   infinite planes of some 17 of a 300-sided prism's sides cross each
   finest cell, more than a sharp cell takes, though two or three of them
   bound the solid there; cell_redundant leaves out those whose facet
   does not reach the cell (the box cut by the others lies inside them).
   Every triangle then lies in one face: on a cap, or its three vertices
   on one chord of the polygon (collinear across y, long double); the
   volume is the polygon's area times the height to rounding; and the
   faces are triangulated as polygons, 4 n - 4 triangles. Before:
   13,350 triangles for 200 sides, the rims cut by marching cells; then
   2,930 with sharp cells of at most 8 planes. */
static void many_sides_exact(void) {
  const long double pi = 3.141592653589793238462643383279503L;
  static const int sides[] = {200, 300};
  for (size_t k = 0; k < sizeof sides / sizeof *sides; k++) {
    int n = sides[k];
    char src[100], name[100], buf[300];
    snprintf(src, sizeof src, "CylinderWith [Sides %d] 1 0.3", n);
    snprintf(name, sizeof name, "a sharp %d-sided prism, its rims exact", n);
    Mesh *m;
    MeshReport rep;
    Scene *s = compile_mesh(name, src, 0.02, &m, &rep);
    if (!s) continue;
    long off = 0;
    for (size_t t = 0; t < m->nt; t++) {
      const double *p[3];
      for (int i = 0; i < 3; i++) p[i] = m->v + 3 * m->t[3 * t + i];
      int cap = 1;
      for (int c = 0; c < 2; c++) {
        int on = 1;
        for (int i = 0; i < 3; i++) on &= fabsl((long double)p[i][1] - 0.3L * c) <= 1e-12L;
        if (on) cap = 0;
      }
      if (!cap) continue;
      /* a side: the three (x, z) on one line */
      long double ux = (long double)p[1][0] - p[0][0], uz = (long double)p[1][2] - p[0][2];
      long double vx = (long double)p[2][0] - p[0][0], vz = (long double)p[2][2] - p[0][2];
      long double lu = sqrtl(ux * ux + uz * uz), lv = sqrtl(vx * vx + vz * vz);
      long double cr = ux * vz - uz * vx;
      off += fabsl(cr) > 1e-10L * (lu > lv ? lu : lv);
    }
    snprintf(buf, sizeof buf, "%s: every triangle in one face (%ld of %zu not; %ld "
             "cells with planes left out)", name, off, m->nt, rep.sharp_pruned);
    CHECK(buf, off == 0 && rep.sharp_pruned > 0);
    /* each cap an n-gon (n - 2 triangles), each side a rectangle (2) */
    snprintf(buf, sizeof buf, "%s: %zu triangles, 2 (n - 2) + 2 n = %d (every face "
             "one polygon)", name, m->nt, 4 * n - 4);
    CHECK(buf, m->nt == (size_t)(4 * n - 4));
    long double area = 0.5L * n * sinl(2 * pi / n);
    snprintf(buf, sizeof buf, "%s: volume %.15g, the polygon's area times 0.3 to "
             "1e-12 (long double)", name, volume(m));
    CHECK(buf, fabsl((long double)volume(m) - area * 0.3L) <= 1e-12L);
    mesh_free(m);
    scene_free(s);
  }
}

static void kit_round_parts(void) {
  char buf[300];
  one("a rounded plate with a 50-sided hole (genus 1)",
      "Rounded 0.04 (Difference (Box (0, 0, 0) (1, 0.18, 1)) "
      "(Shift (0.5, -0.5, 0.5) (Cylinder 0.1 1)))", 0.02, 0, 1, 0, 1);
  one("a rounded 72-sided disc", "Rounded 0.025 (CylinderWith [Sides 72] 1.18 0.3)",
      0.03, 2, 1, 0, 1);
  one("a rounded 50-sided cone (all its faces live at the apex)",
      "Rounded 0.04 (Cone 0.5 1)", 0.02, 2, 1, 0, 1);
  const long double pi = 3.141592653589793238462643383279503L;
  int n = 100;
  long double area = 0.5L * n * sinl(2 * pi / n);
  one("a sharp 100-sided prism", "CylinderWith [Sides 100] 1 0.3", 0.02, 2, 1,
      (double)(area * 0.3L), 1);
  /* a 200-sided prism: some 11 side planes cross each finest cell at
     its rim, more than a sharp cell took (8, now 12); planes that do not meet in
     the cell used to split it as a possible thin part, though the
     prism's sides are nested there (planes_nested): 9223 of 28139 cells
     split below the finest level, 165,842 triangles */
  {
    Mesh *m;
    MeshReport rep;
    n = 200;
    area = 0.5L * n * sinl(2 * pi / n);
    one("a sharp 200-sided prism", "CylinderWith [Sides 200] 1 0.3", 0.02, 2, 1,
        (double)(area * 0.3L), 1);
    Scene *ps = compile_mesh("a sharp 200-sided prism, again",
                             "CylinderWith [Sides 200] 1 0.3", 0.02, &m, &rep);
    if (ps) {
      snprintf(buf, sizeof buf, "a sharp 200-sided prism: %ld of %ld cells split "
               "below the finest level (under 5%%)", rep.thin, rep.leaves);
      CHECK(buf, rep.thin * 20 < rep.leaves);
      mesh_free(m);
      scene_free(ps);
    }
  }
  Scene *s = compile("CylinderWith [Sides 200] 1 0.3");
  CHECK("the 200-sided prism compiles", s != NULL);
  if (!s) return;
  double lo[3], hi[3];
  int ok = render_node_box(s, s->root, lo, hi);
  snprintf(buf, sizeof buf, "a 200-sided prism (202 planes) has a box: [%g %g %g] "
           "- [%g %g %g]", lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]);
  CHECK(buf, ok);
  int holds = ok, snug = ok;
  for (int k = 0; ok && k < n; k++) {
    long double a = 2 * pi * k / n, v[3] = {cosl(a), 0, sinl(a)};
    for (int y = 0; y < 2; y++) {
      v[1] = y ? 0.3L : 0;
      for (int q = 0; q < 3; q++) holds &= lo[q] <= v[q] && v[q] <= hi[q];
    }
  }
  /* 64 of the planes kept: a wider polygon, not much wider */
  for (int q = 0; ok && q < 3; q++)
    snug &= hi[q] - lo[q] <= (q == 1 ? 0.3 : 2) * 1.05;
  CHECK("its box holds the 400 vertices", holds);
  CHECK("its box is within 5% of theirs", snug);
  scene_free(s);
}

/* A box for an unbounded object's error (mesh_suggest_bounds): a sharp
   cube on the floor gets a box from the floor's plane up, and meshed in
   it is the cube alone, 12 triangles of volume 1 (exact); a cube raised
   above the floor, a box that misses the floor; a tilted floor, none. */
static void suggest_bounds(void) {
  static const char *src[2] = {
      "Union UnitCube (Halfspace ((0, 1, 0), 0))",
      "Union (Shift (0, 2, 0) UnitCube) (Halfspace ((0, 1, 0), 0))"};
  for (int c = 0; c < 2; c++) {
    char buf[600], err[400];
    Scene *s = compile(src[c]);
    if (!s) {
      CHECK(src[c], 0);
      continue;
    }
    MeshSettings ms = {0};
    ms.tol = 0.02;
    double y0 = c ? 2 : 0;
    int r = mesh_suggest_bounds(s, s->root, ms.lo, ms.hi);
    snprintf(buf, sizeof buf, "%s: a box [%g %g %g] - [%g %g %g] holding the cube%s",
             src[c], ms.lo[0], ms.lo[1], ms.lo[2], ms.hi[0], ms.hi[1], ms.hi[2],
             c ? " and not the floor" : ", its low y face on the floor's plane");
    CHECK(buf, r && ms.lo[0] < 0 && ms.lo[2] < 0 && ms.hi[0] > 1 && ms.hi[2] > 1 &&
                   ms.hi[1] > y0 + 1 && (c ? ms.lo[1] > 0 && ms.lo[1] < y0
                                           : ms.lo[1] == 0 && r == (1 | 2 << 1)));
    ms.has_bounds = 1;
    Mesh *m;
    MeshReport rep;
    int bad;
    int rc = mesh_scene(s, s->root, &ms, &m, &rep, &bad, err, sizeof err);
    snprintf(buf, sizeof buf, "%s: meshed in that box (%s)", src[c], rc ? err : "ok");
    CHECK(buf, rc == 0);
    if (!rc) {
      long eu;
      snprintf(buf, sizeof buf, "%s: the cube alone, closed, volume %.17g", src[c],
               volume(m));
      CHECK(buf, closed_oriented(m, &eu) && eu == 2 && fabs(volume(m) - 1) < 1e-12);
      mesh_free(m);
    }
    scene_free(s);
  }
  Scene *s = compile("Union UnitCube (Halfspace ((0, 1, 1), 0))");
  double lo[3], hi[3];
  CHECK("a tilted floor: no box suggested", s && !mesh_suggest_bounds(s, s->root, lo, hi));
  if (s) scene_free(s);
}

static void wide_check(const char *name, const MeshReport *rep) {
  char buf[400];
  snprintf(buf, sizeof buf, "%s: every part proven within the tolerance of "
           "the mesh (%ld cells not), the last round splitting the cells "
           "beside two surfaces too", name, rep->cover_unproven);
  CHECK(buf, rep->cover_unproven == 0 && rep->cover_wide && !rep->cover_kept && !rep->cover_topo &&
                 rep->cover <= 0.03);
}

/* Long-run scenes 835 and 851: a box, a rounded box and soft keys, where
   the proof that the surface is within the tolerance of the mesh failed
   in 8 and 1 cells beside cells with two surfaces (which the rounds leave
   alone) and the report said so. When those are all that is left (at
   most 64), one more round splits them too: every part proven, with the
   topology of the mesh before it (both). */
static void cover_wide(void) {
  static const char *objs[] = {
    /* 835 */ "SetDifference (Union (Rounded 0.05944437258005722 (Rotate \"z\" 51.936 (Shift (0.269, 0.396, 0.119) (Scale (0.373, 0.448, 0.501) UnitCube)))) (Rotate \"x\" 24.969 (Shift (-0.396, -0.200, -0.148) (Scale (0.812, 0.783, 0.580) UnitCube)))) (SoftObject 0.5 [Key (0.185, 0.335, 0.423) 0.601 1, Key (0.310, 0.172, 0.359) 0.797 1, Key (-0.146, -0.465, 0.158) 0.872 1, Key (0.463, -0.194, 0.031) 0.764 (-1)])",
    /* 851 */ "SetDifference (Union (Rounded 0.14095049972681922 (Rotate \"x\" 21.972 (Shift (-0.237, -0.095, -0.172) (Scale (0.751, 0.533, 0.285) UnitCube)))) (Rotate \"y\" 68.918 (Shift (-0.444, 0.007, -0.205) (Scale (0.748, 0.692, 0.498) UnitCube)))) (SoftObject 0.5 [Key (0.036, 0.380, 0.410) 0.815 1, Key (0.118, 0.030, 0.444) 0.828 1])"};
  static const int num[] = {835, 851};
  long_run_scenes("cells beside two surfaces", objs, num, 2, wide_check);
}

/* Random scenes of the property test's generator (a run of 240 drawn in
   one stream, as the default run draws its 24, before scenes were drawn
   by seed; their numbers there) that gave up their sharp cells: a vertex of a sharp
   cell's face path on a cell edge had two successors in one plane (the
   faces on both sides of that edge carried paths, of two sharp cells
   facing each other), the second was dropped, a marching neighbour's
   edge across the face was not split along the path and the mesh had a
   hole of one triangle in a cell face, so it was made again without
   sharp cells (each fails so before face_cell in mesh.c). Each now keeps
   them: meshed with sharp cells, closed and oriented by this file's edge
   counting, and free of self-intersections by the exact check. */
static void sharp_kept(void) {
  static const char *objs[] = {
    /* 99 */ "Union (Union (Rounded 0.059116706536565658 (Rotate \"y\" 49.984 (Shift (-0.374, 0.037, 0.134) (Scale (0.516, 0.428, 0.835) UnitCube)))) (Rotate \"y\" 28.123 (Shift (0.118, -0.135, 0.160) (Scale (0.269, 0.411, 0.269) UnitCube)))) (SoftObject 0.5 [Key (0.407, 0.092, -0.474) 0.900 1, Key (-0.316, 0.189, 0.421) 0.776 1, Key (0.091, -0.241, 0.248) 0.861 1, Key (0.259, 0.326, -0.336) 0.867 (-1)])",
    /* 171 */ "SetDifference (Union (Rounded 0.12162031666448116 (Rotate \"z\" 86.658 (Shift (-0.075, 0.127, 0.279) (Scale (0.792, 0.382, 0.568) UnitCube)))) (Rotate \"z\" 17.956 (Shift (-0.418, -0.142, 0.037) (Scale (0.658, 0.407, 0.253) UnitCube)))) (SoftObject 0.5 [Key (-0.455, -0.491, -0.056) 0.644 1, Key (-0.401, -0.129, -0.414) 0.772 1])",
    /* 203 */ "Union (Union (Rounded 0.08472609571053874 (Rotate \"y\" 36.459 (Shift (-0.004, -0.221, 0.345) (Scale (0.284, 0.687, 0.447) UnitCube)))) (Rotate \"y\" 39.106 (Shift (-0.221, -0.192, -0.201) (Scale (0.646, 0.593, 0.639) UnitCube)))) (SoftObject 0.5 [Key (0.363, -0.321, 0.227) 0.820 1, Key (-0.278, 0.059, -0.017) 0.818 1, Key (0.163, -0.212, -0.170) 0.739 (-1)])",
    /* 219 */ "SetDifference (Union (Rounded 0.073488949967598333 (Rotate \"y\" 16.641 (Shift (-0.338, -0.064, 0.162) (Scale (0.786, 0.532, 0.354) UnitCube)))) (Rotate \"z\" 54.568 (Shift (-0.389, 0.118, 0.222) (Scale (0.655, 0.341, 0.847) UnitCube)))) (SoftObject 0.5 [Key (0.396, 0.446, 0.228) 0.655 1, Key (0.208, 0.430, -0.478) 0.705 1, Key (-0.445, 0.426, 0.318) 0.530 (-1)])"};
  static const int num[] = {99, 171, 203, 219};
  sharp_apart_kept();
  cover_wide();
  cover_groove();
  cover_island();
  bounds_floor();
  for (size_t k = 0; k < sizeof objs / sizeof objs[0]; k++) {
    char name[120], buf[300];
    snprintf(name, sizeof name, "long run scene %d (mixed)", num[k]);
    Mesh *m;
    MeshReport rep;
    Scene *s = compile_mesh(name, objs[k], 0.03, &m, &rep);
    if (!s) continue;
    long eu;
    MeshSelfCheck sc;
    snprintf(buf, sizeof buf, "%s: sharp cells kept (%ld), closed and oriented, "
             "no self-intersection", name, rep.sharp);
    CHECK(buf, !rep.sharp_off && rep.sharp > 0 && closed_oriented(m, &eu) &&
                   mesh_self_check(m, &sc) == 0);
    mesh_free(m);
    scene_free(s);
  }
}

/* ---- the property test: random scenes, fixed seed ------------------------ */

/* orient3d, plain doubles: the sign of det(b - a, c - a, d - a). */
static double orient(const double *a, const double *b, const double *c,
                     const double *d) {
  double u[3], v[3], w[3], x[3];
  for (int i = 0; i < 3; i++) u[i] = b[i] - a[i], v[i] = c[i] - a[i], w[i] = d[i] - a[i];
  vec3_cross(u, v, x);
  return vec3_dot(x, w);
}

/* Segment pq crosses the inside of triangle abc strictly (eps: volumes
   this small count as touching, which is not a crossing). */
static int seg_tri(const double *p, const double *q, const double *a,
                   const double *b, const double *c, double eps) {
  double s1 = orient(a, b, c, p), s2 = orient(a, b, c, q);
  if (!((s1 > eps && s2 < -eps) || (s1 < -eps && s2 > eps))) return 0;
  double e1 = orient(p, q, a, b), e2 = orient(p, q, b, c), e3 = orient(p, q, c, a);
  return (e1 > eps && e2 > eps && e3 > eps) || (e1 < -eps && e2 < -eps && e3 < -eps);
}

/* Two triangles intersect (other than along what they share): an edge of
   one not through a shared vertex crosses the other. Coplanar overlaps
   are not seen by this test. */
static int tri_tri(const Mesh *m, size_t i, size_t j, double eps) {
  const int *s = m->t + 3 * i, *t = m->t + 3 * j;
  int shared = 0;
  for (int a = 0; a < 3; a++)
    for (int b = 0; b < 3; b++) shared += s[a] == t[b];
  if (shared >= 2) return 0;
  for (int pass = 0; pass < 2; pass++) {
    const int *x = pass ? t : s, *y = pass ? s : t;
    for (int e = 0; e < 3; e++) {
      int u = x[e], v = x[(e + 1) % 3];
      if (u == y[0] || u == y[1] || u == y[2] || v == y[0] || v == y[1] || v == y[2])
        continue;
      if (seg_tri(m->v + 3 * u, m->v + 3 * v, m->v + 3 * y[0], m->v + 3 * y[1],
                  m->v + 3 * y[2], eps))
        return 1;
    }
  }
  return 0;
}

/* Pairs of intersecting triangles, by a uniform grid over the mesh's box
   (a pair is tested in the first grid cell both boxes share). */
static long self_intersections(const Mesh *m) {
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  for (size_t i = 0; i < 3 * m->nv; i++) {
    if (m->v[i] < lo[i % 3]) lo[i % 3] = m->v[i];
    if (m->v[i] > hi[i % 3]) hi[i % 3] = m->v[i];
  }
  int g = 1;
  while ((size_t)g * (size_t)g * (size_t)g < m->nt / 2 && g < 128) g++;
  double size = fmax(hi[0] - lo[0], fmax(hi[1] - lo[1], hi[2] - lo[2]));
  double cs = size / g * 1.0001, eps = 1e-13 * size * size * size;
  size_t ncell = (size_t)g * (size_t)g * (size_t)g;
  size_t *cnt = calloc(ncell + 1, sizeof *cnt);
  int (*box)[6] = malloc(m->nt * sizeof *box);
  for (size_t i = 0; i < m->nt; i++)
    for (int a = 0; a < 3; a++) {
      double l = 1e300, h = -1e300;
      for (int k = 0; k < 3; k++) {
        double x = m->v[3 * m->t[3 * i + k] + a];
        l = fmin(l, x);
        h = fmax(h, x);
      }
      box[i][a] = (int)((l - lo[a]) / cs);
      box[i][3 + a] = (int)((h - lo[a]) / cs);
      if (box[i][3 + a] >= g) box[i][3 + a] = g - 1;
    }
  for (int pass = 0; pass < 2; pass++) {
    if (pass) {
      for (size_t c = 0, sum = 0; c <= ncell; c++) {
        size_t n = cnt[c];
        cnt[c] = sum;
        sum += n;
      }
    }
    static size_t *items;
    static size_t *fill;
    if (pass == 1) {
      items = malloc((cnt[ncell] + 1) * sizeof *items);
      fill = malloc((ncell + 1) * sizeof *fill);
      memcpy(fill, cnt, (ncell + 1) * sizeof *fill);
    }
    for (size_t i = 0; i < m->nt; i++)
      for (int x = box[i][0]; x <= box[i][3]; x++)
        for (int y = box[i][1]; y <= box[i][4]; y++)
          for (int z = box[i][2]; z <= box[i][5]; z++) {
            size_t c = ((size_t)x * (size_t)g + (size_t)y) * (size_t)g + (size_t)z;
            if (pass) items[fill[c]++] = i;
            else cnt[c]++;
          }
    if (pass == 1) {
      long bad = 0;
      for (size_t c = 0; c < ncell; c++) {
        int cx = (int)(c / ((size_t)g * (size_t)g)), cy = (int)(c / (size_t)g % (size_t)g),
            cz = (int)(c % (size_t)g);
        for (size_t a = cnt[c]; a < fill[c]; a++)
          for (size_t b = a + 1; b < fill[c]; b++) {
            size_t i = items[a], j = items[b];
            int fx = box[i][0] > box[j][0] ? box[i][0] : box[j][0];
            int fy = box[i][1] > box[j][1] ? box[i][1] : box[j][1];
            int fz = box[i][2] > box[j][2] ? box[i][2] : box[j][2];
            if (fx != cx || fy != cy || fz != cz) continue;
            bad += tri_tri(m, i, j, eps);
          }
      }
      free(items);
      free(fill);
      free(cnt);
      free(box);
      return bad;
    }
  }
  return -1;
}

/* The value of a qcs expression (the language's own probes). */
static Value *eval_text(const char *text) {
  Src *src = src_of("<probe>", text);
  ErrFrame f;
  Value *volatile v = NULL;
  if (ERR_TRY(f)) {
    v = force(I, eval(I, parse_expression(I, src), NULL));
    err_pop(&f);
  } else {
    err_pop(&f);
    printf("# probe error: %s\n", err_info()->msg);
  }
  return v;
}

/* Triangle points within tol of the surface, by the Roots probe: a root
   of the object on the segment p -+ tol along the triangle's normal or an
   axis (a root at distance <= tol along any direction proves the
   distance). With rounded (a density tree and its radius), also by the
   Density probe: the density crosses 0.5 on one of those segments (at 9
   points along it). The
   number of points failing both (or either, for rounded). */
static long probe_points(const char *obj, const char *tree, double radius,
                         const Mesh *m, double tol, int n) {
  long bad = 0;
  char buf[4096];
  for (int k = 0; k < n; k++) {
    double p[3], nn[3], l = triangle_point(m, p, nn);
    if (!(l > 0)) continue; /* a sliver: its points are its edges' */
    double dirs[4][3] = {{nn[0] / l, nn[1] / l, nn[2] / l}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    int found = 0, dens = tree == NULL;
    for (int d = 0; d < 4 && !(found && dens); d++) {
      double o[3], e[3];
      for (int j = 0; j < 3; j++) o[j] = p[j] - tol * dirs[d][j], e[j] = 2 * tol * dirs[d][j];
      if (!found) {
        snprintf(buf, sizeof buf, "Roots (%s) (%.17g, %.17g, %.17g) (%.17g, %.17g, %.17g)",
                 obj, o[0], o[1], o[2], e[0], e[1], e[2]);
        for (Value *r = eval_text(buf); r && r->kind == V_CONS; r = force(I, r->u.cons.tail)) {
          Value *t = force(I, r->u.cons.head);
          if (t->kind == V_NUM && t->u.num <= 1) found = 1;
        }
      }
      if (!dens) {
        /* a change of side of 0.5 along the segment, sampled at 9
           points: the ends alone miss it where the solid is thinner
           than the segment (a wedge where two boxes' faces meet at a
           small angle: both ends outside) */
        double q[9];
        for (int k2 = 0; k2 < 9 && !dens; k2++) {
          double f = k2 / 8.0;
          snprintf(buf, sizeof buf, "Density %.17g (%.17g, %.17g, %.17g) (%s)", radius,
                   o[0] + f * e[0], o[1] + f * e[1], o[2] + f * e[2], tree);
          Value *r = eval_text(buf);
          q[k2] = r && r->kind == V_NUM ? r->u.num : NAN;
          if (k2 > 0 && (q[k2 - 1] - 0.5) * (q[k2] - 0.5) <= 0) dens = 1;
        }
      }
    }
    if (!found || !dens) bad++;
  }
  return bad;
}

static void box_text(char *out, size_t n) {
  double s[3], c[3];
  for (int i = 0; i < 3; i++) s[i] = 0.25 + 0.6 * urand(), c[i] = 0.9 * urand() - 0.45;
  const char *ax[3] = {"x", "y", "z"};
  snprintf(out, n, "Rotate \"%s\" %.3f (Shift (%.3f, %.3f, %.3f) (Scale (%.3f, %.3f, %.3f) UnitCube))",
           ax[(int)(urand() * 3)], 90 * urand(), c[0], c[1], c[2], s[0], s[1], s[2]);
}

static void soft_text(char *out, size_t n) {
  char keys[600] = "";
  int nk = 2 + (int)(urand() * 3);
  for (int k = 0; k < nk; k++) {
    char key[120];
    snprintf(key, sizeof key, "%sKey (%.3f, %.3f, %.3f) %.3f %s", k ? ", " : "",
             urand() - 0.5, urand() - 0.5, urand() - 0.5, 0.5 + 0.4 * urand(),
             k == nk - 1 && nk > 2 ? "(-1)" : "1");
    strcat(keys, key);
  }
  snprintf(out, n, "SoftObject 0.5 [%s]", keys);
}

/* One random scene (kind 0 rounded, 1 sharp, 2 soft, 3 mixed) drawn from
   urand: obj the object, tree its density tree (rounded only), radius. */
static void random_scene(int kind, char *obj, size_t nobj, char *tree, size_t ntree,
                         double *radius) {
  static const char *ops[3] = {"Union", "Intersection", "SetDifference"};
  static const char *dops[3] = {"Sum", "Product", "Difference"};
  char a[400], b[400];
  *radius = 0.05 + 0.1 * urand();
  int op = (int)(urand() * 3);
  tree[0] = 0;
  box_text(a, sizeof a);
  box_text(b, sizeof b);
  if (op == 1) snprintf(b, sizeof b, "Scale (1.6, 1.6, 1.6) UnitCube"); /* overlap */
  switch (kind) {
  case 0: /* rounded */
    snprintf(tree, ntree, "%s (%s) (%s)", dops[op], a, b);
    snprintf(obj, nobj, "Rounded %.17g (%s)", *radius, tree);
    break;
  case 1: /* sharp */
    snprintf(obj, nobj, "%s (%s) (%s)", ops[op], a, b);
    break;
  case 2: /* soft */
    soft_text(obj, nobj);
    break;
  default: { /* mixed: rounded, sharp and soft together */
    char so[700];
    soft_text(so, sizeof so);
    snprintf(obj, nobj, "%s (Union (Rounded %.17g (%s)) (%s)) (%s)",
             ops[op == 1 ? 0 : op], *radius, a, b, so);
    break;
  }
  }
}

/* The property test's generator on its own seed: scene seed s draws from
   urand started at a state made from s (xorshift needs a nonzero one), so
   a scene found by a long run is repeated by its number alone. */
static void seed_scene(unsigned long long s) {
  rng = (s + 1) * 0x9E3779B97F4A7C15ull;
  for (int i = 0; i < 4; i++) urand();
}

typedef struct {
  int total, good, gaveup;
  int over_cert, over_meas; /* scenes whose certified / measured error
                               exceeds the tolerance */
  int uncovered;            /* scenes where the surface was not proven
                               within the tolerance of the mesh */
  int topo;                 /* scenes whose kept round changed the first
                               mesh's topology (MeshReport.cover_topo) */
} PropStats;

/* Mesh one random scene at tolerance tol and check it: closed, oriented,
   free of self-intersections, its triangle points within tol by Roots (and
   Density), surface points within tol of the mesh, the certified and the
   measured error within tol. full: all checks (else only the mesh, its
   closure and the two errors, counted, for long runs). */
static void property_scene(const char *name, int kind, const char *obj,
                           const char *tree, double radius, double tol, int full,
                           int strict, PropStats *st) {
  char buf[700], err[300];
  Scene *s = compile(obj);
  if (!s) {
    printf("# %s: %s\n", name, obj);
    CHECK(name, 0);
    return;
  }
  MeshSettings ms = {0};
  ms.tol = tol;
  Mesh *m;
  MeshReport rep;
  int bad;
  int rc = mesh_scene(s, s->root, &ms, &m, &rep, &bad, err, sizeof err);
  if (rc == MESH_EEMPTY) { /* an intersection of boxes may be empty */
    scene_free(s);
    return;
  }
  st->total++;
  snprintf(buf, sizeof buf, "%s: meshed (%s)", name, rc ? err : "ok");
  CHECK(buf, rc == 0);
  if (rc) {
    printf("# %s\n", obj);
    scene_free(s);
    return;
  }
  long eu, si = 0, far = 0;
  int closed = closed_oriented(m, &eu);
  double w = 0;
  snprintf(buf, sizeof buf, "%s: closed and oriented", name);
  CHECK(buf, closed);
  if (full) {
    si = self_intersections(m);
    MeshSelfCheck sc;
    int sr = mesh_self_check(m, &sc);
    far = probe_points(obj, kind == 0 ? tree : NULL, radius, m, tol, 60);
    snprintf(buf, sizeof buf, "%s: no self-intersections (%ld pairs)", name, si);
    CHECK(buf, si == 0);
    snprintf(buf, sizeof buf, "%s: the exact check finds no two triangles meeting "
             "(%ld pairs tested, as mesh_scene reported: %ld)", name, sc.pairs, rep.pairs);
    CHECK(buf, sr == 0 && sc.pairs > 0 && sc.pairs == rep.pairs);
    snprintf(buf, sizeof buf, "%s: 60 triangle points within tol by Roots%s (%ld far)",
             name, kind == 0 ? " and Density" : "", far);
    CHECK(buf, far == 0);
  }
  snprintf(buf, sizeof buf, "%s: certified %.4g <= tol", name, rep.certified);
  CHECK(buf, rep.certified <= tol);
  snprintf(buf, sizeof buf, "%s: measured %.4g <= tol", name, rep.measured);
  CHECK(buf, rep.measured <= tol);
  if (strict || !rep.cover_unproven) {
    snprintf(buf, sizeof buf, "%s: every part of the surface proven within tol of "
             "the mesh (%ld cells not)", name, rep.cover_unproven);
    CHECK(buf, rep.cover_unproven == 0);
  } else if (full) {
    /* where the proof gives up, the surface is far from the mesh (the
       mesh lost a part there), or no surface is near at all (three
       surfaces hidden inside the solid crossing near a point, which the
       classes over a box do not separate: seed 435) */
    double far2 = cover_place(s, m, &rep, tol);
    snprintf(buf, sizeof buf, "%s: %ld cells not proven within tol of the mesh; "
             "near the first the surface is %.4g from it (> 0.8 tol; -1: no surface "
             "within tol)", name, rep.cover_unproven, far2);
    CHECK(buf, far2 > 0.8 * tol || far2 < 0);
  }
  st->over_cert += rep.certified > tol;
  st->over_meas += rep.measured > tol;
  st->uncovered += rep.cover_unproven > 0;
  st->topo += rep.cover_topo;
  if (full) {
    w = surface_to_mesh(s, m, 10);
    snprintf(buf, sizeof buf, "%s: surface points from random rays within tol of the mesh (worst %.3g)", name, w);
    CHECK(buf, w <= tol);
  }
  int ok = closed && si == 0 && far == 0 && w <= tol && rep.certified <= tol &&
           rep.measured <= tol && (!strict || rep.cover_unproven == 0);
  st->good += ok;
  if (!ok || rep.cover_unproven) printf("# %s\n", obj);
  printf("# %s: %zu triangles (%ld plane, %ld smooth, %ld sharp cells%s; %ld "
         "with two surfaces not proven one sheet; certified %.5g, measured %.5g; "
         "%ld components, Euler %ld",
         name, rep.triangles, rep.planar, rep.smooth, rep.sharp,
         rep.sharp_off ? ", sharp given up" : "", rep.two, rep.certified, rep.measured,
         rep.components, rep.euler);
  if (rep.cover_topo)
    printf(", first %ld and %ld", rep.first_components, rep.first_euler);
  printf(")\n");
  if (rep.sharp_off) printf("# sharp cells given up in: %s\n", obj);
  st->gaveup += rep.sharp_off;
  mesh_free(m);
  scene_free(s);
}

static const char *kind_name(int kind) {
  return kind == 0 ? "rounded" : kind == 1 ? "sharp" : kind == 2 ? "soft" : "mixed";
}

/* Random rounded, sharp, soft and mixed scenes: every mesh closed,
   oriented, free of self-intersections and within the tolerance (Roots
   and Density probes), the certified bound within it too. */
static void property(void) {
  PropStats st = {0};
  for (int k = 0; k < 24; k++) {
    char obj[2400], tree[1000], name[80];
    double radius;
    int kind = k % 4;
    random_scene(kind, obj, sizeof obj, tree, sizeof tree, &radius);
    snprintf(name, sizeof name, "random scene %d (%s)", k, kind_name(kind));
    property_scene(name, kind, obj, tree, radius, 0.03, 1, 0, &st);
  }
  printf("# property test: %d of %d random scenes closed, oriented, "
         "self-intersection-free, within tolerance\n", st.good, st.total);
  CHECK("property test: most random scenes were not empty", st.total >= 18);
  /* scene 7 (mixed) gave them up: a sharp box's edge 0.003 inside a
     sharp cell, its wedge crossing the marching neighbour's face between
     corners (see planes_face in mesh.c) */
  CHECK("property test: no random scene gives up its sharp cells", st.gaveup == 0);
}

/* The generator on seeds first .. first + n - 1 (seed_scene), the scene's
   kind seed % 4; full: every check of property(). Returns the counts. */
static PropStats property_seeds(const unsigned long long *seeds, int n, int full) {
  PropStats st = {0};
  unsigned long long keep = rng;
  for (int i = 0; i < n; i++) {
    char obj[2400], tree[1000], name[80];
    double radius;
    int kind = (int)(seeds[i] % 4);
    seed_scene(seeds[i]);
    random_scene(kind, obj, sizeof obj, tree, sizeof tree, &radius);
    snprintf(name, sizeof name, "random seed %llu (%s)", seeds[i], kind_name(kind));
    property_scene(name, kind, obj, tree, radius, 0.03, full, 0, &st);
  }
  rng = keep;
  return st;
}

/* The seeds among 0 .. 999 whose scenes broke the error promise before
   (all mixed): 231 and 887 certified 0.03024 and 0.03018 at tolerance
   0.03 (a smooth cell's triangles certified without the chord bound their
   cell was accepted with), 19 measured 0.032 to 0.06 or inf (the
   distance along the normal alone: a triangle steep to the surface, a
   sliver), and the last 10 (with 363, 435 and 931) kept cells where the
   surface was not proven within the tolerance of the mesh (a round that
   proved them changed the topology and was not kept; 575 lost an island
   0.18 from the mesh); every check of property() on them, the certified
   and measured error within the tolerance among them, and every part of
   the surface proven within it. */
static void property_regressions(void) {
  static const unsigned long long seeds[] = {59,  75,  207, 231, 255, 287, 355,
                                             363, 435, 439, 515, 547, 719, 823,
                                             835, 851, 875, 887, 907, 931, 935,
                                             999, 39,  227, 235, 307, 335, 575,
                                             623, 683, 731, 799};
  int n = (int)(sizeof seeds / sizeof *seeds);
  PropStats st = property_seeds(seeds, n, 1);
  CHECK("regression seeds: all 32 meshed", st.total == n);
  CHECK("regression seeds: none certified or measured above the tolerance",
        st.over_cert == 0 && st.over_meas == 0);
  CHECK("regression seeds: none gives up every sharp cell (255 and 875 did)",
        st.gaveup == 0);
  char buf[200];
  snprintf(buf, sizeof buf, "regression seeds: every part of the surface proven "
           "within the tolerance of the mesh in all (%d not)", st.uncovered);
  CHECK(buf, st.uncovered == 0);
}

/* f(q) = the union's density minus 0.5 at q by the Density probe: the
   largest of the parts' densities (radius r each). */
static long double union_density(const char *const *trees, int nt, double r,
                                 const long double q[3]) {
  char buf[1200];
  long double f = -1;
  for (int i = 0; i < nt; i++) {
    snprintf(buf, sizeof buf, "Density %.17g (%.21Lg, %.21Lg, %.21Lg) (%s)", r, q[0],
             q[1], q[2], trees[i]);
    Value *v = eval_text(buf);
    long double d = v && v->kind == V_NUM ? (long double)v->u.num : NAN;
    if (d > f || d != d) f = d;
  }
  return f - 0.5L;
}

/* The distance from triangle points of m to the surface of a union of
   rounded trees, independently of the mesher: along the normal and the
   three axes, the density sampled at 16 steps on p -+ reach, the sign
   change nearest p bisected in long double (48 halvings), the least
   distance of the four directions (each is at least the true distance).
   The largest over n points; INFINITY if a point found none. */
static double density_distance(const Mesh *m, const char *const *trees, int nt,
                               double r, double reach, int n) {
  double worst = 0;
  for (int k = 0; k < n; k++) {
    double p[3], nn[3], l = triangle_point(m, p, nn);
    if (!(l > 0)) continue;
    double dirs[4][3] = {{nn[0] / l, nn[1] / l, nn[2] / l}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    long double best = INFINITY;
    for (int d = 0; d < 4; d++)
      for (int sg = -1; sg <= 1; sg += 2) {
        long double t0 = 0, q[3], f0;
        for (int j = 0; j < 3; j++) q[j] = p[j];
        f0 = union_density(trees, nt, r, q);
        for (int st = 1; st <= 16 && t0 < best; st++) {
          long double t1 = reach * st / 16.0L, f1;
          for (int j = 0; j < 3; j++) q[j] = p[j] + sg * t1 * dirs[d][j];
          f1 = union_density(trees, nt, r, q);
          if ((f0 <= 0) != (f1 <= 0)) {
            long double a = t0, b = t1, fa = f0;
            for (int it = 0; it < 48; it++) {
              long double c = 0.5L * (a + b), fc;
              for (int j = 0; j < 3; j++) q[j] = p[j] + sg * c * dirs[d][j];
              fc = union_density(trees, nt, r, q);
              if ((fa <= 0) == (fc <= 0)) a = c, fa = fc;
              else b = c;
            }
            if (b < best) best = b;
            break;
          }
          t0 = t1;
          f0 = f1;
        }
      }
    if ((double)best > worst) worst = (double)best;
  }
  return worst;
}

/* figure12's obj5 at tolerance 0.003: the report's measured error was
   0.00413, above the tolerance, from a triangle closing the groove under
   the rounded box's edge (normal (0, 0.22, -0.97), 0.00093 above the
   cube's top face y = 1 in the groove, 0.0041 from it along the normal);
   the mesh is right, the distance along the normal alone was not the
   distance. The measured error within the tolerance, and the distance
   found independently (density_distance, 150 points) within it too. */
static void obj5_measured(void) {
  const char *trees[2] = {"UnitCube", "Shift (0.25, 1, 0.25) (Scale (0.5, 0.5, 0.5) UnitCube)"};
  Scene *s = compile("Union (Rounded 0.07 UnitCube) (Rounded 0.07 (Shift (0.25, 1, 0.25) "
                     "(Scale (0.5, 0.5, 0.5) UnitCube)))");
  CHECK("obj5 at 0.003: compiles", s != NULL);
  if (!s) return;
  MeshSettings ms = {0};
  ms.tol = 0.003;
  Mesh *m;
  MeshReport rep;
  char err[300], buf[200];
  int bad;
  int rc = mesh_scene(s, s->root, &ms, &m, &rep, &bad, err, sizeof err);
  CHECK("obj5 at 0.003: meshed", rc == 0);
  if (rc) {
    scene_free(s);
    return;
  }
  snprintf(buf, sizeof buf, "obj5 at 0.003: certified %.4g <= tol", rep.certified);
  CHECK(buf, rep.certified <= ms.tol);
  snprintf(buf, sizeof buf, "obj5 at 0.003: measured %.4g <= tol", rep.measured);
  CHECK(buf, rep.measured <= ms.tol);
  unsigned long long keep = rng;
  seed_scene(1000);
  double d = density_distance(m, trees, 2, 0.07, 2 * ms.tol, 150);
  rng = keep;
  snprintf(buf, sizeof buf, "obj5 at 0.003: 150 triangle points within tol by "
           "Density and long double bisection (worst %.3g)", d);
  CHECK(buf, d <= ms.tol);
  mesh_free(m);
  scene_free(s);
}

/* QCS_MESH_SEEDS=n: the generator on seeds 0 .. n - 1 as well (closure,
   the certified and the measured error checked), and the counts of
   scenes over the tolerance; QCS_MESH_SEED_LIST=a,b,...: those seeds with
   the regression seeds' full checks. Not run by default. */
static void property_long(void) {
  const char *env = getenv("QCS_MESH_SEEDS");
  const char *list = getenv("QCS_MESH_SEED_LIST");
  int n = env ? atoi(env) : 0, full = 0;
  if (list && *list) {
    /* QCS_MESH_SEED_LIST=575,227: those seeds with the full checks */
    n = 1;
    for (const char *c = list; *c; c++) n += *c == ',';
    full = 1;
  }
  if (n <= 0) return;
  unsigned long long *seeds = malloc((size_t)n * sizeof *seeds);
  for (int i = 0; i < n; i++) seeds[i] = (unsigned long long)i;
  if (full) {
    char *e;
    const char *c = list;
    for (int i = 0; i < n; i++, c = *e ? e + 1 : e) seeds[i] = strtoull(c, &e, 10);
  }
  PropStats st = property_seeds(seeds, n, full);
  printf("# long property run: %d seeds, %d meshed, %d certified > tol, "
         "%d measured > tol, %d sharp given up, %d with cells not proven within "
         "tol of the mesh, %d with the topology changed by a round that proved "
         "every cell\n", n,
         st.total, st.over_cert, st.over_meas, st.gaveup, st.uncovered, st.topo);
  free(seeds);
}

/* Vertices compared as bits (the merge keeps the vertices it keeps). */
static int cmp_vertex(const void *x, const void *y) { return memcmp(x, y, 3 * sizeof(double)); }

/* The largest distance from n random points of the triangles of a (kept
   a thousandth of a side off their edges) to the triangles of b: for each
   triangle of b whose projection along its normal's largest axis holds
   the point's (exact signs, mesh_orient2d, itself checked against GMP
   above), the point's distance from its plane along that axis (at least
   the true distance); the least of them, INFINITY if none holds it. No
   closest-point formula: those lose the sign of a sliver's barycentric
   coordinates. */
static double mesh_gap(const Mesh *a, const Mesh *b, int n) {
  double worst = 0;
  for (int k = 0; k < n; k++) {
    size_t i = (size_t)(urand() * (double)a->nt);
    const double *x = a->v + 3 * a->t[3 * i], *y = a->v + 3 * a->t[3 * i + 1],
                 *z = a->v + 3 * a->t[3 * i + 2];
    double u = urand(), v = urand(), p[3];
    if (u + v > 1) u = 1 - u, v = 1 - v;
    u = 1e-3 + u * (1 - 3e-3);
    v = 1e-3 + v * (1 - 3e-3);
    for (int c = 0; c < 3; c++) p[c] = x[c] + u * (y[c] - x[c]) + v * (z[c] - x[c]);
    double best = INFINITY;
    for (size_t j = 0; j < b->nt; j++) {
      const double *t0 = b->v + 3 * b->t[3 * j], *t1 = b->v + 3 * b->t[3 * j + 1],
                   *t2 = b->v + 3 * b->t[3 * j + 2];
      int out = 0;
      for (int c = 0; c < 3 && !out; c++)
        out = p[c] < fmin(t0[c], fmin(t1[c], t2[c])) - 1e-9 ||
              p[c] > fmax(t0[c], fmax(t1[c], t2[c])) + 1e-9;
      if (out) continue;
      double e1[3], e2[3], nn[3];
      for (int c = 0; c < 3; c++) e1[c] = t1[c] - t0[c], e2[c] = t2[c] - t0[c];
      vec3_cross(e1, e2, nn);
      int ax = fabs(nn[0]) >= fabs(nn[1]) && fabs(nn[0]) >= fabs(nn[2]) ? 0
             : fabs(nn[1]) >= fabs(nn[2]) ? 1 : 2;
      if (nn[ax] == 0) continue;
      int i1 = (ax + 1) % 3, i2 = (ax + 2) % 3;
      int s1 = mesh_orient2d(t0, t1, p, i1, i2, NULL), s2 = mesh_orient2d(t1, t2, p, i1, i2, NULL),
          s3 = mesh_orient2d(t2, t0, p, i1, i2, NULL);
      if (!((s1 >= 0 && s2 >= 0 && s3 >= 0) || (s1 <= 0 && s2 <= 0 && s3 <= 0))) continue;
      double w[3] = {p[0] - t0[0], p[1] - t0[1], p[2] - t0[2]};
      best = fmin(best, fabs(vec3_dot(nn, w) / nn[ax]));
    }
    if (best > 1e-12 && getenv("FLAT_DEBUG"))
      printf("# gap %.3g at %.17g %.17g %.17g\n", best, p[0], p[1], p[2]);
    worst = fmax(worst, best);
  }
  return worst;
}

/* Sharp polyhedra whose every face is triangulated as one polygon:
   every vertex of the mesh is then a corner of the solid, where three or
   more faces meet (its triangles' normals, in long double, take three
   or more directions); a vertex inside a face or on a straight run of an
   edge takes one or two. Random scene 44 of a review's generator (a
   rotated box cut by two many-sided prisms at 0.005) has single-triangle
   faces (a prism's side clipped by the box): the face beside such a
   triangle counted as a rounded part's and went in patches of 64, 584
   triangles with vertices inside faces, where 204 are all corners.
   Five more have degenerate points, where the sides of a polygon that
   mirror each other across a face meet on it (before mesh_exact: 7,002
   to 161,672 triangles, sharp cells given up; now all corners, every
   sharp cell kept). */
static void corners_only(void) {
  static const struct { const char *name, *src; double tol; } objs[] = {
    {"random scene 44 (a box cut by a 14- and a 17-sided prism)",
     "Rotate \"x\" (-33.22) (Intersection (Difference (Union (Rotate \"x\" (-47.98) "
     "(Box (-1.091,-0.229,-0.638) (0.262,0.151,0.42))) (Shift (-0.369,-0.84,0.644) "
     "(Rotate \"x\" (-27.6) (CylinderWith [Sides 14] 0.613 2.112)))) (Shift "
     "(-0.504,-1.466,0.347) (Rotate \"x\" (-29.0) (CylinderWith [Sides 17] 0.222 "
     "2.476)))) (Box (-1.064,-0.481,-0.786) (1.41,0.242,0.871)))", 0.005},
    {"a plate with a 100-sided hole", "Difference (Scale (2, 0.2, 2) UnitCube) (Shift "
     "(1, -0.5, 1) (CylinderWith [Sides 100] 0.5 2))", 0.02},
    {"a 200-sided prism", "CylinderWith [Sides 200] 1 0.3", 0.02},
    /* sheets that nearly touch share no edge and are not welded (a
       review's cases: welding by distance joined them) */
    {"two cubes 1e-13 apart", "Union UnitCube (Shift (1.0000000000001, 0, 0) "
     "UnitCube)", 0.02},
    {"a triangular prism bored by another where their edges touch",
     "Rotate \"y\" 30.0 (Rotate \"z\" 15.0 (SetDifference (Shift (0.0, (-1.0), "
     "0.0) (CylinderWith [Sides 3] 0.7 2.0)) (Shift (0.0, 0.0, "
     "(-0.9999999999999997)) (Rotate \"x\" 90.0 (CylinderWith [Sides 3] 0.7 "
     "2.0)))))", 0.02},
    /* holes whose rim cells hold the plate's face and 13 to 16 of the
       hole's planes (marching cells there before: 26,346 and 3,974
       triangles) */
    {"a plate with a 200-sided hole", "SetDifference (Scale (2, 0.2, 2) UnitCube) "
     "(Shift (1, -0.5, 1) (CylinderWith [Sides 200] 0.5 2))", 0.02},
    {"a 10 x 1 x 10 plate with a hole of radius 0.2 (Cylinder's 50 sides)",
     "SetDifference (Scale (10, 1, 10) UnitCube) (Shift (5, -1, 5) (Cylinder 0.2 3))",
     0.1},
    /* degenerate points (mesh_exact.h): a polygon's sides that mirror
       each other across a face meet on it, three planes through a line
       and four through a point; rotated, only nearly */
    {"a 48-sided half cylinder (a box's face through its axis)",
     "SetDifference (CylinderWith [Sides 48] 1 1) (Shift (-2, -1, 0) (Scale "
     "(4, 3, 2) UnitCube))", 0.02},
    {"a plate with a 32-sided notch centred on its edge, rotated twice",
     "Rotate \"x\" 17 (Rotate \"y\" 30 (SetDifference (Scale (4, 0.5, 2) "
     "UnitCube) (Shift (2, -1, 2) (CylinderWith [Sides 32] 0.5 2))))", 0.02},
    {"a plate with a 40-sided hole centred on its corner",
     "SetDifference (Scale (2, 0.5, 2) UnitCube) (Shift (2, -1, 2) "
     "(CylinderWith [Sides 40] 0.7 2))", 0.02},
    {"a 64-sided prism cut in half by a box whose sides touch its corners",
     "SetDifference (CylinderWith [Sides 64] 1 1) (Shift (0, 0.5, 0) (Scale "
     "(2, 2, 2) (Shift (-0.5, 0, -0.5) UnitCube)))", 0.02},
    {"a 24-sided prism on a 24-sided one",
     "Union (CylinderWith [Sides 24] 1 1) (Shift (0, 1, 0) (CylinderWith "
     "[Sides 24] 0.5 1))", 0.02},
    /* pinches (mesh.c, PINCH): parts of the solid that touch at a point
       (26,924 and 4,410 triangles before, sharp cells given up) */
    {"an 8-sided prism bored through by a 6-sided one of its radius",
     "SetDifference (Shift (0,-1,0) (CylinderWith [Sides 8] 0.3 2)) (Shift "
     "(0,0,-1) (Rotate \"x\" 90 (CylinderWith [Sides 6] 0.3 2)))", 0.02},
    {"two cubes whose corners touch", "Union UnitCube (Shift (1,1,1) UnitCube)",
     0.02},
    {"four cubes in a ring, each edge to edge with the next", "Union (Union "
     "UnitCube (Shift (1,1,0) UnitCube)) (Union (Shift (2,0,0) UnitCube) "
     "(Shift (1,-1,0) UnitCube))", 0.02},
  };
  for (size_t k = 0; k < sizeof objs / sizeof *objs; k++) {
    Scene *s = compile(objs[k].src);
    CHECK(objs[k].name, s != NULL);
    if (!s) continue;
    MeshSettings ms = {0};
    ms.tol = objs[k].tol;
    Mesh *m = NULL;
    MeshReport rep;
    char err[300], buf[400];
    int bad;
    int rc = mesh_scene(s, s->root, &ms, &m, &rep, &bad, err, sizeof err);
    snprintf(buf, sizeof buf, "corners: %s meshed, every sharp cell kept "
             "(%ld given up locally, %d whole)", objs[k].name,
             rc ? 0 : rep.sharp_apart, rc ? 0 : rep.sharp_off);
    CHECK(buf, rc == 0 && rep.sharp_apart == 0 && rep.sharp_off == 0);
    if (rc) {
      scene_free(s);
      continue;
    }
    /* each vertex's distinct normals, at most 8 kept */
    long double(*nv)[8][3] = calloc(m->nv, sizeof *nv);
    int *cnt = calloc(m->nv, sizeof *cnt);
    for (size_t t = 0; t < m->nt && nv && cnt; t++) {
      const double *p[3];
      for (int i = 0; i < 3; i++) p[i] = m->v + 3 * m->t[3 * t + i];
      long double u[3], w[3], c[3];
      for (int a = 0; a < 3; a++) {
        u[a] = (long double)p[1][a] - p[0][a];
        w[a] = (long double)p[2][a] - p[0][a];
      }
      c[0] = u[1] * w[2] - u[2] * w[1];
      c[1] = u[2] * w[0] - u[0] * w[2];
      c[2] = u[0] * w[1] - u[1] * w[0];
      long double l = sqrtl(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
      if (!(l > 0)) continue;
      for (int a = 0; a < 3; a++) c[a] /= l;
      for (int i = 0; i < 3; i++) {
        int v = m->t[3 * t + i], seen = 0;
        for (int q = 0; q < cnt[v] && !seen; q++)
          seen = nv[v][q][0] * c[0] + nv[v][q][1] * c[1] + nv[v][q][2] * c[2] > 1 - 1e-9L;
        if (!seen && cnt[v] < 8) {
          memcpy(nv[v][cnt[v]], c, sizeof c);
          cnt[v]++;
        }
      }
    }
    size_t inner = 0;
    for (size_t v = 0; v < m->nv && cnt; v++) inner += cnt[v] < 3;
    snprintf(buf, sizeof buf, "corners: %s: every one of its %zu vertices a corner "
             "(three or more faces; %zu not), %zu triangles", objs[k].name, m->nv,
             inner, m->nt);
    CHECK(buf, nv && cnt && inner == 0);
    free(nv);
    free(cnt);
    mesh_free(m);
    scene_free(s);
  }
}

/* Pinches (mesh.c, PINCH): a solid whose parts touch at points (a bore
   of a prism's radius through it, both prisms' edges meeting on the
   bore's axis plane; boxes corner to corner, rotated or not) or along
   lines (boxes edge to edge) meshes as its parts apart: the components and Euler characteristic of that
   many spheres, the report's pinches, the closest vertices of two
   components (long double, brute force) apart by more than floats
   resolve (2^-22 of the object's size) and less than 2^-15, the mesh
   rounded to floats (an STL) still closed and oriented with every edge
   once each way, and every sharp cell kept. */
static void pinches(void) {
  static const struct { const char *name, *src; long parts, pinched; } objs[] = {
    {"an 8-sided prism bored through by a 6-sided one of its radius",
     "SetDifference (Shift (0,-1,0) (CylinderWith [Sides 8] 0.3 2)) (Shift "
     "(0,0,-1) (Rotate \"x\" 90 (CylinderWith [Sides 6] 0.3 2)))", 2, 3},
    {"a 16-sided prism bored through by an 8-sided one of its radius",
     "SetDifference (Shift (0,-1,0) (CylinderWith [Sides 16] 0.3 2)) (Shift "
     "(0,0,-1) (Rotate \"x\" 90 (CylinderWith [Sides 8] 0.3 2)))", 2, 2},
    {"two cubes whose corners touch", "Union UnitCube (Shift (1,1,1) UnitCube)",
     2, 1},
    {"a cube on a rotated cube's corner", "Union UnitCube (Shift (1,1,1) "
     "(Rotate \"z\" 45 UnitCube))", 2, 1},
    {"three cubes corner to corner", "Union (Union UnitCube (Shift (1,1,1) "
     "UnitCube)) (Shift (2,2,2) UnitCube)", 3, 2},
    /* along a line (3,448 and 476 triangles before, the sharp cells
       there given up): every vertex of the line parted */
    {"two cubes edge to edge", "Union UnitCube (Shift (1,1,0) UnitCube)", 2, 4},
    {"two cubes edge to edge, rotated twice", "Rotate \"z\" 20 (Rotate \"x\" "
     "10 (Union UnitCube (Shift (1,1,0) UnitCube)))", 2, -1},
    {"four cubes in a ring, each edge to edge with the next", "Union (Union "
     "UnitCube (Shift (1,1,0) UnitCube)) (Union (Shift (2,0,0) UnitCube) "
     "(Shift (1,-1,0) UnitCube))", 4, 12},
    /* three and four parts at a corner, each part's vertex moved away
       from the lines it touches (5,122 and 5,304 triangles before) */
    {"three cubes at a corner, two lines of contact each",
     "Union (Union UnitCube (Shift (1,1,0) UnitCube)) (Shift (1,0,1) UnitCube)",
     3, -1},
    {"a 2 x 2 x 2 checkerboard of four cubes", "Union (Union UnitCube (Shift "
     "(1,1,0) UnitCube)) (Union (Shift (1,0,1) UnitCube) (Shift (0,1,1) "
     "UnitCube))", 4, -1},
    /* the space's parts touching: two notches of a box meeting at its
       centre (22,982 before): one part, its notches' corners apart */
    {"a box with two notches whose corners touch", "SetDifference (Box "
     "(0,0,0) (2,2,2)) (Union UnitCube (Shift (1,1,1) UnitCube))", 1, 1},
  };
  for (size_t k = 0; k < sizeof objs / sizeof *objs; k++) {
    const double tol = 0.02;
    Mesh *m = NULL;
    MeshReport rep;
    char buf[500];
    Scene *s = compile_mesh(objs[k].name, objs[k].src, tol, &m, &rep);
    if (!s) continue;
    snprintf(buf, sizeof buf, "pinches: %s: %ld components, Euler "
             "characteristic %ld, %ld pinches, %ld sharp cells given up, %zu "
             "triangles", objs[k].name, rep.components, rep.euler, rep.pinches,
             rep.sharp_apart + rep.sharp_off, m->nt);
    CHECK(buf, rep.components == objs[k].parts &&
                   rep.euler == 2 * objs[k].parts &&
                   (objs[k].pinched < 0 ? rep.pinches > 0
                                        : rep.pinches == objs[k].pinched) &&
                   rep.sharp_apart == 0 &&
                   rep.sharp_off == 0 && m->nt < 400);
    /* components by the triangles' shared vertices */
    int *par = malloc(m->nv * sizeof *par);
    for (size_t i = 0; i < m->nv; i++) par[i] = (int)i;
    for (size_t t = 0; t < m->nt; t++)
      for (int i = 1; i < 3; i++) {
        int a = m->t[3 * t], b = m->t[3 * t + (size_t)i];
        while (par[a] != a) a = par[a];
        while (par[b] != b) b = par[b];
        if (a != b) par[a] = b;
      }
    long double gap = INFINITY, size = 0;
    for (size_t i = 0; i < 3 * m->nv; i++) size = fmaxl(size, fabsl((long double)m->v[i]));
    for (size_t i = 0; i < m->nv; i++)
      for (size_t j = i + 1; j < m->nv; j++) {
        int a = (int)i, b = (int)j;
        while (par[a] != a) a = par[a];
        while (par[b] != b) b = par[b];
        if (a == b) continue;
        long double d = 0;
        for (int c = 0; c < 3; c++) {
          long double x = (long double)m->v[3 * i + (size_t)c] - m->v[3 * j + (size_t)c];
          d += x * x;
        }
        gap = fminl(gap, sqrtl(d));
      }
    snprintf(buf, sizeof buf, "pinches: %s: the parts' closest vertices %.3Lg "
             "apart (more than 2^-22, less than 2^-15 of the size %.3Lg); the "
             "certified bound %.3g within the tolerance", objs[k].name, gap,
             size, rep.certified);
    CHECK(buf, (objs[k].parts == 1 ||
                (gap > ldexpl(size, -22) && gap < ldexpl(size, -15))) &&
                   rep.certified <= tol);
    /* as an STL keeps it: the vertices rounded to floats and joined where
       they are equal, every directed edge once and its reverse once */
    int *same = malloc(m->nv * sizeof *same);
    for (size_t i = 0; i < m->nv; i++) {
      same[i] = (int)i;
      for (size_t j = 0; j < i; j++)
        if ((float)m->v[3 * i] == (float)m->v[3 * j] &&
            (float)m->v[3 * i + 1] == (float)m->v[3 * j + 1] &&
            (float)m->v[3 * i + 2] == (float)m->v[3 * j + 2]) {
          same[i] = same[j];
          break;
        }
    }
    long badedge = 0;
    for (size_t t = 0; t < m->nt; t++)
      for (int e = 0; e < 3; e++) {
        int a = same[m->t[3 * t + (size_t)e]], b = same[m->t[3 * t + (size_t)(e + 1) % 3]];
        long fw = 0, bw = 0;
        for (size_t u = 0; u < m->nt; u++)
          for (int f = 0; f < 3; f++) {
            int c = same[m->t[3 * u + (size_t)f]], d = same[m->t[3 * u + (size_t)(f + 1) % 3]];
            fw += c == a && d == b;
            bw += c == b && d == a;
          }
        badedge += a == b || fw != 1 || bw != 1;
      }
    snprintf(buf, sizeof buf, "pinches: %s: rounded to floats (as an STL keeps "
             "it), every edge once each way (%ld not)", objs[k].name, badedge);
    CHECK(buf, badedge == 0);
    free(same);
    free(par);
    mesh_free(m);
    scene_free(s);
  }
}

/* The mesh's area, in long double. */
static long double mesh_area(const Mesh *m) {
  long double area = 0;
  for (size_t t = 0; t < m->nt; t++) {
    const double *p0 = m->v + 3 * m->t[3 * t], *p1 = m->v + 3 * m->t[3 * t + 1],
                 *p2 = m->v + 3 * m->t[3 * t + 2];
    long double u[3], w[3];
    for (int a = 0; a < 3; a++) {
      u[a] = (long double)p1[a] - p0[a];
      w[a] = (long double)p2[a] - p0[a];
    }
    long double c0 = u[1] * w[2] - u[2] * w[1], c1 = u[2] * w[0] - u[0] * w[2],
                c2 = u[0] * w[1] - u[1] * w[0];
    area += sqrtl(c0 * c0 + c1 * c1 + c2 * c2) / 2;
  }
  return area;
}

/* The mesh's volume within its area times the certified bound of vol
   (a surface within c of the true one holds a volume within its area
   times c of the true one's), and 3000 of its triangles' points within
   tol of the surface; the checks named "what: name: ...". */
static void volume_and_surface(const char *what, const char *name,
                               const Scene *s, const Mesh *m,
                               const MeshReport *rep, long double vol,
                               double tol) {
  char buf[600];
  long double area = mesh_area(m);
  double v = volume(m);
  snprintf(buf, sizeof buf, "%s: %s: volume %.15g, independently %.15Lg "
           "(within the area %.4Lg times the certified %.3g)", what, name, v,
           vol, area, rep->certified);
  CHECK(buf, fabsl((long double)v - vol) <= area * rep->certified + 1e-12L);
  long far = mesh_to_surface(s, m, tol, 3000);
  snprintf(buf, sizeof buf, "%s: %s: 3000 triangle points within the "
           "tolerance of the surface (%ld not)", what, name, far);
  CHECK(buf, far == 0);
}

/* One scene of touching_prisms (below). */
static void touching_one(const char *name, const char *src, const int n3[3],
                         double tol) {
  const double r = 0.5;
  Mesh *m = NULL;
  MeshReport rep;
  char buf[600];
  Scene *s = compile_mesh(name, src, tol, &m, &rep);
  if (!s) return;
  long parts = 0, eu = 0, want = 0;
  long double vol = 0;
  for (int i = 0; i < 3 && n3[i]; i++) {
    long double n = n3[i];
    vol += n * r * r * sinl(2 * acosl(-1) / n) / 2; /* height 1 */
    want += 4 * n3[i] - 4;
    parts++;
  }
  MeshCheck ck;
  int co = closed_oriented(m, &eu), mc = mesh_check(m, &ck);
  snprintf(buf, sizeof buf, "touching prisms: %s: closed and oriented, %ld "
           "component(s) of %ld prisms, Euler characteristic %ld, sharp cells "
           "kept (%ld given up, %d whole), flat regions kept (undone %d), %zu "
           "triangles (the prisms alone %ld)", name, ck.components,
           parts, eu, rep.sharp_apart, rep.sharp_off, rep.flat_undone, m->nt,
           want);
  CHECK(buf, co && mc == 0 && ck.components >= 1 && ck.components <= parts &&
                 eu == 2 * ck.components && rep.sharp_apart == 0 &&
                 rep.sharp_off == 0 && rep.flat_undone == 0 &&
                 m->nt <= (size_t)want + 16);
  /* parted vertices move by 2^-18 of the size, in the certified bound */
  volume_and_surface("touching prisms", name, s, m, &rep, vol, tol);
  mesh_free(m);
  scene_free(s);
}

/* Prisms side by side whose edges meet, one's corner on the other's: the
   faces beside the line of contact lie in one plane but for rounding
   (two 8-sided prisms), or the doubles overlap them by 1e-16 (a neck of
   no width). Before: three planes all but parallel met where the doubles
   could not say, placed anywhere on the edge (0.12 away: a face folded
   over itself, its sharp cells given up, then refused as thinner than
   the finest cell: the 8-sided pair, a row of three); and the flat merge
   dropped both creases of the neck's top and bottom into one edge of
   four triangles (undone: 222 triangles for 8 and 6 sides, 64,202 for 24
   and 8). Now each is meshed with its sharp cells and its flat regions
   kept, closed and oriented, of 1 to k spheres (the neck is there or not
   as the doubles say), the volume the prisms' own (long double), every
   sampled triangle point within the tolerance, and about as many
   triangles as the prisms alone (4 n - 4 each). */
static void touching_prisms(void) {
  static const struct { const char *name, *src; int n[3]; double tol; } objs[] = {
    {"two 8-sided prisms side by side, corner to corner",
     "Union (CylinderWith [Sides 8] 0.5 1) (Shift (1,0,0) (CylinderWith [Sides 8] 0.5 1))",
     {8, 8, 0}, 0.02},
    {"an 8-sided prism beside a 6-sided one, corner to corner",
     "Union (CylinderWith [Sides 8] 0.5 1) (Shift (1,0,0) (CylinderWith [Sides 6] 0.5 1))",
     {8, 6, 0}, 0.02},
    {"a 24-sided prism beside an 8-sided one, corner to corner",
     "Union (CylinderWith [Sides 24] 0.5 1) (Shift (1,0,0) (CylinderWith [Sides 8] 0.5 1))",
     {24, 8, 0}, 0.01},
    /* at 0.02 the four faces at the line of contact left vertices 1e-16
       apart on no common edge, which crossed: 4 sharp cells given up,
       20,094 triangles, until the second try joined them */
    {"a 24-sided prism beside an 8-sided one, corner to corner, at 0.02",
     "Union (CylinderWith [Sides 24] 0.5 1) (Shift (1,0,0) (CylinderWith [Sides 8] 0.5 1))",
     {24, 8, 0}, 0.02},
    {"a 12-sided prism beside another, corner to corner",
     "Union (CylinderWith [Sides 12] 0.5 1) (Shift (1,0,0) (CylinderWith [Sides 12] 0.5 1))",
     {12, 12, 0}, 0.02},
    {"an 8-sided prism beside a 6-sided one, rotated",
     "Rotate \"z\" 17 (Union (CylinderWith [Sides 8] 0.5 1) (Shift (1,0,0) "
     "(CylinderWith [Sides 6] 0.5 1)))", {8, 6, 0}, 0.02},
    {"a row of three 8-sided prisms, corner to corner",
     "Union (Union (CylinderWith [Sides 8] 0.5 1) (Shift (1,0,0) (CylinderWith "
     "[Sides 8] 0.5 1))) (Shift (2,0,0) (CylinderWith [Sides 8] 0.5 1))", {8, 8, 8}, 0.02},
    /* turned about two axes by angles whose sines round, the edges all but
       on one line: the second try's near weld left the pieces between them
       (1e-16 wide) as triangles on one vertex set facing apart and caps
       with three vertices on the line; the sharp cells were given up
       (89,690 triangles of genus 24 at 0.02, 183,744 of genus 61 at 0.01) */
    {"a 16-sided prism beside a turned 9-sided one, corner to corner, rotated twice",
     "Rotate \"z\" 30 (Rotate \"x\" 15 (Union (CylinderWith [Sides 16] 0.5 1) "
     "(Shift (1,0,0) (Rotate \"y\" 20.0 (CylinderWith [Sides 9] 0.5 1)))))",
     {16, 9, 0}, 0.02},
    {"a 16-sided prism beside a turned 9-sided one, rotated twice, at 0.01",
     "Rotate \"z\" 30 (Rotate \"x\" 15 (Union (CylinderWith [Sides 16] 0.5 1) "
     "(Shift (1,0,0) (Rotate \"y\" 20.0 (CylinderWith [Sides 9] 0.5 1)))))",
     {16, 9, 0}, 0.01},
    /* a corner on a face: the caps of the two parts along the line, each
       split with the triangle that closes its own part's wedge (260,452
       triangles of genus 7 before) */
    {"a 22-sided prism's corner on a 7-sided one's face, rotated twice",
     "Rotate \"z\" 15.368652287845068 (Rotate \"x\" 25.357143557067715 (Union "
     "(CylinderWith [Sides 22] 0.5 1) (Shift (0.9504844339512095,0,0) (Rotate "
     "\"y\" 51.428571428571416 (CylinderWith [Sides 7] 0.5 1)))))",
     {22, 7, 0}, 0.02},
    /* turned about three axes: the exact points where the four planes
       meet cluster within 1e-13, beyond the edge weld's 2^-46; the caps
       then form holes along the line (87,448 triangles of genus 18, 12
       sharp cells given up, before the zip and the near weld at 2^-44) */
    {"a 22-sided prism beside a turned 23-sided one, corner to corner, rotated thrice",
     "Rotate \"y\" 45 (Rotate \"x\" 37.95912375652199 (Rotate \"z\" 7 (Union "
     "(CylinderWith [Sides 22] 0.5 1) (Shift (1,0,0) (Rotate \"y\" "
     "7.826086956521737 (CylinderWith [Sides 23] 0.5 1))))))",
     {22, 23, 0}, 0.02},
    /* many sides: the corners' faces all but in one plane, 3 degrees
       from it or less, so the exact points where they meet spread along
       the line by up to 4e-13, beyond 2^-44 of the size: caps with an
       edge of 4e-13 left a crack (refused as thinner than the finest
       cell once the sharp cells about it were given up; 786 triangles
       for 70 and 72 sides), until the near weld reached 2^-40 */
    {"a 60-sided prism beside a turned 61-sided one, corner to corner, rotated",
     "Rotate \"x\" 31.5 (Union (CylinderWith [Sides 60] 0.5 1) (Shift (1,0,0) "
     "(Rotate \"y\" 2.9508196721311477 (CylinderWith [Sides 61] 0.5 1))))",
     {60, 61, 0}, 0.02},
    {"an 80-sided prism beside a turned 81-sided one, corner to corner, rotated",
     "Rotate \"x\" 7 (Union (CylinderWith [Sides 80] 0.5 1) (Shift (1,0,0) "
     "(Rotate \"y\" 2.2222222222222223 (CylinderWith [Sides 81] 0.5 1))))",
     {80, 81, 0}, 0.02},
    {"a 70-sided prism beside a 72-sided one, corner to corner, rotated",
     "Rotate \"x\" 40 (Union (CylinderWith [Sides 70] 0.5 1) (Shift (1,0,0) "
     "(CylinderWith [Sides 72] 0.5 1)))",
     {70, 72, 0}, 0.02},
  };
  for (size_t k = 0; k < sizeof objs / sizeof *objs; k++)
    touching_one(objs[k].name, objs[k].src, objs[k].n, objs[k].tol);
}

/* Prisms glued face to face, their faces one plane but for rounding
   (built by different rotations and shifts): refused before as thinner
   than the finest cell (the doubles left a gap or a sliver of 1e-16, the
   two faces coplanar and facing, no cell fine enough). Now the planes
   within 2^-46 are made one (mesh.c snap_planes): one solid, the glued
   faces gone, closed and oriented, genus 0, its volume the two prisms'
   (long double polygon areas) within the area times the certified bound,
   3000 triangle points within the tolerance, the report's count of
   planes joined. A gap of 1e-12, far above the rounding, stays a gap:
   two parts, nothing joined. */
static void glued_faces(void) {
  static const struct { const char *name, *src; int n[2]; double r[2];
                        long parts; } objs[] = {
    {"two 6-sided prisms glued face to face, rotated",
     "Rotate \"z\" 12.5 (Union (Rotate \"y\" 30.0 (CylinderWith [Sides 6] 0.5 1)) "
     "(Shift (0.8660254037844387,0,0) (Rotate \"y\" 30.0 (CylinderWith [Sides 6] "
     "0.5 1))))", {6, 6}, {0.5, 0.5}, 1},
    {"a 3-sided prism glued to a 5-sided one, rotated",
     "Rotate \"z\" 61.3 (Union (Rotate \"y\" 60.0 (CylinderWith [Sides 3] 0.3 1)) "
     "(Shift (0.39270509831248424,0,0) (CylinderWith [Sides 5] 0.3 1)))",
     {3, 5}, {0.3, 0.3}, 1},
    {"two 6-sided prisms 1e-12 apart face to face, rotated",
     "Rotate \"z\" 12.5 (Union (Rotate \"y\" 30.0 (CylinderWith [Sides 6] 0.5 1)) "
     "(Shift (0.866025403785439,0,0) (Rotate \"y\" 30.0 (CylinderWith [Sides 6] "
     "0.5 1))))", {6, 6}, {0.5, 0.5}, 2},
  };
  for (size_t k = 0; k < sizeof objs / sizeof *objs; k++) {
    const double tol = 0.02;
    Mesh *m = NULL;
    MeshReport rep;
    char buf[600];
    Scene *s = compile_mesh(objs[k].name, objs[k].src, tol, &m, &rep);
    if (!s) continue;
    long double vol = 0;
    for (int i = 0; i < 2; i++) {
      long double n = objs[k].n[i], r = objs[k].r[i];
      vol += n * r * r * sinl(2 * acosl(-1) / n) / 2; /* height 1 */
    }
    long eu = 0;
    MeshCheck ck;
    int co = closed_oriented(m, &eu), mc = mesh_check(m, &ck);
    snprintf(buf, sizeof buf, "glued faces: %s: closed and oriented, %ld "
             "component(s) (want %ld), Euler characteristic %ld, %ld planes "
             "joined, sharp cells kept (%ld given up, %d whole), %zu triangles",
             objs[k].name, ck.components, objs[k].parts, eu, rep.snapped,
             rep.sharp_apart, rep.sharp_off, m->nt);
    CHECK(buf, co && mc == 0 && ck.components == objs[k].parts &&
                   eu == 2 * objs[k].parts &&
                   (objs[k].parts == 1 ? rep.snapped > 0 : rep.snapped == 0) &&
                   rep.sharp_apart == 0 && rep.sharp_off == 0 && m->nt < 200);
    volume_and_surface("glued faces", objs[k].name, s, m, &rep, vol, tol);
    mesh_free(m);
    scene_free(s);
  }
}

/* A box bored through from the side by a 24-sided prism of its half
   width, whose corners touch the box's two sides and its top along
   lines (four planes all but through each line: the box's face and the
   prism's two faces there, and the cell's): given up and meshed by
   marching before, 5,140,740 triangles in two minutes, two parts (the
   perturbation's vertices 1e-16 apart crossed). Now: no sharp cell given
   up, a few hundred triangles, closed, 1 to 3 parts (below the bore, and
   above it on either side of the top's line) each of genus 0, the volume
   the box's less the prism's (long double), 3000 points within the
   tolerance. */
static void bored_half_width(void) {
  static const struct { int n; size_t most; } objs[] = {
    {24, 400},
    /* one cell, the contact line inside the box top's flat region: the
       top's new diagonal lay along the line where the bore's crease, its
       straight run dropped, had the same ends (one edge of four
       triangles: the flat merge undone, 208 and 642 triangles as made);
       now such regions keep the crease's vertex */
    {8, 120},
    {12, 160},
  };
  for (size_t k = 0; k < sizeof objs / sizeof *objs; k++) {
    const double tol = 0.005;
    Mesh *m = NULL;
    MeshReport rep;
    char buf[600], name[120], src[400];
    snprintf(name, sizeof name, "a box bored by a %d-sided prism of its half "
             "width, rotated", objs[k].n);
    snprintf(src, sizeof src, "Rotate \"x\" 45 (SetDifference (Box (-0.7,0,-0.7) "
             "(0.7,2,0.7)) (Shift (-1.4,1.3,0) (Rotate \"z\" (-90) "
             "(CylinderWith [Sides %d] 0.7 2.8))))", objs[k].n);
    Scene *s = compile_mesh(name, src, tol, &m, &rep);
    if (!s) continue;
    long eu = 0;
    MeshCheck ck;
    int co = closed_oriented(m, &eu), mc = mesh_check(m, &ck);
    snprintf(buf, sizeof buf, "bored: %s: closed and oriented, %ld component(s), "
             "Euler characteristic %ld, sharp cells kept (%ld given up, %d whole), "
             "flat regions kept (undone %d), %zu triangles (at most %zu)", name,
             ck.components, eu, rep.sharp_apart, rep.sharp_off, rep.flat_undone,
             m->nt, objs[k].most);
    CHECK(buf, co && mc == 0 && ck.components >= 1 && ck.components <= 3 &&
                   eu == 2 * ck.components && rep.sharp_apart == 0 &&
                   rep.sharp_off == 0 && rep.flat_undone == 0 &&
                   m->nt <= objs[k].most);
    long double n = objs[k].n;
    long double vol = 1.4L * 2 * 1.4L - n * 0.49L * sinl(2 * acosl(-1) / n) / 2 * 1.4L;
    volume_and_surface("bored", name, s, m, &rep, vol, tol);
    mesh_free(m);
    scene_free(s);
  }
}

/* A rotated plate with a many-sided notch centred on its top edge: at
   the notch's ends the polygon's corner all but lies on the top (a
   sliver 1e-14 wide), and more than 16 of the notch's planes and the top
   cross the cells there. Cells of up to 16 planes left them to marching
   cells, which split them to the deepest level and refused the mesh as
   thinner than the finest cell (250 and 300 sides), or made 8,428 and
   15,792 triangles (150, 200); cells of up to 32 planes are sharp. Now:
   closed, one part of genus 0, sharp cells kept, about 2 n + 16
   triangles, the volume the plate's less half the polygon's prism. */
static void many_sided_notch(void) {
  static const int sides[] = {150, 300};
  for (size_t k = 0; k < sizeof sides / sizeof *sides; k++) {
    const double tol = 0.02;
    Mesh *m = NULL;
    MeshReport rep;
    char buf[600], name[120], src[400];
    snprintf(name, sizeof name, "a plate with a %d-sided notch centred on its "
             "edge, rotated twice", sides[k]);
    snprintf(src, sizeof src, "Rotate \"x\" 17 (Rotate \"y\" 30 (SetDifference "
             "(Scale (4, 0.5, 2) UnitCube) (Shift (2, -1, 2) (CylinderWith "
             "[Sides %d] 0.5 2))))", sides[k]);
    Scene *s = compile_mesh(name, src, tol, &m, &rep);
    if (!s) continue;
    long eu = 0;
    MeshCheck ck;
    int co = closed_oriented(m, &eu), mc = mesh_check(m, &ck);
    size_t most = 2 * (size_t)sides[k] + 32;
    snprintf(buf, sizeof buf, "notch: %s: closed and oriented, %ld component(s), "
             "Euler characteristic %ld, sharp cells kept (%ld given up, %d whole), "
             "%zu triangles (at most %zu)", name, ck.components, eu,
             rep.sharp_apart, rep.sharp_off, m->nt, most);
    CHECK(buf, co && mc == 0 && ck.components == 1 && eu == 2 &&
                   rep.sharp_apart == 0 && rep.sharp_off == 0 && m->nt <= most);
    long double n = sides[k];
    long double vol = 4 * 0.5L * 2 - 0.5L * (n * 0.25L * sinl(2 * acosl(-1) / n) / 2) / 2;
    volume_and_surface("notch", name, s, m, &rep, vol, tol);
    mesh_free(m);
    scene_free(s);
  }
}

/* Flat regions triangulated again (mesh_merge.h), against the octree's
   own triangles (MeshSettings.keep_flat) of the same object: fewer
   triangles (a unit cube 12, figure12's sharp obj1 28, OpenSCAD's count
   for it; a rotated plate with a sunk square, the case a review found
   the clipping giving up on, 1746 -> 72; a plate with a 50-sided hole,
   216); the same components and Euler characteristic; every vertex
   one of the octree's, to the bit; and the same surface: 1500 points of
   either mesh within the stated bound (MeshReport.flat_moved) of the
   other, by brute force over its triangles. */
static void flat_merge(void) {
  static const struct { const char *name, *src; double tol; long want; } objs[] = {
    {"UnitCube", "UnitCube", 0.01, 12},
    {"figure12 obj1 (sharp)", "SetDifference UnitCube (Shift (0.25, 0.8, 0.25) "
     "(Scale (0.5, 0.5, 0.5) UnitCube))", 0.001, 28},
    {"a rotated cube", "Rotate \"z\" 30 (Rotate \"x\" 20 UnitCube)", 0.001, 12},
    {"Rounded 0.1 UnitCube", "Rounded 0.1 UnitCube", 0.02, -1},
    {"sharp cube with a hole", "SetDifference UnitCube (Shift (0.3, -0.5, 0.3) "
     "(Scale (0.4, 2, 0.4) UnitCube))", 0.01, -1},
    {"a rotated union of plates (faces collinear only to rounding)",
     "Rotate \"y\" 17 (Union (Scale (3, 3, 1) UnitCube) (SetDifference (Shift "
     "(0.5, 0.5, 1) (Scale (2, 2, 1) UnitCube)) (Shift (1, 1, 0.9) (Scale (1, 1, 2) "
     "UnitCube))))", 0.01, -1},
    {"a box minus soft keys (random seed 835)", "SetDifference (Union (Rounded "
     "0.05944437258005722 (Rotate \"z\" 51.936 (Shift (0.269, 0.396, 0.119) (Scale "
     "(0.373, 0.448, 0.501) UnitCube)))) (Rotate \"x\" 24.969 (Shift (-0.396, "
     "-0.200, -0.148) (Scale (0.812, 0.783, 0.580) UnitCube)))) (SoftObject 0.5 "
     "[Key (0.185, 0.335, 0.423) 0.601 1, Key (0.310, 0.172, 0.359) 0.797 1, Key "
     "(-0.146, -0.465, 0.158) 0.872 1, Key (0.463, -0.194, 0.031) 0.764 (-1)])", 0.03, -1},
    /* 54 corners on each of its two faces, Euler characteristic 0: at
       least 2 * 108 triangles, and no more when no vertex but a corner is
       left (its top was 125 patches, 5722 triangles, while the boundary's
       straight runs counted towards a region's length) */
    {"a plate with a 50-sided hole", "Difference (Scale (2, 0.2, 2) UnitCube) (Shift "
     "(1, -0.5, 1) (CylinderWith [Sides 50] 0.5 2))", 0.02, 216},
    /* 104 corners on each face: 2 * 104 + 2 * 100 + 4 * 2. Its rim's
       cells hold up to 12 planes (8 was the most a sharp cell took: they
       were marching cells), and a triangle of a side seeded that side's
       region with a plane tilted 5.8e-13 by its vertices' rounding,
       leaving a neighbour alone and the top counted as a rounded part's
       face (seeds are now the largest triangles first): 6,540 */
    {"a plate with a 100-sided hole", "Difference (Scale (2, 0.2, 2) UnitCube) (Shift "
     "(1, -0.5, 1) (CylinderWith [Sides 100] 0.5 2))", 0.02, 416},
    {"a rotated plate with a 50-sided hole", "Rotate \"z\" 30 (Rotate \"x\" 20 "
     "(Difference (Scale (2, 0.2, 2) UnitCube) (Shift (1, -0.5, 1) (CylinderWith "
     "[Sides 50] 0.5 2))))", 0.001, -1},
  };
  unsigned long long keep = rng;
  for (size_t k = 0; k < sizeof objs / sizeof *objs; k++) {
    Scene *s = compile(objs[k].src);
    CHECK(objs[k].name, s != NULL);
    if (!s) continue;
    MeshSettings ms = {0};
    ms.tol = objs[k].tol;
    Mesh *a = NULL, *b = NULL;
    MeshReport ra, rb;
    char err[300], buf[400];
    int bad;
    ms.keep_flat = 1;
    int rc = mesh_scene(s, s->root, &ms, &a, &ra, &bad, err, sizeof err);
    ms.keep_flat = 0;
    rc |= mesh_scene(s, s->root, &ms, &b, &rb, &bad, err, sizeof err);
    snprintf(buf, sizeof buf, "flat: %s meshed both ways", objs[k].name);
    CHECK(buf, rc == 0);
    if (rc) {
      mesh_free(a);
      mesh_free(b);
      scene_free(s);
      continue;
    }
    snprintf(buf, sizeof buf, "flat: %s: %zu -> %zu triangles%s", objs[k].name,
             a->nt, b->nt, objs[k].want > 0 ? " (as many as expected)" : " (fewer)");
    CHECK(buf, objs[k].want > 0 ? b->nt == (size_t)objs[k].want : b->nt < a->nt);
    snprintf(buf, sizeof buf, "flat: %s: components %ld, Euler %ld both", objs[k].name,
             rb.components, rb.euler);
    CHECK(buf, ra.components == rb.components && ra.euler == rb.euler &&
               rb.flat_regions > 0 && !rb.flat_undone);
    double *va = malloc(3 * a->nv * sizeof *va);
    memcpy(va, a->v, 3 * a->nv * sizeof *va);
    qsort(va, a->nv, 3 * sizeof *va, cmp_vertex);
    size_t missing = 0;
    for (size_t v = 0; v < b->nv; v++)
      missing += !bsearch(b->v + 3 * v, va, a->nv, 3 * sizeof *va, cmp_vertex);
    free(va);
    snprintf(buf, sizeof buf, "flat: %s: every vertex one of the octree's (%zu not)",
             objs[k].name, missing);
    CHECK(buf, missing == 0);
    double ab = mesh_gap(a, b, 1500), ba = mesh_gap(b, a, 1500);
    snprintf(buf, sizeof buf, "flat: %s: the same surface, 1500 points each way within "
             "%.3g (%.3g, %.3g)", objs[k].name, rb.flat_moved, ab, ba);
    CHECK(buf, ab <= rb.flat_moved && ba <= rb.flat_moved);
    mesh_free(a);
    mesh_free(b);
    scene_free(s);
  }
  rng = keep;
}

/* A rotated sharp cube: its 8 corners, computed here from the definition
   (Rotate's convention: about x, y towards z; about z, x towards y), are
   vertices of the mesh, and every vertex lies on one of its 6 planes. */
static void sharp_corners(void) {
  Scene *s = compile("Rotate \"z\" 30 (Rotate \"x\" 20 UnitCube)");
  CHECK("rotated cube compiled", s != NULL);
  if (!s) return;
  MeshSettings ms = {0};
  ms.tol = 0.001;
  Mesh *m;
  MeshReport rep;
  char err[300];
  int bad;
  int rc = mesh_scene(s, s->root, &ms, &m, &rep, &bad, err, sizeof err);
  CHECK("rotated cube meshed", rc == 0);
  if (rc) {
    scene_free(s);
    return;
  }
  double ax = 20 * M_PI / 180, az = 30 * M_PI / 180, R[3][3];
  /* R = Rz Rx */
  double rx[3][3] = {{1, 0, 0}, {0, cos(ax), -sin(ax)}, {0, sin(ax), cos(ax)}};
  double rz[3][3] = {{cos(az), -sin(az), 0}, {sin(az), cos(az), 0}, {0, 0, 1}};
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      R[i][j] = 0;
      for (int k = 0; k < 3; k++) R[i][j] += rz[i][k] * rx[k][j];
    }
  int corners = 0;
  for (int c = 0; c < 8; c++) {
    double p[3] = {c & 1, c >> 1 & 1, c >> 2 & 1}, q[3];
    for (int i = 0; i < 3; i++) q[i] = R[i][0] * p[0] + R[i][1] * p[1] + R[i][2] * p[2];
    int found = 0;
    for (size_t v = 0; v < m->nv && !found; v++) {
      double d = 0;
      for (int i = 0; i < 3; i++) d += (m->v[3 * v + i] - q[i]) * (m->v[3 * v + i] - q[i]);
      found = sqrt(d) < 1e-9;
    }
    corners += found;
  }
  CHECK_NEAR("rotated cube: its 8 true corners are mesh vertices (1e-9)", corners, 8, 0);
  long off = 0;
  for (size_t v = 0; v < m->nv; v++) {
    /* in the cube's own frame (R transposed), some coordinate is 0 or 1 */
    double u[3];
    for (int i = 0; i < 3; i++)
      u[i] = R[0][i] * m->v[3 * v] + R[1][i] * m->v[3 * v + 1] + R[2][i] * m->v[3 * v + 2];
    double best = 1e300;
    for (int i = 0; i < 3; i++) best = fmin(best, fmin(fabs(u[i]), fabs(u[i] - 1)));
    off += best > 1e-9;
  }
  CHECK_NEAR("rotated cube: every vertex on a face plane (1e-9)", (double)off, 0, 0);
  printf("# rotated cube: %zu triangles, %zu vertices\n", m->nt, m->nv);
  mesh_free(m);
  scene_free(s);
}

static void bad_input(void) {
  Scene *s = compile("UnitCube");
  MeshSettings ms = {0};
  Mesh *m = NULL;
  MeshReport rep;
  char err[300];
  int bad;
  double tols[] = {0, NAN, 1e-300, -1, INFINITY};
  for (int i = 0; i < 5; i++) {
    ms.tol = tols[i];
    CHECK("bad tolerance refused", mesh_scene(s, s->root, &ms, &m, &rep, &bad, err,
                                              sizeof err) == MESH_ETOL && !m);
  }
  scene_free(s);
  s = compile("Rounded 0.2 UnitCube"); /* a sharp cube is 40 triangles */
  ms.tol = 0.05;
  ms.max_triangles = 100;
  CHECK("max-triangles refused before the crossings",
        mesh_scene(s, s->root, &ms, &m, &rep, &bad, err, sizeof err) == MESH_ELIMIT &&
            rep.crossings == 0 && strstr(err, "max-triangles"));
  ms.max_triangles = 0;
  ms.max_cells = 10;
  CHECK("max-cells refused", mesh_scene(s, s->root, &ms, &m, &rep, &bad, err,
                                        sizeof err) == MESH_ELIMIT);
  scene_free(s);
  s = compile("Halfspace ((0, 1, 0), 0)");
  ms.max_cells = 0;
  CHECK("unbounded refused, naming the node",
        mesh_scene(s, s->root, &ms, &m, &rep, &bad, err, sizeof err) ==
                MESH_EUNBOUNDED && bad == s->root);
  ms.has_bounds = 1;
  double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1};
  memcpy(ms.lo, lo, sizeof lo);
  memcpy(ms.hi, hi, sizeof hi);
  int rc = mesh_scene(s, s->root, &ms, &m, &rep, &bad, err, sizeof err);
  long eu;
  CHECK("a floor with Bounds: a closed slab", rc == 0 && closed_oriented(m, &eu) && eu == 2);
  if (!rc) CHECK_NEAR("the slab's volume", volume(m), 4, 0.05);
  mesh_free(m);
  scene_free(s);
  s = compile("Intersection UnitCube (Shift (3, 0, 0) UnitCube)");
  ms.has_bounds = 0;
  rc = mesh_scene(s, s->root, &ms, &m, &rep, &bad, err, sizeof err);
  if (rc != MESH_EEMPTY) printf("# rc %d: %s\n", rc, err);
  CHECK("an empty object refused", rc == MESH_EEMPTY);
  scene_free(s);
  /* written whole or not at all */
  s = compile("UnitCube");
  ms.tol = 0.1;
  rc = mesh_scene(s, s->root, &ms, &m, &rep, &bad, err, sizeof err);
  CHECK("no file for a bad folder",
        rc == 0 && mesh_write(m, "/nonexistent/x.stl", err, sizeof err) < 0 &&
            access("/nonexistent/x.stl", F_OK) != 0);
  char path[] = "/tmp/qcs-mesh-test.stl";
  CHECK("binary STL size", mesh_write(m, path, err, sizeof err) == 0);
  FILE *f = fopen(path, "rb");
  fseek(f, 0, SEEK_END);
  CHECK_NEAR("binary STL is 84 + 50 n bytes", (double)ftell(f),
             84.0 + 50.0 * (double)m->nt, 0);
  fclose(f);
  unlink(path);
  mesh_free(m);
  scene_free(s);
}

/* The self-intersection check's failure paths, by mesh_test_fault: a
   mesh made with sharp cells that intersects itself is made again without
   them (and that one passes); one that intersects itself without them is
   an error, and `mesh` writes no file. The corruption is a real crossing:
   the exact check must find it. */
static void self_check_failures(void) {
  Scene *s = compile("UnitCube");
  MeshSettings ms = {0};
  ms.tol = 0.05;
  Mesh *m = NULL;
  MeshReport rep;
  char err[400];
  int bad;
  mesh_test_fault(1);
  int rc = mesh_scene(s, s->root, &ms, &m, &rep, &bad, err, sizeof err);
  long eu;
  MeshSelfCheck sc;
  CHECK("a sharp mesh that intersects itself is made again without sharp "
        "cells, and that one is closed and free of intersections",
        rc == 0 && m && rep.sharp_off == 2 && closed_oriented(m, &eu) &&
            eu == 2 && mesh_self_check(m, &sc) == 0);
  mesh_free(m);
  m = NULL;
  mesh_test_fault(2);
  rc = mesh_scene(s, s->root, &ms, &m, &rep, &bad, err, sizeof err);
  CHECK("a mesh that intersects itself without sharp cells is an error "
        "naming the place",
        rc == MESH_ESELF && !m && strstr(err, "intersects itself") &&
            strstr(err, "nothing was written"));
  scene_free(s);
  const char *path = "/tmp/qcs-test-fault.stl";
  remove(path);
  char text[200];
  snprintf(text, sizeof text, "mesh \"%s\" UnitCube", path);
  Src *src = src_of("<test>", text);
  ErrFrame f;
  int failed = 0;
  if (ERR_TRY(f)) {
    Expr *e = parse_expression(I, src);
    force(I, eval(I, e, NULL));
    err_pop(&f);
  } else {
    err_pop(&f);
    failed = strstr(err_info()->msg, "intersects itself") != NULL;
  }
  CHECK("mesh \"f.stl\" of a mesh that intersects itself: an error, and no "
        "file", failed && access(path, F_OK) != 0);
  mesh_test_fault(0);
}

/* The file's floats (mesh_float.h): a prism's corner all but on another's
   face leaves features 1e-16 wide (two triangles on nearly one vertex
   set facing apart; two cone tips 1e-15 apart), which an STL's, a PLY's
   or a 3MF's floats put on one place: the file was not the checked mesh
   (a warning). Scenes of tools/fuzz-prisms.py (seed 41, 3-24 sides, s99
   and s185): before, vertices joined in floats; now mesh_to_floats
   makes the floats' mesh one again, by joining them (s99: the pair facing
   apart dropped, the fans that then met at a point parted) or by moving
   them apart into their parts (s185). Checked: no two vertices on one
   float place, every coordinate a float, closed and oriented (the edge
   count here), no self-intersections (exact), the components and Euler
   characteristic kept, the largest move within a sixteenth of the
   tolerance, the volume the prisms' (long double) within the area times
   the certified bound grown by it, and 3000 triangle points within the
   tolerance of the surface. */
static void float_files(void) {
  static const struct { const char *name, *src; int n[2]; double r[2], tol; int apart; } objs[] = {
    {"fuzz-prisms 41 s99: a 6-sided prism's corner on a 15-sided one's face, turned thrice",
     "Rotate \"z\" 30.379 (Rotate \"y\" 38.114 (Rotate \"z\" 17.204 (Union (CylinderWith "
     "[Sides 6] 0.5 1) (Shift (0.8752892688256854,0,0) (Rotate \"y\" 12.0 (CylinderWith "
     "[Sides 15] 0.37528926882568536 1))))))", {6, 15}, {0.5, 0.37528926882568536}, 0.056, 0},
    {"fuzz-prisms 41 s185: a 14-sided prism beside a smaller 16-sided one, corner to corner, turned",
     "Rotate \"x\" 58.257 (Union (CylinderWith [Sides 14] 0.5 1) (Shift (0.8,0,0) "
     "(CylinderWith [Sides 16] 0.3 1)))", {14, 16}, {0.5, 0.3}, 0.052, 1},
  };
  for (size_t k = 0; k < sizeof objs / sizeof *objs; k++) {
    Mesh *m = NULL;
    MeshReport rep;
    char buf[700];
    Scene *s = compile_mesh(objs[k].name, objs[k].src, objs[k].tol, &m, &rep);
    if (!s) continue;
    MeshCheck c0, c1;
    mesh_check(m, &c0);
    long joined = mesh_float_joined(m);
    MeshFloatReport fr;
    int rc = mesh_to_floats(m, objs[k].tol / 16, &fr);
    int floats = 1;
    for (size_t i = 0; i < 3 * m->nv; i++) floats &= (double)(float)m->v[i] == m->v[i];
    long eu = 0;
    int co = closed_oriented(m, &eu), mc = mesh_check(m, &c1);
    MeshSelfCheck sc;
    int self = mesh_self_check(m, &sc);
    snprintf(buf, sizeof buf, "float files: %s: %ld vertices on another's float "
             "place before, %ld after; made a mesh again (%s; %ld joined, %ld closed "
             "up, %ld pairs facing apart, %ld fans parted, moved %.3g), every "
             "coordinate a float, closed and oriented, no self-intersections, "
             "components %ld -> %ld, Euler %ld -> %ld", objs[k].name, joined,
             mesh_float_joined(m), fr.kept_apart ? "kept apart" : "joined",
             fr.joined, fr.closed, fr.pairs, fr.parted, fr.moved, c0.components,
             c1.components, c0.euler, c1.euler);
    CHECK(buf, joined > 0 && rc == 0 && fr.ok && fr.kept_apart == objs[k].apart &&
                   mesh_float_joined(m) == 0 && floats && co && mc == 0 &&
                   self == 0 && c1.components == c0.components &&
                   c1.euler == c0.euler && eu == c0.euler &&
                   fr.moved <= objs[k].tol / 16);
    long double vol = 0;
    for (int i = 0; i < 2; i++) {
      long double n = objs[k].n[i], r = objs[k].r[i];
      vol += n * r * r * sinl(2 * acosl(-1) / n) / 2; /* height 1 */
    }
    MeshReport r2 = rep;
    r2.certified += fr.moved;
    volume_and_surface("float files", objs[k].name, s, m, &r2, vol, objs[k].tol);
    mesh_free(m);
    scene_free(s);
  }
}

/* The flat merge done again where it met itself (mesh.c, FLAT_TRIES):
   a corner all but on a face, or two prisms corner to corner, leave
   flat regions whose new triangles meet the other part's within 1e-16
   (tools/fuzz-prisms.py seed 43 s91, a 24-sided prism's corner on a
   triangular one's face, turned thrice; seed 44 s283, 29 and 44 sides
   corner to corner, turned about z). Before, the whole merge was undone:
   the octree's triangles, 506 and 6,168. Now the regions of the pair that
   met are kept as made and the rest merged again: flat_undone 0, the
   merge done again at least once, closed and oriented, no
   self-intersections (exact, here too), at most half the octree's
   triangles, the volume (long double) and 3000 triangle points within
   the tolerance. */
static void flat_retry(void) {
  static const struct { const char *name, *src; int n[2]; double tol; } objs[] = {
    {"fuzz-prisms 43 s91: a 24-sided prism's corner on a 3-sided one's face, turned thrice",
     "Rotate \"x\" 60.0 (Rotate \"x\" 20.0 (Rotate \"z\" 20.0 (Union (CylinderWith "
     "[Sides 24] 0.5 1) (Shift (0.75,0,0) (CylinderWith [Sides 3] 0.5 1)))))", {24, 3}, 0.078},
    {"fuzz-prisms 44 s283: a 29-sided prism beside a 44-sided one, corner to corner, turned",
     "Rotate \"z\" (-47.437) (Union (CylinderWith [Sides 29] 0.5 1) (Shift (1.0,0,0) "
     "(CylinderWith [Sides 44] 0.5 1)))", {29, 44}, 0.052},
  };
  for (size_t k = 0; k < sizeof objs / sizeof *objs; k++) {
    Mesh *m = NULL;
    MeshReport rep;
    char buf[600];
    Scene *s = compile_mesh(objs[k].name, objs[k].src, objs[k].tol, &m, &rep);
    if (!s) continue;
    long eu = 0;
    MeshCheck ck;
    MeshSelfCheck sc;
    int co = closed_oriented(m, &eu), mc = mesh_check(m, &ck), self = mesh_self_check(m, &sc);
    snprintf(buf, sizeof buf, "flat merge again: %s: undone %d, done again %d "
             "time(s), %ld regions, %zu -> %zu triangles, closed and oriented, "
             "no self-intersections, %ld component(s), Euler %ld", objs[k].name,
             rep.flat_undone, rep.flat_frozen, rep.flat_regions, rep.flat_before,
             m->nt, ck.components, eu);
    CHECK(buf, rep.flat_undone == 0 && rep.flat_frozen >= 1 && rep.flat_regions > 0 &&
                   2 * m->nt <= rep.flat_before && co && mc == 0 && self == 0 &&
                   eu == 2 * ck.components);
    long double vol = 0;
    for (int i = 0; i < 2; i++) {
      long double n = objs[k].n[i];
      vol += n * 0.25L * sinl(2 * acosl(-1) / n) / 2; /* radius 0.5, height 1 */
    }
    volume_and_surface("flat merge again", objs[k].name, s, m, &rep, vol, objs[k].tol);
    mesh_free(m);
    scene_free(s);
  }
}

int main(void) {
  check_prefix = "mesh";
  I = bind_interp_new();
  char probe;
  interp_set_stack(I, &probe, 4u << 20);
  const char *hole = "(Shift (0.25, -0.5, 0.25) (Scale (0.5, 2, 0.5) UnitCube))";
  const char *pocket = "(Shift (0.25, 0.8, 0.25) (Scale (0.5, 0.5, 0.5) UnitCube))";
  char src[600];
  one("UnitCube", "UnitCube", 0.04, 2, 1, 1, 1);
  one("Rounded 0.2 UnitCube", "Rounded 0.2 UnitCube", 0.04, 2, 1, 0, 1);
  snprintf(src, sizeof src, "Rounded 0.07 (Difference UnitCube %s)", pocket);
  one("obj4 (a pocket)", src, 0.04, 2, 1, 0.95, 0);
  snprintf(src, sizeof src, "Rounded 0.07 (Difference UnitCube %s)", hole);
  one("rounded cube with a hole (genus 1)", src, 0.04, 0, 1, 0, 1);
  snprintf(src, sizeof src, "SetDifference UnitCube %s", hole);
  one("sharp cube with a hole (genus 1)", src, 0.04, 0, 1, 0.75, 1);
  one("two cubes", "Union UnitCube (Shift (2, 0, 0) UnitCube)", 0.05, 4, 2, 2, 0);
  one("soft, a negative key", "SoftObject 0.5 [Key (0, 0, 0) 1 1, "
      "Key (0.5, 0, 0) 0.5 (-1)]", 0.04, 2, 1, 0, 1);
  one("soft, a quadric key", "SoftObject 0.5 [QuadricKey ((1, 0, 0, 0), "
      "(0, 4, 0, 0), (0, 0, 1, 0), (0, 0, 0, 0)) 1 1]", 0.04, 2, 1, 0, 1);
  snprintf(src, sizeof src, "SetDifference (Rounded 0.1 UnitCube) "
           "(SoftObject 0.5 [Key (1, 1, 1) 0.8 1])");
  one("rounded minus soft", src, 0.04, 2, 1, 0, 1);
  kit_round_parts();
  pruned_same();
  flush_dome();
  many_sides_exact();
  suggest_bounds();
  predicates();
  cover_sphere();
  cover_columns_sphere();
  cover_uniform();
  fast_pairs();
  hand_meshes();
  bad_input();
  self_check_failures();
  sharp_corners();
  flat_merge();
  corners_only();
  pinches();
  touching_prisms();
  many_sided_notch();
  glued_faces();
  bored_half_width();
  thin_parts();
  property();
  sharp_kept();
  soft_adaptive(); /* after the property test: it draws from urand too */
  property_regressions();
  obj5_measured();
  property_long();
  /* figure12's obj5: a rounded box resting flush on a rounded cube (the
     faces on one plane with opposite sides, a groove narrowing to
     nothing under the box's edge); at 0.01 splitting the cells beside
     the groove's end once left a bubble of it (2 components); after the
     property test, whose random scenes would change if these drew from
     urand before it. Random rays are not used here: their spans end at
     the contact plane (0.126 from the mesh at (0.523, 1, 0.407), the
     same on the branch's start), where the union is inside on both
     sides and the mesh rightly has no surface. */
  snprintf(src, sizeof src, "Union (Rounded 0.07 UnitCube) (Rounded 0.07 (Shift "
           "(0.25, 1, 0.25) (Scale (0.5, 0.5, 0.5) UnitCube)))");
  one("figure12 obj5 (a rounded box resting flush on a rounded cube)", src, 0.02,
      2, 1, 0, 0);
  one("figure12 obj5 at 0.01", src, 0.01, 2, 1, 0, 0);
  float_files();
  flat_retry();
  /* tools/fuzz-prisms.py seed 44 (20-80 sides) s233, 63 and 62 sides
     corner to corner turned thrice: the corners' faces within 3 degrees
     of one plane; refused as thinner than the finest cell until the
     second try's near weld reached 2^-39 of the size (NEAR_WELD 128);
     after the property test, whose random scenes these would shift */
  {
    static const int n3[3] = {63, 62, 0};
    touching_one("fuzz-prisms 44 s233: a 63-sided prism beside a 62-sided one, corner to "
                 "corner, turned thrice",
                 "Rotate \"x\" (-31.490448487124475) (Rotate \"y\" 43.69948551104545 (Rotate "
                 "\"x\" 36.596 (Union (CylinderWith [Sides 63] 0.5 1) (Shift (1.0,0,0) "
                 "(CylinderWith [Sides 62] 0.5 1)))))", n3, 0.05);
  }
  CHECK_DONE();
}
