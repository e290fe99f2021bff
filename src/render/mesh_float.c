/* mesh_float.c: the mesh as the file's floats keep it (mesh_float.h). */
#include "render/mesh_float.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render/mesh_check.h"

typedef struct { float x[3]; int i; } FKey;

static int fkey_cmp(const void *a, const void *b) {
  const FKey *p = a, *q = b;
  for (int k = 0; k < 3; k++)
    if (p->x[k] != q->x[k]) return p->x[k] < q->x[k] ? -1 : 1;
  return (p->i > q->i) - (p->i < q->i);
}

/* A triangle by its vertex set (sorted), then its index. */
typedef struct { int s[3]; int t; } TKey;

static int tkey_cmp(const void *a, const void *b) {
  const TKey *p = a, *q = b;
  for (int k = 0; k < 3; k++)
    if (p->s[k] != q->s[k]) return p->s[k] < q->s[k] ? -1 : 1;
  return (p->t > q->t) - (p->t < q->t);
}

/* 1 if triangles a and b (on one vertex set) go round it the same way. */
static int same_turn(const int *a, const int *b) {
  for (int r = 0; r < 3; r++)
    if (a[0] == b[r] && a[1] == b[(r + 1) % 3]) return 1;
  return 0;
}

static void sort3(const int *t, int s[3]) {
  int a = t[0], b = t[1], c = t[2], x;
  if (a > b) x = a, a = b, b = x;
  if (b > c) x = b, b = c, c = x;
  if (a > b) x = a, a = b, b = x;
  s[0] = a, s[1] = b, s[2] = c;
}


static int find(int *par, int i) {
  while (par[i] != i) i = par[i] = par[par[i]];
  return i;
}

/* Where the joining left a vertex of two or more fans (two cones of the
   solid that all but touched at a point, now touching there): each fan
   given its own vertex, moved into its own part (against the fan's
   normal, area-weighted) by nudge, then rounded to floats. fm->v grows.
   Returns the fans parted, or -1 out of memory, -2 when a fan has no
   normal or a moved vertex lands on a float place already taken. */
static long part_fans(Mesh *fm, double nudge) {
  size_t nv = fm->nv, nt = fm->nt;
  long parted = 0;
  int *cnt = calloc(nv + 1, sizeof *cnt), *cn = malloc(3 * nt * sizeof *cn),
      *par = malloc(3 * nt * sizeof *par), *pos = malloc((nv + 1) * sizeof *pos);
  if (!cnt || !cn || !par || !pos) {
    parted = -1;
    goto out;
  }
  for (size_t i = 0; i < 3 * nt; i++) cnt[fm->t[i] + 1]++;
  for (size_t v = 0; v < nv; v++) cnt[v + 1] += cnt[v];
  memcpy(pos, cnt, (nv + 1) * sizeof *pos);
  for (size_t i = 0; i < 3 * nt; i++) cn[pos[fm->t[i]]++] = (int)i;
  for (size_t i = 0; i < 3 * nt; i++) par[i] = (int)i;
  for (size_t v = 0; v < nv; v++) {
    int a0 = cnt[v], a1 = cnt[v + 1], fans = 0;
    /* corners of v joined where their triangles share an edge at v */
    for (int x = a0; x < a1; x++)
      for (int y = x + 1; y < a1; y++) {
        size_t tx = (size_t)cn[x] / 3, kx = (size_t)cn[x] % 3;
        size_t ty = (size_t)cn[y] / 3, ky = (size_t)cn[y] % 3;
        int bx = fm->t[3 * tx + (kx + 1) % 3], cx = fm->t[3 * tx + (kx + 2) % 3];
        int by = fm->t[3 * ty + (ky + 1) % 3], cy = fm->t[3 * ty + (ky + 2) % 3];
        if (bx == cy || cx == by || bx == by || cx == cy) {
          int p = find(par, cn[x]), q = find(par, cn[y]);
          if (p != q) par[p] = q;
        }
      }
    for (int x = a0; x < a1; x++) fans += find(par, cn[x]) == cn[x];
    if (fans < 2) continue;
    /* every fan its own vertex, moved into its part */
    for (int x = a0; x < a1; x++) {
      int root = find(par, cn[x]);
      if (root != cn[x]) continue;
      double N[3] = {0, 0, 0};
      for (int y = a0; y < a1; y++) {
        if (find(par, cn[y]) != root) continue;
        const int *t = fm->t + 3 * ((size_t)cn[y] / 3);
        const double *A = fm->v + 3 * (size_t)t[0], *B = fm->v + 3 * (size_t)t[1],
                     *C = fm->v + 3 * (size_t)t[2];
        double u[3] = {B[0] - A[0], B[1] - A[1], B[2] - A[2]},
               w[3] = {C[0] - A[0], C[1] - A[1], C[2] - A[2]};
        N[0] += u[1] * w[2] - u[2] * w[1];
        N[1] += u[2] * w[0] - u[0] * w[2];
        N[2] += u[0] * w[1] - u[1] * w[0];
      }
      double l = sqrt(N[0] * N[0] + N[1] * N[1] + N[2] * N[2]);
      if (!(l > 0)) {
        parted = -2;
        goto out;
      }
      size_t w = fm->nv;
      double *nvv = realloc(fm->v, 3 * (w + 1) * sizeof *fm->v);
      if (!nvv) {
        parted = -1;
        goto out;
      }
      fm->v = nvv;
      if (fm->rgb) {
        float *nc = realloc(fm->rgb, 3 * (w + 1) * sizeof *fm->rgb);
        if (!nc) {
          parted = -1;
          goto out;
        }
        fm->rgb = nc;
        memcpy(fm->rgb + 3 * w, fm->rgb + 3 * v, 3 * sizeof *nc);
      }
      for (int k = 0; k < 3; k++)
        fm->v[3 * w + (size_t)k] = (double)(float)(fm->v[3 * v + (size_t)k] - nudge * N[k] / l);
      fm->nv++;
      for (int y = a0; y < a1; y++)
        if (find(par, cn[y]) == root) fm->t[cn[y]] = (int)w;
      parted++;
    }
  }
out:
  free(cnt);
  free(cn);
  free(par);
  free(pos);
  return parted;
}

/* The other way, when joining fails its checks: the vertices that share
   a float place kept apart, each moved into its own part (against its
   fan's normal, area-weighted) by nudge, doubled while their floats
   still meet another's, up to maxmove; every vertex rounded to floats,
   the triangles as they were. fk holds the vertices sorted by their
   floats. Into *fm (a copy); 0, -1 out of memory, -2 when a vertex has
   no normal or its nudge would pass maxmove. */
static int apart(const Mesh *m, const FKey *fk, double nudge, double maxmove,
                 Mesh *fm, double *moved) {
  size_t nv = m->nv, nt = m->nt;
  double *N = calloc(6 * nv, sizeof *N); /* normal, far vertices */
  unsigned char *hit = calloc(nv, 1);
  FKey *fk2 = NULL;
  fm->v = malloc(3 * nv * sizeof *fm->v);
  fm->t = malloc(3 * nt * sizeof *fm->t);
  fm->rgb = m->rgb ? malloc(3 * nv * sizeof *fm->rgb) : NULL;
  int rc = -1;
  if (!N || !hit || !fm->v || !fm->t || (m->rgb && !fm->rgb)) goto out;
  fm->nv = nv;
  fm->nt = nt;
  memcpy(fm->t, m->t, 3 * nt * sizeof *fm->t);
  if (m->rgb) memcpy(fm->rgb, m->rgb, 3 * nv * sizeof *fm->rgb);
  for (size_t i = 0; i < 3 * nv; i++) fm->v[i] = (double)(float)m->v[i];
  for (size_t a = 0; a < nv;) {
    size_t b = a + 1;
    while (b < nv && !memcmp(fk[b].x, fk[a].x, sizeof fk[a].x)) b++;
    for (size_t c = a; b - a > 1 && c < b; c++) hit[fk[c].i] = 1;
    a = b;
  }
  for (size_t t = 0; t < nt; t++) {
    const int *q = m->t + 3 * t;
    const double *A = m->v + 3 * (size_t)q[0], *B = m->v + 3 * (size_t)q[1],
                 *C = m->v + 3 * (size_t)q[2];
    double u[3] = {B[0] - A[0], B[1] - A[1], B[2] - A[2]},
           w[3] = {C[0] - A[0], C[1] - A[1], C[2] - A[2]},
           n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2],
                   u[0] * w[1] - u[1] * w[0]};
    for (int k = 0; k < 3; k++)
      if (hit[q[k]]) {
        size_t v = (size_t)q[k];
        for (int j = 0; j < 3; j++) {
          N[6 * v + (size_t)j] += n[j];
          /* the far vertices, each twice over the fan */
          N[6 * v + 3 + (size_t)j] += m->v[3 * (size_t)q[(k + 1) % 3] + (size_t)j] +
                                      m->v[3 * (size_t)q[(k + 2) % 3] + (size_t)j] -
                                      2 * m->v[3 * v + (size_t)j];
        }
      }
  }
  for (size_t v = 0; v < nv; v++) {
    if (!hit[v]) continue;
    /* into the part: towards the far vertices' centroid where it lies
       behind the fan (a corner's tip: the way that leaves the faces it
       all but touches), else against the normal */
    const double *P = m->v + 3 * v, *nn = N + 6 * v, *cc = N + 6 * v + 3;
    double n[3], l = sqrt(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]),
           lc = sqrt(cc[0] * cc[0] + cc[1] * cc[1] + cc[2] * cc[2]);
    if (!(l > 0)) {
      rc = -2;
      goto out;
    }
    int toc = lc > 0 && cc[0] * nn[0] + cc[1] * nn[1] + cc[2] * nn[2] < 0;
    for (int k = 0; k < 3; k++) n[k] = toc ? -cc[k] : nn[k];
    if (toc) l = lc;
    for (double d = nudge;; d *= 2) {
      if (d > maxmove) {
        rc = -2;
        goto out;
      }
      float f[3];
      for (int k = 0; k < 3; k++) f[k] = (float)(P[k] - d * n[k] / l);
      /* its floats no other vertex's (those of the vertices in fk
         order, by bisection; the moved ones checked below) */
      size_t lo = 0, hi = nv;
      while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        FKey key = {{f[0], f[1], f[2]}, -1};
        if (fkey_cmp(fk + mid, &key) < 0) lo = mid + 1;
        else hi = mid;
      }
      if (lo < nv && !memcmp(fk[lo].x, f, sizeof f)) continue;
      for (int k = 0; k < 3; k++) fm->v[3 * v + (size_t)k] = f[k];
      double e = 0;
      for (int k = 0; k < 3; k++) e += (f[k] - P[k]) * (f[k] - P[k]);
      *moved = fmax(*moved, sqrt(e));
      break;
    }
  }
  /* the moved vertices' floats apart from each other too */
  size_t nh = 0;
  for (size_t v = 0; v < nv; v++)
    if (hit[v]) {
      fk2 = fk2 ? fk2 : malloc(nv * sizeof *fk2);
      if (!fk2) goto out;
      for (int k = 0; k < 3; k++) fk2[nh].x[k] = (float)fm->v[3 * v + (size_t)k];
      fk2[nh++].i = (int)v;
    }
  if (nh) qsort(fk2, nh, sizeof *fk2, fkey_cmp);
  for (size_t i = 1; i < nh; i++)
    if (!memcmp(fk2[i].x, fk2[i - 1].x, sizeof fk2[i].x)) {
      rc = -2;
      goto out;
    }
  rc = 0;
out:
  free(N);
  free(hit);
  free(fk2);
  return rc;
}

int mesh_to_floats(Mesh *m, double maxmove, MeshFloatReport *r) {
  memset(r, 0, sizeof *r);
  size_t nv = m->nv, nt = m->nt;
  if (!nv || !nt) return 0;
  int rc = -1;
  FKey *fk = malloc(nv * sizeof *fk);
  int *rep = malloc(nv * sizeof *rep), *nt3 = NULL, *newi = NULL;
  TKey *tk = NULL;
  unsigned char *drop = NULL;
  Mesh fm = {0};
  if (!fk || !rep) goto out;
  for (size_t v = 0; v < nv; v++) {
    for (int k = 0; k < 3; k++) fk[v].x[k] = (float)m->v[3 * v + (size_t)k];
    fk[v].i = (int)v;
  }
  qsort(fk, nv, sizeof *fk, fkey_cmp);
  for (size_t a = 0; a < nv;) {
    size_t b = a + 1;
    while (b < nv && !memcmp(fk[b].x, fk[a].x, sizeof fk[a].x)) b++;
    for (size_t c = a; c < b; c++) rep[fk[c].i] = fk[a].i; /* the least index */
    r->joined += (long)(b - a - 1);
    a = b;
  }
  if (!r->joined) {
    rc = 0;
    goto out;
  }
  /* the triangles on the joined vertices: those that closed up (a
     vertex twice) dropped, then pairs on one vertex set facing apart */
  nt3 = malloc(3 * nt * sizeof *nt3);
  tk = malloc(nt * sizeof *tk);
  drop = calloc(nt, 1);
  newi = malloc(nv * sizeof *newi);
  if (!nt3 || !tk || !drop || !newi) goto out;
  size_t nk = 0;
  for (size_t t = 0; t < nt; t++) {
    int *u = nt3 + 3 * t;
    for (int k = 0; k < 3; k++) u[k] = rep[m->t[3 * t + (size_t)k]];
    if (u[0] == u[1] || u[1] == u[2] || u[2] == u[0]) {
      drop[t] = 1;
      r->closed++;
      continue;
    }
    sort3(u, tk[nk].s);
    tk[nk++].t = (int)t;
  }
  qsort(tk, nk, sizeof *tk, tkey_cmp);
  for (size_t a = 0; a < nk;) {
    size_t b = a + 1;
    while (b < nk && !memcmp(tk[b].s, tk[a].s, sizeof tk[a].s)) b++;
    /* pair each with one facing the other way, in index order */
    for (size_t x = a; x < b; x++) {
      if (drop[tk[x].t]) continue;
      for (size_t y = x + 1; y < b; y++)
        if (!drop[tk[y].t] &&
            !same_turn(nt3 + 3 * (size_t)tk[x].t, nt3 + 3 * (size_t)tk[y].t)) {
          drop[tk[x].t] = drop[tk[y].t] = 1;
          r->pairs++;
          break;
        }
    }
    a = b;
  }
  /* the used vertices, at their floats, in their first order */
  for (size_t v = 0; v < nv; v++) newi[v] = -1;
  size_t fnv = 0, fnt = 0;
  for (size_t t = 0; t < nt; t++)
    if (!drop[t])
      for (int k = 0; k < 3; k++) {
        int v = nt3[3 * t + (size_t)k];
        if (newi[v] < 0) newi[v] = (int)fnv++;
      }
  fm.v = malloc(3 * (fnv ? fnv : 1) * sizeof *fm.v);
  fm.t = malloc(3 * (nt ? nt : 1) * sizeof *fm.t);
  if (m->rgb) fm.rgb = malloc(3 * (fnv ? fnv : 1) * sizeof *fm.rgb);
  if (!fm.v || !fm.t || (m->rgb && !fm.rgb)) goto out;
  for (size_t v = 0; v < nv; v++) {
    if (newi[v] < 0) continue;
    size_t w = (size_t)newi[v];
    for (int k = 0; k < 3; k++) {
      fm.v[3 * w + (size_t)k] = (double)(float)m->v[3 * v + (size_t)k];
      if (fm.rgb) fm.rgb[3 * w + (size_t)k] = m->rgb[3 * v + (size_t)k];
    }
  }
  for (size_t v = 0; v < nv; v++) { /* every vertex's move to its place */
    const double *p = m->v + 3 * v, *q = m->v + 3 * (size_t)rep[v];
    double d = 0;
    for (int k = 0; k < 3; k++) {
      double e = p[k] - (double)(float)q[k];
      d += e * e;
    }
    r->moved = fmax(r->moved, sqrt(d));
  }
  for (size_t t = 0; t < nt; t++)
    if (!drop[t]) {
      for (int k = 0; k < 3; k++) fm.t[3 * fnt + (size_t)k] = newi[nt3[3 * t + (size_t)k]];
      fnt++;
    }
  fm.nv = fnv;
  fm.nt = fnt;
  /* the fans the joining made meet at a point parted again: by 2^-18 of
     the mesh's size, 64 floats' ulps of its largest coordinate */
  double big = 0;
  for (size_t i = 0; i < 3 * fnv; i++) big = fmax(big, fabs(fm.v[i]));
  double nudge = 0x1p-18 * big;
  long parted = nudge <= maxmove ? part_fans(&fm, nudge) : 0;
  if (parted == -1) goto out;
  if (parted == -2) r->why = MF_FANS;
  if (parted > 0) {
    /* the vertices kept that were parted, now unused, left out: their
       places are every fan's own */
    size_t *keep = malloc(fm.nv * sizeof *keep);
    unsigned char *used = calloc(fm.nv, 1);
    if (!keep || !used) {
      free(keep);
      free(used);
      goto out;
    }
    for (size_t i = 0; i < 3 * fm.nt; i++) used[fm.t[i]] = 1;
    size_t n = 0;
    for (size_t v = 0; v < fm.nv; v++) {
      keep[v] = n;
      if (!used[v]) continue;
      memmove(fm.v + 3 * n, fm.v + 3 * v, 3 * sizeof *fm.v);
      if (fm.rgb) memmove(fm.rgb + 3 * n, fm.rgb + 3 * v, 3 * sizeof *fm.rgb);
      n++;
    }
    for (size_t i = 0; i < 3 * fm.nt; i++) fm.t[i] = (int)keep[fm.t[i]];
    fm.nv = n;
    free(keep);
    free(used);
    r->parted = parted;
    r->moved += nudge + 0x1p-23 * big; /* the place, the move, its rounding */
  }
  /* the checks, on the floats: as the doubles' mesh passed them */
  MeshCheck before, after;
  MeshSelfCheck sc;
  int c0 = mesh_check(m, &before), c1 = fnt ? mesh_check(&fm, &after) : -1;
  if (c0 == -2 || c1 == -2) goto out;
  int s = c1 == 0 ? mesh_self_check(&fm, &sc) : 1;
  if (s == -2) goto out;
  r->why = r->why ? r->why : c0 ? MF_BEFORE : c1 ? MF_CLOSURE : s ? MF_SELF
         : after.components != before.components || after.euler != before.euler ? MF_TOPOLOGY
         : 0;
  if (c1 == -1) {
    r->boundary = after.boundary_edges;
    r->nonmanifold = after.nonmanifold_edges + after.nonmanifold_verts;
  }
  r->ok = !r->why;
  if (!r->ok && nudge <= maxmove) {
    /* the other way: nothing joined, the vertices on one float place
       moved apart into their parts */
    free(fm.v);
    free(fm.t);
    free(fm.rgb);
    fm = (Mesh){0};
    double mv = 0;
    int a = apart(m, fk, nudge, maxmove, &fm, &mv);
    if (a == -1) goto out;
    int sa = a == 0 ? mesh_self_check(&fm, &sc) : 1;
    if (sa == -2) goto out;
    if (sa != 0) r->why_apart = a == -2 ? MF_FANS : MF_SELF;
    if (sa == 0) {
      r->ok = 1;
      r->kept_apart = 1;
      r->parted = r->closed = r->pairs = 0;
      r->moved = mv;
      r->why = 0;
    }
  }
  if (r->ok) {
    free(m->v);
    free(m->t);
    free(m->rgb);
    *m = fm;
    fm = (Mesh){0};
  }
  rc = 0;
out:
  free(fk);
  free(rep);
  free(nt3);
  free(tk);
  free(drop);
  free(newi);
  free(fm.v);
  free(fm.t);
  free(fm.rgb);
  return rc;
}
