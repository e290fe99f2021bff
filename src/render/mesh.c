/* mesh.c: the adaptive octree, its conforming tetrahedra, marching and
   exact (sharp) tetrahedra, the checks and the writers (see mesh.h). */
#include "render/mesh.h"

#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#include <zip.h>
#include <fcntl.h>
#include <sys/resource.h>

#include "core/bounds.h"
#include "core/interval.h"
#include "core/mix.h"
#include "core/vec.h"
#include "render/image.h"
#include "render/mesh_check.h"
#include "render/mesh_cover.h"
#include "render/mesh_exact.h"
#include "render/mesh_merge.h"
#include "render/render.h"
#include "scene/ray.h"

#define MAX_DEPTH 19       /* grid coordinates fit 20 bits */
/* weld joins edges shorter than this (of the octree's side) */
#define WELD 0x1p-46
/* the second try's weld of vertices on no common edge: 2^-39 of the size
   (prisms of 60 to 80 sides corner to corner, turned: their corners'
   faces all but in one plane, the exact points spread along the line of
   contact by up to 4e-13; 2^-40 left 63 and 62 sides turned thrice,
   fuzz-prisms seed 44 s233, refused) */
#define NEAR_WELD 128
/* Times the flat merge is done again with the regions where it met
   itself kept as made, before it is undone */
#define FLAT_TRIES 8
/* Cells where two surfaces, each one sheet, are not proven one sheet
   together split this many levels below the finest at most (walk). */
#define TWO_LEVELS 2
/* Rounds of splitting the cells where the surface is not proven within
   the tolerance of the mesh (mesh_rounds). */
#define COVER_ROUNDS 4
/* Failing cells within this many finest cells of a cell with two surfaces
   not proven one sheet together are not split for the cover proof. */
#define NEAR_TWO 2
/* ... unless at most this many are left and no others (cover_check) */
#define WIDE_MAX 64
/* ... or at most this many, the round kept only with the topology of
   the mesh before the rounds (a groove: mesh_rounds) */
#define WIDE_SPLIT_MAX 2048

static Mesh *mesh_copy(const Mesh *m);

/* mesh_run's answer: mesh again (cover_check split cells) */
#define MESH_RECOVER 100
/* A mesh needs about this many bytes per marching triangle at its peak
   (vertices, triangles, the octree's maps, the checks' tables): 112 to
   140 measured (peak RSS over the triangles before flat regions are
   merged: `Rounded 0.1 UnitCube` at 1e-4, figure12's obj2, a soft pair);
   the estimate before the crossings are sought takes the lower end, the
   resident memory checked as the work goes on takes the rest */
#define TRI_BYTES 75
/* mesh_run's answer: mesh again, the sharp cells at a crack or a
   self-intersection meshed by their tetrahedra (sharp_apart) */
#define MESH_RESHARP 101
/* Times mesh_scene meshes again so (then every sharp cell is given up) */
#define RESHARP_TRIES 6

/* ---- a hash map from 64-bit keys to ints ------------------------------ */

typedef struct {
  uint64_t *k;             /* key + 1; 0 is free */
  int *v;
  size_t cap, n;
} hmap;

static size_t hslot(const hmap *h, uint64_t key) {
  /* every key bit reaches the low bits (point keys have their low bits
     0 when cells stop above the deepest level) */
  size_t i = (size_t)mix64(key) & (h->cap - 1);
  while (h->k[i] && h->k[i] != key + 1) i = (i + 1) & (h->cap - 1);
  return i;
}

static int hgrow(hmap *h) {
  size_t ncap = h->cap ? h->cap * 2 : 1024;
  hmap g = {calloc(ncap, sizeof *g.k), malloc(ncap * sizeof *g.v), ncap, 0};
  if (!g.k || !g.v) {
    free(g.k);
    free(g.v);
    return -1;
  }
  for (size_t i = 0; i < h->cap; i++)
    if (h->k[i]) {
      size_t j = hslot(&g, h->k[i] - 1);
      g.k[j] = h->k[i];
      g.v[j] = h->v[i];
    }
  g.n = h->n;
  free(h->k);
  free(h->v);
  *h = g;
  return 0;
}

/* The value of key, or -1 if absent. */
static int hget(const hmap *h, uint64_t key) {
  if (!h->cap) return -1;
  size_t i = hslot(h, key);
  return h->k[i] ? h->v[i] : -1;
}

static int hput(hmap *h, uint64_t key, int v) {
  if (2 * (h->n + 1) > h->cap && hgrow(h) < 0) return -1;
  size_t i = hslot(h, key);
  if (!h->k[i]) h->n++;
  h->k[i] = key + 1;
  h->v[i] = v;
  return 0;
}

static void hfree(hmap *h) {
  free(h->k);
  free(h->v);
}

/* ---- a hash map from 4 x 64-bit keys to ints ------------------------------ */

typedef struct {
  uint64_t *k;             /* 4 per slot */
  int *v;                  /* -1: free */
  size_t cap, n;
} kmap;

static size_t kslot(const kmap *h, const uint64_t *key) {
  uint64_t x = 0;
  for (int i = 0; i < 4; i++) {
    x ^= key[i] + 0x9E3779B97F4A7C15ull + (x << 6) + (x >> 2);
    x *= 0xBF58476D1CE4E5B9ull;
  }
  x ^= x >> 31;
  size_t i = (size_t)x & (h->cap - 1);
  while (h->v[i] >= 0 && memcmp(h->k + 4 * i, key, 4 * sizeof *key))
    i = (i + 1) & (h->cap - 1);
  return i;
}

static int kmap_get(const kmap *h, const uint64_t *key) {
  return h->cap ? h->v[kslot(h, key)] : -1;
}

static int kmap_put(kmap *h, const uint64_t *key, int v) {
  if (2 * (h->n + 1) > h->cap) {
    size_t nc = h->cap ? 2 * h->cap : 1024;
    kmap g = {malloc(4 * nc * sizeof *g.k), malloc(nc * sizeof *g.v), nc, h->n};
    if (!g.k || !g.v) {
      free(g.k);
      free(g.v);
      return -1;
    }
    for (size_t i = 0; i < nc; i++) g.v[i] = -1;
    for (size_t i = 0; i < h->cap; i++)
      if (h->v[i] >= 0) {
        size_t j = kslot(&g, h->k + 4 * i);
        memcpy(g.k + 4 * j, h->k + 4 * i, 4 * sizeof *g.k);
        g.v[j] = h->v[i];
      }
    free(h->k);
    free(h->v);
    *h = g;
  }
  size_t i = kslot(h, key);
  if (h->v[i] < 0) h->n++;
  memcpy(h->k + 4 * i, key, 4 * sizeof *key);
  h->v[i] = v;
  return 0;
}

/* ---- proofs over a box -------------------------------------------------- */

/* T_ONE: undecided, but the solid in the box is decided by one node's
   inside test; T_PL: undecided, and every undecided leaf below is a sharp
   halfspace. */
enum { T_OUT = CSG_BOX_OUT, T_IN = CSG_BOX_IN, T_MIX = CSG_BOX_MIX, T_ONE = 3,
       T_PL = 4 };

static int leaf_box(const ScNode *nd, const double lo[3], const double hi[3]) {
  switch (nd->kind) {
  case SC_HALFSPACE: {
    double rl, rh;
    vec3_plane_range(nd->n, nd->d, lo, hi, &rl, &rh);
    return rh < 0 ? T_IN : (rl > 0 ? T_OUT : T_ONE);
  }
  case SC_ROUNDED: {
    if (nd->outer && csg_box_class(nd->outer, lo, hi) == T_OUT) return T_OUT;
    if (nd->inner && csg_box_class(nd->inner, lo, hi) == T_IN) return T_IN;
    double dl, dh;
    dt_range_box(nd->tape, lo, hi, &dl, &dh);
    return dh < 0.5 ? T_OUT : (dl > 0.5 ? T_IN : T_ONE);
  }
  case SC_SOFT: {
    double fl, fh, mg = soft_magic(nd->soft);
    soft_field_box(nd->soft, lo, hi, &fl, &fh);
    return fh < mg ? T_OUT : (fl > mg ? T_IN : T_ONE);
  }
  case SC_EMPTY: return T_OUT;
  case SC_ALL: return T_IN;
  default: return T_MIX;
  }
}

/* Nodes a and b have the same surface: the same node, or two halfspaces
   on one plane (either side). */
static int same_surface(const Scene *s, int a, int b) {
  if (a == b) return 1;
  const ScNode *x = &s->nodes[a], *y = &s->nodes[b];
  if (x->kind != SC_HALFSPACE || y->kind != SC_HALFSPACE) return 0;
  int same = 1, opp = 1;
  for (int i = 0; i < 3; i++) {
    same &= x->n[i] == y->n[i];
    opp &= x->n[i] == -y->n[i];
  }
  return (same && x->d == y->d) || (opp && x->d == -y->d);
}

/* Node x's surface over [lo, hi] is one plane, (*n, *d) with the solid on
   one side (n . p < d, or > d): a halfspace's, or a rounded node's whose
   tape folded over the box (each leaf whose filter misses it a constant)
   has one leaf left (r > 0), met once in the tape, and
   whose density with that leaf at 0.5 (the others are 0 or 1 over the
   box) is exactly 0.5. The density is then affine in that leaf's value
   (every operation has a constant operand), not constant (the node is
   undecided), so its 0.5 level is where the leaf is 0.5: its plane. */
static int node_plane(const Scene *s, int x, const double lo[3],
                      const double hi[3], const double **n, double *d,
                      int *side) {
  const ScNode *nd = &s->nodes[x];
  *side = 1;
  if (nd->kind == SC_HALFSPACE) {
    *n = nd->n;
    *d = nd->d;
    return 1;
  }
  if (nd->kind != SC_ROUNDED) return 0;
  /* the tape folded over the box (dt_prune_class: a leaf whose filter
     misses it is a constant there), so that a leaf multiplied by one at
     0 there (the infinite plane of a far cylinder's facet passing
     through the box) is not counted live */
  const dt_tape *t0 = nd->tape;
  size_t nl = (size_t)t0->nleaves, nc = (size_t)t0->ncode,
         np = t0->prog ? (size_t)t0->prog->npcode : 0;
  void *mem = malloc(nl + nc * sizeof(dt_instr) + np * sizeof(dt_instr) +
                     nl * sizeof(dt_leaf) + nl * sizeof(int) + 64);
  if (!mem) return 0;
  dt_instr *code = mem, *pcode = code + nc;
  dt_leaf *lv = (dt_leaf *)(pcode + np);
  int *livei = (int *)(lv + nl);
  signed char *cls = (signed char *)(livei + nl);
  int reach = t0->live ? t0->nlive : t0->nleaves;
  for (int q = 0; q < reach; q++) {
    int i = t0->live ? t0->live[q] : q;
    const dt_leaf *lf = &t0->leaves[i];
    double rl, rh;
    vec3_plane_range(lf->n, lf->d, lo, hi, &rl, &rh);
    if (lf->r <= 0) cls[i] = rl > 0 ? 0 : rh < 0 ? 1 : -1;
    else cls[i] = rl >= lf->r ? 0 : rh <= -lf->r ? 1 : -1;
  }
  dt_prune_prog pg;
  dt_tape tv;
  dt_prune_class(t0, cls, code, lv, pcode, &pg, livei, &tv);
  const dt_tape *t = &tv;
  int live = -1, seen = 0;
  /* the whole code: a leaf met again after another (a, b, ..., a) is
     not one leaf met once */
  for (int i = 0; i < t->ncode; i++)
    if (t->code[i].op == DT_LEAF) {
      if (live >= 0 && t->code[i].arg != live) {
        seen = 2;
        break;
      }
      live = t->code[i].arg;
      seen++;
    }
  double vl = 0, vh = 0;
  if (live >= 0) dt_range_box_fix(t, lo, hi, live, 0.5, &vl, &vh);
  if (live < 0 || seen != 1 || t->leaves[live].r <= 0 || vl != 0.5 || vh != 0.5) {
    free(mem);
    return 0;
  }
  /* the plane as t0 holds it (the view's leaves may be copies) */
  const dt_leaf *lp = &t->leaves[live];
  *n = NULL;
  for (int q = 0; q < reach && !*n; q++) {
    int i = t0->live ? t0->live[q] : q;
    if (!memcmp(&t0->leaves[i], lp, sizeof *lp)) {
      *n = t0->leaves[i].n;
      *d = t0->leaves[i].d;
    }
  }
  if (!*n) {
    free(mem);
    return 0;
  }
  /* the density is affine in the leaf, 0.5 where it is 0.5: inside is
     where the leaf is above 0.5 (n . x < d) if it rises with the leaf */
  dt_range_box_fix(t, lo, hi, live, 0.75, &vl, &vh);
  *side = vl > 0.5 ? 1 : vh < 0.5 ? -1 : 0;
  free(mem);
  return 1;
}

/* Nodes a and b (not both halfspaces: same_surface has them) have one
   plane for their surface over [lo, hi] (node_plane), either side: 1 if
   their insides are on one side of it, 2 if on opposite sides (they
   complement each other over the box), 3 if that is not known; else 0. */
static int same_plane_box(const Scene *s, int a, int b, const double lo[3],
                          const double hi[3]) {
  const double *na, *nb;
  double da, db;
  int sa, sb;
  if (s->nodes[a].kind == SC_HALFSPACE && s->nodes[b].kind == SC_HALFSPACE)
    return 0;
  if (!node_plane(s, a, lo, hi, &na, &da, &sa) ||
      !node_plane(s, b, lo, hi, &nb, &db, &sb))
    return 0;
  int same = 1, opp = 1;
  for (int i = 0; i < 3; i++) {
    same &= na[i] == nb[i];
    opp &= na[i] == -nb[i];
  }
  if (!((same && da == db) || (opp && da == -db))) return 0;
  if (!sa || !sb) return 3;
  return (sa == sb) == same ? 1 : 2; /* b's side in a's frame */
}

/* A set operation on classes. T_ONE (undecided, but the solid in the box
   is decided by one node's inside test, so the surface there is that
   node's) carries its node in *o. With flush set, two
   nodes whose surfaces over the box [lo, hi] are one plane
   (same_plane_box: a rounded node with one live leaf, a halfspace) count
   as the same surface, as two halfspaces on one plane do: a rounded box
   resting flush on another is then one surface there (none, or the
   plane), not two sheets facing each other. With flush 2 (the cover
   proof's), two such nodes whose insides complement each other over the
   box decide it: their union is full there, their intersection empty,
   the difference a - b is a. */
static int set_op(const Scene *s, ScKind k, int a, int oa, int b, int ob,
                  int *o, const double *lo, const double *hi, int flush) {
  int ra, rb; /* the classes that decide alone */
  switch (k) {
  case SC_UNION:
    if (a == T_IN || b == T_IN) return T_IN;
    ra = b == T_OUT;
    rb = a == T_OUT;
    break;
  case SC_INTER:
    if (a == T_OUT || b == T_OUT) return T_OUT;
    ra = b == T_IN;
    rb = a == T_IN;
    break;
  default: /* a - b */
    if (a == T_OUT || b == T_IN) return T_OUT;
    if (a == T_IN && b == T_OUT) return T_IN;
    ra = b == T_OUT;
    rb = a == T_IN;
    break;
  }
  if (ra) { /* the result is a */
    *o = oa;
    return a;
  }
  if (rb) { /* the result is b, or the complement of b */
    *o = ob;
    return b;
  }
  int sp = a == T_ONE && b == T_ONE && !same_surface(s, oa, ob) && flush
               ? same_plane_box(s, oa, ob, lo, hi)
               : 0;
  if (sp == 2 && flush == 2 && k != SC_DIFF) return k == SC_UNION ? T_IN : T_OUT;
  if (sp == 2 && flush == 2) {
    *o = oa;
    return T_ONE;
  }
  if (a == T_ONE && b == T_ONE && (same_surface(s, oa, ob) || sp)) {
    *o = oa;
    return T_ONE;
  }
  if ((a == T_PL || (a == T_ONE && s->nodes[oa].kind == SC_HALFSPACE)) &&
      (b == T_PL || (b == T_ONE && s->nodes[ob].kind == SC_HALFSPACE)))
    return T_PL;
  return T_MIX;
}

/* The node over the box, children first (st and one have room for the
   subtree); *onep is the node deciding a T_ONE result. flush as set_op's. */
static int scene_box_g(const Scene *s, int node, const double lo[3],
                       const double hi[3], unsigned char *st, int *one,
                       int *onep, int flush, const unsigned char *forced) {
  int f = s->nodes[node].first;
  for (int i = f; i <= node; i++) {
    const ScNode *nd = &s->nodes[i];
    int r, o = i;
    switch (nd->kind) {
    case SC_UNION:
    case SC_INTER:
    case SC_DIFF:
      r = set_op(s, nd->kind, st[nd->a - f], one[nd->a - f], st[nd->b - f],
                 one[nd->b - f], &o, lo, hi, flush);
      break;
    default:
      r = forced && forced[i - f] ? forced[i - f] - 1 : leaf_box(nd, lo, hi);
      break;
    }
    st[i - f] = (unsigned char)r;
    one[i - f] = o;
  }
  *onep = one[node - f];
  return st[node - f];
}


/* ---- the gradient of a density tape over a box -------------------------- */

/* Over a box the gradient of a density tape is sum_k c_k n_k over its
   leaves k whose filter meets the box (n_k the leaf's unit normal), with
   c_k = d rho / d s_k bounded by forward-mode interval arithmetic: a leaf's
   own derivative 3/4 (alpha^2 - 1) / r over its alpha range, the product
   and union rules with the operands' value ranges. Keeping one interval
   per leaf, not per axis, keeps a lone leaf's gradient exactly along its
   normal, so a flat face of a rounded solid is seen to be flat. At most
   GR_MAX leaves are kept; past that the least (by the largest |c_k|) go
   into a remainder, the sum of their c_k n_k bounded per axis (a
   rounded hole of 50 faces has some 36 of them live at its rim, most
   with c_k near 0; a rounded cone's apex, all 50: without the remainder
   no bound at all was found there, and the rim or the apex split to the
   octree's limit). */
#define GR_MAX 16

typedef struct {
  double l, h;             /* the value range */
  int n;                   /* leaves whose filter meets the box */
  int leaf[GR_MAX];
  unsigned char step[GR_MAX]; /* a sharp leaf: no derivative, a jump */
  double cl[GR_MAX], ch[GR_MAX];
  double rl[3], rh[3];     /* the leaves' part not kept, per axis */
} GrIv;

/* [*l, *h] += [a, b], rounded outwards (with room) */
static void gr_acc(double *l, double *h, double a, double b) {
  *l += a;
  *h += b;
  *l -= 4 * DBL_EPSILON * fabs(*l);
  *h += 4 * DBL_EPSILON * fabs(*h);
}

/* The remainder of o += c n, c in [l, h]. */
static void gr_rest_add(GrIv *o, const double n[3], double l, double h) {
  for (int q = 0; q < 3; q++) {
    double a, b;
    iv_mul(n[q], n[q], l, h, &a, &b);
    gr_acc(&o->rl[q], &o->rh[q], a, b);
  }
}

static int gr_rest_none(const GrIv *r) {
  for (int q = 0; q < 3; q++)
    if (r->rl[q] != 0 || r->rh[q] != 0) return 0;
  return 1;
}

/* The remainder R of r: its middle into mid (added), the bounds of
   u . R into *al, *ah (added; u may be NULL), and the length of its
   half-widths (a bound of |R - mid|), returned; HUGE_VAL if not finite. */
static double gr_rest(const GrIv *r, const double *u, double mid[3], double *al,
                      double *ah) {
  double w2 = 0;
  for (int q = 0; q < 3; q++) {
    if (!isfinite(r->rl[q]) || !isfinite(r->rh[q])) return HUGE_VAL;
    mid[q] += 0.5 * (r->rl[q] + r->rh[q]);
    double hw = 0.5 * (r->rh[q] - r->rl[q]);
    w2 += hw * hw;
    if (u) {
      double a, b;
      iv_mul(u[q], u[q], r->rl[q], r->rh[q], &a, &b);
      *al += a;
      *ah += b;
    }
  }
  return sqrt(w2) * (1 + 1e-12) + 1e-300;
}

/* Adds leaf's coefficient [l, h] to o as a new entry; when o is full,
   the entry of least magnitude (this one or a kept one, not a step) goes
   into the remainder. 0, or -1 when every entry is a step. */
static int gr_push(GrIv *o, const dt_leaf *lv, int leaf, unsigned char step,
                   double l, double h) {
  if (o->n < GR_MAX) {
    o->leaf[o->n] = leaf;
    o->step[o->n] = step;
    o->cl[o->n] = l;
    o->ch[o->n] = h;
    o->n++;
    return 0;
  }
  int j = -1;
  double mj = HUGE_VAL, m = fmax(fabs(l), fabs(h));
  for (int i = 0; i < o->n; i++) {
    double mi = fmax(fabs(o->cl[i]), fabs(o->ch[i]));
    if (!o->step[i] && !(mi >= mj)) j = i, mj = mi;
  }
  if (!step && !(m > mj)) { /* also when no kept entry may go */
    gr_rest_add(o, lv[leaf].n, l, h);
    return 0;
  }
  if (j < 0) return -1;
  gr_rest_add(o, lv[o->leaf[j]].n, o->cl[j], o->ch[j]);
  o->leaf[j] = leaf;
  o->step[j] = step;
  o->cl[j] = l;
  o->ch[j] = h;
  return 0;
}

/* r = sx x + sy y on the coefficients (sx, sy intervals); -1 when more
   than GR_MAX steps are live. An operand multiplied by exactly 0 (a
   product with a factor that is 0 over the whole box) drops out: the
   result does not depend on its leaves there. */
static int gr_lin(GrIv *r, const GrIv *x, double sxl, double sxh,
                  const GrIv *y, double syl, double syh, const dt_leaf *lv) {
  GrIv o;
  o.n = 0;
  int zx = sxl == 0 && sxh == 0, zy = syl == 0 && syh == 0;
  for (int q = 0; q < 3; q++) {
    double a = 0, b = 0, c = 0, d = 0;
    o.rl[q] = o.rh[q] = 0;
    if (!zx) iv_mul(sxl, sxh, x->rl[q], x->rh[q], &a, &b);
    if (!zy) iv_mul(syl, syh, y->rl[q], y->rh[q], &c, &d);
    gr_acc(&o.rl[q], &o.rh[q], a, b);
    gr_acc(&o.rl[q], &o.rh[q], c, d);
  }
  for (int i = 0; i < x->n && !zx; i++) {
    o.leaf[o.n] = x->leaf[i];
    o.step[o.n] = x->step[i];
    iv_mul(sxl, sxh, x->cl[i], x->ch[i], &o.cl[o.n], &o.ch[o.n]);
    o.n++;
  }
  for (int i = 0; i < y->n && !zy; i++) {
    double l, h;
    iv_mul(syl, syh, y->cl[i], y->ch[i], &l, &h);
    int j = 0;
    while (j < o.n && o.leaf[j] != y->leaf[i]) j++;
    if (j == o.n) {
      if (gr_push(&o, lv, y->leaf[i], y->step[i], l, h) < 0) return -1;
    } else {
      iv_add(o.cl[j], o.ch[j], l, h, &o.cl[j], &o.ch[j]);
      o.step[j] |= y->step[i];
    }
  }
  o.l = r->l;
  o.h = r->h;
  *r = o;
  return 0;
}

typedef struct {
  int planar;              /* one live leaf: the 0.5 level is a plane */
  double w;                /* |grad - g0| <= w over the box */
  double gmin;             /* grad . n0 >= gmin > 0 over the box */
  double n0[3];            /* the unit direction of g0 */
  double slope;            /* |grad - (grad . n0) n0| / gmin bound: a chord
                              c between two points of the surface in the
                              box has |c . n0| <= slope |c| */
} GrBound;

/* The longest vector c in [-1, 1]^3 (the difference of two points of a
   unit cube) with |c . u| <= tau (u a unit vector): |c|^2 is convex, so
   its largest value on that convex polytope is at a vertex, a cube
   corner inside the slab or where the slab's planes cut a cube edge. */
static double chord_max(const double u[3], double tau) {
  double best = 0;
  for (int c = 0; c < 8; c++) {
    double v[3] = {c & 1 ? 1 : -1, c & 2 ? 1 : -1, c & 4 ? 1 : -1};
    if (fabs(vec3_dot(v, u)) <= tau) best = fmax(best, vec3_dot(v, v));
  }
  for (int a = 0; a < 3; a++) { /* edges along axis a */
    int b = (a + 1) % 3, e = (a + 2) % 3;
    if (u[a] == 0) continue;
    for (int c = 0; c < 4; c++)
      for (int sgn = -1; sgn <= 1; sgn += 2) {
        double v[3];
        v[b] = c & 1 ? 1 : -1;
        v[e] = c & 2 ? 1 : -1;
        v[a] = (sgn * tau - u[b] * v[b] - u[e] * v[e]) / u[a];
        if (fabs(v[a]) <= 1) best = fmax(best, vec3_dot(v, v));
      }
  }
  return sqrt(best) * (1 + 1e-12);
}

/* The tape's value range and per-leaf gradient coefficients over
   [lo, hi] (see GrIv): &st[0], or NULL when more than GR_MAX leaves are
   live. */
static const GrIv *gr_tape(const dt_tape *t, const double lo[3],
                           const double hi[3], GrIv *st) {
  int sp = 0;
  for (int i = 0; i < t->ncode; i++) {
    const dt_instr *in = &t->code[i];
    GrIv *x = &st[sp];
    if (in->op == DT_LEAF) {
      const dt_leaf *lf = &t->leaves[in->arg];
      double rl, rh;
      vec3_plane_range(lf->n, lf->d, lo, hi, &rl, &rh);
      x->n = 0;
      memset(x->rl, 0, sizeof x->rl);
      memset(x->rh, 0, sizeof x->rh);
      if (lf->r <= 0) {
        x->l = rh < 0 ? 1 : 0;
        x->h = rl > 0 ? 0 : 1;
        if (rl <= 0 && rh >= 0) { /* a step crossing the box */
          x->step[0] = 1;
          x->leaf[0] = in->arg;
          x->cl[0] = x->ch[0] = 0;
          x->n = 1;
        }
      } else {
        double al = rl / lf->r, ah = rh / lf->r;
        x->l = dt_halfspace_a(ah);
        x->h = dt_halfspace_a(al);
        if (al < 1 && ah > -1) {
          double a0 = fmax(al, -1), a1 = fmin(ah, 1);
          double m0 = a0 <= 0 && a1 >= 0 ? 0 : fmin(a0 * a0, a1 * a1);
          double m1 = fmax(a0 * a0, a1 * a1);
          x->leaf[0] = in->arg;
          x->step[0] = 0;
          x->cl[0] = 0.75 * (m0 - 1) / lf->r;
          x->ch[0] = 0.75 * (m1 - 1) / lf->r;
          x->n = 1;
        }
      }
      sp++;
    } else if (in->op == DT_CONST) {
      x->l = x->h = in->c;
      x->n = 0;
      memset(x->rl, 0, sizeof x->rl);
      memset(x->rh, 0, sizeof x->rh);
      sp++;
    } else {
      sp--;
      GrIv *a = &st[sp - 1], *y = &st[sp];
      double l, h;
      dt_range_op(in->op, a->l, a->h, y->l, y->h, &l, &h);
      int rc;
      switch (in->op) {
      case DT_SUM: rc = gr_lin(a, a, 1, 1, y, 1, 1, t->leaves); break;
      case DT_DIFF: rc = gr_lin(a, a, 1, 1, y, -1, -1, t->leaves); break;
      case DT_RDIFF: rc = gr_lin(a, a, -1, -1, y, 1, 1, t->leaves); break;
      case DT_PRODUCT: rc = gr_lin(a, a, y->l, y->h, y, a->l, a->h, t->leaves); break;
      default: /* x + y - x y */
        rc = gr_lin(a, a, 1 - y->h, 1 - y->l, y, 1 - a->h, 1 - a->l, t->leaves);
        break;
      }
      if (rc < 0) return NULL;
      a->l = l;
      a->h = h;
    }
  }
  return &st[0];
}
/* The gradient bound of t over [lo, hi]: 0 when found (*b), -1 when the
   tape is not smooth there (a sharp leaf crosses it, too many live leaves,
   or no direction n0 with a positive lower bound). */
static int grad_box(const dt_tape *t, const double lo[3], const double hi[3],
                    GrIv *st, GrBound *b) {
  int step = 0;
  const GrIv *r = gr_tape(t, lo, hi, st);
  if (!r) return -1;
  memset(b, 0, sizeof *b);
  for (int i = 0; i < r->n; i++) step |= r->step[i];
  if (r->n == 1 && gr_rest_none(r)) {
    b->planar = 1;
    return 0;
  }
  if (step || r->n == 0) return -1;
  /* the remainder: its middle in g0, its half-widths' length in w */
  double g0[3] = {0, 0, 0}, dummy = 0, w = gr_rest(r, NULL, g0, &dummy, &dummy);
  double rw = w;
  for (int i = 0; i < r->n; i++) {
    const double *n = t->leaves[r->leaf[i]].n;
    double c = 0.5 * (r->cl[i] + r->ch[i]);
    for (int q = 0; q < 3; q++) g0[q] += c * n[q];
    w += 0.5 * (r->ch[i] - r->cl[i]);
  }
  double len = sqrt(vec3_dot(g0, g0));
  if (!(len > 0) || !isfinite(len)) return -1;
  double al = 0, ah = 0, u0[3] = {g0[0] / len, g0[1] / len, g0[2] / len}, m0[3];
  if (gr_rest(r, u0, m0, &al, &ah) == HUGE_VAL) return -1;
  for (int i = 0; i < r->n; i++) {
    double k = vec3_dot(t->leaves[r->leaf[i]].n, g0) / len, l, h;
    iv_mul(k, k, r->cl[i], r->ch[i], &l, &h);
    al += l;
    ah += h;
  }
  double gmin = al > 0 ? al : (ah < 0 ? -ah : 0);
  if (!(gmin > 0) || !isfinite(w)) return -1;
  /* the deviation from g0 along u = g0 / |g0| and across it */
  double wu = rw, wp = rw;
  for (int i = 0; i < r->n; i++) {
    const double *n = t->leaves[r->leaf[i]].n;
    double k = vec3_dot(n, g0) / len, p[3];
    double hw = 0.5 * (r->ch[i] - r->cl[i]);
    wu += hw * fabs(k);
    /* n across u by components (1 - k^2 loses it when k rounds to 1) */
    for (int q = 0; q < 3; q++) p[q] = n[q] - k * g0[q] / len;
    wp += hw * (sqrt(vec3_dot(p, p)) + 1e-15);
  }
  /* chords of the surface are nearly across u: see tri_bound */
  double we = wp * (1 + wu / (gmin * (1 - 1e-9)));
  if (we < w) w = we;
  for (int q = 0; q < 3; q++) b->n0[q] = g0[q] / len;
  b->slope = wp * (1 + 1e-9) / (gmin * (1 - 1e-9));
  b->w = w * (1 + 1e-9) + 1e-300;
  b->gmin = gmin * (1 - 1e-9);
  return 0;
}

/* The gradient bound from per-axis intervals [gl, gh] of the gradient
   over a box (a soft object's field, soft_grad_box): g0 the midpoint, w
   the radii's length, gmin the lower bound of grad . g0 / |g0|. 0, or -1
   when it is not positive. */
static int grad_axes(const double gl[3], const double gh[3], GrBound *b) {
  double g0[3], r2 = 0;
  for (int j = 0; j < 3; j++) {
    g0[j] = 0.5 * (gl[j] + gh[j]);
    double r = 0.5 * (gh[j] - gl[j]);
    r2 += r * r;
  }
  double len = sqrt(vec3_dot(g0, g0)), gmin = 0;
  if (!(len > 0) || !isfinite(len) || !isfinite(r2)) return -1;
  for (int j = 0; j < 3; j++) {
    double u = g0[j] / len;
    gmin += u > 0 ? u * gl[j] : u * gh[j];
  }
  if (!(gmin > 0)) return -1;
  memset(b, 0, sizeof *b);
  b->w = sqrt(r2) * (1 + 1e-9) + 1e-300;
  b->gmin = gmin * (1 - 1e-9);
  for (int j = 0; j < 3; j++) b->n0[j] = g0[j] / len;
  b->slope = b->w / b->gmin; /* |grad_perp| <= |grad - g0| */
  return 0;
}

/* ---- the mesher's state --------------------------------------------------- */

/* A surface leaf of the octree and how its triangles are certified. */
enum { LEAF_PLANE, LEAF_SMOOTH, LEAF_FINE, LEAF_EXACT };

/* The most planes a sharp cell (LEAF_EXACT) may hold. */
#define PL_MAX MESH_PLANES_MAX
/* A cell of more planes than this tries leaving out the ones that do not
   reach the solid (cell_redundant) */
#define PL_PRUNE 12

typedef struct {
  uint32_t q[3];           /* its lowest corner, in units of its side */
  unsigned char level, kind;
  unsigned char plain;     /* its faces are plain (cell, set by the first
                              pass) */
  unsigned char two;       /* two surfaces in it, each one sheet, not
                              proven one sheet together (settled: 2) */
  int pl0, npl;            /* LEAF_EXACT: its planes, pls[pl0 .. + npl) */
  double w, gmin;          /* LEAF_SMOOTH: the gradient bound */
  double chord;            /* LEAF_SMOOTH: the longest chord the surface
                              can have in the cell (smooth_bound) */
} Leaf;

struct ExTet;

typedef struct {
  const Scene *s;
  int node;
  double org[3], h;        /* finest grid point (i, j, k) is org + h (i, j, k) */
  double clo[3], chi[3];   /* the clip box: outside it is outside */
  double tol, vtol;
  double flat_moved;       /* how far merging flat regions moved the mesh */
  int depth;               /* the deepest level the octree may reach */
  int fine;                /* the level whose side the tolerance fixes */
  double bad[6];           /* MESH_ETHIN: the cell that was not settled */
  int badnode;             /* and the node not proven one sheet, or -1 */
  unsigned char *flip;     /* per node of the subtree: 1 if its solid
                              enters the object complemented (the right
                              side of an odd number of differences) */
  unsigned char *forced;   /* per node of the subtree, 0 or 1 + its class
                              over the whole clip box (clip_forced) */
  unsigned char *st;       /* scene_box scratch: classes */
  int *one;                /* scene_box scratch: T_ONE's node */
  unsigned char *st2, *rel;/* solid_along scratch: classes, live nodes */
  int *one2;
  GrIv *gst;               /* grad_box scratch */
  Leaf *leaves;
  size_t nleaves, capleaves;
  size_t max_cells;
  size_t mem0, peak0;      /* resident bytes when meshing began, and the
                              process's peak then */
  size_t max_mem;          /* the growth allowed (MeshSettings.max_memory) */
  hmap split;              /* (level, cell) -> 1 for every split cell */
  hmap *force;             /* (level, cell) -> 1 for cells that must split:
                              the surface in them was not proven within
                              the tolerance of the mesh (cover_check) */
  hmap *plainc;            /* (level, cell) -> 1 for cells, and their
                              parts, meshed by their tetrahedra's
                              crossings rather than exactly: two sharp
                              cells left a crack between them there
                              (sharp_apart) */
  hmap two_near;           /* near_two's table */
  hmap ring;               /* cover_check: finest cells whose leaves split */
  hmap pt;                 /* point (doubled finest coordinates) -> index */
  uint32_t *pc;            /* its coordinates */
  unsigned char *ps;       /* its sign: 1 inside */
  size_t np, capp, capps;
  hmap vert;               /* point pair -> mesh vertex */
  double *v;
  size_t nv, capv;
  int *t;
  size_t nt, capt;
  int *fl;                 /* scratch: a face's boundary loop */
  size_t nfl, capfl;
  int *ft;                 /* scratch: a cell's face triangles */
  size_t nft, capft;
  const Leaf *cur;         /* the leaf being meshed */
  int sharp;               /* make LEAF_EXACT cells */
  int near_weld;           /* weld: vertices within WELD joined, not only
                              edges' ends */
  int near_exact;          /* place the meeting points of near parallel
                              planes exactly (ex_split) */
  int uniform;             /* no leaf above the finest level */
  int refining;            /* walk splits cells where settled gives 2
                              (refine_two) */
  int *pls;                /* the planes of the sharp cells (node indices) */
  size_t npls, cappls;
  int *plmap;              /* per node of the subtree: 2 (plane) + flip */
  unsigned char *pv;       /* pl_eval scratch */
  int *prog, nprog;        /* pl_eval's nodes in the cell (pl_prog) */
  struct PlMemo *memo;     /* pl_eval's answers in the cell, or NULL */
  int *alias;              /* per node: the node whose value it takes in
                              the cell, or -1 when its class decides it */
  struct ExTet *ex;        /* exact_tet scratch */
  kmap vert2;              /* named corners of sharp cells -> mesh vertex */
  hmap crease;             /* (u, v) -> the surface's path between the
                              edge vertices u < v on a sharp cell's face,
                              poly[off] points then the points in order */
  int *poly;
  size_t npoly, cappoly;
  kmap fpath;              /* (vertex, axis, plane) -> the next vertex of
                              a sharp cell's surface along a cell face */
  uint64_t *fstart;        /* the keys of fpath, in order */
  size_t nfs, capfs;
  unsigned char *uni;      /* per mesh vertex: made by edge_vertex */
  unsigned char *xact;     /* per mesh vertex: placed exactly (lv_exact) */
  size_t capxact;
  size_t capuni;
  RayCtx *ray;
  MeshReport *rep;
  int err;                 /* MESH_E* */
  const Scene *s0;         /* the scene as given (s is a cell's pruned copy
                              while its children are walked) */
  int *rnd, nrnd;          /* the rounded nodes of the subtree */
  struct PruneLevel *plev; /* per level: its split cell's pruned tapes */
  signed char *cls;        /* prune_cell scratch: leaf classes */
  size_t capcls;
  int *par;                /* per node of the subtree: its parent, or -1 */
  int *grp;                /* per node: the top of the intersections above
                              it (its group, cell_redundant), or -1 */
  unsigned char *frc;      /* cell_redundant's forced classes */
  double *pin;             /* part_contacts' parted vertices: each its
                              place (3) and where widen puts it (3) */
  size_t npin, cappin;
} Mesher;

/* Whether halfspace nd's open solid (n . p < d) misses the open box
   (blo, bhi): the least of n . p - d over the closed box is >= 0,
   exactly for an axis-aligned plane (n_k c is exact: an exact
   comparison), past a bound on its rounding otherwise. */
static int halfspace_misses(const ScNode *nd, const double blo[3],
                            const double bhi[3]) {
  double v = 0, mag = fabs(nd->d);
  int nz = 0, k1 = 0;
  for (int k = 0; k < 3; k++) {
    if (nd->n[k] == 0) continue;
    double c = nd->n[k] > 0 ? blo[k] : bhi[k];
    if (!isfinite(c)) return 0;
    v += nd->n[k] * c;
    mag += fabs(nd->n[k] * c);
    nz++;
    k1 = k;
  }
  if (nz == 0) return 0;
  return nz == 1 && fabs(nd->n[k1]) == 1 ? v >= nd->d
                                         : v - nd->d - 8 * DBL_EPSILON * mag >= 0;
}

/* Halfspaces whose open solid misses the open Bounds box (blo, bhi), as
   a floor does under a box whose low face lies in its plane: forced[]
   says so (1 + T_OUT), so that no cell counts them. Else a cell on that
   face, whose closed box touches the plane, is undecided, and the
   surface-to-mesh proof fails along the whole face though nothing is
   there. Only halfspaces that enter the object as they are (not
   complemented by a difference: m->flip), so that the object with them
   taken out is the object in the box; outside the box the clip (or,
   where there is none, the object's box without them:
   box_without_missing) excludes them anyway. */
static void clip_forced(const Mesher *m, const double blo[3],
                        const double bhi[3], unsigned char *forced) {
  int f = m->s->nodes[m->node].first;
  for (int x = f; x <= m->node; x++) {
    const ScNode *nd = &m->s->nodes[x];
    forced[x - f] = (unsigned char)(nd->kind == SC_HALFSPACE && !m->flip[x - f] &&
                                            halfspace_misses(nd, blo, bhi)
                                        ? 1 + T_OUT
                                        : 0);
  }
}

/* The box of node with the halfspaces that clip_forced leaves out taken
   as empty (a floor under the Bounds box): into lo, hi (lo > hi when
   nothing is left), 1 if it is finite, 0 if not or out of memory. Node
   by node, children first: a union's box is its operands', an
   intersection's the bounded operands', a difference's its left
   operand's (the right one is subtracted: its halfspaces are never left
   out), any other node's render_node_box, and so is an operation's
   whose operands are unbounded (planes that only bound together). */
static int box_without_missing(const Scene *s, int node, const double blo[3],
                               const double bhi[3], double lo[3],
                               double hi[3]) {
  int f = s->nodes[node].first, n = node - f + 1;
  double (*b)[6] = malloc((size_t)n * sizeof *b);
  unsigned char *ok = malloc((size_t)n);
  if (!b || !ok) {
    free(b);
    free(ok);
    return 0;
  }
  for (int x = f; x <= node; x++) {
    const ScNode *nd = &s->nodes[x];
    double *r = b[x - f];
    int i = x - f;
    if (nd->kind == SC_UNION || nd->kind == SC_INTER || nd->kind == SC_DIFF) {
      int a = nd->a - f, c = nd->b - f;
      if (nd->kind == SC_DIFF || (nd->kind == SC_INTER && !ok[c])) {
        ok[i] = ok[a];
        memcpy(r, b[a], sizeof b[a]);
      } else if (nd->kind == SC_INTER && !ok[a]) {
        ok[i] = 1;
        memcpy(r, b[c], sizeof b[c]);
      } else {
        ok[i] = (unsigned char)(ok[a] && ok[c]);
        for (int k = 0; k < 3; k++) {
          r[k] = nd->kind == SC_UNION ? fmin(b[a][k], b[c][k]) : fmax(b[a][k], b[c][k]);
          r[3 + k] = nd->kind == SC_UNION ? fmax(b[a][3 + k], b[c][3 + k])
                                          : fmin(b[a][3 + k], b[c][3 + k]);
        }
      }
      /* halfspaces only bound together (a cube is six): the node's own */
      if (!ok[i]) ok[i] = (unsigned char)render_node_box(s, x, r, r + 3);
    } else if (nd->kind == SC_HALFSPACE && halfspace_misses(nd, blo, bhi)) {
      ok[i] = 1;
      for (int k = 0; k < 3; k++) r[k] = HUGE_VAL, r[3 + k] = -HUGE_VAL;
    } else {
      ok[i] = (unsigned char)render_node_box(s, x, r, r + 3);
    }
  }
  int res = ok[n - 1];
  if (res) {
    memcpy(lo, b[n - 1], 3 * sizeof *lo);
    memcpy(hi, b[n - 1] + 3, 3 * sizeof *hi);
  }
  free(b);
  free(ok);
  return res;
}

/* A number of the form k 10^e, as a double: k / 10^-e when e < 0, so
   that it is the double nearest the decimal (it prints back short). */
static double decimal(double k, int e) {
  return e < 0 ? k / pow(10, -e) : k * pow(10, e);
}

int mesh_suggest_bounds(const Scene *s, int node, double lo[3], double hi[3]) {
  int f = s->nodes[node].first, n = node - f + 1;
  double (*b)[6] = malloc((size_t)n * sizeof *b);
  unsigned char *st = malloc((size_t)n); /* 0 unbounded, 1 box, 2 a
                                            halfspace, 3 one a union drops,
                                            4 to do */
  if (!b || !st) {
    free(b);
    free(st);
    return 0;
  }
  /* the nodes reached from the root through unions (st 4), then their
     boxes children first; a union's from its operands' (as
     render_node_box makes it), not again from its subtree, so that the
     work is linear in a long union */
  memset(st, 0, (size_t)n);
  st[n - 1] = 4;
  for (int x = node; x >= f; x--)
    if (st[x - f] == 4 && s->nodes[x].kind == SC_UNION)
      st[s->nodes[x].a - f] = st[s->nodes[x].b - f] = 4;
  for (int x = f; x <= node; x++) {
    const ScNode *nd = &s->nodes[x];
    double *r = b[x - f];
    int i = x - f;
    if (st[i] != 4) continue;
    st[i] = 0;
    if (nd->kind == SC_UNION) {
      int a = nd->a - f, c = nd->b - f;
      if (!st[a] || !st[c]) continue;
      if (st[a] >= 2 && st[c] >= 2) continue; /* nothing bounded left */
      const double *p = st[a] == 1 ? b[a] : b[c], *q = st[c] == 1 ? b[c] : b[a];
      if (st[a] == 2) st[a] = 3; /* a union leaves it out */
      if (st[c] == 2) st[c] = 3;
      for (int k = 0; k < 3; k++) {
        r[k] = fmin(p[k], q[k]);
        r[3 + k] = fmax(p[3 + k], q[3 + k]);
      }
      st[i] = 1;
    } else {
      st[i] = (unsigned char)render_node_box(s, x, r, r + 3);
      if (!st[i] && nd->kind == SC_HALFSPACE) st[i] = 2;
    }
  }
  int ok = st[n - 1] == 1, faces = 0;
  double blo[3], bhi[3], size = 0;
  if (ok) {
    memcpy(blo, b[n - 1], sizeof blo);
    memcpy(bhi, b[n - 1] + 3, sizeof bhi);
    for (int k = 0; k < 3; k++) {
      if (!isfinite(blo[k]) || !isfinite(bhi[k]) || !(bhi[k] >= blo[k])) ok = 0;
      else size = fmax(size, bhi[k] - blo[k]);
    }
    if (!(size > 0)) ok = 0;
  }
  if (ok) {
    /* pad each side by 2% of it (of a millionth of the largest at
       least), out to a grid of a power of ten no wider than the pad, so
       that the numbers are short to type */
    for (int k = 0; k < 3; k++) {
      double pad = 0.02 * fmax(bhi[k] - blo[k], 1e-6 * size);
      int e = (int)floor(log10(pad));
      double g = pow(10, e);
      lo[k] = decimal(floor((blo[k] - pad) / g), e);
      hi[k] = decimal(ceil((bhi[k] + pad) / g), e);
    }
    /* an axis-aligned dropped halfspace: the face on its plane, which
       then leaves it out (clip_forced) when the bounded parts stand on
       it; a plane beyond the bounded parts is already outside */
    for (int x = f; x <= node; x++) {
      const ScNode *nd = &s->nodes[x];
      if (st[x - f] != 3) continue;
      for (int k = 0; k < 3; k++) {
        if (nd->n[k] == 1 && nd->d > lo[k] && nd->d < bhi[k])
          lo[k] = nd->d, faces |= 1 << k;
        if (nd->n[k] == -1 && -nd->d < hi[k] && -nd->d > blo[k])
          hi[k] = -nd->d, faces |= 8 << k;
      }
    }
    double l2[3], h2[3];
    ok = 1;
    for (int k = 0; k < 3; k++) ok &= lo[k] < hi[k];
    /* the box must make the object bounded as the mesher takes it */
    ok = ok && box_without_missing(s, node, lo, hi, l2, h2);
  }
  free(b);
  free(st);
  return ok ? 1 | faces << 1 : 0;
}

/* 1 if no point of the closed box [lo, hi] is inside node's solid, by
   three-valued classes node by node (children first): a halfspace is
   out when the least of n . p - d over the box is >= 0
   (halfspace_misses, the open box's test: the same), a rounded node
   when its outer bound or its density's range (at most 0.5) says so, a
   soft object when its field's range is at most its level; the
   halfspaces in forced (clip_forced) are out. Unlike walk's classes, a
   box touching a surface from outside counts as out: it holds none of
   the open solid. 0 when undecided or out of memory. */
static int solid_misses(const Scene *s, int node, const double lo[3],
                        const double hi[3], const unsigned char *forced) {
  int f = s->nodes[node].first, n = node - f + 1;
  unsigned char *st = malloc((size_t)n);
  if (!st) return 0;
  for (int x = f; x <= node; x++) {
    const ScNode *nd = &s->nodes[x];
    int a = nd->a - f, b = nd->b - f, r = T_MIX;
    double l, h;
    switch (nd->kind) {
    case SC_UNION:
      r = st[a] == T_OUT && st[b] == T_OUT ? T_OUT
          : st[a] == T_IN || st[b] == T_IN ? T_IN : T_MIX;
      break;
    case SC_INTER:
      r = st[a] == T_OUT || st[b] == T_OUT ? T_OUT
          : st[a] == T_IN && st[b] == T_IN ? T_IN : T_MIX;
      break;
    case SC_DIFF:
      r = st[a] == T_OUT || st[b] == T_IN ? T_OUT
          : st[a] == T_IN && st[b] == T_OUT ? T_IN : T_MIX;
      break;
    case SC_HALFSPACE:
      vec3_plane_range(nd->n, nd->d, lo, hi, &l, &h);
      r = (forced && forced[x - f]) || halfspace_misses(nd, lo, hi) ? T_OUT
          : h < 0 ? T_IN : T_MIX;
      break;
    case SC_ROUNDED:
      if (nd->outer && csg_box_class(nd->outer, lo, hi) == T_OUT) {
        r = T_OUT;
        break;
      }
      dt_range_box(nd->tape, lo, hi, &l, &h);
      r = h <= 0.5 ? T_OUT : l > 0.5 ? T_IN : T_MIX;
      break;
    case SC_SOFT:
      soft_field_box(nd->soft, lo, hi, &l, &h);
      r = h <= soft_magic(nd->soft) ? T_OUT : T_MIX;
      break;
    case SC_EMPTY: r = T_OUT; break;
    case SC_ALL: r = T_IN; break;
    default: r = T_MIX; break;
    }
    st[x - f] = (unsigned char)r;
  }
  int out = st[n - 1] == T_OUT;
  free(st);
  return out;
}

/* A smooth cell's bound (manual, "smooth enough"): a triangle with
   longest side d is within vtol + w (2/3) D'' / gmin of the surface, D''
   the diameter of its vertices' true crossings, at most d + 2 vtol and at
   most chord, the longest chord the surface can have in the cell (the
   crossings lie on the cell's edges, so in it). The cell is accepted with
   d its diagonal, and each triangle certified with its own d and the same
   chord: taking d + 2 vtol alone there gave a triangle a larger bound
   than its cell's (0.03024 at tolerance 0.03, the property test's random
   seed 231). */
static double smooth_bound(const Mesher *m, double w, double gmin, double d,
                           double chord) {
  return m->vtol + w * (2.0 / 3) * fmin(d + 2 * m->vtol, chord) / gmin;
}

static int in_clip(const Mesher *m, const double p[3]) {
  for (int i = 0; i < 3; i++)
    if (!(p[i] > m->clo[i] && p[i] < m->chi[i])) return 0;
  return 1;
}

/* The process's resident bytes (/proc/self/statm), 0 where unknown. */
static size_t resident(void) {
  int fd = open("/proc/self/statm", O_RDONLY);
  if (fd < 0) return 0;
  char b[128];
  ssize_t n = read(fd, b, sizeof b - 1);
  close(fd);
  if (n <= 0) return 0;
  b[n] = 0;
  unsigned long long size, res;
  const char *c = b;
  char *e;
  size = strtoull(c, &e, 10);
  if (e == c) return 0;
  res = strtoull(e, &e, 10);
  (void)size;
  long page = sysconf(_SC_PAGESIZE);
  return page > 0 ? (size_t)res * (size_t)page : 0;
}

/* The process's peak resident bytes so far (getrusage). */
static size_t peak_resident(void) {
  struct rusage u;
  if (getrusage(RUSAGE_SELF, &u) < 0 || u.ru_maxrss < 0) return 0;
  return (size_t)u.ru_maxrss * 1024;
}

/* The resident memory has grown by more than the limit since meshing
   began, now or at a peak since (a check's tables freed before this
   looked: a peak above the process's peak before meshing is one of
   meshing's). MESH_ELIMIT in m->err, m->rep->memout set. */
static int over_memory(Mesher *m) {
  if (!m->max_mem) return 0;
  size_t r = resident(), pk = peak_resident();
  if (pk > m->peak0 && pk > r) r = pk;
  if (r > m->mem0 && r - m->mem0 > m->max_mem) {
    m->err = MESH_ELIMIT;
    m->rep->memout = 1;
    return 1;
  }
  return 0;
}

/* "512M" for a size in bytes. */
static void fmt_size(char *buf, size_t n, size_t bytes) {
  static const char unit[] = "KMGT";
  double v = (double)bytes;
  int u = -1;
  while (v >= 1024 && u < 3) v /= 1024, u++;
  if (u < 0) snprintf(buf, n, "%zu bytes", bytes);
  else snprintf(buf, n, "%.4g%c", v, unit[u]);
}

static int memory_error(const Mesher *m, char *err, size_t errlen,
                        size_t need) {
  m->rep->memout = 1;
  char lim[32], nd[32];
  fmt_size(lim, sizeof lim, m->max_mem);
  if (need) {
    fmt_size(nd, sizeof nd, need);
    snprintf(err, errlen, "the mesh would need about %s of memory, over "
             "%s (limit max-memory; raise it with :set max-memory SIZE or "
             "--max-memory SIZE), or give a larger tolerance than %g; nothing "
             "was written", nd, lim, m->tol);
  } else {
    snprintf(err, errlen, "meshing took more than %s of memory (limit "
             "max-memory; raise it with :set max-memory SIZE or --max-memory "
             "SIZE), or give a larger tolerance than %g; nothing was written",
             lim, m->tol);
  }
  return MESH_ELIMIT;
}

static int grow(void **p, size_t *cap, size_t need, size_t size) {
  if (need <= *cap) return 0;
  size_t nc = *cap ? *cap : 1024;
  while (nc < need) nc *= 2;
  void *g = realloc(*p, nc * size);
  if (!g) return -1;
  *p = g;
  *cap = nc;
  return 0;
}

static uint64_t ckey(int level, uint64_t i, uint64_t j, uint64_t k) {
  return (uint64_t)level << 57 | i << 38 | j << 19 | k;
}

/* Cell (i, j, k) of the level exists in the tree and is split. */
static int is_split(const Mesher *m, int level, int64_t i, int64_t j,
                    int64_t k) {
  int64_t n = (int64_t)1 << level;
  if (i < 0 || j < 0 || k < 0 || i >= n || j >= n || k >= n) return 0;
  return hget(&m->split, ckey(level, (uint64_t)i, (uint64_t)j, (uint64_t)k)) >= 0;
}

/* The point at doubled finest coordinates c, with its sign: its index, or
   -1 when memory runs out. */
static int point(Mesher *m, const uint32_t c[3]) {
  uint64_t key = (uint64_t)c[0] | (uint64_t)c[1] << 21 | (uint64_t)c[2] << 42;
  int v = hget(&m->pt, key);
  if (v >= 0) return v;
  if (grow((void **)&m->pc, &m->capp, 3 * (m->np + 1), sizeof *m->pc) < 0 ||
      grow((void **)&m->ps, &m->capps, m->np + 1, 1) < 0) {
    m->err = MESH_ENOMEM;
    return -1;
  }
  double p[3];
  for (int i = 0; i < 3; i++) p[i] = m->org[i] + 0.5 * m->h * c[i];
  int s = in_clip(m, p) ? scene_inside(m->s, m->node, p) : 0;
  v = (int)m->np;
  if (s < 0 || hput(&m->pt, key, v) < 0) {
    m->err = MESH_ENOMEM;
    return -1;
  }
  memcpy(m->pc + 3 * m->np, c, 3 * sizeof *c);
  m->ps[m->np++] = (unsigned char)s;
  return v;
}

/* Over [lo, hi], node x's field (a rounded node's density, a soft
   object's field; larger inside): the midpoint of its gradient's bound
   into g0 (if not NULL) and a lower bound of grad . u (if u is not NULL).
   0, or -1 when there is no bound (a sharp leaf of the tape crossing the
   box, too many live leaves). */
static int grad_dir(Mesher *m, int x, const double lo[3], const double hi[3],
                    double g0[3], const double *u, double *gl) {
  const ScNode *nd = &m->s->nodes[x];
  if (nd->kind == SC_ROUNDED) {
    const GrIv *r = gr_tape(nd->tape, lo, hi, m->gst);
    if (!r) return -1;
    double low = 0, high = 0, mid[3] = {0, 0, 0};
    if (gr_rest(r, u, mid, &low, &high) == HUGE_VAL) return -1;
    if (g0) memcpy(g0, mid, sizeof mid);
    for (int i = 0; i < r->n; i++) {
      if (r->step[i]) return -1;
      const double *n = nd->tape->leaves[r->leaf[i]].n;
      for (int q = 0; g0 && q < 3; q++) g0[q] += 0.5 * (r->cl[i] + r->ch[i]) * n[q];
      if (u) {
        double k = vec3_dot(n, u), l, h;
        iv_mul(k, k, r->cl[i], r->ch[i], &l, &h);
        low += l;
      }
    }
    if (u) *gl = low * (1 - 1e-9) - 1e-300;
    return 0;
  }
  if (nd->kind == SC_SOFT) {
    double dl[3], dh[3], low = 0;
    soft_grad_box(nd->soft, lo, hi, dl, dh);
    for (int q = 0; q < 3; q++) {
      if (g0) g0[q] = 0.5 * (dl[q] + dh[q]);
      if (u) low += u[q] > 0 ? u[q] * dl[q] : u[q] * dh[q];
    }
    if (u) *gl = low * (1 - 1e-9) - 1e-300;
    return isfinite(low) ? 0 : -1;
  }
  return -1;
}

/* Eighth c of the box [lo, hi] (bit a of c: the upper half along axis a). */
static void eighth(const double lo[3], const double hi[3], int c, double l2[3],
                   double h2[3]) {
  for (int a = 0; a < 3; a++) {
    double mid = 0.5 * (lo[a] + hi[a]);
    l2[a] = c >> a & 1 ? mid : lo[a];
    h2[a] = c >> a & 1 ? hi[a] : mid;
  }
}

/* Every line along u meets node x's surface in [lo, hi] at most once when
   each part of the box (the box, or its eighths down to k more levels)
   is proven inside or outside x, or has grad . u > 0 over it: along such
   a line the field is continuous and every crossing of the level is
   upward, so two crossings would need a downward one between them. */
static int sheet_along(Mesher *m, int x, const double lo[3],
                       const double hi[3], const double u[3], int k) {
  if (leaf_box(&m->s->nodes[x], lo, hi) != T_ONE) return 1;
  double gl;
  if (grad_dir(m, x, lo, hi, NULL, u, &gl) < 0) return 0;
  if (gl > 0) return 1;
  if (k == 0) return 0;
  for (int c = 0; c < 8; c++) {
    double l2[3], h2[3];
    eighth(lo, hi, c, l2, h2);
    if (!sheet_along(m, x, l2, h2, u, k - 1)) return 0;
  }
  return 1;
}

/* Node x's surface in the box is one sheet: a graph over the plane
   across a direction u (the midpoint of its gradient's bound), since
   every line along u meets it at most once (sheet_along, parts down to
   1/16 of the box's side: where the rounding is narrower than the box the
   density is flat, gradient 0, away from the surface, and only parts
   proven inside or outside leave those out). So it has no closed part,
   no tunnel, and is not two sides of a thin part. A plane always is. */
static int one_sheet(Mesher *m, int x, const double lo[3], const double hi[3]) {
  const ScNode *nd = &m->s->nodes[x];
  if (nd->kind == SC_HALFSPACE) return 1;
  double g0[3];
  if (grad_dir(m, x, lo, hi, g0, NULL, NULL) < 0) return 0;
  double len = sqrt(vec3_dot(g0, g0));
  if (!(len > 0) || !isfinite(len)) return 0;
  for (int q = 0; q < 3; q++) g0[q] /= len;
  return sheet_along(m, x, lo, hi, g0, 4);
}

/* Two undecided sharp halfspaces x and y cross the box [lo, hi] without
   meeting in it: their planes are parallel or cross on a line that misses
   the box. Then the solid between them in the box (a slab, or a wedge
   whose edge lies outside) may be thinner than the cell, and no corner
   sees it: a marching cell would miss it, and a sharp neighbour holding
   the wedge's edge would leave its face unmatched. (Planes crossing in
   the box make an edge there, meshed as a crease.) */
static int planes_face(const Mesher *m, int x, int y, const double lo[3],
                       const double hi[3]) {
  const ScNode *a = &m->s->nodes[x], *b = &m->s->nodes[y];
  double w[3], u[3], v[3], p0[3];
  vec3_cross(a->n, b->n, w);
  double w2 = vec3_dot(w, w);
  if (!(w2 > 1e-24)) return 1; /* parallel */
  vec3_cross(b->n, w, u);
  vec3_cross(w, a->n, v);
  for (int q = 0; q < 3; q++) p0[q] = (a->d * u[q] + b->d * v[q]) / w2;
  /* the line p0 + t w against the box, grown a little: where it nearly
     meets the box, it is taken as an edge */
  double t0 = -HUGE_VAL, t1 = HUGE_VAL;
  for (int q = 0; q < 3; q++) {
    double g = 1e-9 * (hi[q] - lo[q]), l = lo[q] - g, h = hi[q] + g;
    if (w[q] == 0) {
      if (p0[q] < l || p0[q] > h) return 1;
      continue;
    }
    double e0 = (l - p0[q]) / w[q], e1 = (h - p0[q]) / w[q];
    if (e0 > e1) { double t = e0; e0 = e1; e1 = t; }
    t0 = fmax(t0, e0);
    t1 = fmin(t1, e1);
  }
  return t0 > t1;
}

/* The sign of plane x's n . p - d at a point of plane y's part in the box
   [lo, hi] (found on a box edge that plane y crosses): -1 inside x's
   solid, 1 outside, 0 when none is found or it is too near x's plane to
   tell. */
static int side_on(const Mesher *m, int x, int y, const double lo[3],
                   const double hi[3]) {
  const ScNode *a = &m->s->nodes[x], *b = &m->s->nodes[y];
  for (int e = 0; e < 12; e++) {
    int ax = e / 4, u = (ax + 1) % 3, v = (ax + 2) % 3;
    double p0[3], p1[3];
    p0[ax] = lo[ax];
    p1[ax] = hi[ax];
    p0[u] = p1[u] = e & 1 ? hi[u] : lo[u];
    p0[v] = p1[v] = e & 2 ? hi[v] : lo[v];
    double s0 = vec3_dot(b->n, p0) - b->d, s1 = vec3_dot(b->n, p1) - b->d;
    if ((s0 < 0) == (s1 < 0) || !(s0 != s1)) continue;
    double t = s0 / (s0 - s1), p[3], mag = fabs(a->d);
    for (int q = 0; q < 3; q++) {
      p[q] = p0[q] + t * (p1[q] - p0[q]);
      mag += fabs(a->n[q] * p[q]);
    }
    double w = vec3_dot(a->n, p) - a->d;
    /* the crossing's rounding moves p by a few ulps of the box */
    if (fabs(w) <= 1e-9 * (mag + fabs(hi[ax] - lo[ax]))) return 0;
    return w < 0 ? -1 : 1;
  }
  return 0;
}

/* Two undecided halfspaces x and y whose planes do not meet in the box
   (planes_face) cut it into three parts, the middle one touching both
   planes; the solid has a part (or a gap) there thinner than the cell
   only if its value in the middle differs from both sides'. Not so when
   the middle lies inside exactly one of the two solids (they are
   nested there: the sides of a many-sided prism, or of its hole) and
   both enter the object alike (neither or both complemented, m->flip):
   the object is then monotone in both, so the middle's value is between
   the sides', equal to one of them. 1 when that is proven. */
static int planes_nested(const Mesher *m, int x, int y, const double lo[3],
                         const double hi[3]) {
  int f = m->s->nodes[m->node].first;
  if (m->flip[x - f] != m->flip[y - f]) return 0;
  int sx = side_on(m, x, y, lo, hi), sy = side_on(m, y, x, lo, hi);
  return sx && sy && (sx < 0) != (sy < 0);
}

/* ---- the solid as one sheet where several surfaces cross a cell ------- */

/* The most surfaces solid_along follows in a box. */
#define SH_MAX 16

/* The nodes the solid over a box depends on, from scene_box's classes
   st and one, into m->rel: those reached from the root through undecided
   nodes, a node decided by one child (T_ONE) passing only to that
   child's leaf (both children's, when two surfaces were taken as one
   plane: same_surface, same_plane_box). 1 when there were such two,
   whose side of the plane the classes do not give; else 0. */
static int mark_relevant(const Mesher *m, const unsigned char *st,
                         const int *one) {
  const Scene *s = m->s;
  int f = s->nodes[m->node].first, two = 0;
  memset(m->rel, 0, (size_t)(m->node - f + 1));
  m->rel[m->node - f] = st[m->node - f] != T_IN && st[m->node - f] != T_OUT;
  for (int x = m->node; x >= f; x--) { /* parents before children */
    if (!m->rel[x - f]) continue;
    const ScNode *nd = &s->nodes[x];
    if (nd->kind != SC_UNION && nd->kind != SC_INTER && nd->kind != SC_DIFF)
      continue;
    int a = nd->a - f, b = nd->b - f;
    if (st[x - f] == T_ONE && st[a] == T_ONE && st[b] == T_ONE) {
      m->rel[one[a] - f] = m->rel[one[b] - f] = 1;
      two = 1;
    } else if (st[x - f] == T_ONE) {
      m->rel[one[x - f] - f] = 1;
    } else {
      m->rel[a] = st[a] != T_IN && st[a] != T_OUT;
      m->rel[b] = st[b] != T_IN && st[b] != T_OUT;
    }
  }
  return two;
}

/* The surfaces the solid over a box depends on (mark_relevant's leaves)
   into xs; their number, or -1 when there are more than SH_MAX, or when
   two surfaces were taken as one plane. */
static int live_surfaces(const Mesher *m, const unsigned char *st,
                         const int *one, int *xs) {
  const Scene *s = m->s;
  int f = s->nodes[m->node].first, n = 0;
  if (mark_relevant(m, st, one)) return -1;
  for (int x = m->node; x >= f; x--) {
    ScKind k = s->nodes[x].kind;
    if (!m->rel[x - f] || k == SC_UNION || k == SC_INTER || k == SC_DIFF)
      continue;
    if (n == SH_MAX) return -1;
    xs[n++] = x;
  }
  return n;
}

/* The inside of node x, taken complemented when it enters the object
   so (flip), does not shrink along u anywhere in [lo, hi], where x is
   undecided: a halfspace whose normal n has n . u <= 0 (n . u = 0: the
   lines along u do not cross it), a rounded or soft field whose
   gradient's bound has grad . u > 0. */
static int rising(Mesher *m, int x, int flip, const double lo[3],
                  const double hi[3], const double u[3]) {
  const ScNode *nd = &m->s->nodes[x];
  double v[3], g;
  for (int q = 0; q < 3; q++) v[q] = flip ? -u[q] : u[q];
  if (nd->kind == SC_HALFSPACE) return vec3_dot(nd->n, v) <= 0;
  return grad_dir(m, x, lo, hi, NULL, v, &g) == 0 && g > 0;
}

/* Nodes a and b, both live over [lo, hi], are complements there: their
   surfaces are one plane with their insides on opposite sides of it
   (same_plane_box 2, or two halfspaces on one plane facing apart). */
static int complements(const Scene *s, int a, int b, const double lo[3],
                       const double hi[3]) {
  const ScNode *x = &s->nodes[a], *y = &s->nodes[b];
  if (x->kind == SC_HALFSPACE && y->kind == SC_HALFSPACE) {
    int opp = 1;
    for (int i = 0; i < 3; i++) opp &= x->n[i] == -y->n[i];
    return opp && x->d == -y->d;
  }
  return same_plane_box(s, a, b, lo, hi) == 2;
}

/* The object's value (1 inside, 0 outside, 2 unknown) over a box whose
   classes are st, with the live surfaces xs[i] taken inside where bit i
   of bits is set (an undecided node not among them is unknown). */
static int value_at(const Mesher *m, const unsigned char *st, const int *xs,
                    int n, unsigned bits, unsigned char *val) {
  const Scene *s = m->s;
  int f = s->nodes[m->node].first;
  for (int x = f; x <= m->node; x++) {
    const ScNode *nd = &s->nodes[x];
    int v;
    if (st[x - f] == T_IN || st[x - f] == T_OUT) {
      v = st[x - f] == T_IN;
    } else if (nd->kind == SC_UNION || nd->kind == SC_INTER || nd->kind == SC_DIFF) {
      int a = val[nd->a - f], b = val[nd->b - f];
      if (nd->kind == SC_DIFF) b = b == 2 ? 2 : !b;
      if (nd->kind == SC_UNION)
        v = a == 1 || b == 1 ? 1 : a == 0 && b == 0 ? 0 : 2;
      else
        v = a == 0 || b == 0 ? 0 : a == 1 && b == 1 ? 1 : 2;
    } else {
      v = 2;
      for (int i = 0; i < n; i++)
        if (xs[i] == x) v = (int)(bits >> i & 1);
    }
    val[x - f] = (unsigned char)v;
  }
  return val[m->node - f];
}

/* The live surfaces xs (n of them, classes st over [lo, hi]) with their
   flips into fl; where two of them, a and b, are complements over the
   box (a table's flat top and the halfspace cutting a dome flat where
   it rests on it: T + (S . H) with H = not T), b is dropped and a kept
   with the flip the object then has in it, when it has one: the object
   is a function of a and the rest alone, and if it only grows (or only
   shrinks) with a whatever the rest are (every assignment tried), it is
   monotone in every surface left, as the one-sheet argument needs (one
   pair a box, of at most 8 surfaces: 2^8 assignments). The new count; n
   when nothing was dropped. */
static int complement_pairs(Mesher *m, const unsigned char *st,
                            const double lo[3], const double hi[3], int *xs,
                            int n, unsigned char *fl) {
  const Scene *s = m->s;
  int f = s->nodes[m->node].first;
  for (int i = 0; i < n; i++) fl[i] = m->flip[xs[i] - f];
  if (n < 3 || n > 8) return n;
  for (int i = 0; i < n; i++)
    for (int j = i + 1; j < n; j++) {
      if (!complements(s, xs[i], xs[j], lo, hi)) continue;
      int up = 1, down = 1;
      for (unsigned r = 0; r < 1u << n && (up || down); r++) {
        /* i in, j out against i out, j in; every other assignment */
        if (r >> i & 1 || r >> j & 1) continue;
        int v1 = value_at(m, st, xs, n, r | 1u << i, m->rel);
        int v0 = value_at(m, st, xs, n, r | 1u << j, m->rel);
        if (v1 == 2 || v0 == 2) up = down = 0;
        up &= v1 >= v0;
        down &= v1 <= v0;
      }
      if (!up && !down) continue;
      fl[i] = (unsigned char)!up; /* grows with i's inside, or with its complement */
      for (int k = j; k + 1 < n; k++) {
        xs[k] = xs[k + 1];
        fl[k] = fl[k + 1];
      }
      return n - 1; /* one pair a box */
    }
  return n;
}

/* Every line along u meets the boundary of the solid in [lo, hi] at most
   once when in each part of the box (the box, or its eighths down to k
   more levels) the solid is proven inside or outside, or every surface
   it depends on there (live_surfaces) is rising along u. The object is a
   union, intersection and difference of its nodes: with each node
   complemented where it enters through the right side of a difference,
   it grows with each of them, so along a line where each only grows (its
   inside a half-line, or all or none) so does the object: its inside
   there is a half-line. In a part of the box proven inside or outside it
   is constant, and the parts are closed boxes sharing their faces, so
   along the whole line it only grows: it is crossed once. xs (n of them)
   are the surfaces live in the box holding this one: when they all rise
   the box is not classified again. */
static int solid_along(Mesher *m, const double lo[3], const double hi[3],
                       const double u[3], int k, const int *xs,
                       const unsigned char *fx, int n) {
  int ok = 1, one, ys[SH_MAX];
  unsigned char fy[SH_MAX];
  for (int i = 0; i < n && ok; i++) ok = rising(m, xs[i], fx[i], lo, hi, u);
  if (ok) return 1;
  int c = scene_box_g(m->s, m->node, lo, hi, m->st2, m->one2, &one, 0,
                      m->forced);
  if (c == T_IN || c == T_OUT) return 1;
  int ny = live_surfaces(m, m->st2, m->one2, ys);
  if (ny < 0) return 0;
  ny = complement_pairs(m, m->st2, lo, hi, ys, ny, fy);
  ok = 1;
  for (int i = 0; i < ny && ok; i++) ok = rising(m, ys[i], fy[i], lo, hi, u);
  if (ok) return 1;
  if (k == 0) return 0;
  for (int c8 = 0; c8 < 8; c8++) {
    double l2[3], h2[3];
    eighth(lo, hi, c8, l2, h2);
    if (!solid_along(m, l2, h2, u, k - 1, ys, fy, ny)) return 0;
  }
  return 1;
}

/* The solid's boundary in the box is one sheet (solid_along) along the
   mean u of the surfaces' directions there (the midpoints of their
   gradients' bounds, each unit and turned by the node's flip; a
   halfspace's -n). 1 proven, 0 not, -1 when fewer than two surfaces
   cross the box, or only planes (the sharp rules have them). */
static int solid_sheet(Mesher *m, const double lo[3], const double hi[3]) {
  int xs[SH_MAX], n = live_surfaces(m, m->st, m->one, xs), curved = 0;
  unsigned char fx[SH_MAX];
  if (n < 0) return 0;
  n = complement_pairs(m, m->st, lo, hi, xs, n, fx);
  double u[3] = {0, 0, 0};
  for (int i = 0; i < n; i++) {
    const ScNode *nd = &m->s->nodes[xs[i]];
    double g[3], len;
    if (nd->kind == SC_HALFSPACE)
      for (int q = 0; q < 3; q++) g[q] = -nd->n[q];
    else if (grad_dir(m, xs[i], lo, hi, g, NULL, NULL) < 0) return 0;
    else curved = 1;
    len = sqrt(vec3_dot(g, g)) * (fx[i] ? -1 : 1);
    if (!(fabs(len) > 0) || !isfinite(len)) return 0;
    for (int q = 0; q < 3; q++) u[q] += g[q] / len;
  }
  if (n < 2 || !curved) return -1;
  double len = sqrt(vec3_dot(u, u));
  if (!(len > 1e-9 * n) || !isfinite(len)) return 0;
  for (int q = 0; q < 3; q++) u[q] /= len;
  return solid_along(m, lo, hi, u, 2, xs, fx, n);
}

/* An undecided cell at or below the finest level is settled (meshed by
   marching tetrahedra from its corners' signs) when the solid's boundary
   in it is proven one sheet: the surface of the node deciding the solid
   in the cell (one_sheet), or where several surfaces may cross it, the
   solid's own (solid_sheet); and no two undecided sharp halfspaces face
   each other across it (planes_face). 1 settled; 0 not, a surface alone
   not proven one sheet (two sides of a thin part of one node); 2 not,
   but each surface alone is one sheet: two of them may bound a part, or
   a gap, thinner than the cell. */
static int settled(Mesher *m, int c, int one, const double lo[3],
                   const double hi[3]) {
  m->badnode = -1;
  if (c == T_ONE)
    return one_sheet(m, one, lo, hi) ? 1 : ((void)(m->badnode = one), 0);
  int f = m->s->nodes[m->node].first;
  /* only the planes the solid in the cell depends on: one of a part
     proven outside it (the far side of a prism touching this one) makes
     no thin part with another */
  mark_relevant(m, m->st, m->one);
  for (int x = f; x <= m->node; x++) {
    if (m->s->nodes[x].kind != SC_HALFSPACE || m->st[x - f] != T_ONE ||
        !m->rel[x - f])
      continue;
    for (int y = f; y < x; y++)
      if (m->s->nodes[y].kind == SC_HALFSPACE && m->st[y - f] == T_ONE &&
          m->rel[y - f] &&
          !same_surface(m->s, x, y) && planes_face(m, x, y, lo, hi) &&
          !planes_nested(m, x, y, lo, hi))
        return (void)(m->badnode = x), 0;
  }
  int whole = solid_sheet(m, lo, hi);
  if (whole == 1) return 1;
  for (int x = f; x <= m->node; x++) {
    ScKind k = m->s->nodes[x].kind;
    if (m->st[x - f] != T_ONE || (k != SC_ROUNDED && k != SC_SOFT)) continue;
    if (!one_sheet(m, x, lo, hi)) return (void)(m->badnode = x), 0;
  }
  return whole == 0 ? 2 : 1;
}

/* A dry run: splitting the cell [lo, hi], where two surfaces are not
   proven one sheet together (settled gave 2), settles it within k more
   levels: every part of it then proven decided, one sheet, or left to
   the other rules (one node alone not one sheet, sharp halfspaces),
   none with two surfaces unproven. 1 yes, 0 no. Uses m->st and m->one
   (walk's classes are spent by then). */
static int resolvable(Mesher *m, const double lo[3], const double hi[3],
                      int k) {
  if (k <= 0) return 0;
  for (int c8 = 0; c8 < 8; c8++) {
    double l2[3], h2[3];
    int one;
    eighth(lo, hi, c8, l2, h2);
    int c = scene_box_g(m->s, m->node, l2, h2, m->st, m->one, &one, 1,
                        m->forced);
    if (c != T_MIX) continue;
    if (settled(m, c, one, l2, h2) == 2 && !resolvable(m, l2, h2, k - 1))
      return 0;
  }
  return 1;
}

/* Whether the cell (level, q) is in m->plainc (2) or a cell holding it
   is (1), or neither (0). */
static int plain_cell_set(const Mesher *m, int level, const uint32_t q[3]) {
  if (!m->plainc || !m->plainc->n) return 0;
  for (int up = 0; up <= level; up++)
    if (hget(m->plainc, ckey(level - up, q[0] >> up, q[1] >> up, q[2] >> up)) >= 0)
      return up ? 1 : 2;
  return 0;
}

/* ---- a split cell's rounded tapes pruned for its children ------------- */

/* A split cell's copy of the subtree's nodes whose rounded nodes' tapes
   are views pruned over the cell grown by the tolerance (dt_prune_class:
   a leaf whose filter misses that box is a constant there), with the
   buffers the views borrow. The walk below the cell evaluates only the
   views: every box it asks about (a descendant, grown by at most the
   tolerance for grad_box) lies within the box the leaves were classified
   over, where a view's density is its tape's (the same folds as a ray's
   pruning), so every proof is as before, on a tape of the live leaves
   alone (examples/gear.qcs's part: 588 leaves, 36 on average in the
   cells split at the level above the finest). */
typedef struct PruneLevel {
  ScNode *nodes;           /* indices as the scene's; only the subtree set */
  Scene sc;
  dt_tape *views;
  dt_prune_prog *progs;
  dt_instr *code, *pcode;
  dt_leaf *leaves;
  int *live;
  csg_tape *bviews;        /* the outer and inner bounds' views */
  csg_instr *bcode;
  size_t capcode, cappcode, capleaves, caplive, capbcode;
} PruneLevel;

static void prune_levels_free(Mesher *m) {
  if (!m->plev) return;
  for (int l = 0; l <= MAX_DEPTH; l++) {
    PruneLevel *P = &m->plev[l];
    free(P->nodes);
    free(P->views);
    free(P->progs);
    free(P->code);
    free(P->pcode);
    free(P->leaves);
    free(P->live);
    free(P->bviews);
    free(P->bcode);
  }
  free(m->plev);
  m->plev = NULL;
}

static int grow(void **p, size_t *cap, size_t need, size_t size);

/* Rounded nodes of fewer leaves are not pruned. */
#define PRUNE_MIN 12

/* The scene the children of the split cell [lo, hi] of the level are
   walked with: m->s itself when no rounded leaf is constant over the
   cell grown by the tolerance (or memory runs short: pruning is only
   speed), else the level's copy with the pruned views. */
static const Scene *prune_cell(Mesher *m, int level, const double lo[3],
                               const double hi[3]) {
  const Scene *s = m->s;
  if (!m->nrnd || !m->plev || level > MAX_DEPTH) return s;
  PruneLevel *P = &m->plev[level];
  int f = m->s0->nodes[m->node].first;
  if (!P->nodes) {
    P->nodes = malloc((size_t)(m->node + 1) * sizeof *P->nodes);
    P->views = malloc((size_t)m->nrnd * sizeof *P->views);
    P->progs = malloc((size_t)m->nrnd * sizeof *P->progs);
    P->bviews = malloc(2 * (size_t)m->nrnd * sizeof *P->bviews);
    if (!P->nodes || !P->views || !P->progs || !P->bviews) {
      free(P->nodes);
      free(P->views);
      free(P->progs);
      free(P->bviews);
      P->nodes = NULL;
      P->views = NULL;
      P->progs = NULL;
      P->bviews = NULL;
      return s;
    }
    memcpy(P->nodes + f, m->s0->nodes + f,
           (size_t)(m->node - f + 1) * sizeof *P->nodes);
    P->sc = *m->s0;
    P->sc.nodes = P->nodes;
  }
  size_t nc = 0, npc = 0, nl = 0, maxl = 0, nb = 0;
  for (int k = 0; k < m->nrnd; k++) {
    const ScNode *nd = &s->nodes[m->rnd[k]];
    const dt_tape *t = nd->tape;
    nb += (nd->outer ? (size_t)nd->outer->ncode + 1 : 0) +
          (nd->inner ? (size_t)nd->inner->ncode + 1 : 0);
    nc += (size_t)t->ncode;
    npc += t->prog ? (size_t)t->prog->npcode : 0;
    nl += (size_t)t->nleaves;
    if ((size_t)t->nleaves > maxl) maxl = (size_t)t->nleaves;
  }
  if (grow((void **)&P->code, &P->capcode, nc, sizeof *P->code) < 0 ||
      grow((void **)&P->pcode, &P->cappcode, npc ? npc : 1, sizeof *P->pcode) < 0 ||
      grow((void **)&P->leaves, &P->capleaves, nl, sizeof *P->leaves) < 0 ||
      grow((void **)&P->live, &P->caplive, nl, sizeof *P->live) < 0 ||
      grow((void **)&m->cls, &m->capcls, maxl, 1) < 0 ||
      grow((void **)&P->bcode, &P->capbcode, nb ? nb : 1, sizeof *P->bcode) < 0)
    return s;
  double gl[3], gh[3];
  for (int a = 0; a < 3; a++) {
    double pad = m->tol + 1e-9 * (hi[a] - lo[a]);
    gl[a] = lo[a] - pad;
    gh[a] = hi[a] + pad;
  }
  size_t oc = 0, opc = 0, ol = 0, olv = 0, ob = 0;
  int any = 0;
  for (int k = 0; k < m->nrnd; k++) {
    int x = m->rnd[k];
    const dt_tape *t = s->nodes[x].tape;
    P->nodes[x].tape = s->nodes[x].tape;
    P->nodes[x].outer = s->nodes[x].outer;
    P->nodes[x].inner = s->nodes[x].inner;
    /* a small node (a rounded cube: 6 leaves, its bounds 6 planes each)
       costs more to prune than its evaluations save */
    if ((t->live ? t->nlive : t->nleaves) < PRUNE_MIN) continue;
    for (int w = 0; w < 2; w++) { /* the bound solids, by csg_prune_box */
      csg_tape *const *src = w ? &s->nodes[x].inner : &s->nodes[x].outer;
      csg_tape **dst = w ? &P->nodes[x].inner : &P->nodes[x].outer;
      *dst = *src;
      if (!*src) continue;
      csg_tape *bv = &P->bviews[2 * k + w];
      csg_prune_box(*src, gl, gh, P->bcode + ob, bv);
      if (bv->ncode < (*src)->ncode) {
        ob += (size_t)bv->ncode;
        *dst = bv;
        any = 1;
      }
    }
    int reach = t->live ? t->nlive : t->nleaves, live = 0;
    for (int q = 0; q < reach; q++) {
      int j = t->live ? t->live[q] : q;
      const dt_leaf *lf = &t->leaves[j];
      double rl, rh;
      vec3_plane_range(lf->n, lf->d, gl, gh, &rl, &rh);
      double w = 1e-12 * (fabs(rl) + fabs(rh) + 1);
      if (rl - w > lf->r) m->cls[j] = 0;
      else if (rh + w < -lf->r) m->cls[j] = 1;
      else m->cls[j] = -1, live++;
    }
    if (live == reach) continue;
    dt_tape *v = &P->views[k];
    dt_prune_class(t, m->cls, P->code + oc, P->leaves + ol, P->pcode + opc,
                   &P->progs[k], P->live + olv, v);
    oc += (size_t)v->ncode;
    if (v->prog) {
      opc += (size_t)P->progs[k].npcode;
      olv += (size_t)v->nlive;
    } else {
      ol += (size_t)v->nleaves;
    }
    P->nodes[x].tape = v;
    any = 1;
  }
  return any ? &P->sc : s;
}

/* ---- planes that do not reach the solid in a sharp cell --------------- */

/* The most planes of one intersection cell_redundant takes (each pair of
   its planes and the box's, clipped by every other: 134^3 / 2, some 1.2
   million steps at most). 24 before: near the side of a prism of n sides
   the infinite planes of about n sqrt(1.7 s) / pi of them cross a cell of
   side s, so a 400-sided prism's cells had to shrink to 0.02 before they
   were pruned (111,025 cells, 11 s; a 1000-sided one 108 s); with 128,
   777 cells and 0.7 s, and 6,185 cells and 5.5 s (bench/NOTES.md). */
#define RED_MAX 128

/* Whether some pair of the np planes n . p = d + off (the first six the
   box's faces, no pair of two of them) meets on a segment inside every
   other halfspace grown by slack: the edges of the polytope of the
   halfspaces n . p <= d + slack, as far as they lie on the planes moved
   by off. Each plane with such a segment is marked in tight (if given). */
static int pair_segments(const double (*n)[3], const double *d, int np,
                         double off, double slack, const double lo[3],
                         const double hi[3], int *tight) {
  double c[3];
  for (int q = 0; q < 3; q++) c[q] = 0.5 * (lo[q] + hi[q]);
  int any = 0;
  for (int a = 0; a < np; a++)
    for (int b = (a < 6 ? 6 : a + 1); b < np; b++) {
      /* nothing to learn from a pair whose planes are both marked (the
         box's faces need no mark), once one segment is found */
      if (tight && any && (a < 6 || tight[a]) && tight[b]) continue;
      double u[3], ul;
      vec3_cross(n[a], n[b], u);
      ul = sqrt(vec3_dot(u, u));
      if (!(ul > 1e-9)) continue;
      for (int q = 0; q < 3; q++) u[q] /= ul;
      /* the point of the line nearest the origin, then the one nearest
         the box's centre (where a plane nearly parallel to the line is
         judged, and the clipped parameters are small) */
      double bu[3], ua[3], p0[3], da = d[a] + off, db = d[b] + off;
      vec3_cross(n[b], u, bu);
      vec3_cross(u, n[a], ua);
      for (int q = 0; q < 3; q++) p0[q] = (da * bu[q] + db * ua[q]) / ul;
      double cu = (c[0] - p0[0]) * u[0] + (c[1] - p0[1]) * u[1] +
                  (c[2] - p0[2]) * u[2];
      for (int q = 0; q < 3; q++) p0[q] += cu * u[q];
      double t0 = -HUGE_VAL, t1 = HUGE_VAL;
      int ok = 1;
      for (int q = 0; q < np && ok; q++) {
        if (q == a || q == b) continue;
        double nu = vec3_dot(n[q], u), r = d[q] + slack - vec3_dot(n[q], p0);
        if (fabs(nu) < 1e-12) ok = r >= 0;
        else if (nu > 0) t1 = fmin(t1, r / nu);
        else t0 = fmax(t0, r / nu);
      }
      if (!ok || !(t0 <= t1)) continue;
      any = 1;
      if (!tight) return 1;
      tight[a] = tight[b] = 1;
    }
  return any;
}

/* Where more than PL_PRUNE distinct undecided halfspaces cross the box
   [lo, hi] (classes in m->st), all of them reaching the object through
   one intersection (a group: a prism's sides and caps, or the hole cut
   by one, away from the plate's faces), those that take no part in the
   solid there: a halfspace x whose group's
   undecided members cut the box to a polytope P lying strictly inside x.
   The group is then the intersection of the others over the box (where
   x is 0, so is another member), and x's value does not matter: it is
   forced inside (frc, from m->forced). A member is taken so when no
   vertex of P lies within eps of its plane: had it a facet of P, the
   facet's edges would be edges of P on it. The edges are found from
   every pair of a member's plane and another's or the box's: their line
   clipped by every halfspace (each within eps), a segment not empty
   marking both; a group with none is left alone. The infinite planes of a many-sided prism's
   sides near a rim cross many cells their faces never reach (some 17 of
   a 300-sided one's cross each finest cell at the rim): without them a
   cell there holds two or three and is meshed exactly, its edges on the
   prism's. The number of halfspaces forced; frc is set when it is > 0. */
static int cell_redundant(Mesher *m, const double lo[3], const double hi[3]) {
  const Scene *s = m->s;
  int f = s->nodes[m->node].first, nd = 0, nforced = 0;
  int pl[PL_MAX + 1];
  for (int x = f; x <= m->node && nd <= PL_MAX; x++) {
    if (s->nodes[x].kind != SC_HALFSPACE || m->st[x - f] != T_ONE) continue;
    int dup = 0;
    for (int y = 0; y < nd && !dup; y++) dup = same_surface(s, pl[y], x);
    if (!dup) pl[nd++] = x;
  }
  if (nd <= PL_PRUNE || !m->par || !m->grp || !m->frc) return 0;
  /* one group holds every undecided plane, or nothing is forced: a
     plane of another part (a plate's face at a hole's rim) has its
     polygon split by every plane crossing the cell, so a neighbour that
     keeps x would cut it where this cell does not (a crack) */
  int g = m->grp[pl[0] - f];
  if (g < 0 || m->st[g - f] == T_IN || m->st[g - f] == T_OUT) return 0;
  for (int x = pl[0]; x <= m->node; x++)
    if (s->nodes[x].kind == SC_HALFSPACE && m->st[x - f] == T_ONE &&
        m->grp[x - f] != g)
      return 0;
  double w = 0, sc = 0;
  for (int a = 0; a < 3; a++) {
    w = fmax(w, hi[a] - lo[a]);
    sc = fmax(sc, fmax(fabs(lo[a]), fabs(hi[a])));
  }
  double eps = 1e-9 * w + 1e-13 * sc;
  /* the one group's members */
  int mem[RED_MAX], k = 0;
  for (int y = pl[0]; y <= m->node && k <= RED_MAX; y++)
    if (s->nodes[y].kind == SC_HALFSPACE && m->st[y - f] == T_ONE) {
      if (k < RED_MAX) mem[k] = y;
      k++;
    }
  if (k < 2 || k > RED_MAX) return 0;
  {
    double n[RED_MAX + 6][3], d[RED_MAX + 6];
    int np = 0, tight[RED_MAX + 6] = {0}, any = 0;
    for (int a = 0; a < 3; a++)
      for (int e = 0; e < 2; e++) {
        n[np][0] = n[np][1] = n[np][2] = 0;
        n[np][a] = e ? 1 : -1;
        d[np++] = e ? hi[a] : -lo[a];
      }
    for (int i = 0; i < k; i++) {
      memcpy(n[np], s->nodes[mem[i]].n, sizeof n[np]);
      d[np++] = s->nodes[mem[i]].d;
    }
    /* P must hold a point eps inside every halfspace. An empty P (two
       members facing apart, or three around nothing, nearer than eps)
       can have a grown P that is not empty, and a member whose plane
       misses the grown P may be the one that empties P. When P is not
       empty each facet of P has edges on the grown P's planes' pairs
       (below), and a member with none is redundant. */
    if (!pair_segments(n, d, np, -eps, -eps, lo, hi, NULL)) return 0;
    /* each pair's line clipped by every halfspace: a member on no pair
       whose segment is not empty has no edge of P (its facet's edges
       would be such segments), and no vertex */
    any = pair_segments(n, d, np, 0, eps, lo, hi, tight);
    if (!any) return 0;
    for (int i = 0; i < k; i++)
      if (!tight[6 + i]) {
        if (!nforced) {
          int nsub = m->node - f + 1;
          if (m->forced) memcpy(m->frc, m->forced, (size_t)nsub);
          else memset(m->frc, 0, (size_t)nsub);
        }
        m->frc[mem[i] - f] = 1 + T_IN;
        nforced++;
      }
  }
  return nforced;
}

/* Classify the cell (i, j, k) of the level (in units of its side) and
   either drop it (proven empty or full), keep it as a surface leaf, or
   split it. A leaf is kept above the finest level when its error is
   proven within the tolerance: the surface in the box is one plane
   (LEAF_PLANE), or one rounded node whose gradient bound over the box
   grown by the tolerance makes the triangles close enough (LEAF_SMOOTH,
   see mesh.h). */
/* The distinct planes of the undecided halfspaces (m->st), appended to
   m->pls from n0: their count, at most PL_MAX + 1 (more: not a sharp
   cell), or -1 out of memory. */
static int collect_planes(Mesher *m, int n0) {
  int f = m->s->nodes[m->node].first, n = 0;
  for (int x = f; x <= m->node && n <= PL_MAX; x++) {
    if (m->s->nodes[x].kind != SC_HALFSPACE || m->st[x - f] != T_ONE) continue;
    int dup = 0;
    for (int y = 0; y < n && !dup; y++) dup = same_surface(m->s, m->pls[n0 + y], x);
    if (dup) continue;
    if (grow((void **)&m->pls, &m->cappls, m->npls + 1, sizeof *m->pls) < 0) {
      m->err = MESH_ENOMEM;
      return -1;
    }
    m->pls[m->npls++] = x;
    n++;
  }
  return n;
}

static int walk(Mesher *m, uint32_t i, uint32_t j, uint32_t k, int level) {
  double side = ldexp(m->h, m->depth - level), lo[3], hi[3];
  uint32_t q[3] = {i, j, k};
  for (int a = 0; a < 3; a++) {
    lo[a] = m->org[a] + side * q[a];
    hi[a] = m->org[a] + side * (q[a] + 1);
  }
  m->rep->cells++;
  int clip_out = 0, clip_in = 1;
  for (int a = 0; a < 3; a++) {
    if (hi[a] <= m->clo[a] || lo[a] >= m->chi[a]) clip_out = 1;
    if (lo[a] <= m->clo[a] || hi[a] >= m->chi[a]) clip_in = 0;
  }
  int one = -1;
  int c = clip_out ? T_OUT
                   : scene_box_g(m->s, m->node, lo, hi, m->st, m->one, &one, 1,
                                 m->forced);
  /* Full, and cut by one face of the clip box (no other face in or on
     it): the clipped solid in the cell is that face's halfspace, a plane
     the marching tetrahedra reproduce, their crossings on it exactly (a
     slab of the floor cut by the box's sides) */
  int clip_plane = 0;
  if (c == T_IN && !clip_in && !m->uniform) {
    int cut = 0, touch = 0;
    for (int a = 0; a < 3; a++)
      for (int e = 0; e < 2; e++) {
        double f = e ? m->chi[a] : m->clo[a];
        if (!isfinite(f)) continue;
        if (lo[a] < f && f < hi[a]) cut++;
        else if (lo[a] == f || hi[a] == f) touch++;
      }
    clip_plane = cut == 1 && !touch;
  }
  if (c == T_IN && !clip_in) c = T_MIX;
  if (c == T_OUT) {
    m->rep->empty++;
    return 0;
  }
  if (c == T_IN) {
    m->rep->full++;
    return 0;
  }
  Leaf lf = {{i, j, k}, (unsigned char)level, LEAF_FINE, 0, 0, 0, 0, 0, 0, 0};
  int leaf = m->uniform && level == m->fine;
  if (clip_plane) {
    lf.kind = LEAF_PLANE;
    leaf = 1;
  }
  int sheet = 0;           /* the surface in the cell is proven one sheet */
  if (c == T_ONE && clip_in && !m->uniform) {
    const ScNode *nd = &m->s->nodes[one];
    if (nd->kind == SC_HALFSPACE) {
      lf.kind = LEAF_PLANE;
      leaf = 1;
    } else if (nd->kind == SC_ROUNDED || nd->kind == SC_SOFT) {
      double gl[3], gh[3], dl[3], dh[3];
      GrBound b;
      for (int a = 0; a < 3; a++) {
        gl[a] = lo[a] - m->tol;
        gh[a] = hi[a] + m->tol;
      }
      int ok;
      if (nd->kind == SC_ROUNDED) ok = grad_box(nd->tape, gl, gh, m->gst, &b) == 0;
      else {
        soft_grad_box(nd->soft, gl, gh, dl, dh);
        ok = grad_axes(dl, dh, &b) == 0;
      }
      sheet = ok; /* grad . n0 > 0 over a box holding the cell */
      if (ok) {
        double d = sqrt(3.0) * side;
        if (b.planar) {
          lf.kind = LEAF_PLANE;
          leaf = 1;
        } else if (smooth_bound(m, b.w, b.gmin, d, side * chord_max(b.n0, sqrt(3.0) * b.slope)) <=
                   m->tol) {
          /* the crossings' diameter: chords of the surface in the cell
             are within slope of across n0, so at most the cell's longest
             such chord (|c| <= sqrt 3 side gives |c . n0| <= sqrt 3 slope
             side) */
          lf.kind = LEAF_SMOOTH;
          lf.w = b.w;
          lf.gmin = b.gmin;
          lf.chord = side * chord_max(b.n0, sqrt(3.0) * b.slope);
          leaf = 1;
        }
      }
    }
  }
  int pset = c == T_PL && clip_in && m->sharp ? plain_cell_set(m, level, q) : 0;
  if (pset == 2) m->rep->sharp_apart++;
  if (c == T_PL && clip_in && m->sharp && !pset) {
    /* the distinct planes of the undecided halfspaces */
    int n0 = (int)m->npls, n = collect_planes(m, n0);
    if (n < 0) return -1;
    if (n > PL_PRUNE && cell_redundant(m, lo, hi) > 0) {
      /* again without the planes that do not reach the solid (a cell of
         up to PL_MAX planes is exact with them all, but each tetrahedron
         costs as the cube of their count) */
      int one2, c2 = scene_box_g(m->s, m->node, lo, hi, m->st, m->one, &one2, 1,
                                 m->frc);
      int n1 = n;
      m->npls = (size_t)n0;
      n = c2 == T_PL ? collect_planes(m, n0) : PL_MAX + 1;
      if (n < 0) return -1;
      if (c2 != T_PL || n > PL_MAX || n >= n1) { /* as it was */
        m->npls = (size_t)n0;
        scene_box_g(m->s, m->node, lo, hi, m->st, m->one, &one2, 1, m->forced);
        n = collect_planes(m, n0);
        if (n < 0) return -1;
      } else {
        m->rep->sharp_pruned++;
      }
    }
    if (n <= PL_MAX) {
      lf.kind = LEAF_EXACT;
      lf.pl0 = n0;
      lf.npl = n;
      leaf = 1;
    } else {
      m->npls = (size_t)n0;
    }
  }
  if (!leaf && level >= m->fine && !m->uniform) {
    /* the finest level, or below it: a thin part of the object (two of
       its sides in one cell) or a fold splits the cell further, down to
       the octree's limit; two surfaces each one sheet but not proven one
       sheet together split it down to TWO_LEVELS below the finest level,
       where the cell is meshed and counted (MeshReport.two) */
    int st = sheet ? 1 : settled(m, c, one, lo, hi);
    if (st == 1) leaf = 1;
    else if (st == 2 && (!m->refining || level >= m->fine + TWO_LEVELS)) {
      leaf = 1; /* refine_two decides */
      lf.two = 1;
    } else if (level == m->depth) {
      memcpy(m->bad, lo, sizeof lo);
      memcpy(m->bad + 3, hi, sizeof hi);
      m->err = MESH_ETHIN;
      return -1;
    } else m->rep->thin++;
  }
  if (leaf && level < m->depth && m->force->n &&
      hget(m->force, ckey(level, i, j, k)) >= 0) {
    leaf = 0;
    m->rep->cover_split++;
  }
  if (leaf) {
    if (level > m->rep->deepest) m->rep->deepest = level;
    if (m->nleaves >= m->max_cells) {
      m->err = MESH_ELIMIT;
      return -1;
    }
    if ((m->nleaves & 4095) == 4095 && over_memory(m)) return -1;
    if (grow((void **)&m->leaves, &m->capleaves, m->nleaves + 1,
             sizeof *m->leaves) < 0) {
      m->err = MESH_ENOMEM;
      return -1;
    }
    m->leaves[m->nleaves++] = lf;
    if (lf.kind == LEAF_PLANE) m->rep->planar++;
    else if (lf.kind == LEAF_EXACT) m->rep->sharp++;
    else if (lf.kind == LEAF_SMOOTH) m->rep->smooth++;
    return 0;
  }
  if (hput(&m->split, ckey(level, i, j, k), 1) < 0) {
    m->err = MESH_ENOMEM;
    return -1;
  }
  const Scene *up = m->s;
  m->s = prune_cell(m, level, lo, hi);
  int rc = 0;
  for (int c8 = 0; c8 < 8 && !rc; c8++)
    rc = walk(m, 2 * i + (uint32_t)(c8 & 1), 2 * j + (uint32_t)(c8 >> 1 & 1),
              2 * k + (uint32_t)(c8 >> 2 & 1), level + 1);
  m->s = up;
  return rc < 0 ? -1 : 0;
}

/* The leaves where settled gave 2 (Leaf.two), in clusters of cells of one
   level sharing faces: a cluster is split (walked again, its cells split
   down to TWO_LEVELS below the finest) only when every cell of it
   settles so (resolvable); else all of it stays as it is. Where two
   surfaces touch (a box resting flush on another: the groove under its
   edge narrows to nothing) no cell at the touch settles, and splitting
   the cells beside it while those stay would close the groove at two
   places and leave a bubble of it between; a thin part or gap that does
   not touch settles everywhere. Then counts the leaves left with two
   surfaces (MeshReport.two, two_at). 0, or -1 (m->err). */
static int find(int *p, int x);

static int refine_two(Mesher *m) {
  size_t n = 0, *ix = NULL;
  int *par = NULL, rc = -1;
  hmap at = {0};
  for (size_t l = 0; l < m->nleaves; l++) n += m->leaves[l].two;
  if (!n) return 0;
  if (!(ix = malloc(n * sizeof *ix)) || !(par = malloc(2 * n * sizeof *par))) {
    m->err = MESH_ENOMEM;
    goto done;
  }
  n = 0;
  for (size_t l = 0; l < m->nleaves; l++)
    if (m->leaves[l].two) {
      const Leaf *lf = &m->leaves[l];
      par[n] = (int)n;
      ix[n] = l;
      if (hput(&at, ckey(lf->level, lf->q[0], lf->q[1], lf->q[2]), (int)n++) < 0) {
        m->err = MESH_ENOMEM;
        goto done;
      }
    }
  for (size_t t = 0; t < n; t++) { /* union the face neighbours */
    const Leaf *lf = &m->leaves[ix[t]];
    for (int f = 0; f < 6; f++) {
      int64_t q[3] = {lf->q[0], lf->q[1], lf->q[2]};
      q[f >> 1] += f & 1 ? 1 : -1;
      if (q[f >> 1] < 0) continue;
      int u = hget(&at, ckey(lf->level, (uint64_t)q[0], (uint64_t)q[1], (uint64_t)q[2]));
      if (u < 0) continue;
      int a = find(par, (int)t), b = find(par, u);
      if (a != b) par[a] = b;
    }
  }
  int *ok = par + n; /* per root: -1 unknown, 0 stays, 1 split */
  for (size_t t = 0; t < n; t++) ok[t] = -1;
  for (size_t t = 0; t < n; t++) {
    int r = find(par, (int)t);
    if (ok[r] == 0) continue;
    const Leaf *lf = &m->leaves[ix[t]];
    double side = ldexp(m->h, m->depth - lf->level), lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
      lo[a] = m->org[a] + side * lf->q[a];
      hi[a] = m->org[a] + side * (lf->q[a] + 1); /* as walk's */
    }
    const Scene *up = m->s;
    m->s = prune_cell(m, lf->level, lo, hi);
    ok[r] = resolvable(m, lo, hi, m->fine + TWO_LEVELS - lf->level);
    m->s = up;
  }
  m->refining = 1;
  for (size_t t = 0; t < n; t++) {
    if (!ok[find(par, (int)t)]) continue;
    Leaf lf = m->leaves[ix[t]];
    m->leaves[ix[t]].level = 0xff; /* gone */
    m->rep->thin++;
    if (hput(&m->split, ckey(lf.level, lf.q[0], lf.q[1], lf.q[2]), 1) < 0) {
      m->err = MESH_ENOMEM;
      goto done;
    }
    double side = ldexp(m->h, m->depth - lf.level), lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
      lo[a] = m->org[a] + side * lf.q[a];
      hi[a] = m->org[a] + side * (lf.q[a] + 1); /* as walk's */
    }
    const Scene *up = m->s;
    m->s = prune_cell(m, lf.level, lo, hi);
    int rc8 = 0;
    for (int c8 = 0; c8 < 8 && !rc8; c8++)
      rc8 = walk(m, 2 * lf.q[0] + (uint32_t)(c8 & 1), 2 * lf.q[1] + (uint32_t)(c8 >> 1 & 1),
                 2 * lf.q[2] + (uint32_t)(c8 >> 2 & 1), lf.level + 1);
    m->s = up;
    if (rc8 < 0) goto done;
  }
  size_t w = 0;
  for (size_t l = 0; l < m->nleaves; l++) {
    Leaf *lf = &m->leaves[l];
    if (lf->level == 0xff) continue;
    if (lf->two) {   /* counted, with the side of the largest */
      double side = ldexp(m->h, m->depth - lf->level);
      if (!m->rep->two++)
        for (int a = 0; a < 3; a++) m->rep->two_at[a] = m->org[a] + side * lf->q[a];
      if (side > m->rep->two_side) m->rep->two_side = side;
    }
    m->leaves[w++] = *lf;
  }
  m->nleaves = w;
  rc = 0;
done:
  free(ix);
  free(par);
  hfree(&at);
  return rc;
}

/* Inside at o + t d (the clipped solid). */
static int inside_at(Mesher *m, const double o[3], const double d[3],
                     double t) {
  double p[3] = {o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]};
  return in_clip(m, p) ? scene_inside(m->s, m->node, p) : 0;
}

/* A crossing on the segment from a (inside = sa) to b: t in (0, 1). */
static double crossing(Mesher *m, const double a[3], const double b[3],
                       int sa) {
  double d[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  double len = sqrt(vec3_dot(d, d));
  /* the clip box's slab along the edge */
  double t0 = 0, t1 = 1;
  for (int i = 0; i < 3; i++) {
    if (d[i] == 0) continue;
    double u = (m->clo[i] - a[i]) / d[i], w = (m->chi[i] - a[i]) / d[i];
    if (u > w) { double x = u; u = w; w = x; }
    if (u > t0) t0 = u;
    if (w < t1) t1 = w;
  }
  double best = NAN;
  if (t0 < t1) {
    csg_span *sp;
    ray_reset(m->ray);
    int n = ray_spans(m->s, m->node, a, d, 0, 1, m->ray, &sp);
    for (int q = 0; q < n && isnan(best); q++) {
      double e[2] = {sp[q].t0 > t0 ? sp[q].t0 : t0,
                     sp[q].t1 < t1 ? sp[q].t1 : t1};
      if (e[0] >= e[1]) continue;
      for (int r = 0; r < 2; r++)
        if (e[r] > 0 && e[r] < 1 && isnan(best)) best = e[r];
    }
  }
  if (isnan(best)) { /* bisection on the point classification */
    double lo = 0, hi = 1;
    for (int it = 0; it < 80 && (hi - lo) * len > m->vtol * 0.5; it++) {
      double mid = 0.5 * (lo + hi);
      int s = inside_at(m, a, d, mid);
      if (s < 0) break;
      if (s == sa) lo = mid;
      else hi = mid;
    }
    best = 0.5 * (lo + hi);
    m->rep->bisected++;
  }
  /* keep off the corners (no repeated vertex position), by far less than
     the vertices' tolerance */
  double edge = fmin(1.0 / 1048576, 0.01 * m->vtol / len);
  if (best < edge) best = edge;
  if (best > 1 - edge) best = 1 - edge;
  return best;
}

/* The mesh vertex on the segment between points pa and pb (signs differ). */
static int edge_vertex(Mesher *m, int pa, int pb) {
  if (pa > pb) {
    int x = pa;
    pa = pb;
    pb = x;
  }
  uint64_t key = (uint64_t)pa << 32 | (uint64_t)pb;
  int v = hget(&m->vert, key);
  if (v >= 0) return v;
  double a[3], b[3];
  for (int q = 0; q < 3; q++) {
    a[q] = m->org[q] + 0.5 * m->h * m->pc[3 * pa + q];
    b[q] = m->org[q] + 0.5 * m->h * m->pc[3 * pb + q];
  }
  double t = crossing(m, a, b, m->ps[pa]);
  if (grow((void **)&m->v, &m->capv, 3 * (m->nv + 1), sizeof *m->v) < 0) {
    m->err = MESH_ENOMEM;
    return -1;
  }
  if (grow((void **)&m->uni, &m->capuni, m->nv + 1, 1) < 0) {
    m->err = MESH_ENOMEM;
    return -1;
  }
  m->uni[m->nv] = 1;
  if (grow((void **)&m->xact, &m->capxact, m->nv + 1, 1) < 0) {
    m->err = MESH_ENOMEM;
    return -1;
  }
  m->xact[m->nv] = 0;
  double *p = m->v + 3 * m->nv;
  for (int q = 0; q < 3; q++) p[q] = a[q] + t * (b[q] - a[q]);
  v = (int)m->nv++;
  m->rep->crossings++;
  if (hput(&m->vert, key, v) < 0) {
    m->err = MESH_ENOMEM;
    return -1;
  }
  return v;
}

static double dist3(const double *a, const double *b) {
  double x = a[0] - b[0], y = a[1] - b[1], z = a[2] - b[2];
  return sqrt(x * x + y * y + z * z);
}

/* The covering radius of a triangle by its vertices: the circumradius if
   no angle is obtuse, else half the longest side. */
static double cover_radius(const double *a, const double *b, const double *c) {
  double la = dist3(b, c), lb = dist3(a, c), lc = dist3(a, b);
  double l = fmax(la, fmax(lb, lc));
  double s2 = la * la + lb * lb + lc * lc;
  if (2 * l * l >= s2) return 0.5 * l; /* obtuse or right */
  double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]}, x[3];
  vec3_cross(u, w, x);
  double area2 = sqrt(vec3_dot(x, x));
  if (!(area2 > 0)) return l; /* degenerate: the longest side bounds it */
  double r = la * lb * lc / (2 * area2);
  return r < l ? r : l;
}

/* The proven distance bound of a triangle of the current leaf (mesh.h). */
static double tri_bound(const Mesher *m, int a, int b, int c) {
  const double *pa = m->v + 3 * a, *pb = m->v + 3 * b, *pc = m->v + 3 * c;
  switch (m->cur->kind) {
  case LEAF_PLANE:
  case LEAF_EXACT: return m->vtol;
  case LEAF_SMOOTH: {
    double d = fmax(dist3(pa, pb), fmax(dist3(pb, pc), dist3(pa, pc)));
    /* sum_i l_i |p - x_i| <= sum_i l_i (1 - l_i) D'' <= 2/3 D'', with
       D'' <= d + 2 vtol the crossings' diameter (sum l_i^2 >= 1/3); w is
       grad_box's: the whole deviation, or w_perp (1 + w_par / gmin) where
       smaller (each p - x_i a combination of chords c between crossings,
       |c . u| gmin <= w_perp |c| since the density is equal at both ends,
       so the deviation along u meets only w_perp / gmin of the length) */
    return smooth_bound(m, m->cur->w, m->cur->gmin, d, m->cur->chord);
  }
  default: return m->vtol + cover_radius(pa, pb, pc);
  }
}

static int emit(Mesher *m, int a, int b, int c) {
  if (a < 0 || b < 0 || c < 0) return -1;
  if (grow((void **)&m->t, &m->capt, 3 * (m->nt + 1), sizeof *m->t) < 0) {
    m->err = MESH_ENOMEM;
    return -1;
  }
  m->t[3 * m->nt] = a;
  m->t[3 * m->nt + 1] = b;
  m->t[3 * m->nt + 2] = c;
  m->nt++;
  double e = tri_bound(m, a, b, c);
  if (e > m->rep->certified) m->rep->certified = e;
  return 0;
}

static int parity4(const int p[4]) {
  int inv = 0;
  for (int i = 0; i < 4; i++)
    for (int j = i + 1; j < 4; j++) inv += p[i] > p[j];
  return inv & 1;
}

/* A marching triangle whose edge (u, v) lies on a face where a sharp
   neighbour put the crease point c between u and v is split there, so
   the two sides meet edge to edge (c is on the surface and in the cell,
   so the cell's proof still covers the pieces). */
static int emit_split(Mesher *m, int a, int b, int c, int depth) {
  if (a < 0 || b < 0 || c < 0) return -1;
  if (m->crease.n && depth < 4) {
    int t[3] = {a, b, c};
    for (int e = 0; e < 3; e++) {
      int u = t[e], v = t[(e + 1) % 3], w = t[(e + 2) % 3];
      uint64_t key = u < v ? (uint64_t)u << 32 | (uint64_t)v
                           : (uint64_t)v << 32 | (uint64_t)u;
      int off = hget(&m->crease, key);
      if (off < 0) continue;
      int n = m->poly[off], prev = u;
      for (int q = 0; q <= n; q++) {
        int x = q == n ? v : m->poly[off + 1 + (u < v ? q : n - 1 - q)];
        if (emit_split(m, prev, x, w, depth + 1) < 0) return -1;
        prev = x;
      }
      return 0;
    }
  }
  return emit(m, a, b, c);
}

/* Marching tetrahedra: the triangles of the positively oriented
   tetrahedron on points c. When count is set, only count them. */
static int tet(Mesher *m, const int c[4], size_t *count) {
  static const int lone[4][4] = {
      {0, 1, 2, 3}, {1, 0, 3, 2}, {2, 3, 0, 1}, {3, 2, 1, 0}};
  int in[4], n = 0;
  for (int i = 0; i < 4; i++) n += in[i] = m->ps[c[i]];
  if (n == 0 || n == 4) return 0;
  if (n == 1 || n == 3) {
    if (count) return (void)(*count += 1), 0;
    int i = 0;
    while (in[i] != (n == 1)) i++;
    const int *p = lone[i];
    int e1 = edge_vertex(m, c[p[0]], c[p[1]]);
    int e2 = edge_vertex(m, c[p[0]], c[p[2]]);
    int e3 = edge_vertex(m, c[p[0]], c[p[3]]);
    return n == 1 ? emit_split(m, e1, e2, e3, 0) : emit_split(m, e1, e3, e2, 0);
  }
  if (count) return (void)(*count += 2), 0;
  int p[4], a = 0, b = 2;
  for (int i = 0; i < 4; i++) {
    if (in[i]) p[a++] = i;
    else p[b++] = i;
  }
  if (parity4(p)) {
    int x = p[2];
    p[2] = p[3];
    p[3] = x;
  }
  int q0 = edge_vertex(m, c[p[0]], c[p[2]]);
  int q1 = edge_vertex(m, c[p[0]], c[p[3]]);
  int q2 = edge_vertex(m, c[p[1]], c[p[3]]);
  int q3 = edge_vertex(m, c[p[1]], c[p[2]]);
  if (q0 < 0 || q1 < 0 || q2 < 0 || q3 < 0) return -1;
  if (dist3(m->v + 3 * q0, m->v + 3 * q2) <= dist3(m->v + 3 * q1, m->v + 3 * q3))
    return emit_split(m, q0, q1, q2, 0) < 0 ? -1 : emit_split(m, q0, q2, q3, 0);
  return emit_split(m, q1, q2, q3, 0) < 0 ? -1 : emit_split(m, q1, q3, q0, 0);
}

/* ---- a conforming tetrahedral mesh of the octree's surface leaves ----------

   A leaf whose six faces are plain (the cell across a face is not split
   and no edge carries a corner of a smaller cell) is cut into the 6 Kuhn
   tetrahedra around its main diagonal, as a uniform grid would be. Any
   other leaf gets a point at its centre and one tetrahedron from it to
   each triangle of its faces: a face whose neighbour is split is cut into
   its four quarters (recursively); a leaf face is cut along its diagonal
   from its lowest to its highest corner if it has only its 4 corners (the
   diagonal the Kuhn split of both cells uses), else fanned from its
   centre to its corners and to every corner of a smaller cell on its
   edges. Both cells sharing a face compute the same cut from the same
   global facts (which cells are split), so the tetrahedra meet face to
   face and the level set of the signs is closed across cells of any
   sizes. A corner of a smaller cell lies on an edge of a cell of level l
   exactly when one of the 4 cells of level l around that edge is split. */

static int fl_push(Mesher *m, int p) {
  if (p < 0) return -1;
  if (grow((void **)&m->fl, &m->capfl, m->nfl + 1, sizeof *m->fl) < 0) {
    m->err = MESH_ENOMEM;
    return -1;
  }
  m->fl[m->nfl++] = p;
  return 0;
}

/* The corners of smaller cells strictly inside the edge of level l from
   corner c (level-l units) along axis a, pushed in order from c, or from
   the far end when rev. */
static int edge_points(Mesher *m, int l, const int64_t c[3], int a, int rev) {
  int b = (a + 1) % 3, e = (a + 2) % 3, split = 0;
  for (int u = 0; u < 2 && !split; u++)
    for (int w = 0; w < 2 && !split; w++) {
      int64_t q[3] = {c[0], c[1], c[2]};
      q[b] -= u;
      q[e] -= w;
      split = is_split(m, l, q[0], q[1], q[2]);
    }
  if (!split) return 0;
  int64_t h0[3] = {2 * c[0], 2 * c[1], 2 * c[2]}, h1[3];
  memcpy(h1, h0, sizeof h1);
  h1[a] += 1;
  uint32_t mid[3];
  for (int i = 0; i < 3; i++)
    mid[i] = (uint32_t)(h1[i] << (m->depth - l));
  const int64_t *first = rev ? h1 : h0, *second = rev ? h0 : h1;
  if (edge_points(m, l + 1, first, a, rev) < 0) return -1;
  if (fl_push(m, point(m, mid)) < 0) return -1;
  return edge_points(m, l + 1, second, a, rev);
}

static int ft_push(Mesher *m, int a, int b, int c) {
  if (grow((void **)&m->ft, &m->capft, m->nft + 3, sizeof *m->ft) < 0) {
    m->err = MESH_ENOMEM;
    return -1;
  }
  m->ft[m->nft++] = a;
  m->ft[m->nft++] = b;
  m->ft[m->nft++] = c;
  return 0;
}

/* The triangles of the face of cell q (level l) on axis a, side s (0 low,
   1 high), counter-clockwise seen from outside the cell; *plain is cleared
   unless the face is one leaf face with its 4 corners only. */
static int face(Mesher *m, int l, const int64_t q[3], int a, int s,
                int *plain) {
  int64_t nb[3] = {q[0], q[1], q[2]};
  nb[a] += s ? 1 : -1;
  int b = (a + 1) % 3, e = (a + 2) % 3;
  if (is_split(m, l, nb[0], nb[1], nb[2])) {
    *plain = 0;
    for (int u = 0; u < 2; u++)
      for (int w = 0; w < 2; w++) {
        int64_t ch[3];
        ch[a] = 2 * q[a] + s;
        ch[b] = 2 * q[b] + u;
        ch[e] = 2 * q[e] + w;
        int dummy = 1;
        if (face(m, l + 1, ch, a, s, &dummy) < 0) return -1;
      }
    return 0;
  }
  /* the loop (0,0) (1,0) (1,1) (0,1) in (b, e) is counter-clockwise seen
     from +a; from -a it runs the other way */
  static const int cu[4] = {0, 1, 1, 0}, cw[4] = {0, 0, 1, 1};
  m->nfl = 0;
  for (int r = 0; r < 4; r++) {
    int k0 = s ? r : (4 - r) % 4, k1 = s ? (r + 1) % 4 : (3 - r) % 4;
    int64_t p0[3], p1[3];
    p0[a] = p1[a] = q[a] + s;
    p0[b] = q[b] + cu[k0];
    p0[e] = q[e] + cw[k0];
    p1[b] = q[b] + cu[k1];
    p1[e] = q[e] + cw[k1];
    uint32_t dc[3];
    for (int i = 0; i < 3; i++) dc[i] = (uint32_t)(p0[i] << (m->depth - l + 1));
    if (fl_push(m, point(m, dc)) < 0) return -1;
    int ax = p0[b] != p1[b] ? b : e, rev = p1[ax] < p0[ax];
    const int64_t *lowc = rev ? p1 : p0;
    if (edge_points(m, l, lowc, ax, rev) < 0) return -1;
  }
  size_t n = m->nfl;
  if (n == 4) {
    /* loop[0] is corner (0,0) and loop[2] is (1,1) either way round */
    if (ft_push(m, m->fl[0], m->fl[1], m->fl[2]) < 0) return -1;
    return ft_push(m, m->fl[0], m->fl[2], m->fl[3]);
  }
  *plain = 0;
  uint32_t fc[3];
  fc[a] = (uint32_t)((q[a] + s) << (m->depth - l + 1));
  fc[b] = (uint32_t)((2 * q[b] + 1) << (m->depth - l));
  fc[e] = (uint32_t)((2 * q[e] + 1) << (m->depth - l));
  int cp = point(m, fc);
  if (cp < 0) return -1;
  for (size_t i = 0; i < n; i++)
    if (ft_push(m, cp, m->fl[i], m->fl[(i + 1) % n]) < 0) return -1;
  return 0;
}

/* ---- sharp cells: the exact surface of a CSG of planes in a tetrahedron ----

   In a LEAF_EXACT cell the solid is decided by a Boolean combination of at
   most PL_MAX halfspaces (all other nodes are proven in or out over the
   box). In each tetrahedron the polygon of every plane i (plane i cut by
   the tetrahedron) is split by every other plane into convex pieces; a
   piece is surface exactly when the solid's value on it changes with the
   side of plane i (the value is computed from the sides, combinatorially,
   not from a sample), and it is oriented by which side is inside. The
   pieces' corners are named by what defines them: a plane on a
   tetrahedron edge, two planes on a tetrahedron face, three planes; the
   neighbours that share an edge or a face compute the same names and the
   same positions (from the sorted points and planes), so pieces meet edge
   to edge across tetrahedra and across the crease between two planes, and
   edges and corners of the solid are vertices and edges of the mesh. A
   plane's single crossing on an edge whose ends differ is the same vertex
   the marching cells make there (edge_vertex). Every side is decided
   exactly, a tie by a symbolic perturbation of the planes
   (mesh_exact.h), so every tetrahedron that asks gets the same answer,
   and the polygon's order comes from the corners' sides alone: where
   three planes share a line or four a point (a polygon's sides that
   mirror each other across a face), the pieces meet in vertices an
   infinitesimal apart, which weld makes one. The whole mesh is checked
   for closure at the end; should two neighbours still leave a crack, the
   sharp cells there are meshed by their tetrahedra (sharp_apart) or, at
   last, the mesh is made again without sharp cells (mesh_scene). */
/* a piece's vertices (a tetrahedron's section, at most 4, cut by the
   other 31 planes at most), the pieces of one plane's polygon (1 + 31 +
   31 * 30 / 2 at most), a tetrahedron's vertices (4 corners, 6 edges
   times 32 planes, 4 faces times 496 pairs, 4960 triples: 7140 at
   most): for up to 32 planes (PL_MAX) */
#define PV_MAX 40
#define PC_MAX 700
#define LV_MAX 8192

typedef struct {
  int n;
  unsigned bits;           /* side of each plane: 1 inside */
  int v[PV_MAX];           /* local vertices, counter-clockwise about +n_i */
  int sup[PV_MAX];         /* support of edge v[q] -> v[q+1]: a plane
                              (list index) or -1 - (tetrahedron face) */
} Piece;

typedef struct {
  uint64_t key[4];
  double x[3];
  int kind, la, lb, plane; /* kind 0: plane on a tetrahedron edge */
  int pi, pj, ps;          /* kind 1: planes pi and pj, and ps (a plane,
                              or -1 - the tetrahedron face) */
  unsigned asked, inside;  /* the planes asked of it (mesh_exact), and
                              the answers */
  int tie;                 /* at a degenerate point (some plane through
                              it exactly): placed exactly (mesh_exact) */
  int boxed;               /* box: 0 not yet made, 1 made, -1 none */
  MxBox box;               /* a box sure to hold it (mesh_exact) */
  int global;              /* mesh vertex, -1 until needed */
  int unified;             /* global is the marching cells' edge vertex */
} LVert;

typedef struct ExTet {
  Mesher *m;
  const int *p;            /* the tetrahedron's 4 points */
  double x[4][3];
  double s[PL_MAX][4];     /* each plane's signed distance at the corners */
  unsigned char in[PL_MAX][4]; /* and its side there, exactly (mesh_exact) */
  unsigned char on[PL_MAX][4]; /* 1 where the corner is on the plane */
  double se[PL_MAX][4];    /* a bound of s's rounding error */
  MxPlane pl[PL_MAX];      /* the planes, ranked by node */
  MxPlane face[4];         /* the faces (face q misses corner q), through
                              their corners in point order */
  unsigned faces;          /* those made (lv_three) */
  LVert lv[LV_MAX];
  int nlv;
  Piece pc[2][PC_MAX];
  int fe[LV_MAX][3];       /* surface edges on the faces: face, from, to */
  int nfe;
  int bad;
} ExTet;

static void pl_plane(const Mesher *m, int j, double n[3], double *d) {
  const ScNode *nd = &m->s->nodes[m->pls[m->cur->pl0 + j]];
  memcpy(n, nd->n, 3 * sizeof *n);
  *d = nd->d;
}

/* Solve rows a x = b (3 x 3) by Cramer's rule: 0, or -1 if near singular. */
static int solve3(const double a[3][3], const double b[3], double x[3]) {
  double c0[3], det;
  double r1[3] = {a[1][0], a[1][1], a[1][2]}, r2[3] = {a[2][0], a[2][1], a[2][2]};
  vec3_cross(r1, r2, c0);
  det = vec3_dot(a[0], c0);
  double sc = sqrt(vec3_dot(a[0], a[0]) * vec3_dot(r1, r1) * vec3_dot(r2, r2));
  if (!(fabs(det) > 1e-9 * sc)) return -1;
  for (int i = 0; i < 3; i++) {
    double m[3][3];
    memcpy(m, a, sizeof m);
    for (int r = 0; r < 3; r++) m[r][i] = b[r];
    double q1[3] = {m[1][0], m[1][1], m[1][2]}, q2[3] = {m[2][0], m[2][1], m[2][2]}, c[3];
    vec3_cross(q1, q2, c);
    x[i] = vec3_dot(m[0], c) / det;
  }
  return 0;
}

static int lv_find(ExTet *e, const uint64_t k[4]) {
  for (int i = 0; i < e->nlv; i++)
    if (!memcmp(e->lv[i].key, k, sizeof e->lv[i].key)) return i;
  return -1;
}

static int lv_add(ExTet *e, const uint64_t k[4], const double x[3], int kind,
                  int la, int lb, int plane) {
  int i = lv_find(e, k);
  if (i >= 0) return i;
  if (e->nlv == LV_MAX) {
    e->bad = 1;
    return -1;
  }
  LVert *v = &e->lv[e->nlv];
  memcpy(v->key, k, sizeof v->key);
  memcpy(v->x, x, sizeof v->x);
  v->kind = kind;
  v->la = la;
  v->lb = lb;
  v->plane = plane;
  v->pi = v->pj = v->ps = -1;
  v->asked = v->inside = 0;
  v->tie = 0;
  v->boxed = 0;
  v->global = -1;
  v->unified = 0;
  return e->nlv++;
}

/* t in [0, 1] (NaN, from 0 / 0, as 1/2). */
static double clamp01(double t) {
  return t >= 0 ? (t <= 1 ? t : 1) : t < 0 ? 0 : 0.5;
}

/* Plane i on the tetrahedron edge la - lb (its sides differ there). */
static int ex_edge(ExTet *e, int i, int la, int lb) {
  int pa = e->p[la], pb = e->p[lb];
  if (pa > pb) {
    int t = la;
    la = lb;
    lb = t;
    pa = e->p[la];
    pb = e->p[lb];
  }
  /* (the sides are exact; the distances rounded, so t is kept in [0, 1]) */
  double sa = e->s[i][la], sb = e->s[i][lb], t = clamp01(sa / (sa - sb)), x[3];
  /* a plane exactly through a corner crosses there */
  if (e->on[i][la]) t = 0;
  else if (e->on[i][lb]) t = 1;
  for (int q = 0; q < 3; q++) x[q] = e->x[la][q] + t * (e->x[lb][q] - e->x[la][q]);
  uint64_t k[4] = {5, (uint64_t)pa << 32 | (uint64_t)pb,
                   (uint64_t)e->m->pls[e->m->cur->pl0 + i], 0};
  int v = lv_add(e, k, x, 0, la, lb, i);
  if (v >= 0 && (e->on[i][la] || e->on[i][lb])) e->lv[v].tie = 1;
  return v;
}

/* The corners of the tetrahedron's face ex (the one without corner ex),
   in point order: every tetrahedron sharing the face takes them alike. */
static void face_corners(const ExTet *e, int ex, int f[3]) {
  int nf = 0;
  for (int q = 0; q < 4; q++)
    if (q != ex) f[nf++] = q;
  for (int a = 0; a < 2; a++)
    for (int c = 0; c < 2 - a; c++)
      if (e->p[f[c]] > e->p[f[c + 1]]) {
        int t = f[c];
        f[c] = f[c + 1];
        f[c + 1] = t;
      }
}

/* The vertex where piece edge (a, b) with support sup meets plane j. */
static void lv_three(ExTet *e, const LVert *w, const MxPlane *three[3]);

static int ex_split(ExTet *e, int i, int sup, int j, int a, int b) {
  const Mesher *m = e->m;
  uint64_t k[4];
  double A[3][3], B[3], x[3];
  pl_plane(m, i, A[0], &B[0]);
  pl_plane(m, j, A[1], &B[1]);
  uint64_t ni = (uint64_t)m->pls[m->cur->pl0 + i], nj = (uint64_t)m->pls[m->cur->pl0 + j];
  if (ni > nj) {
    uint64_t t = ni;
    ni = nj;
    nj = t;
  }
  if (sup >= 0) { /* three planes */
    pl_plane(m, sup, A[2], &B[2]);
    uint64_t n3[3] = {ni, nj, (uint64_t)m->pls[m->cur->pl0 + sup]};
    for (int r = 0; r < 2; r++)
      for (int c = 0; c < 2 - r; c++)
        if (n3[c] > n3[c + 1]) {
          uint64_t t = n3[c];
          n3[c] = n3[c + 1];
          n3[c + 1] = t;
        }
    k[0] = 3;
    k[1] = n3[0];
    k[2] = n3[1];
    k[3] = n3[2];
    /* the rows in node order, so that every tetrahedron solves alike */
    double R[3][3], Rb[3];
    for (int r = 0; r < 3; r++) {
      int li = n3[r] == (uint64_t)m->pls[m->cur->pl0 + i] ? i
               : n3[r] == (uint64_t)m->pls[m->cur->pl0 + j] ? j : sup;
      pl_plane(m, li, R[r], &Rb[r]);
    }
    memcpy(A, R, sizeof A);
    memcpy(B, Rb, sizeof B);
  } else { /* two planes on a tetrahedron face */
    int f[3];
    face_corners(e, -1 - sup, f);
    double u[3], w[3];
    for (int q = 0; q < 3; q++) {
      u[q] = e->x[f[1]][q] - e->x[f[0]][q];
      w[q] = e->x[f[2]][q] - e->x[f[0]][q];
    }
    double fi[3], fj[3], bi, bj;
    pl_plane(m, ni == (uint64_t)m->pls[m->cur->pl0 + i] ? i : j, fi, &bi);
    pl_plane(m, ni == (uint64_t)m->pls[m->cur->pl0 + i] ? j : i, fj, &bj);
    memcpy(A[0], fi, sizeof fi);
    memcpy(A[1], fj, sizeof fj);
    B[0] = bi;
    B[1] = bj;
    vec3_cross(u, w, A[2]);
    B[2] = vec3_dot(A[2], e->x[f[0]]);
    k[0] = 4;
    k[1] = (uint64_t)e->p[f[0]] << 32 | (uint64_t)e->p[f[1]];
    k[2] = (uint64_t)e->p[f[2]];
    k[3] = ni << 32 | nj;
  }
  int near = solve3(A, B, x) < 0;
  if (near) { /* near parallel: between the two ends, unless placed below */
    double n[3], d;
    pl_plane(m, j, n, &d);
    double sa = vec3_dot(n, e->lv[a].x) - d, sb = vec3_dot(n, e->lv[b].x) - d;
    double t = sa / (sa - sb);
    t = clamp01(t);
    for (int q = 0; q < 3; q++) x[q] = e->lv[a].x[q] + t * (e->lv[b].x[q] - e->lv[a].x[q]);
  }
  int n0 = e->nlv, v = lv_add(e, k, x, 1, -1, -1, -1);
  if (v >= 0 && e->nlv > n0) {
    e->lv[v].pi = i;
    e->lv[v].pj = j;
    e->lv[v].ps = sup;
    /* near parallel planes (a face of one prism and the same face of a
       prism touching it, their doubles rounded apart) meet where the
       doubles cannot say: the two ends' sides of plane j are then both
       rounding, and a point between them anywhere on the edge (0.12
       away on two 8-sided prisms side by side: a spike folding the
       face over itself). In the second try (mesh_scene) placed exactly
       (rounded toward 0) instead, when that is farther than the weld
       joins. (Not always: where two faces of parts touching face to face
       cross at a tiny angle, the exact points made sharp cells the first
       way kept fail their checks: 4 of 400 fuzzed contact scenes.) */
    const MxPlane *three[3];
    double y[3];
    if (near && m->near_exact) {
      lv_three(e, &e->lv[v], three);
      double g = ldexp(m->h, MAX_DEPTH) * WELD, *xv = e->lv[v].x;
      if (mx_three_point(three, y) == 0 &&
          !(fabs(y[0] - xv[0]) <= g && fabs(y[1] - xv[1]) <= g &&
            fabs(y[2] - xv[2]) <= g))
        memcpy(xv, y, sizeof y);
    }
  }
  /* a split beside a degenerate point may be at it too (the edge's line
     in a third plane, whose test at the edge's ends was a tie): placed
     exactly like its ends */
  if (v >= 0 && (e->lv[a].tie || e->lv[b].tie)) e->lv[v].tie = 1;
  return v;
}

/* The three planes meeting at split vertex w. */
static void lv_three(ExTet *e, const LVert *w, const MxPlane *three[3]) {
  if (w->ps >= 0) {
    three[0] = &e->pl[w->pi];
    three[1] = &e->pl[w->pj];
    three[2] = &e->pl[w->ps];
    return;
  }
  int ex = -1 - w->ps;
  if (!(e->faces >> ex & 1)) {
    /* face ex through its corners in point order, as ex_split takes it */
    int f[3];
    face_corners(e, ex, f);
    MxPlane *fp = &e->face[ex];
    for (int c = 0; c < 3; c++) fp->pts[c] = e->x[f[c]];
    fp->rank = -1;
    mx_plane_prep(fp);
    e->faces |= 1u << ex;
  }
  three[0] = &e->face[ex];
  three[1] = &e->pl[w->pi];
  three[2] = &e->pl[w->pj];
}

static int lv_box(ExTet *e, LVert *w) {
  if (w->kind == 0) /* from the corners' rounded distances and bounds */
    return mx_edge_box(e->x[w->la], e->x[w->lb], e->s[w->plane][w->la],
                       e->se[w->plane][w->la], e->s[w->plane][w->lb],
                       e->se[w->plane][w->lb], &w->box);
  const MxPlane *three[3];
  lv_three(e, w, three);
  return mx_three_box(three, &w->box);
}

/* Whether local vertex v is inside plane j (list index), exactly and
   perturbed (mesh_exact.h): the same answer in every tetrahedron that
   asks, whatever rounding did to v's position. */
static int lv_in(ExTet *e, int v, int j) {
  LVert *w = &e->lv[v];
  unsigned bit = 1u << j;
  if (w->asked & bit) return (w->inside & bit) != 0;
  int r, tie = 0;
  if (!w->boxed) w->boxed = lv_box(e, w) == 0 ? 1 : -1;
  if (w->boxed > 0 && (r = mx_box_in(&w->box, &e->pl[j])) >= 0) {
    /* decided by the box: no tie */
  } else if (w->kind == 0) {
    r = mx_edge_in(e->x[w->la], e->x[w->lb], e->in[w->plane][w->la],
                   &e->pl[w->plane], &e->pl[j], &tie);
  } else {
    const MxPlane *three[3];
    lv_three(e, w, three);
    r = mx_three_in(three, &e->pl[j], &tie);
  }
  if (tie) w->tie = 1;
  w->asked |= bit;
  if (r) w->inside |= bit;
  return r;
}

/* pl_eval's answers in one cell: its six tetrahedra ask of the same
   sides again (a piece of the arrangement crosses several), and the
   program is the cell's. A slot holds the bits it was asked for, from
   the cell whose number (cur, counted by pl_prog) is in gen. */
#define PL_MEMO 1024
typedef struct PlMemo {
  unsigned key[PL_MEMO], gen[PL_MEMO];
  unsigned char val[PL_MEMO];
  unsigned cur;
} PlMemo;

/* pl_eval's program for the cell whose classes are in m->st: the nodes
   its value depends on, children first. A node decided by its class
   takes no part; an operation one of whose operands leaves the other
   unchanged (an intersection with a part the cell is inside, a union
   with one it is outside, a difference with one it is outside) takes
   that operand's value: an intersection of n halfspaces of which two
   cross the cell is two nodes and one operation, not 2n nodes. */
static void pl_prog(Mesher *m) {
  const Scene *s = m->s;
  if (m->memo && ++m->memo->cur == 0) { /* a new cell's answers */
    memset(m->memo->gen, 0, sizeof m->memo->gen);
    m->memo->cur = 1;
  }
  int f = s->nodes[m->node].first;
  m->nprog = 0;
  for (int i = f; i <= m->node; i++) {
    const ScNode *nd = &s->nodes[i];
    int c = m->st[i - f];
    if (c == T_IN || c == T_OUT) {
      m->alias[i - f] = -1;
      continue;
    }
    if (nd->kind == SC_UNION || nd->kind == SC_INTER || nd->kind == SC_DIFF) {
      int ca = m->st[nd->a - f], cb = m->st[nd->b - f], id = nd->kind == SC_INTER ? T_IN : T_OUT;
      if (nd->kind != SC_DIFF && ca == id) {
        m->alias[i - f] = m->alias[nd->b - f];
        continue;
      }
      if (cb == id) {
        m->alias[i - f] = m->alias[nd->a - f];
        continue;
      }
    }
    m->alias[i - f] = i;
    m->prog[m->nprog++] = i;
  }
}

/* A node's value in pl_eval: its class's, or its alias's. */
static int pl_val(const Mesher *m, int f, int x) {
  int c = m->st[x - f];
  if (c == T_IN || c == T_OUT) return c == T_IN;
  return m->pv[m->alias[x - f] - f];
}

/* The solid's value with each plane on the side its bit says (scene_box's
   classes in m->st decide every other node; pl_prog made the program). */
static int pl_run(const Mesher *m, unsigned bits) {
  const Scene *s = m->s;
  int f = s->nodes[m->node].first;
  for (int k = 0; k < m->nprog; k++) {
    int i = m->prog[k], v;
    const ScNode *nd = &s->nodes[i];
    if (nd->kind == SC_HALFSPACE) {
      int q = m->plmap[i - f];
      v = (int)(bits >> (q >> 1) & 1) ^ (q & 1);
    } else {
      int a = pl_val(m, f, nd->a), b = pl_val(m, f, nd->b);
      v = nd->kind == SC_UNION ? a | b : nd->kind == SC_INTER ? a & b : a & !b;
    }
    m->pv[i - f] = (unsigned char)v;
  }
  return pl_val(m, f, m->node);
}

/* Plane j at plane a's crossing of the edge la - lb (whose box is ba, or
   NULL), exactly. */
static int edge_order(ExTet *e, int la, int lb, int a, const MxBox *ba, int j) {
  int r, tie;
  if (ba && (r = mx_box_in(ba, &e->pl[j])) >= 0) return r;
  return mx_edge_in(e->x[la], e->x[lb], e->in[a][la], &e->pl[a], &e->pl[j], &tie);
}

/* A vertex at a degenerate point placed exactly (mesh_exact.h), so that
   every vertex there has the same position and weld makes them one. */
static void lv_exact(ExTet *e, LVert *v) {
  if (v->kind == 0) {
    if (e->on[v->plane][v->la]) memcpy(v->x, e->x[v->la], sizeof v->x);
    else if (e->on[v->plane][v->lb]) memcpy(v->x, e->x[v->lb], sizeof v->x);
    else mx_edge_point(e->x[v->la], e->x[v->lb], &e->pl[v->plane], v->x);
    return;
  }
  const MxPlane *three[3];
  lv_three(e, v, three);
  double x[3];
  if (mx_three_point(three, x) == 0) memcpy(v->x, x, sizeof x);
}

static int pl_eval(const Mesher *m, unsigned bits) {
  PlMemo *c = m->memo;
  if (!c) return pl_run(m, bits);
  unsigned h = (bits * 0x9E3779B1u) >> 22; /* 10 bits: PL_MEMO */
  if (c->gen[h] == c->cur && c->key[h] == bits) return c->val[h];
  int v = pl_run(m, bits);
  c->gen[h] = c->cur;
  c->key[h] = bits;
  c->val[h] = (unsigned char)v;
  return v;
}

static int lv_global(ExTet *e, int i) {
  LVert *v = &e->lv[i];
  if (v->global >= 0) return v->global;
  Mesher *m = e->m;
  if (v->kind == 0) {
    /* the solid's value along the edge, between the planes' crossings:
       one change, with the ends' signs differing, is the one crossing a
       marching neighbour finds there too */
    int la = v->la, lb = v->lb, pa = e->p[la], pb = e->p[lb];
    int k = m->cur->npl, nt = 0, cr[PL_MAX], bx[PL_MAX];
    MxBox box[PL_MAX];
    unsigned bits = 0;
    for (int j = 0; j < k; j++) {
      if (e->in[j][la]) bits |= 1u << j;
      if (e->in[j][la] == e->in[j][lb]) continue;
      /* the crossings in their (perturbed) order from la: b's is after
         a's when b is still on its la side at a's */
      int r = nt++;
      bx[r] = mx_edge_box(e->x[la], e->x[lb], e->s[j][la], e->se[j][la],
                          e->s[j][lb], e->se[j][lb], &box[r]) == 0;
      MxBox bj = box[r];
      int bjok = bx[r];
      while (r > 0 && edge_order(e, la, lb, cr[r - 1], bx[r - 1] ? &box[r - 1] : NULL,
                                 j) != e->in[j][la]) {
        box[r] = box[r - 1];
        bx[r] = bx[r - 1];
        cr[r] = cr[r - 1];
        r--;
      }
      cr[r] = j;
      box[r] = bj;
      bx[r] = bjok;
    }
    int changes = 0, prev = pl_eval(m, bits);
    for (int r = 0; r < nt; r++) {
      bits ^= 1u << cr[r];
      int val = pl_eval(m, bits);
      changes += val != prev;
      prev = val;
    }
    if (m->ps[pa] != m->ps[pb] && changes == 1) {
      v->unified = 1;
      return v->global = edge_vertex(m, pa, pb);
    }
  }
  if (v->tie) lv_exact(e, v);
  int g = kmap_get(&m->vert2, v->key);
  if (g >= 0) {
    if (v->tie && !m->xact[g]) { /* placed before by a tetrahedron that
                                    did not see the degeneracy */
      memcpy(m->v + 3 * (size_t)g, v->x, sizeof v->x);
      m->xact[g] = 1;
    }
    return v->global = g;
  }
  if (grow((void **)&m->v, &m->capv, 3 * (m->nv + 1), sizeof *m->v) < 0 ||
      kmap_put(&m->vert2, v->key, (int)m->nv) < 0) {
    m->err = MESH_ENOMEM;
    return -1;
  }
  if (grow((void **)&m->uni, &m->capuni, m->nv + 1, 1) < 0) {
    m->err = MESH_ENOMEM;
    return -1;
  }
  m->uni[m->nv] = 0;
  if (grow((void **)&m->xact, &m->capxact, m->nv + 1, 1) < 0) {
    m->err = MESH_ENOMEM;
    return -1;
  }
  m->xact[m->nv] = (unsigned char)v->tie;
  memcpy(m->v + 3 * m->nv, v->x, sizeof v->x);
  return v->global = (int)m->nv++;
}

static void pc_push(Piece *p, int v, int sup, int *bad) {
  if (p->n == PV_MAX) {
    *bad = 1;
    return;
  }
  p->v[p->n] = v;
  p->sup[p->n++] = sup;
}

/* The exact surface in the positively oriented tetrahedron on points p. */
/* The sharp cell being meshed, as the last word of its face paths' keys:
   a path runs along one face of one cell. (With the plane alone, a
   vertex on a cell edge had two successors in one plane when the faces
   on both sides of that edge carried paths -- of two sharp cells facing
   each other there -- and the second was dropped: the marching
   neighbour's edge was then not split, leaving a hole of one triangle;
   random scenes 99, 171, 203 and 219 of the property test's generator
   gave up their sharp cells for it.) Level and corner in 5 + 3 x 19
   bits (q < 2^level, level <= MAX_DEPTH). */
static uint64_t face_cell(const Mesher *m) {
  const Leaf *lf = m->cur;
  return (uint64_t)lf->level << 57 | (uint64_t)lf->q[0] << 38 |
         (uint64_t)lf->q[1] << 19 | (uint64_t)lf->q[2];
}

static int exact_tet(Mesher *m, const int p[4], size_t *count) {
  ExTet *e = m->ex;
  e->m = m;
  e->p = p;
  e->nlv = 0;
  e->nfe = 0;
  e->bad = 0;
  int k = m->cur->npl;
  for (int q = 0; q < 4; q++)
    for (int a = 0; a < 3; a++) e->x[q][a] = m->org[a] + 0.5 * m->h * m->pc[3 * p[q] + a];
  e->faces = 0;
  for (int j = 0; j < k; j++) {
    MxPlane *pl = &e->pl[j];
    pl_plane(m, j, pl->n, &pl->d);
    pl->pts[0] = pl->pts[1] = pl->pts[2] = NULL;
    pl->rank = m->pls[m->cur->pl0 + j];
    mx_plane_prep(pl);
    for (int q = 0; q < 4; q++) {
      int tie;
      /* the rounded distance decides when it is beyond 2^-50 of the
         permanent (3 ulps bound its error; mesh_exact.h) */
      const double *x = e->x[q];
      double p0 = pl->n[0] * x[0], p1 = pl->n[1] * x[1], p2 = pl->n[2] * x[2];
      double sv = p0 + p1 + p2 - pl->d;
      double eb = 0x1p-50 * (fabs(p0) + fabs(p1) + fabs(p2) + fabs(pl->d)) + 0x1p-400;
      e->s[j][q] = sv; /* vec3_dot's order */
      e->se[j][q] = eb;
      if (sv > eb || sv < -eb) {
        e->in[j][q] = sv < 0;
        e->on[j][q] = 0;
        continue;
      }
      e->in[j][q] = (unsigned char)mx_point_in(pl, x, &tie);
      e->on[j][q] = (unsigned char)tie;
    }
  }
  for (int i = 0; i < k; i++) {
    /* plane i's polygon: its crossings of the tetrahedron's edges, in
       counter-clockwise order about +n_i, decided from the corners' sides
       alone (a plane through a corner, perturbed, has its crossings there
       apart by an infinitesimal): with one corner L alone on its side
       and the others a < b < c, (L a, L b, L c) when the permutation
       (L a b c) of the positive tetrahedron is even and L inside, or odd
       and L outside; with a < b on one side and c < d on the other,
       (a c, a d, b d, b c) when (a b c d) is even and a, b inside, or
       odd and a, b outside; else the reverse */
    const unsigned char *si = e->in[i];
    int nsi = si[0] + si[1] + si[2] + si[3];
    if (nsi == 0 || nsi == 4) continue;
    int ce[4][2], nc = 0, cv[4], ord[4] = {0, 1, 2, 3};
    int odd = 0, ccw;
    if (nsi == 1 || nsi == 3) {
      int L = 0;
      while ((si[L] != 0) != (nsi == 1)) L++;
      for (int q = 0; q < 4; q++)
        if (q != L) {
          ce[nc][0] = L;
          ce[nc][1] = q;
          nc++;
        }
      odd = L & 1; /* (L a b c): L transpositions */
      ccw = !odd == !!si[L];
    } else {
      int in2[2], out2[2], ni = 0, no = 0;
      for (int q = 0; q < 4; q++) {
        if (si[q]) in2[ni++] = q;
        else out2[no++] = q;
      }
      const int a = in2[0], b = in2[1], c = out2[0], d = out2[1];
      const int seq[4] = {a, b, c, d};
      for (int x = 0; x < 4; x++)
        for (int y = x + 1; y < 4; y++) odd ^= seq[x] > seq[y];
      ce[0][0] = a, ce[0][1] = c;
      ce[1][0] = a, ce[1][1] = d;
      ce[2][0] = b, ce[2][1] = d;
      ce[3][0] = b, ce[3][1] = c;
      nc = 4;
      ccw = !odd; /* a, b are the inside pair */
    }
    for (int q = 0; q < nc; q++) cv[q] = ex_edge(e, i, ce[q][0], ce[q][1]);
    if (e->bad) return (void)(m->err = MESH_EINTERNAL), -1;
    if (!ccw)
      for (int q = 0; q < nc / 2; q++) {
        int t = ord[q];
        ord[q] = ord[nc - 1 - q];
        ord[nc - 1 - q] = t;
      }
    Piece *cur = e->pc[0], *nxt = e->pc[1];
    int np = 1;
    cur[0].n = 0;
    cur[0].bits = 0;
    for (int q = 0; q < nc; q++) {
      int a = ord[q], b = ord[(q + 1) % nc], ex = 0;
      /* the face holding both edges misses one corner */
      int seen[4] = {0, 0, 0, 0};
      seen[ce[a][0]] = seen[ce[a][1]] = seen[ce[b][0]] = seen[ce[b][1]] = 1;
      while (seen[ex]) ex++;
      pc_push(&cur[0], cv[a], -1 - ex, &e->bad);
    }
    for (int j = 0; j < k; j++) {
      if (j == i) continue;
      int nn = 0;
      for (int r = 0; r < np; r++) {
        Piece *P = &cur[r];
        int in[PV_MAX], nin = 0;
        for (int q = 0; q < P->n; q++) nin += in[q] = lv_in(e, P->v[q], j);
        if (nin == 0 || nin == P->n) {
          if (nn == PC_MAX) return (void)(m->err = MESH_EINTERNAL), -1;
          nxt[nn] = *P;
          if (nin) nxt[nn].bits |= 1u << j;
          nn++;
          continue;
        }
        if (nn + 2 > PC_MAX) return (void)(m->err = MESH_EINTERNAL), -1;
        Piece *I = &nxt[nn], *O = &nxt[nn + 1];
        I->n = O->n = 0;
        I->bits = P->bits | 1u << j;
        O->bits = P->bits;
        for (int q = 0; q < P->n; q++) {
          int r2 = (q + 1) % P->n;
          pc_push(in[q] ? I : O, P->v[q], P->sup[q], &e->bad);
          if (in[q] != in[r2]) {
            int x = ex_split(e, i, P->sup[q], j, P->v[q], P->v[r2]);
            if (x < 0) return (void)(m->err = MESH_EINTERNAL), -1;
            if (in[q]) {
              pc_push(I, x, j, &e->bad);
              pc_push(O, x, P->sup[q], &e->bad);
            } else {
              pc_push(O, x, j, &e->bad);
              pc_push(I, x, P->sup[q], &e->bad);
            }
          }
        }
        nn += 2;
      }
      Piece *t = cur;
      cur = nxt;
      nxt = t;
      np = nn;
    }
    if (e->bad) return (void)(m->err = MESH_EINTERNAL), -1;
    for (int r = 0; r < np; r++) {
      const Piece *P = &cur[r];
      int vin = pl_eval(m, P->bits | 1u << i), vout = pl_eval(m, P->bits & ~(1u << i));
      if (vin == vout || P->n < 3) continue;
      if (count) {
        *count += (size_t)(P->n - 2);
        continue;
      }
      int g[PV_MAX];
      for (int q = 0; q < P->n; q++)
        if ((g[q] = lv_global(e, P->v[q])) < 0) return -1;
      /* its edges on the cell's faces, as the surface runs (paths) */
      for (int q = 0; q < P->n; q++) {
        if (P->sup[q] >= 0) continue;
        int ex = -1 - P->sup[q], ax = -1;
        for (int a = 0; a < 3 && ax < 0; a++) {
          uint32_t c0 = UINT32_MAX;
          int same = 1;
          for (int r2 = 0; r2 < 4; r2++)
            if (r2 != ex) {
              uint32_t cc = m->pc[3 * p[r2] + a];
              if (c0 == UINT32_MAX) c0 = cc;
              else same &= cc == c0;
            }
          if (same) ax = a;
        }
        if (ax < 0) continue; /* inside the cell */
        int ga = g[q], gb = g[(q + 1) % P->n];
        if (!vin) {
          int t = ga;
          ga = gb;
          gb = t;
        }
        uint64_t key[4] = {(uint64_t)ga, (uint64_t)ax,
                           m->pc[3 * p[ex == 0 ? 1 : 0] + ax], face_cell(m)};
        if (kmap_get(&m->fpath, key) >= 0) continue;
        if (kmap_put(&m->fpath, key, gb) < 0 ||
            grow((void **)&m->fstart, &m->capfs, 4 * (m->nfs + 1), sizeof *m->fstart) < 0)
          return (void)(m->err = MESH_ENOMEM), -1;
        memcpy(m->fstart + 4 * m->nfs++, key, sizeof key);
      }
      for (int q = 1; q + 1 < P->n; q++) {
        int rc = vin ? emit(m, g[0], g[q], g[q + 1]) : emit(m, g[0], g[q + 1], g[q]);
        if (rc < 0) return -1;
      }
    }
  }
  return 0;
}

/* The mesh's edges shorter than WELD (of the octree's side) collapsed,
   and the triangles that lose their area by it dropped. The sharp
   cells' perturbed planes (mesh_exact.h) meet a degenerate point (three
   planes through one line, four through one point: a polygon's sides
   that mirror each other across a face) in several vertices an
   infinitesimal apart, joined by edges of no length and triangles of no
   area, the same in every tetrahedron: closed and consistently oriented,
   but not a mesh to write. When the planes' doubles make the point only
   nearly degenerate (a mirrored polygon's offsets rounded), those
   vertices are 1e-16 apart and their rounded positions can cross. Only
   edges are collapsed: two sheets that nearly touch (a gap of 1e-13)
   share no edge and stay apart; a pinch is parted (weld_fans). In
   mesh_scene's second try (m->near_weld) any two vertices within the
   distance are joined too: four planes all but through one line leave
   vertices 1e-16 apart on no common edge. The closure and
   self-intersection checks judge the result.
   0, or -1 out of memory. */

/* par: each vertex's class (its first vertex). Every class whose first
   vertex would not be made of closed fans once welded (its triangles'
   far edges, b -> c of each (r, b, c) left with area: each end must
   start exactly one far edge, so that they make disjoint cycles) is
   undone: its vertices map to themselves. A class of several cycles (a
   pinch joined by a neck of no width) is welded, and part_contacts
   parts it. 0, or -1 out of memory. */
static int weld_fans(Mesher *m, int *par) {
  size_t nv = m->nv, nt = m->nt;
  int *cnt = calloc(nv + 1, sizeof *cnt), *at = NULL, *lk = NULL;
  unsigned char *multi = NULL, *bad = NULL;
  int rc = -1;
  if (!cnt) return -1;
  /* the far edges of the welded triangles, by their class's vertex */
  for (size_t t = 0; t < nt; t++) {
    int v[3];
    for (int k = 0; k < 3; k++) v[k] = par[m->t[3 * t + (size_t)k]];
    if (v[0] == v[1] || v[1] == v[2] || v[2] == v[0]) continue;
    for (int k = 0; k < 3; k++) cnt[v[k] + 1]++;
  }
  for (size_t i = 0; i < nv; i++) cnt[i + 1] += cnt[i];
  size_t ne = (size_t)(cnt[nv] ? cnt[nv] : 1);
  at = malloc(nv * sizeof *at);
  lk = malloc(2 * ne * sizeof *lk);
  multi = calloc(nv, 1);
  bad = calloc(nv, 1);
  if (!at || !lk || !multi || !bad) goto done;
  for (size_t i = 0; i < nv; i++) at[i] = cnt[i];
  for (size_t t = 0; t < nt; t++) {
    int v[3];
    for (int k = 0; k < 3; k++) v[k] = par[m->t[3 * t + (size_t)k]];
    if (v[0] == v[1] || v[1] == v[2] || v[2] == v[0]) continue;
    for (int k = 0; k < 3; k++) {
      int q = at[v[k]]++;
      lk[2 * q] = v[(k + 1) % 3];
      lk[2 * q + 1] = v[(k + 2) % 3];
    }
  }
  /* which classes have more than one vertex */
  for (size_t i = 0; i < nv; i++)
    if (par[i] != (int)i) multi[par[i]] = 1;
  for (size_t r = 0; r < nv; r++) {
    if (!multi[r]) continue;
    int lo = cnt[r], n = cnt[r + 1] - lo;
    if (n < 3) { /* none: a part of no size, gone whole; else not closed */
      bad[r] = n > 0;
      continue;
    }
    /* closed: every far edge's end starts as many far edges as end
       there (one each: one fan or disjoint fans; more: parts touching
       along a line through the vertex, part_contacts pairs them) */
    for (int q = lo; q < lo + n && !bad[r]; q++) {
      int starts = 0, ends = 0;
      for (int p = lo; p < lo + n; p++) {
        starts += lk[2 * p] == lk[2 * q + 1];
        ends += lk[2 * p + 1] == lk[2 * q + 1];
      }
      if (starts != ends || lk[2 * q] == lk[2 * q + 1]) bad[r] = 1;
    }
  }
  for (size_t i = 0; i < nv; i++)
    if (bad[par[i]]) par[i] = (int)i;
  rc = 0;
done:
  free(cnt);
  free(at);
  free(lk);
  free(multi);
  free(bad);
  return rc;
}

/* Parts of the solid that touch, at a point (a prism bored through by
   another of its radius, whose edges meet on the bore's axis plane; two
   boxes corner to corner) or along a line (boxes or prisms edge to
   edge): the perturbation of the sharp cells joins them by a neck of no
   width (welded into one vertex) or meets them at shared vertices and
   edges. A vertex whose triangles make several fans (joined across its
   edges: an edge of two triangles joins them; an edge of more is a
   line where parts touch, whose triangles are paired about it, each
   with the one that closes its part's wedge) gets a vertex per fan,
   each moved into its part by PINCH of the octree's side or of the
   point's largest coordinate, whichever is larger (32 of its ulps at
   least; a thousandth of its nearest neighbour's distance, if less),
   towards its neighbours' centroid, or against its normal when that
   points out, less its component along the lines of contact: the parts
   touch no more, the mesh is a manifold, and the move, within the flat
   regions' flatness (2^-44 of the size, mesh_merge_flat), leaves the
   faces about the point to be merged whole. After the merge, widen
   moves each such vertex on, the same way, to PINCH_OUT of that size
   (at most a sixteenth of the tolerance): STL, PLY and 3MF keep floats,
   whose rounding (2^-24) would put the parts' vertices back together.
   *moved: the largest move, widened. 0 (nothing parted when a line's
   triangles do not alternate in and out about it), or -1 out of
   memory. */
#define PINCH 0x1p-47
#define PINCH_OUT 0x1p-18
#define FACES_MAX 16 /* triangles about a line of contact */

/* The way from P into the part of a fan (its corners cnr[0 .. k-1],
   each a triangle's corner 3 t + c): towards its far vertices'
   centroid, or against its normal when the fan is flat, less the
   components along ln[0 .. nl-1] (orthonormal); unit, in u; *dmin: the
   nearest far vertex's distance; N, if not NULL: the fan's normal (its
   triangles' area-weighted). 0, or -1 if there is none. */
static int fan_dir(const Mesher *m, const double *P, const int *cnr, int k,
                   const double (*ln)[3], int nl, double u[3], double *dmin,
                   double *Nout) {
  double C[3] = {0, 0, 0}, N[3] = {0, 0, 0}, area = 0;
  *dmin = INFINITY;
  for (int j = 0; j < k; j++) {
    size_t t = (size_t)cnr[j] / 3, c = (size_t)cnr[j] % 3;
    const double *a = m->v + 3 * (size_t)m->t[3 * t + (c + 1) % 3],
                 *b = m->v + 3 * (size_t)m->t[3 * t + (c + 2) % 3];
    double x[3], w[3], y[3];
    for (int i = 0; i < 3; i++) {
      x[i] = a[i] - P[i];
      w[i] = b[i] - P[i];
      C[i] += a[i];
    }
    vec3_cross(x, w, y);
    for (int i = 0; i < 3; i++) N[i] += y[i];
    area += sqrt(vec3_dot(y, y));
    *dmin = fmin(*dmin, sqrt(vec3_dot(x, x)));
  }
  if (Nout) memcpy(Nout, N, sizeof N);
  if (k < 1) return -1;
  /* into the fan's own cone, the solid's (a tip) or the space's (a
     cavity's corner): parts that touch have cones that meet only at P;
     a flat fan (its triangles' normals alike) has none: into the solid */
  for (int i = 0; i < 3; i++) u[i] = C[i] / k - P[i];
  if (sqrt(vec3_dot(N, N)) >= (1 - 1e-9) * area)
    for (int i = 0; i < 3; i++) u[i] = -N[i];
  for (int l = 0; l < nl; l++) {
    double p = vec3_dot(u, ln[l]);
    for (int i = 0; i < 3; i++) u[i] -= p * ln[l][i];
  }
  double l = sqrt(vec3_dot(u, u));
  if (!(l > 0) || !(*dmin > 0)) return -1;
  for (int i = 0; i < 3; i++) u[i] /= l;
  return 0;
}

static int corner_find(int *p, int x) {
  while (p[x] != x) x = p[x] = p[p[x]];
  return x;
}

/* Each vertex's corners: *cntp (nv + 1 offsets) and *cnp (each corner as
   3 t + c, vertex by vertex). 0, or -1 out of memory (nothing kept). */
static int vertex_corners(const Mesher *m, int **cntp, int **cnp) {
  size_t nv = m->nv, nc = 3 * m->nt;
  int *cnt = calloc(nv + 1, sizeof *cnt), *at = malloc((nv ? nv : 1) * sizeof *at),
      *cn = malloc((nc ? nc : 1) * sizeof *cn);
  if (!cnt || !at || !cn) {
    free(cnt);
    free(at);
    free(cn);
    return -1;
  }
  for (size_t i = 0; i < nc; i++) cnt[m->t[i] + 1]++;
  for (size_t i = 0; i < nv; i++) cnt[i + 1] += cnt[i];
  for (size_t i = 0; i < nv; i++) at[i] = cnt[i];
  for (size_t i = 0; i < nc; i++) cn[at[m->t[i]]++] = (int)i;
  free(at);
  *cntp = cnt;
  *cnp = cn;
  return 0;
}

static int part_contacts(Mesher *m, double *moved) {
  size_t nv = m->nv, nt = m->nt, nc = 3 * nt;
  *moved = 0;
  if (!nv || !nt) return 0;
  int rc = -1;
  int *cnt = NULL, *cn = NULL, *up = NULL, *root = NULL, *re = NULL,
      *fc = NULL;
  unsigned char *line = NULL;
  double *np = NULL; /* each fan's place: x, y, z, the vertex it goes to */
  size_t nnew = 0, capnew = 0, nadd = 0, capfc = 0;
  long pinches = m->rep->pinches;
  size_t npin = m->npin;
  int applied = 0;
  if (vertex_corners(m, &cnt, &cn) < 0) return -1;
  up = malloc(nc * sizeof *up);
  line = calloc(nv, 1);
  if (!up || !line) goto done;
  for (size_t q = 0; q < nc; q++) up[q] = (int)q;
#define NXT(q) m->t[(size_t)cn[q] / 3 * 3 + ((size_t)cn[q] % 3 + 1) % 3]
#define PRV(q) m->t[(size_t)cn[q] / 3 * 3 + ((size_t)cn[q] % 3 + 2) % 3]
  for (size_t v = 0; v < nv; v++)
    for (int q = cnt[v]; q < cnt[v + 1]; q++) {
      int x = NXT(q), out = 0, in = 0, qin = -1;
      for (int r = cnt[v]; r < cnt[v + 1]; r++) {
        out += NXT(r) == x;
        if (PRV(r) == x) in++, qin = r;
      }
      if (out == 1 && in == 1) {
        int a = corner_find(up, q), b = corner_find(up, qin);
        if (a != b) up[a] = b;
        continue;
      }
      if (out != in || (size_t)x < v) continue; /* not closed; or from x */
      /* a line of contact: its triangles by their angle about v -> x */
      int f[FACES_MAX], n = 0;
      double ang[FACES_MAX];
      line[v] = line[x] = 1;
      const double *pv = m->v + 3 * v, *px = m->v + 3 * (size_t)x;
      double e[3], e2 = 0, rx[3] = {0, 0, 0}, ry[3];
      for (int i = 0; i < 3; i++) e[i] = px[i] - pv[i], e2 += e[i] * e[i];
      for (int r = cnt[v]; r < cnt[v + 1]; r++) {
        int c;
        if (NXT(r) == x) c = PRV(r);
        else if (PRV(r) == x) c = NXT(r);
        else continue;
        if (n == FACES_MAX) goto flat;
        double w[3], d = 0;
        for (int i = 0; i < 3; i++) w[i] = m->v[3 * (size_t)c + (size_t)i] - pv[i];
        for (int i = 0; i < 3; i++) d += w[i] * e[i];
        for (int i = 0; i < 3; i++) w[i] -= d / e2 * e[i];
        if (!n) {
          memcpy(rx, w, sizeof w);
          vec3_cross(e, rx, ry);
        }
        ang[n] = atan2(vec3_dot(w, ry), vec3_dot(w, rx) * sqrt(e2));
        f[n++] = r;
      }
      /* sorted about the line, counter-clockwise seen from x */
      for (int i = 1; i < n; i++)
        for (int j = i; j > 0 && ang[j] < ang[j - 1]; j--) {
          double ta = ang[j];
          ang[j] = ang[j - 1];
          ang[j - 1] = ta;
          int tf = f[j];
          f[j] = f[j - 1];
          f[j - 1] = tf;
        }
      /* a triangle v -> x has its part clockwise of it, one x -> v
         counter-clockwise: they alternate, each x -> v paired with the
         next */
      for (int i = 0; i < n; i++)
        if (ang[i] == ang[(i + 1) % n] ||
            (NXT(f[i]) == x) == (NXT(f[(i + 1) % n]) == x))
          goto flat;
      int s0 = NXT(f[0]) == x ? 1 : 0;
      for (int i = s0; i < n + s0; i += 2) {
        int q1 = f[i % n], q2 = f[(i + 1) % n];
        int a = corner_find(up, q1), b = corner_find(up, q2);
        if (a != b) up[a] = b;
        /* the same two triangles at x */
        int r1 = -1, r2 = -1;
        for (int r = cnt[x]; r < cnt[x + 1]; r++) {
          if (cn[r] / 3 == cn[q1] / 3) r1 = r;
          if (cn[r] / 3 == cn[q2] / 3) r2 = r;
        }
        if (r1 < 0 || r2 < 0) goto flat;
        a = corner_find(up, r1);
        b = corner_find(up, r2);
        if (a != b) up[a] = b;
      }
    }
  /* each vertex's fans: a vertex of several gets one more vertex for
     each fan but the first, placed after all are decided */
  root = malloc(nc * sizeof *root);
  if (!root) goto done;
  double size = ldexp(m->h, MAX_DEPTH);
  for (size_t v = 0; v < nv; v++) {
    int lo = cnt[v], hi = cnt[v + 1], nf = 0;
    for (int q = lo; q < hi; q++) {
      int r = corner_find(up, q);
      int j = lo;
      while (j < q && root[j] != r) j++;
      root[q] = r;
      if (j == q) nf++;
    }
    if (nf < 2) continue;
    const double *P = m->v + 3 * v;
    double big = fmax(size, fmax(fabs(P[0]), fmax(fabs(P[1]), fabs(P[2]))));
    int first = 1;
    for (int q0 = lo; q0 < hi; q0++) {
      int j = lo;
      while (j < q0 && root[j] != root[q0]) j++;
      if (j < q0) continue; /* a fan already placed */
      int k = 0;
      /* the lines of contact this fan borders at v, made orthonormal
         (three parts meeting at a corner: each part's vertex moves
         along the third axis, away from both lines it touches) */
      double ln[2][3];
      int nl = 0, many = 0;
      for (int q = q0; q < hi; q++) {
        if (root[q] != root[q0]) continue;
        if (grow((void **)&fc, &capfc, (size_t)k + 1, sizeof *fc) < 0) goto done;
        fc[k++] = cn[q];
        for (int e = 0; e < 2 && line[v] && !many; e++) {
          int x = e ? PRV(q) : NXT(q), out = 0, in = 0;
          for (int r = lo; r < hi; r++) out += NXT(r) == x, in += PRV(r) == x;
          if (out + in <= 2) continue;
          double d[3];
          for (int i = 0; i < 3; i++) d[i] = m->v[3 * (size_t)x + (size_t)i] - P[i];
          for (int c = 0; c < nl; c++) {
            double p = vec3_dot(d, ln[c]);
            for (int i = 0; i < 3; i++) d[i] -= p * ln[c][i];
          }
          double l = sqrt(vec3_dot(d, d));
          if (!(l > 1e-6 * dist3(m->v + 3 * (size_t)x, P))) continue;
          if (nl == 2) { /* three lines (a corner of a checkerboard's
                            cube): along none, into the fan's cone */
            many = 1;
            nl = 0;
            break;
          }
          for (int i = 0; i < 3; i++) ln[nl][i] = d[i] / l;
          nl++;
        }
      }
      double u[3], dmin;
      if (fan_dir(m, P, fc, k, (const double (*)[3])ln, nl, u, &dmin, NULL) < 0)
        goto flat;
      double d = fmin(PINCH * big, 1e-3 * dmin),
             d2 = fmax(d, fmin(PINCH_OUT * big, fmin(m->tol / 16, 1e-3 * dmin)));
      if (!(d > 0)) goto flat;
      if (grow((void **)&np, &capnew, 4 * (nnew + 1), sizeof *np) < 0 ||
          grow((void **)&m->pin, &m->cappin, 6 * (m->npin + 1), sizeof *m->pin) < 0)
        goto done;
      if (!re) { /* each corner's new vertex, -1 if none: set at the end, so
                    that the fans still to place see the triangles as made */
        if (!(re = malloc(nc * sizeof *re))) goto done;
        for (size_t i = 0; i < nc; i++) re[i] = -1;
      }
      double *to = np + 4 * nnew++, *pn = m->pin + 6 * m->npin++;
      for (int i = 0; i < 3; i++) {
        to[i] = pn[i] = P[i] + d * u[i];
        pn[3 + i] = P[i] + d2 * u[i];
      }
      /* the fan's vertex: v itself, or the next new one */
      to[3] = first ? (double)v : (double)(nv + nadd);
      if (!first) {
        for (int q = q0; q < hi; q++)
          if (root[q] == root[q0]) re[cn[q]] = (int)(nv + nadd);
        nadd++;
      }
      *moved = fmax(*moved, d2);
      first = 0;
    }
    m->rep->pinches++;
  }
  if (nnew) {
    if (grow((void **)&m->v, &m->capv, 3 * (nv + nadd), sizeof *m->v) < 0)
      goto done;
    for (size_t i = 0; i < nnew; i++)
      memcpy(m->v + 3 * (size_t)np[4 * i + 3], np + 4 * i, 3 * sizeof *np);
    for (size_t i = 0; i < nc; i++)
      if (re[i] >= 0) m->t[i] = re[i];
    m->nv = nv + nadd;
  }
  rc = 0;
  applied = 1;
  goto done;
flat: /* not parted: the checks judge the mesh as it is */
  rc = 0;
done:
  if (!applied) {
    *moved = 0;
    m->rep->pinches = pinches;
    m->npin = npin;
  }
#undef NXT
#undef PRV
  free(cnt);
  free(cn);
  free(up);
  free(root);
  free(line);
  free(np);
  free(re);
  free(fc);
  return rc;
}

/* A place's bits hashed (widen, near_vertices: a parted vertex is found
   by its place). */
static uint64_t place_key(const double *p) {
  uint64_t k = 1469598103934665603ull;
  for (int a = 0; a < 3; a++) {
    uint64_t b;
    memcpy(&b, p + a, sizeof b);
    k = (k ^ b) * 1099511628211ull;
  }
  return k >> 1;
}

/* Vertices of different sheets nearer than floats resolve: where two
   parts touch at a point the perturbation can also leave them apart,
   their tips two vertices 1e-16 apart, which an STL's floats would make
   one. Every two vertices of two parts of the mesh within 2^-22 of the
   size (the octree's side or the largest coordinate) are each moved into
   its part (fan_dir over all its corners) by widen, after the flat
   merge, by PINCH_OUT of that size (at most a sixteenth of the
   tolerance and a thousandth of its nearest neighbour); *moved: the
   largest move. 0, or -1 out of memory. */
typedef struct { double x; int i; } XKey;

static int xkey_cmp(const void *a, const void *b) {
  double x = ((const XKey *)a)->x, y = ((const XKey *)b)->x;
  return (x > y) - (x < y);
}

static int near_vertices(Mesher *m, double *moved) {
  size_t nv = m->nv, nt = m->nt;
  if (nv < 2 || !nt) return 0;
  double big = ldexp(m->h, MAX_DEPTH);
  for (size_t i = 0; i < 3 * nv; i++) big = fmax(big, fabs(m->v[i]));
  double thr = 0x1p-22 * big;
  int rc = -1;
  XKey *xs = malloc(nv * sizeof *xs);
  int *cnt = NULL, *cn = NULL, *comp = malloc(nv * sizeof *comp);
  unsigned char *near = calloc(nv, 1);
  hmap pinned = {0};
  if (!xs || !near || !comp || vertex_corners(m, &cnt, &cn) < 0) goto done;
  for (size_t i = 0; i < nv; i++) comp[i] = (int)i;
  for (size_t t = 0; t < nt; t++)
    for (int k = 1; k < 3; k++) {
      int a = corner_find(comp, m->t[3 * t]), b = corner_find(comp, m->t[3 * t + (size_t)k]);
      if (a != b) comp[a] = b;
    }
  for (size_t i = 0; i < nv; i++) xs[i] = (XKey){m->v[3 * i], (int)i};
  qsort(xs, nv, sizeof *xs, xkey_cmp);
  size_t found = 0;
  for (size_t a = 0; a < nv; a++)
    for (size_t b = a + 1; b < nv && xs[b].x - xs[a].x <= thr; b++) {
      int i = xs[a].i, j = xs[b].i;
      const double *p = m->v + 3 * (size_t)i, *q = m->v + 3 * (size_t)j;
      if (!(fabs(p[1] - q[1]) <= thr && fabs(p[2] - q[2]) <= thr)) continue;
      int joined = 0;
      for (int c = cnt[i]; c < cnt[i + 1] && !joined; c++) {
        size_t t = (size_t)cn[c] / 3, k = (size_t)cn[c] % 3;
        joined = m->t[3 * t + (k + 1) % 3] == j || m->t[3 * t + (k + 2) % 3] == j;
      }
      if (joined) continue;
      /* of two parts (one part's vertices this near are a sharp edge's
         chamfer in a mixed cell, figure12's obj2, or a sliver's corners,
         and stay) */
      if (corner_find(comp, i) == corner_find(comp, j)) continue;
      near[i] = near[j] = 1;
      found++;
    }
  /* those part_contacts moved already stay its */
  for (size_t i = 0; found && i < m->npin; i++)
    if (hput(&pinned, place_key(m->pin + 6 * i), (int)i) < 0) goto done;
  for (size_t v = 0; found && v < nv; v++) {
    if (!near[v]) continue;
    const double *P = m->v + 3 * v;
    int pi = hget(&pinned, place_key(P));
    if (pi >= 0 && !memcmp(P, m->pin + 6 * (size_t)pi, 3 * sizeof *P)) continue;
    double u[3], dmin;
    if (fan_dir(m, P, cn + cnt[v], cnt[v + 1] - cnt[v], NULL, 0, u, &dmin, NULL) < 0)
      continue;
    double bv = fmax(ldexp(m->h, MAX_DEPTH), fmax(fabs(P[0]), fmax(fabs(P[1]), fabs(P[2]))));
    double d2 = fmin(PINCH_OUT * bv, fmin(m->tol / 16, 1e-3 * dmin));
    if (grow((void **)&m->pin, &m->cappin, 6 * (m->npin + 1), sizeof *m->pin) < 0)
      goto done;
    double *pn = m->pin + 6 * m->npin++;
    for (int i = 0; i < 3; i++) {
      pn[i] = P[i];
      pn[3 + i] = P[i] + d2 * u[i];
    }
    *moved = fmax(*moved, d2);
    m->rep->pinches++;
  }
  rc = 0;
done:
  free(xs);
  free(cnt);
  free(cn);
  free(near);
  free(comp);
  hfree(&pinned);
  return rc;
}

/* The parted vertices of me (found by their places, to the bit) moved
   on to where part_contacts put them for the writing (PINCH_OUT). */
static int widen(const Mesher *m, Mesh *me) {
  if (!m->npin || !me) return 0;
  hmap at = {0};
  for (size_t i = 0; i < m->npin; i++)
    if (hput(&at, place_key(m->pin + 6 * i), (int)i) < 0) {
      hfree(&at);
      return -1;
    }
  for (size_t v = 0; v < me->nv; v++) {
    double *p = me->v + 3 * v;
    int i = hget(&at, place_key(p));
    if (i >= 0 && !memcmp(p, m->pin + 6 * (size_t)i, 3 * sizeof *p))
      memcpy(p, m->pin + 6 * (size_t)i + 3, 3 * sizeof *p);
  }
  hfree(&at);
  return 0;
}

/* widen undone: the parted vertices of me moved back to where
   part_contacts first put them (PINCH), as the flat merge saw them. */
static int unwiden(const Mesher *m, Mesh *me) {
  if (!m->npin || !me) return 0;
  hmap at = {0};
  for (size_t i = 0; i < m->npin; i++)
    if (hput(&at, place_key(m->pin + 6 * i + 3), (int)i) < 0) {
      hfree(&at);
      return -1;
    }
  for (size_t v = 0; v < me->nv; v++) {
    double *p = me->v + 3 * v;
    int i = hget(&at, place_key(p));
    if (i >= 0 && !memcmp(p, m->pin + 6 * (size_t)i + 3, 3 * sizeof *p))
      memcpy(p, m->pin + 6 * (size_t)i, 3 * sizeof *p);
  }
  hfree(&at);
  return 0;
}

/* part_contacts where the sharp cells met (elsewhere nothing touches:
   each marching triangle lies in its own tetrahedron), its moves in the
   certified bound. 0, or -1 out of memory. */
static int contacts(Mesher *m) {
  double mv = 0, mv2 = 0;
  if (!m->rep->sharp) return 0;
  if (part_contacts(m, &mv) < 0 || near_vertices(m, &mv2) < 0) return -1;
  m->rep->certified += fmax(mv, mv2);
  return 0;
}

/* ---- planes that are one plane but for rounding ------------------------ */

/* Two halfspaces whose planes differ by at most SNAP (of a normal's
   components, and of the object's size in the offset) either way are one
   plane but for rounding: the faces of two prisms glued face to face, or
   two boxes' tops flush, built by different rotations and shifts. Left
   apart, the doubles overlap them by a sliver or part them by a gap of
   1e-16, coplanar faces the self-intersection check rightly refuses, and
   no cell can be split fine enough to settle them. SNAP is a few dozen
   ulps: a gap of 1e-13 stays a gap. */
#define SNAP 0x1p-46

typedef struct {
  double key;
  int x, sg;
} SnapEnt;

static int snap_cmp(const void *a, const void *b) {
  double x = ((const SnapEnt *)a)->key, y = ((const SnapEnt *)b)->key;
  return x < y ? -1 : x > y;
}

/* What a sliver of the solid 1e-16 wide leaves once the second try's
   near weld has joined its vertices (two prisms edge to edge, turned by
   angles whose sines round: their edges all but on one line, the exact
   pieces between them 1e-16 wide). Two triangles on the same three
   vertices facing apart bound nothing: both dropped. A triangle whose
   vertex b lies within g of its longest side c -> a (a cap: its three
   vertices all but on one line) is removed and a triangle across that
   side split at b, (a, c, d) -> (a, b, d) and (b, c, d), which cover
   the same ground but for the cap's height (in the certified bound; the
   choice of the triangle where several lie across is below). What is
   left the closure and self-intersection checks judge. 0, or -1 out of
   memory. */
typedef struct {
  int v[3], sg;
  size_t t;
} SlTri;

static int sltri_cmp(const void *a, const void *b) {
  const SlTri *x = a, *y = b;
  for (int k = 0; k < 3; k++)
    if (x->v[k] != y->v[k]) return x->v[k] < y->v[k] ? -1 : 1;
  return x->sg - y->sg;
}

/* the distance of m's vertex d from the line through a and c (infinity
   if they are one point) */
static double line_dist(const Mesher *m, int a, int c, int d) {
  const double *pa = m->v + 3 * (size_t)a, *pc = m->v + 3 * (size_t)c,
               *pd = m->v + 3 * (size_t)d;
  double u[3], w[3];
  for (int k = 0; k < 3; k++) {
    u[k] = pc[k] - pa[k];
    w[k] = pd[k] - pa[k];
  }
  double uu = u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
  if (!(uu > 0)) return INFINITY;
  double x[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2],
                 u[0] * w[1] - u[1] * w[0]};
  return sqrt((x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) / uu);
}

/* the height of m's vertex b over the line through a and c if its foot
   lies strictly between them, else infinity */
static double cap_height(const Mesher *m, int a, int b, int c) {
  const double *pa = m->v + 3 * (size_t)a, *pb = m->v + 3 * (size_t)b,
               *pc = m->v + 3 * (size_t)c;
  double uu = 0, uw = 0;
  for (int k = 0; k < 3; k++) {
    uu += (pc[k] - pa[k]) * (pc[k] - pa[k]);
    uw += (pc[k] - pa[k]) * (pb[k] - pa[k]);
  }
  if (!(uu > 0) || !(uw > 0) || !(uw < uu)) return INFINITY;
  return line_dist(m, a, c, b);
}

/* [*e0, *e1): the directed edges a -> b in ed (sorted, n of them) */
static void edge_range(const SlTri *ed, size_t n, int a, int b, size_t *e0,
                       size_t *e1) {
  size_t lo = 0, hi = n;
  SlTri key = {{a, b, 0}, 0, 0};
  while (lo < hi) {
    size_t mid = lo + (hi - lo) / 2;
    if (sltri_cmp(&ed[mid], &key) < 0) lo = mid + 1;
    else hi = mid;
  }
  *e0 = *e1 = lo;
  while (*e1 < n && ed[*e1].v[0] == a && ed[*e1].v[1] == b) ++*e1;
}

/* the vertex of m's triangle t after its side a -> b */
static int tri_third(const Mesher *m, size_t t, int a, int b) {
  const int *v = m->t + 3 * t;
  for (int q = 0; q < 3; q++)
    if (v[q] == a && v[(q + 1) % 3] == b) return v[(q + 2) % 3];
  return v[0] == a ? v[2] : v[0]; /* not reached: t has the side */
}

/* the part of vertex d - a across the line a -> c, as a unit vector in
   w; 0 if d is on the line */
static int wing(const Mesher *m, int a, int c, int d, double w[3]) {
  const double *pa = m->v + 3 * (size_t)a, *pc = m->v + 3 * (size_t)c,
               *pd = m->v + 3 * (size_t)d;
  double u[3], x[3];
  for (int k = 0; k < 3; k++) {
    u[k] = pc[k] - pa[k];
    x[k] = pd[k] - pa[k];
  }
  double uu = u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
  double ux = u[0] * x[0] + u[1] * x[1] + u[2] * x[2];
  if (!(uu > 0)) return 0;
  for (int k = 0; k < 3; k++) w[k] = x[k] - u[k] * (ux / uu);
  double n = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
  if (!(n > 0)) return 0;
  for (int k = 0; k < 3; k++) w[k] /= n;
  return 1;
}

/* how far d's wing lies turned about a -> c from the unit wing ref (right
   handed, in (0, 2 pi]); infinity if d is on the line */
static double wing_angle(const Mesher *m, int a, int c, int d,
                         const double ref[3]) {
  double w[3];
  if (!wing(m, a, c, d, w)) return INFINITY;
  const double *pa = m->v + 3 * (size_t)a, *pc = m->v + 3 * (size_t)c;
  double u[3] = {pc[0] - pa[0], pc[1] - pa[1], pc[2] - pa[2]};
  double un = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
  double e2[3] = {(u[1] * ref[2] - u[2] * ref[1]) / un,
                  (u[2] * ref[0] - u[0] * ref[2]) / un,
                  (u[0] * ref[1] - u[1] * ref[0]) / un};
  double ang = atan2(w[0] * e2[0] + w[1] * e2[1] + w[2] * e2[2],
                     w[0] * ref[0] + w[1] * ref[1] + w[2] * ref[2]);
  return ang > 0 ? ang : ang + 2 * M_PI;
}

/* a cap's long side at least this many times the near weld's distance */
#define CAP_SIDE 1024
/* the zip's passes, and its open edges at most (more are not a
   sliver's: left to the checks) */
#define ZIP_PASSES 64
#define ZIP_OPEN_MAX 4096
/* triangles on one open edge split at once, at most */
#define ZIP_FAN 8
/* holes the zip leaves filled: at most so many vertices, all within
   HOLE_LINE near weld distances of one line */
#define HOLE_MAX 8
#define HOLE_LINE 1024

/* What the zip leaves: a hole whose open edges make a cycle of 3 to
   HOLE_MAX vertices, each with one open edge leaving it, all within h of
   the line through the two farthest apart (two caps' vertices 1e-13
   apart, beyond the near weld's distance), closed by a fan from one end
   of that line: slivers of the line's own, which the self-intersection
   check judges. 0, or -1 out of memory. */
static int fill_slivers(Mesher *m, double h, double *moved) {
  size_t nt = m->nt, ne = 3 * nt, no = 0;
  if (!nt) return 0;
  SlTri *ed = malloc(ne * sizeof *ed);
  int *next = NULL, rc = -1;
  if (!ed) return -1;
  for (size_t t = 0; t < nt; t++)
    for (int q = 0; q < 3; q++)
      ed[3 * t + (size_t)q] = (SlTri){{m->t[3 * t + (size_t)q],
                                       m->t[3 * t + (size_t)(q + 1) % 3], 0},
                                      0, t};
  qsort(ed, ne, sizeof *ed, sltri_cmp);
  if (!(next = malloc(m->nv * sizeof *next))) goto done;
  for (size_t i = 0; i < m->nv; i++) next[i] = -1;
  /* next[p]: the end of p's one open edge; -2 if it has several, or an
     open edge of several triangles */
  for (size_t x = 0; x < ne;) {
    size_t y = x, r0, r1;
    while (y < ne && ed[y].v[0] == ed[x].v[0] && ed[y].v[1] == ed[x].v[1]) y++;
    edge_range(ed, ne, ed[x].v[1], ed[x].v[0], &r0, &r1);
    if (y - x > r1 - r0) {
      int p = ed[x].v[0];
      next[p] = next[p] == -1 && y - x == 1 && r1 == r0 ? ed[x].v[1] : -2;
      no++;
    }
    x = y;
  }
  for (size_t s = 0; no && s < m->nv; s++) {
    int cyc[HOLE_MAX], k = 0, p = (int)s;
    while (k < HOLE_MAX && p >= 0 && (k == 0 || p != (int)s)) {
      cyc[k++] = p;
      p = next[p];
    }
    if (p != (int)s || k < 3) continue;
    /* the two farthest apart, and every vertex within h of their line */
    int fa = 0, fb = 1;
    double far = -1;
    for (int i = 0; i < k; i++)
      for (int j = i + 1; j < k; j++) {
        double d = dist3(m->v + 3 * (size_t)cyc[i], m->v + 3 * (size_t)cyc[j]);
        if (d > far) far = d, fa = i, fb = j;
      }
    double hi = 0;
    for (int i = 0; i < k; i++)
      if (i != fa && i != fb) hi = fmax(hi, line_dist(m, cyc[fa], cyc[fb], cyc[i]));
    if (!(hi <= h)) continue;
    if (grow((void **)&m->t, &m->capt, 3 * (m->nt + (size_t)k - 2), sizeof *m->t) < 0)
      goto done;
    /* the fan from cyc[fa]: (c0, c[i+1], c[i]) holds the reverse of each
       open edge c[i] -> c[i+1] */
    for (int i = 1; i + 1 < k; i++) {
      int *tv = m->t + 3 * m->nt++;
      tv[0] = cyc[fa], tv[1] = cyc[(fa + i + 1) % k], tv[2] = cyc[(fa + i) % k];
    }
    for (int i = 0; i < k; i++) next[cyc[i]] = -2;
    if (hi > *moved) *moved = hi;
    m->rep->sliver_holes++;
  }
  rc = 0;
done:
  free(ed);
  free(next);
  return rc;
}

static int drop_slivers(Mesher *m, double g) {
  size_t nt = m->nt;
  if (!nt) return 0;
  SlTri *o = malloc(nt * sizeof *o);
  if (!o) return -1;
  for (size_t t = 0; t < nt; t++) {
    int a = m->t[3 * t], b = m->t[3 * t + 1], c = m->t[3 * t + 2], sg = 1;
    /* sorted, each swap turning the orientation over */
    if (a > b) { int x = a; a = b; b = x; sg = -sg; }
    if (b > c) { int x = b; b = c; c = x; sg = -sg; }
    if (a > b) { int x = a; a = b; b = x; sg = -sg; }
    o[t] = (SlTri){{a, b, c}, sg, t};
  }
  qsort(o, nt, sizeof *o, sltri_cmp);
  unsigned char *gone = calloc(nt, 1);
  if (!gone) {
    free(o);
    return -1;
  }
  long dropped = 0;
  for (size_t i = 0; i < nt;) {
    size_t j = i;
    while (j < nt && !memcmp(o[j].v, o[i].v, sizeof o[i].v)) j++;
    /* [i, j): one vertex set, those facing -1 first */
    size_t neg = i;
    while (neg < j && o[neg].sg < 0) neg++;
    for (size_t x = i, y = neg; x < neg && y < j; x++, y++) {
      gone[o[x].t] = gone[o[y].t] = 1;
      dropped += 2;
    }
    i = j;
  }
  free(o);
  if (dropped) {
    size_t w = 0;
    for (size_t t = 0; t < nt; t++)
      if (!gone[t]) {
        memmove(m->t + 3 * w, m->t + 3 * t, 3 * sizeof *m->t);
        w++;
      }
    m->nt = nt = w;
  }
  free(gone);
  /* the caps, removed. Each leaves the sides across its own as directed
     edges that outnumber their reverses: open edges along the line, with
     the caps' middle vertices on them. Then, while an open edge p -> q
     has an open edge's end v on it (within g of the segment, strictly
     between), a triangle with the side p -> q is split at v: (p, q, d)
     -> (p, v, d) and (v, q, d), covering the same ground but for v's
     distance (in the certified bound); the nearest such v to p first.
     Where several triangles have the side (two parts meet along the
     line), the one split is the one that closes the wedge of the part
     beside v: turning about p -> q from the triangle of an open edge
     leaving v, into its solid, the first triangle along the line met.
     A split whose new triangles would be flat (d within g of p - v or
     v - q) is not made, so the open edges only get shorter. */
  double moved = 0;
  long caps = 0;
  int rc = 0;
  SlTri *ed = NULL;
  size_t *open = NULL;
  int *ov = NULL;
  {
    size_t w = 0;
    for (size_t t = 0; t < nt; t++) {
      const int *tv = m->t + 3 * t;
      int k = -1; /* the longest side, tv[k+1] -> tv[k+2], opposite tv[k] */
      double best = -1;
      for (int q = 0; q < 3; q++) {
        double d = dist3(m->v + 3 * (size_t)tv[(q + 2) % 3], m->v + 3 * (size_t)tv[q]);
        if (d > best) {
          best = d;
          k = (q + 1) % 3;
        }
      }
      double h = cap_height(m, tv[(k + 2) % 3], tv[k], tv[(k + 1) % 3]);
      /* a long side, not a cluster of points a few g apart */
      if (h <= g && best > CAP_SIDE * g) {
        if (h > moved) moved = h;
        caps++;
        continue;
      }
      memmove(m->t + 3 * w, tv, 3 * sizeof *m->t);
      w++;
    }
    m->nt = nt = w;
  }
  for (int pass = 0; caps && pass < ZIP_PASSES; pass++) {
    free(ed);
    free(open);
    free(ov);
    open = NULL;
    ov = NULL;
    if (!(ed = malloc(3 * (nt ? nt : 1) * sizeof *ed))) goto oom;
    for (size_t t = 0; t < nt; t++)
      for (int q = 0; q < 3; q++)
        ed[3 * t + (size_t)q] = (SlTri){{m->t[3 * t + (size_t)q],
                                         m->t[3 * t + (size_t)(q + 1) % 3], 0},
                                        0, t};
    size_t ne = 3 * nt, no = 0, nov = 0;
    qsort(ed, ne, sizeof *ed, sltri_cmp);
    /* the open edges (the first of each run of one directed edge) */
    for (size_t x = 0; x < ne;) {
      size_t y = x, r0, r1;
      while (y < ne && ed[y].v[0] == ed[x].v[0] && ed[y].v[1] == ed[x].v[1]) y++;
      edge_range(ed, ne, ed[x].v[1], ed[x].v[0], &r0, &r1);
      if (y - x > r1 - r0) {
        if (no == ZIP_OPEN_MAX) goto done; /* not a sliver's: the checks */
        if (!open && !(open = malloc(ZIP_OPEN_MAX * sizeof *open))) goto oom;
        open[no++] = x;
      }
      x = y;
    }
    if (!no) break;
    if (!(ov = malloc(2 * no * sizeof *ov))) goto oom;
    for (size_t oi = 0; oi < no; oi++) {
      ov[nov++] = ed[open[oi]].v[0];
      ov[nov++] = ed[open[oi]].v[1];
    }
    unsigned char *hit = calloc(nt ? nt : 1, 1); /* split in this pass */
    if (!hit) goto oom;
    int any = 0;
    for (size_t oi = 0; oi < no; oi++) {
      int p = ed[open[oi]].v[0], q = ed[open[oi]].v[1];
      const double *pp = m->v + 3 * (size_t)p, *pq = m->v + 3 * (size_t)q;
      double u[3] = {pq[0] - pp[0], pq[1] - pp[1], pq[2] - pp[2]};
      double uu = u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
      int v = -1;
      double vs = INFINITY;
      for (size_t z = 0; z < nov; z++) {
        int x = ov[z];
        if (x == p || x == q || !(cap_height(m, p, x, q) <= g)) continue;
        const double *px = m->v + 3 * (size_t)x;
        double sx = (u[0] * (px[0] - pp[0]) + u[1] * (px[1] - pp[1]) +
                     u[2] * (px[2] - pp[2])) / uu;
        if (sx < vs) vs = sx, v = x;
      }
      if (v < 0) continue;
      size_t e0, e1, r0, r1, np = 0;
      edge_range(ed, ne, p, q, &e0, &e1);
      edge_range(ed, ne, q, p, &r0, &r1);
      size_t picks[ZIP_FAN];
      if (r1 == r0) {
        /* no side q -> p left: every triangle with p -> q */
        for (size_t x = e0; x < e1 && np < ZIP_FAN; x++) picks[np++] = ed[x].t;
      } else {
        /* each triangle of an open edge leaving v along the line picks
           the one that closes its part's wedge */
        for (size_t o2 = 0; o2 < no; o2++) {
          size_t x = open[o2];
          if (ed[x].v[0] != v || !(line_dist(m, p, q, ed[x].v[1]) <= g)) continue;
          int fy = ed[x].v[1];
          /* turning right-handed about p -> q goes into the solid of a
             triangle whose side runs back toward p (v -> fy against p ->
             q); one running on toward q is left alone */
          {
            const double *pv = m->v + 3 * (size_t)v, *pf = m->v + 3 * (size_t)fy;
            if (!((pf[0] - pv[0]) * u[0] + (pf[1] - pv[1]) * u[1] +
                  (pf[2] - pv[2]) * u[2] < 0))
              continue;
          }
          for (size_t x1 = x; x1 < ne && ed[x1].v[0] == v && ed[x1].v[1] == fy; x1++) {
            double ref[3];
            if (!wing(m, p, q, tri_third(m, ed[x1].t, v, fy), ref)) continue;
            double bestang = INFINITY;
            long pick = -1;
            for (size_t y = e0; y < e1; y++) {
              if (hit[ed[y].t]) continue; /* split in this pass */
              double ang = wing_angle(m, p, q, tri_third(m, ed[y].t, p, q), ref);
              if (ang < bestang) bestang = ang, pick = (long)ed[y].t;
              else if (ang == bestang) pick = -1;
            }
            for (size_t y = r0; y < r1; y++) {
              if (hit[ed[y].t]) continue;
              double ang = wing_angle(m, p, q, tri_third(m, ed[y].t, q, p), ref);
              if (ang <= bestang) bestang = ang, pick = -1;
            }
            int seen = pick < 0;
            for (size_t z = 0; z < np; z++) seen |= picks[z] == (size_t)pick;
            if (!seen && np < ZIP_FAN) picks[np++] = (size_t)pick;
          }
        }
      }
      for (size_t z = 0; z < np; z++) {
        size_t pick = picks[z];
        if (hit[pick]) continue;
        int d = tri_third(m, pick, p, q);
        if (!(line_dist(m, p, q, d) > g) || !(line_dist(m, p, v, d) > g) ||
            !(line_dist(m, v, q, d) > g))
          continue;
        if (grow((void **)&m->t, &m->capt, 3 * (nt + 1), sizeof *m->t) < 0) {
          free(hit);
          goto oom;
        }
        int *tv = m->t + 3 * pick;
        tv[0] = p, tv[1] = v, tv[2] = d;
        m->t[3 * nt] = v, m->t[3 * nt + 1] = q, m->t[3 * nt + 2] = d;
        nt++;
        hit[pick] = 1;
        double dv = line_dist(m, p, q, v);
        if (dv > moved) moved = dv;
        any = 1;
      }
    }
    free(hit);
    m->nt = nt;
    if (!any) break;
  }
  if (caps && fill_slivers(m, g * HOLE_LINE, &moved) < 0) goto oom;
  goto done;
oom:
  rc = -1;
done:
  free(ed);
  free(open);
  free(ov);
  m->rep->sliver_pairs += dropped / 2;
  m->rep->sliver_caps += caps;
  m->rep->certified += moved;
  return rc;
}

static int weld(Mesher *m) {
  if (!m->nv) return 0;
  double g = ldexp(m->h, MAX_DEPTH) * WELD;
  int *par = malloc(m->nv * sizeof *par);
  if (!par) return -1;
  for (size_t i = 0; i < m->nv; i++) par[i] = (int)i;
  int moved = 0;
  for (size_t t = 0; t < m->nt; t++)
    for (int k = 0; k < 3; k++) {
      int a = m->t[3 * t + (size_t)k], b = m->t[3 * t + (size_t)(k + 1) % 3];
      const double *x = m->v + 3 * (size_t)a, *y = m->v + 3 * (size_t)b;
      if (!(fabs(x[0] - y[0]) <= g && fabs(x[1] - y[1]) <= g &&
            fabs(x[2] - y[2]) <= g))
        continue;
      int ra = find(par, a), rb = find(par, b);
      if (ra == rb) continue;
      par[ra > rb ? ra : rb] = ra < rb ? ra : rb;
      moved = 1;
    }
  if (m->near_weld) {
    /* wider than an edge's: where the turned planes of a line of contact
       meet, the exact points cluster within 1e-13, and within 4e-13
       where those planes are all but one plane (NEAR_WELD) */
    double gn = g * NEAR_WELD;
    SnapEnt *o = malloc(m->nv * sizeof *o);
    if (!o) {
      free(par);
      return -1;
    }
    for (size_t i = 0; i < m->nv; i++) o[i] = (SnapEnt){m->v[3 * i], (int)i, 0};
    qsort(o, m->nv, sizeof *o, snap_cmp);
    for (size_t i = 0; i < m->nv; i++)
      for (size_t j = i + 1; j < m->nv && o[j].key - o[i].key <= gn; j++) {
        const double *x = m->v + 3 * (size_t)o[i].x, *y = m->v + 3 * (size_t)o[j].x;
        if (!(fabs(x[1] - y[1]) <= gn && fabs(x[2] - y[2]) <= gn)) continue;
        int ra = find(par, o[i].x), rb = find(par, o[j].x);
        if (ra == rb) continue;
        par[ra > rb ? ra : rb] = ra < rb ? ra : rb;
        moved = 1;
      }
    free(o);
  }
  if (!moved) {
    free(par);
    return contacts(m);
  }
  for (size_t i = 0; i < m->nv; i++) par[i] = find(par, (int)i);
  /* a class whose vertex would not be closed fans is not welded: its
     vertices stay as they were */
  if (weld_fans(m, par) < 0) {
    free(par);
    return -1;
  }
  size_t w = 0;
  for (size_t t = 0; t < m->nt; t++) {
    int a = par[m->t[3 * t]], b = par[m->t[3 * t + 1]], c = par[m->t[3 * t + 2]];
    if (a == b || b == c || c == a) continue;
    m->t[3 * w] = a;
    m->t[3 * w + 1] = b;
    m->t[3 * w + 2] = c;
    w++;
  }
  /* a vertex moved to its class's first (a chain of short edges can
     reach past g): each triangle's bound grows by the largest move */
  double mv = 0;
  for (size_t i = 0; i < m->nv; i++) {
    size_t r = (size_t)par[i];
    if (r == i) continue;
    double d = dist3(m->v + 3 * i, m->v + 3 * r);
    if (d > mv) mv = d;
  }
  m->rep->welded += (long)(m->nt - w);
  m->rep->certified += mv;
  /* the vertices no triangle uses any more left out (par reused as the
     new numbers; the per-vertex flags are done with) */
  for (size_t i = 0; i < m->nv; i++) par[i] = -1;
  for (size_t t = 0; t < 3 * w; t++) par[m->t[t]] = 0;
  size_t nv = 0;
  for (size_t i = 0; i < m->nv; i++)
    if (par[i] == 0) {
      par[i] = (int)nv;
      memmove(m->v + 3 * nv, m->v + 3 * i, 3 * sizeof *m->v);
      nv++;
    }
  for (size_t t = 0; t < 3 * w; t++) m->t[t] = par[m->t[t]];
  m->nv = nv;
  m->nt = w;
  free(par);
  if (m->near_weld && drop_slivers(m, g) < 0) return -1;
  return contacts(m);
}

/* The Kuhn split: 6 tetrahedra around the diagonal 0 - 7, each ordered to
   positive orientation (corner masks: bit 0 x, 1 y, 2 z). */
static const int kuhn[6][4] = {
    {0, 1, 3, 7}, {0, 2, 6, 7}, {0, 4, 5, 7}, /* even permutations */
    {0, 1, 7, 5}, {0, 4, 7, 6}, {0, 2, 7, 3}, /* odd, last two swapped */
};

/* The faces of cell q (level l) are all plain (see face): no cell of the
   level sharing a face or an edge with it is split. */
static int plain_cell(const Mesher *m, int l, const int64_t q[3]) {
  for (int dx = -1; dx <= 1; dx++)
    for (int dy = -1; dy <= 1; dy++)
      for (int dz = -1; dz <= 1; dz++) {
        int nz = (dx != 0) + (dy != 0) + (dz != 0);
        if ((nz == 1 || nz == 2) &&
            is_split(m, l, q[0] + dx, q[1] + dy, q[2] + dz))
          return 0;
      }
  return 1;
}

/* The corner points of a plain cell, made in the order face makes them
   (so that the points' numbers do not depend on the shortcut). */
static int plain_points(Mesher *m, int l, const int64_t q[3]) {
  static const int cu[4] = {0, 1, 1, 0}, cw[4] = {0, 0, 1, 1};
  for (int a = 0; a < 3; a++)
    for (int s = 0; s < 2; s++) {
      int b = (a + 1) % 3, e = (a + 2) % 3;
      for (int r = 0; r < 4; r++) {
        int k0 = s ? r : (4 - r) % 4;
        int64_t p0[3];
        p0[a] = q[a] + s;
        p0[b] = q[b] + cu[k0];
        p0[e] = q[e] + cw[k0];
        uint32_t dc[3];
        for (int i = 0; i < 3; i++) dc[i] = (uint32_t)(p0[i] << (m->depth - l + 1));
        if (point(m, dc) < 0) return -1;
      }
    }
  return 0;
}

static int cell(Mesher *m, size_t leaf, size_t *count) {
  Leaf *lf = &m->leaves[leaf];
  m->cur = lf;
  int l = lf->level, plain = 1;
  int64_t q[3] = {lf->q[0], lf->q[1], lf->q[2]};
  int (*mk)(Mesher *, const int *, size_t *) = tet;
  if (lf->kind == LEAF_EXACT) {
    /* the classes over this box again, for pl_eval, and each undecided
       halfspace's plane in the cell's list */
    double side = ldexp(m->h, m->depth - l), lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
      lo[a] = m->org[a] + side * (double)q[a];
      hi[a] = m->org[a] + side * (double)(q[a] + 1); /* as walk's */
    }
    int one, f = m->s->nodes[m->node].first;
    scene_box_g(m->s, m->node, lo, hi, m->st, m->one, &one, 0, m->forced);
    if (cell_redundant(m, lo, hi) > 0) /* as the walk found them */
      scene_box_g(m->s, m->node, lo, hi, m->st, m->one, &one, 0, m->frc);
    for (int x = f; x <= m->node; x++) {
      if (m->s->nodes[x].kind != SC_HALFSPACE || m->st[x - f] != T_ONE) continue;
      int y = 0;
      while (y < lf->npl && !same_surface(m->s, m->pls[lf->pl0 + y], x)) y++;
      if (y == lf->npl) return (void)(m->err = MESH_EINTERNAL), -1;
      const ScNode *a = &m->s->nodes[x], *b = &m->s->nodes[m->pls[lf->pl0 + y]];
      m->plmap[x - f] = 2 * y + (vec3_dot(a->n, b->n) < 0);
    }
    pl_prog(m);
    mk = exact_tet;
  }
  m->nft = 0;
  /* the first pass (count) finds whether the faces are plain: a plain
     cell needs only its corners */
  /* with no cell split below the finest level, a finest cell's faces
     are plain (no smaller neighbour) */
  if (count)
    lf->plain = (unsigned char)(l == m->depth || (l == m->fine && !m->rep->thin && !m->rep->cover_split) ||
                                plain_cell(m, l, q));
  if (lf->plain) {
    if (count && l < m->depth && !(l == m->fine && !m->rep->thin && !m->rep->cover_split) &&
        plain_points(m, l, q) < 0)
      return -1;
  } else {
    for (int a = 0; a < 3; a++)
      for (int s = 0; s < 2; s++)
        if (face(m, l, q, a, s, &plain) < 0) return -1;
    if (plain) return (void)(m->err = MESH_EINTERNAL), -1;
  }
  if (plain) {
    int c[8];
    for (int k = 0; k < 8; k++) {
      uint32_t dc[3];
      for (int i = 0; i < 3; i++)
        dc[i] = (uint32_t)((q[i] + (k >> i & 1)) << (m->depth - l + 1));
      if ((c[k] = point(m, dc)) < 0) return -1;
    }
    for (int t = 0; t < 6; t++) {
      int p[4] = {c[kuhn[t][0]], c[kuhn[t][1]], c[kuhn[t][2]], c[kuhn[t][3]]};
      if (mk(m, p, count) < 0) return -1;
    }
    return 0;
  }
  uint32_t cc[3];
  for (int i = 0; i < 3; i++) cc[i] = (uint32_t)((2 * q[i] + 1) << (m->depth - l));
  int cp = point(m, cc);
  if (cp < 0) return -1;
  for (size_t i = 0; i < m->nft; i += 3) {
    /* (a, b, c) counter-clockwise from outside, the centre inside:
       (a, c, b, centre) is positive */
    int p[4] = {m->ft[i], m->ft[i + 2], m->ft[i + 1], cp};
    if (mk(m, p, count) < 0) return -1;
  }
  return 0;
}

/* The node of node's subtree that makes it unbounded. */
static int unbounded_leaf(const Scene *s, int node) {
  double lo[3], hi[3];
  for (;;) {
    const ScNode *nd = &s->nodes[node];
    if (nd->kind != SC_UNION && nd->kind != SC_INTER && nd->kind != SC_DIFF)
      return node;
    if (!render_node_box(s, nd->a, lo, hi)) node = nd->a;
    else if (nd->kind == SC_UNION && !render_node_box(s, nd->b, lo, hi))
      node = nd->b;
    else return node;
  }
}

/* The sharp cells' surface along each cell face, from one vertex that a
   marching neighbour also makes (edge_vertex) to the next, through crease
   points and double crossings: a marching triangle edge (u, v) on that
   face is split into the same path (emit_split: a fan from the
   triangle's third vertex over a simple path in the face's plane). */
static int face_paths(Mesher *m) {
  for (size_t f = 0; f < m->nfs; f++) {
    uint64_t key[4];
    memcpy(key, m->fstart + 4 * f, sizeof key);
    int a = (int)key[0];
    if (!m->uni[a]) continue;
    size_t mark = m->npoly;
    if (grow((void **)&m->poly, &m->cappoly, m->npoly + 1, sizeof *m->poly) < 0)
      return (void)(m->err = MESH_ENOMEM), -1;
    m->npoly++;
    int cur = a, n = 0, ok = 1;
    for (;;) {
      key[0] = (uint64_t)cur;
      int nx = kmap_get(&m->fpath, key);
      if (nx < 0 || n > 1000) {
        ok = 0;
        break;
      }
      cur = nx;
      if (m->uni[cur]) break;
      if (grow((void **)&m->poly, &m->cappoly, m->npoly + 1, sizeof *m->poly) < 0)
        return (void)(m->err = MESH_ENOMEM), -1;
      m->poly[m->npoly++] = cur;
      n++;
    }
    uint64_t pk = a < cur ? (uint64_t)a << 32 | (uint64_t)cur
                          : (uint64_t)cur << 32 | (uint64_t)a;
    if (!ok || n == 0 || hget(&m->crease, pk) >= 0) {
      m->npoly = mark;
      continue;
    }
    m->poly[mark] = n;
    if (cur < a) /* stored from the lower index to the higher */
      for (int q = 0; q < n / 2; q++) {
        int t = m->poly[mark + 1 + (size_t)q];
        m->poly[mark + 1 + (size_t)q] = m->poly[mark + (size_t)n - (size_t)q];
        m->poly[mark + (size_t)n - (size_t)q] = t;
      }
    if (hput(&m->crease, pk, (int)mark) < 0) return (void)(m->err = MESH_ENOMEM), -1;
  }
  return 0;
}

/* The distance from p to the nearest crossing of the surface on the
   segment p -+ reach dir (dir a unit vector) by the exact ray spans, or
   INFINITY if none. The ends of the segment are not crossings (a span
   clipped there), and two spans meeting with no gap between them (a span
   ending where the next begins to within 2^-40 of the segment) are one:
   the spans of a union report a face resting flush on another (figure12's
   obj5: the rounded box's bottom on the cube's top, y = 1) as an end and
   a start 1 ulp apart, inside on both sides, where there is no surface.
   Joining them only drops crossings, so the distance found is never less
   than the true one along dir. */
static double crossing_along(Mesher *m, const double p[3], const double dir[3],
                             double reach) {
  double o[3], d[3];
  for (int j = 0; j < 3; j++) {
    o[j] = p[j] - reach * dir[j];
    d[j] = 2 * reach * dir[j];
  }
  csg_span *sp;
  ray_reset(m->ray);
  int ns = ray_spans(m->s, m->node, o, d, 0, 1, m->ray, &sp);
  double best = INFINITY, gap = ldexp(1, -40);
  for (int q = 0; q < ns; q++) {
    double t0 = sp[q].t0, t1 = sp[q].t1;
    if (t0 > 0 && t0 < 1 && !(q > 0 && t0 - sp[q - 1].t1 <= gap))
      best = fmin(best, fabs(t0 - 0.5) * 2 * reach);
    if (t1 > 0 && t1 < 1 && !(q + 1 < ns && sp[q + 1].t0 - t1 <= gap))
      best = fmin(best, fabs(t1 - 0.5) * 2 * reach);
  }
  return best;
}

/* The measured error: from n sample points of the triangles (a fixed
   sequence), the distance to the nearest crossing of the surface within
   reach along the triangle's normal or one of the three axes, whichever
   is least (each is at least the distance to the surface: the normal
   alone overstates it where a triangle stands steep to the surface, as
   one closing a groove thinner than its cell does, and misses it on a
   sliver whose normal is rounding); the largest, or INFINITY if some
   point found none (points within reach of a user's clip box are
   skipped: its faces are not in the spans). */
static double measured_error(Mesher *m, const Mesh *me, double reach, int n,
                             int *used) {
  uint64_t x = 0x2545F4914F6CDD1Dull;
  double worst = 0;
  *used = 0;
  for (int k = 0; k < n && me->nt; k++) {
    x ^= x << 13;
    x ^= x >> 7;
    x ^= x << 17;
    size_t i = (size_t)(x % me->nt);
    double u = (double)(x >> 11 & 0xffff) / 65536.0, v = (double)(x >> 27 & 0xffff) / 65536.0;
    if (u + v > 1) {
      u = 1 - u;
      v = 1 - v;
    }
    const int *t = me->t + 3 * i;
    const double *a = me->v + 3 * t[0], *b = me->v + 3 * t[1], *c = me->v + 3 * t[2];
    double p[3], ab[3], ac[3], nn[3];
    for (int j = 0; j < 3; j++) {
      p[j] = a[j] + u * (b[j] - a[j]) + v * (c[j] - a[j]);
      ab[j] = b[j] - a[j];
      ac[j] = c[j] - a[j];
    }
    vec3_cross(ab, ac, nn);
    double l = sqrt(vec3_dot(nn, nn));
    if (!(l > 0)) continue;
    int near_clip = 0;
    for (int j = 0; j < 3; j++) {
      near_clip |= p[j] - m->clo[j] < reach || m->chi[j] - p[j] < reach;
      nn[j] /= l;
    }
    if (near_clip) continue;
    double best = crossing_along(m, p, nn, reach);
    /* the axes only where the normal's distance would raise the largest
       (the least of the four cannot exceed it) */
    for (int ax = 0; ax < 3 && best > worst; ax++) {
      double e[3] = {0, 0, 0};
      e[ax] = 1;
      best = fmin(best, crossing_along(m, p, e, reach));
    }
    worst = fmax(worst, best);
    (*used)++;
  }
  return worst;
}

static int test_fault;

void mesh_test_fault(int fault) { test_fault = fault; }

/* mesh_test_fault's corruption: vertex 0 reflected through the centroid
   of the vertices, 1.5 times as far: its triangles then cross the solid
   and meet the far side's. */
static void push_through(Mesh *me) {
  double c[3] = {0, 0, 0};
  for (size_t i = 0; i < me->nv; i++)
    for (size_t k = 0; k < 3; k++) c[k] += me->v[3 * i + k];
  for (size_t k = 0; k < 3; k++) {
    c[k] /= (double)me->nv;
    me->v[k] = c[k] + 1.5 * (c[k] - me->v[k]);
  }
}

/* The sharp cells (LEAF_EXACT) whose box, grown by a finest cell on
   every side, holds p go to m->plainc. The count added, or -1 out of
   memory. */
static int plain_at(Mesher *m, const double p[3]) {
  double g = ldexp(m->h, m->depth - m->fine);
  int added = 0;
  for (size_t l = 0; l < m->nleaves; l++) {
    const Leaf *lf = &m->leaves[l];
    if (lf->kind != LEAF_EXACT) continue;
    double side = ldexp(m->h, m->depth - lf->level);
    int in = 1;
    for (int a = 0; a < 3 && in; a++) {
      double lo = m->org[a] + side * lf->q[a];
      in = p[a] >= lo - g && p[a] <= lo + side + g;
    }
    uint64_t k = ckey(lf->level, lf->q[0], lf->q[1], lf->q[2]);
    if (!in || hget(m->plainc, k) >= 0) continue;
    if (hput(m->plainc, k, 1) < 0) return -1;
    added++;
  }
  return added;
}

/* Two sharp cells can decide a degenerate case apart (a crease point on
   the face between them placed by each its own way: a crack), or a fan
   of a crease path can reach past its tetrahedron (a self-intersection).
   The sharp cells about such a place are then meshed again by their
   tetrahedra's crossings (m->plainc) and the rest stay sharp. For the
   closure check's failure (sc NULL), the places are the midpoints of
   the edges not used once each way; for the self-intersection check's,
   the first pair's box centre and its two triangles' centroids. The
   count of cells added (0: nothing to do here), or -1 out of memory. */
static int sharp_apart(Mesher *m, const Mesh *me, const MeshSelfCheck *sc) {
  int added = 0, r;
  if (sc) {
    if ((r = plain_at(m, sc->at)) < 0) return -1;
    added += r;
    for (int k = 0; k < 2; k++) {
      double c[3] = {0, 0, 0};
      for (int v = 0; v < 3; v++)
        for (int a = 0; a < 3; a++)
          c[a] += me->v[3 * (size_t)me->t[3 * sc->tri[k] + (size_t)v] + (size_t)a] / 3;
      if ((r = plain_at(m, c)) < 0) return -1;
      added += r;
    }
    return added;
  }
  hmap e = {0};   /* directed edge (a << 32 | b) -> its count */
  for (size_t t = 0; t < me->nt; t++)
    for (int k = 0; k < 3; k++) {
      uint64_t a = (uint32_t)me->t[3 * t + (size_t)k],
               b = (uint32_t)me->t[3 * t + (size_t)(k + 1) % 3];
      int c = hget(&e, a << 32 | b);
      if (hput(&e, a << 32 | b, c < 0 ? 1 : c + 1) < 0) goto oom;
    }
  for (size_t t = 0; t < me->nt; t++)
    for (int k = 0; k < 3; k++) {
      uint64_t a = (uint32_t)me->t[3 * t + (size_t)k],
               b = (uint32_t)me->t[3 * t + (size_t)(k + 1) % 3];
      if (hget(&e, a << 32 | b) == 1 && hget(&e, b << 32 | a) == 1) continue;
      double mid[3];
      for (int x = 0; x < 3; x++)
        mid[x] = 0.5 * (me->v[3 * a + (uint64_t)x] + me->v[3 * b + (uint64_t)x]);
      if ((r = plain_at(m, mid)) < 0) goto oom;
      added += r;
    }
  hfree(&e);
  return added;
oom:
  hfree(&e);
  return -1;
}

/* No two triangles meet other than in what they share, checked exactly
   (mesh_check.c); else *rc is set and the error names the place (the
   check's answer in *out, if out is not NULL). */
static int self_check(const Mesh *me, MeshReport *rep, char *err,
                      size_t errlen, int *rc, MeshSelfCheck *out) {
  MeshSelfCheck sc;
  int r = mesh_self_check(me, &sc);
  if (out) *out = sc;
  rep->pairs = sc.pairs;
  rep->pairs_exact = sc.exact;
  rep->check_seconds = sc.seconds;
  if (r == 0) return 0;
  *rc = r == -2 ? MESH_ENOMEM : r == -1 ? MESH_EINTERNAL : MESH_ESELF;
  if (r == 1)
    snprintf(err, errlen, "the mesh intersects itself: triangles %zu and %zu "
             "meet near (%.6g, %.6g, %.6g) other than in what they share "
             "(%ld pair%s of %ld); nothing was written", sc.tri[0], sc.tri[1],
             sc.at[0], sc.at[1], sc.at[2], sc.bad, sc.bad == 1 ? "" : "s",
             sc.pairs);
  else if (r == -1)
    snprintf(err, errlen, "internal error: a mesh vertex is not finite; "
             "nothing was written");
  return -1;
}

/* The cover proof's classifier (mesh_cover.h): 0 when the closed box is
   proven wholly outside or inside the clipped solid, as walk does. */
typedef struct {
  const Mesher *m;
  unsigned char *st;
  int *one;
  GrIv *gst;               /* gr_tape's scratch */
} CoverCtx;

static int cover_class(void *ctx, const double lo[3], const double hi[3]) {
  CoverCtx *c = ctx;
  const Mesher *m = c->m;
  int clip_in = 1, one;
  for (int a = 0; a < 3; a++) {
    if (hi[a] <= m->clo[a] || lo[a] >= m->chi[a]) return 0;
    if (lo[a] <= m->clo[a] || hi[a] >= m->chi[a]) clip_in = 0;
  }
  int k = scene_box_g(m->s, m->node, lo, hi, c->st, c->one, &one, 2,
                      m->forced);
  return !(k == T_OUT || (k == T_IN && clip_in));
}

/* The column proof's field (mesh_cover.h, MeshField): node x's density
   or soft field less its level. */
static double field_value(void *ctx, int x, const double p[3]) {
  const ScNode *nd = &((CoverCtx *)ctx)->m->s->nodes[x];
  if (nd->kind == SC_ROUNDED) return dt_density(nd->tape, p) - 0.5;
  return soft_field(nd->soft, p) - soft_magic(nd->soft);
}

static void field_range(void *ctx, int x, const double lo[3],
                        const double hi[3], double *l, double *h) {
  const ScNode *nd = &((CoverCtx *)ctx)->m->s->nodes[x];
  double fl, fh, lv = 0.5;
  if (nd->kind == SC_ROUNDED) dt_range_box(nd->tape, lo, hi, &fl, &fh);
  else {
    soft_field_box(nd->soft, lo, hi, &fl, &fh);
    lv = soft_magic(nd->soft);
  }
  *l = fl - lv;
  *h = fh - lv;
}

/* Over [lo, hi]: with u, grad . u >= gmin, |grad across u| <= wperp,
   |grad . u| <= gmax; without, g0 the middle of the gradient's bound.
   A rounded node's gradient is sum_k c_k n_k (gr_tape: c_k in an
   interval per leaf); a soft object's, per-axis intervals. */
static int field_grad(void *ctx, int x, const double lo[3], const double hi[3],
                      const double *u, double *gmin, double *wperp,
                      double *gmax, double g0[3]) {
  CoverCtx *c = ctx;
  const ScNode *nd = &c->m->s->nodes[x];
  double mid[3] = {0, 0, 0}, rad = 0, al = 0, ah = 0, mag = 0;
  if (nd->kind == SC_ROUNDED) {
    const GrIv *r = gr_tape(nd->tape, lo, hi, c->gst);
    if (!r || r->n == 0) return -1;
    /* the remainder: its middle (across u with u) and half-widths */
    double rm[3] = {0, 0, 0};
    rad = gr_rest(r, u, rm, &al, &ah);
    if (rad == HUGE_VAL) return -1;
    double ru = u ? vec3_dot(rm, u) : 0;
    for (int q = 0; q < 3; q++) {
      mid[q] = rm[q] - ru * (u ? u[q] : 0);
      mag += fabs(r->rl[q]) + fabs(r->rh[q]);
    }
    if (!u) rad = 0;
    for (int i = 0; i < r->n; i++) {
      if (r->step[i]) return -1;
      const double *n = nd->tape->leaves[r->leaf[i]].n;
      double cm = 0.5 * (r->cl[i] + r->ch[i]), hw = 0.5 * (r->ch[i] - r->cl[i]);
      if (!u) {
        for (int q = 0; q < 3; q++) mid[q] += cm * n[q];
        continue;
      }
      double k = vec3_dot(n, u), l, h, p[3];
      iv_mul(k, k, r->cl[i], r->ch[i], &l, &h);
      al += l;
      ah += h;
      mag += fabs(l) + fabs(h) + fabs(cm) + hw;
      /* n across u by components (1 - k^2 loses it when k rounds to 1),
         with room for their rounding */
      for (int q = 0; q < 3; q++) p[q] = n[q] - k * u[q];
      for (int q = 0; q < 3; q++) mid[q] += cm * p[q];
      rad += hw * (sqrt(vec3_dot(p, p)) + 1e-15);
    }
  } else if (nd->kind == SC_SOFT) {
    double dl[3], dh[3];
    soft_grad_box(nd->soft, lo, hi, dl, dh);
    double r2 = 0, mu = 0;
    for (int q = 0; q < 3; q++) {
      mid[q] = 0.5 * (dl[q] + dh[q]);
      double hw = 0.5 * (dh[q] - dl[q]);
      r2 += hw * hw;
      if (u) {
        al += u[q] > 0 ? u[q] * dl[q] : u[q] * dh[q];
        ah += u[q] > 0 ? u[q] * dh[q] : u[q] * dl[q];
        mu += u[q] * mid[q];
        mag += fabs(dl[q]) + fabs(dh[q]);
      }
    }
    rad = sqrt(r2);
    for (int q = 0; u && q < 3; q++) mid[q] -= mu * u[q];
  } else
    return -1;
  if (!u) {
    memcpy(g0, mid, sizeof mid);
    return isfinite(vec3_dot(mid, mid)) ? 0 : -1;
  }
  /* the sums' rounding: relative, with room, and absolute against the
     terms' magnitudes (the sums can cancel) */
  double abs_err = 1e-14 * mag + 1e-300;
  *gmin = (al > 0 ? al * (1 - 1e-9) : al * (1 + 1e-9)) - abs_err;
  *gmax = fmax(fabs(al), fabs(ah)) * (1 + 1e-9) + abs_err;
  *wperp = (sqrt(vec3_dot(mid, mid)) + rad) * (1 + 1e-9) + abs_err;
  return isfinite(*gmax) && isfinite(*wperp) ? 0 : -1;
}

/* Whether leaf lf lies within one finest cell of a leaf with two
   surfaces not proven one sheet together (Leaf.two): 1 or 0. op 0 makes
   the table (finest cells holding such a leaf), op 2 frees it; -1 out of
   memory. */
/* The finest-level cells leaf lf covers, or the one holding it: lo ..
   hi on each axis. */
static void fine_range(const Mesher *m, const Leaf *lf, int64_t lo[3],
                       int64_t hi[3]) {
  int sh = lf->level - m->fine;
  for (int a = 0; a < 3; a++) {
    lo[a] = sh >= 0 ? (int64_t)(lf->q[a] >> sh) : (int64_t)lf->q[a] << -sh;
    hi[a] = sh >= 0 ? lo[a] : lo[a] + ((int64_t)1 << -sh) - 1;
  }
}

static int near_two(Mesher *m, const Leaf *lf, int op) {
  hmap *tw = &m->two_near;
  if (op == 2) {
    hfree(tw);
    memset(tw, 0, sizeof *tw);
    return 0;
  }
  if (op == 0) {
    hfree(tw);
    memset(tw, 0, sizeof *tw);
    for (size_t l = 0; l < m->nleaves; l++) {
      const Leaf *t = &m->leaves[l];
      if (!t->two) continue;
      int sh = t->level - m->fine; /* the finest cell holding it */
      uint64_t q[3];
      for (int a = 0; a < 3; a++) q[a] = sh >= 0 ? t->q[a] >> sh : t->q[a] << -sh;
      if (hput(tw, ckey(m->fine, q[0], q[1], q[2]), 1) < 0) return -1;
    }
    return 0;
  }
  if (!tw->n) return 0;
  int64_t lo[3], hi[3];
  fine_range(m, lf, lo, hi);
  int64_t n = (int64_t)1 << m->fine;
  for (int64_t i = lo[0] - NEAR_TWO; i <= hi[0] + NEAR_TWO; i++)
    for (int64_t j = lo[1] - NEAR_TWO; j <= hi[1] + NEAR_TWO; j++)
      for (int64_t k = lo[2] - NEAR_TWO; k <= hi[2] + NEAR_TWO; k++)
        if (i >= 0 && j >= 0 && k >= 0 && i < n && j < n && k < n &&
            hget(tw, ckey(m->fine, (uint64_t)i, (uint64_t)j, (uint64_t)k)) >= 0)
          return 1;
  return 0;
}

/* Whether a leaf's cell gets a proof: plane and sharp cells need none
   (the mesh there is the surface); smooth cells get columns, finest cells
   boxes (mesh_cover.h). */
static int cover_kind(const Mesher *m, const Leaf *lf) {
  (void)m;
  return lf->kind == LEAF_FINE || lf->kind == LEAF_SMOOTH;
}

/* Every part of the surface within the tolerance of the mesh: proven by
   construction in plane and sharp cells (the mesh there is the surface),
   and by mesh_cover over the smooth and finest cells. 0, or -1 out of
   memory. */
static int cover_check(Mesher *m, const Mesh *me, MeshReport *rep) {
  size_t n = 0;
  for (size_t l = 0; l < m->nleaves; l++) n += (size_t)cover_kind(m, &m->leaves[l]);
  /* plane and sharp cells: the mesh is the surface (to what merging
     flat regions moved it) */
  rep->cover = m->vtol + m->flat_moved;
  if (!n) return 0;
  double *bx = malloc(6 * n * sizeof *bx);
  size_t *ix = malloc(n * sizeof *ix);
  int *fnode = malloc(n * sizeof *fnode);
  unsigned char *bad = malloc(n);
  size_t nsub = (size_t)(m->node - m->s->nodes[m->node].first + 1);
  int rc = -1;
  CoverCtx cc[2] = {{m, malloc(nsub), malloc(nsub * sizeof(int)),
                     malloc(DT_STACK_MAX * sizeof(GrIv))},
                    {m, malloc(nsub), malloc(nsub * sizeof(int)),
                     malloc(DT_STACK_MAX * sizeof(GrIv))}};
  void *ctx[2] = {&cc[0], &cc[1]};
  if (!bx || !ix || !fnode || !bad || !cc[0].st || !cc[0].one || !cc[0].gst ||
      !cc[1].st || !cc[1].one || !cc[1].gst)
    goto done;
  n = 0;
  for (size_t l = 0; l < m->nleaves; l++) {
    const Leaf *lf = &m->leaves[l];
    if (!cover_kind(m, lf)) continue;
    ix[n] = l;
    double side = ldexp(m->h, m->depth - lf->level);
    for (size_t a = 0; a < 3; a++) {
      bx[6 * n + a] = m->org[a] + side * lf->q[a];
      bx[6 * n + 3 + a] = m->org[a] + side * (lf->q[a] + 1);
    }
    /* a smooth cell's surface is one node's level set: its columns */
    fnode[n] = -1;
    int one = -1;
    if (lf->kind == LEAF_SMOOTH &&
        scene_box_g(m->s, m->node, bx + 6 * n, bx + 6 * n + 3, cc[0].st,
                    cc[0].one, &one, 1, m->forced) == T_ONE)
      fnode[n] = one;
    n++;
  }
  MeshField fld = {fnode, field_value, field_range, field_grad};
  double scale = 0;
  for (size_t i = 0; i < 3 * me->nv; i++) scale = fmax(scale, fabs(me->v[i]));
  MeshCover mc;
  /* a computed distance is a distance to a convex combination of the
     vertices, computed to a few ulps of the coordinates */
  if (mesh_cover(me, bx, n, m->tol, 0x1p-40 * scale, cover_class, ctx, 2, &fld,
                 bad, &mc) < 0)
    goto done;
  rep->cover_columns += mc.columns;
  rep->cover_colcells = mc.col_boxes;
  rep->cover = fmax(mc.bound, m->vtol + m->flat_moved);
  rep->cover_boxes += mc.boxes;
  rep->cover_unproven = mc.unproven;
  memcpy(rep->cover_at, mc.at, sizeof mc.at);
  rep->cover_seconds += mc.seconds;
  /* the cells not proven split in the next round, where they can and
     are not beside a cell holding two surfaces not proven one sheet
     together: those are refine_two's, taken in clusters (splitting some
     cells of a groove narrowing to nothing and not the others opens it
     in places and closes it between, which makes tunnels: figure12's
     obj5 had Euler characteristic -4 instead of 2 that way) */
  rep->cover_more = 0;
  /* the uniform grid (to compare) stays uniform: it is not split */
  if (mc.unproven && !m->uniform && near_two(m, NULL, 0) < 0) goto done;
  /* and with them every leaf within one finest cell of them: a thin part
     opened in a split cell and not in the cell beside it is pinched at
     their face, which makes tunnels (seed 207 at 0.03: Euler
     characteristic -2 for 2 with the failing cells alone split) */
  /* When the failing cells left are all beside such cells and few
     (WIDE_MAX), they are split too, from then on (MeshReport.cover_wide):
     a round that opens a groove in places and closes it between is not
     kept (mesh_rounds), and few cells cost one round, where figure12's
     obj5 at 0.0015 (thousands of them) took 3 times the time. More, up
     to WIDE_SPLIT_MAX, are a groove (cover_wide 2): split at once, the
     round kept only with the first mesh's topology (obj5 at 0.01: 741
     cells, proven in one round) */
  long skipped = 0;
  for (int pass = 0; pass < 2; pass++) {
    for (size_t i = 0; i < n && !m->uniform; i++) {
      const Leaf *lf = &m->leaves[ix[i]];
      if (!bad[i] || lf->level >= m->depth) continue;
      int nt = rep->cover_wide_next ? 0 : near_two(m, lf, 1);
      if (nt < 0) goto done;
      if (nt) {
        skipped++;
        continue;
      }
      int64_t lo[3], hi[3];
      fine_range(m, lf, lo, hi);
      for (int64_t a = lo[0] - 1; a <= hi[0] + 1; a++)
        for (int64_t b = lo[1] - 1; b <= hi[1] + 1; b++)
          for (int64_t c = lo[2] - 1; c <= hi[2] + 1; c++)
            if (a >= 0 && b >= 0 && c >= 0 &&
                hput(&m->ring, ckey(m->fine, (uint64_t)a, (uint64_t)b, (uint64_t)c), 1) < 0)
              goto done;
    }
    if (m->ring.n || !skipped || skipped > WIDE_SPLIT_MAX) break;
    rep->cover_wide_next = skipped > WIDE_MAX ? 2 : 1;
  }
  for (size_t l = 0; m->ring.n && l < m->nleaves; l++) {
    const Leaf *lf = &m->leaves[l];
    if (lf->level >= m->depth) continue;
    int64_t lo[3], hi[3], hit = 0;
    fine_range(m, lf, lo, hi);
    for (int64_t a = lo[0]; a <= hi[0] && !hit; a++)
      for (int64_t b = lo[1]; b <= hi[1] && !hit; b++)
        for (int64_t c = lo[2]; c <= hi[2] && !hit; c++)
          hit = hget(&m->ring, ckey(m->fine, (uint64_t)a, (uint64_t)b, (uint64_t)c)) >= 0;
    if (!hit) continue;
    if (hput(m->force, ckey(lf->level, lf->q[0], lf->q[1], lf->q[2]), 1) < 0)
      goto done;
    rep->cover_more++;
  }
  near_two(m, NULL, 2);
  rc = 0;
done:
  free(bx);
  free(ix);
  free(fnode);
  free(bad);
  for (int t = 0; t < 2; t++) {
    free(cc[t].st);
    free(cc[t].one);
    free(cc[t].gst);
  }
  return rc;
}

/* mesh_check's failure cr (-2 out of memory, -1 not closed) as mesh_run's
   answer, the error naming what the count found. */
static int closure_failed(int cr, const MeshCheck *ck, char *err, size_t errlen) {
  if (cr == -2) return MESH_ENOMEM;
  snprintf(err, errlen, "internal error: the mesh failed its closure check "
           "(%ld boundary, %ld non-manifold edges, %ld non-manifold "
           "vertices); nothing was written", ck->boundary_edges,
           ck->nonmanifold_edges, ck->nonmanifold_verts);
  return MESH_EINTERNAL;
}

static int mesh_run(const Scene *s, int node, const MeshSettings *ms,
                    Mesh **out, MeshReport *rep, int *bad_node, char *err,
                    size_t errlen, int sharp, hmap *force, hmap *plainc,
                    const size_t mem0[2]) {
  struct timespec t0, t1;
  clock_gettime(CLOCK_MONOTONIC, &t0);
  MeshReport keep = *rep;
  memset(rep, 0, sizeof *rep);
  /* what the rounds before spent on the proof */
  rep->cover_rounds = keep.cover_rounds;
  rep->cover_last = keep.cover_last;
  rep->cover_boxes = keep.cover_boxes;
  rep->cover_columns = keep.cover_columns;
  rep->cover_seconds = keep.cover_seconds;
  /* the cells split for this round were chosen wide (cover_check) */
  rep->cover_wide = rep->cover_wide_next = keep.cover_wide_next;
  *out = NULL;
  *bad_node = -1;
  /* lo, hi: the object's box (olo, ohi) within the Bounds box; an
     unbounded object's with the halfspaces that miss the Bounds box
     left out (a floor: clip_forced), else the Bounds box */
  double lo[3], hi[3], olo[3], ohi[3];
  int bounded = render_node_box(s, node, lo, hi);
  if (!bounded && ms->has_bounds)
    bounded = box_without_missing(s, node, ms->lo, ms->hi, lo, hi);
  if (!bounded) {
    if (!ms->has_bounds) {
      *bad_node = unbounded_leaf(s, node);
      snprintf(err, errlen, "the object is unbounded (it has no finite "
               "box): give Bounds lo hi to mesh the part inside a box");
      return MESH_EUNBOUNDED;
    }
    for (int i = 0; i < 3; i++) olo[i] = -HUGE_VAL, ohi[i] = HUGE_VAL;
    memcpy(lo, ms->lo, sizeof lo);
    memcpy(hi, ms->hi, sizeof hi);
  } else {
    memcpy(olo, lo, sizeof olo);
    memcpy(ohi, hi, sizeof ohi);
  }
  if (bounded && ms->has_bounds) {
    for (int i = 0; i < 3; i++) {
      lo[i] = fmax(lo[i], ms->lo[i]);
      hi[i] = fmin(hi[i], ms->hi[i]);
    }
  }
  double size = 0, scale = 1;
  for (int i = 0; i < 3; i++)
    if (!(hi[i] > lo[i])) {
      snprintf(err, errlen, "the object is empty: nothing to mesh");
      return MESH_EEMPTY;
    }
  for (int i = 0; i < 3; i++) {
    if (!isfinite(lo[i]) || !isfinite(hi[i])) {
      snprintf(err, errlen, "the box to mesh is not finite");
      return MESH_EUNBOUNDED;
    }
    if (hi[i] <= lo[i]) {
      snprintf(err, errlen, "the object is empty: nothing to mesh");
      return MESH_EEMPTY;
    }
    size = fmax(size, hi[i] - lo[i]);
    scale = fmax(scale, fmax(fabs(lo[i]), fabs(hi[i])));
  }
  double e = ms->tol;
  if (!(e > 0) || !isfinite(e) || e < 1e-12 * scale) {
    snprintf(err, errlen, "the tolerance must be finite and at least %g "
             "(what doubles resolve at this object's coordinates), not %g",
             1e-12 * scale, e);
    return MESH_ETOL;
  }
  double vtol = fmax(0.01 * e, 64 * RAY_TOL_FLOOR * scale);
  double ht = e - vtol, L = size + 3 * ht;
  int depth = 0;
  while (L / ldexp(1, depth) > ht) depth++;
  if (depth > MAX_DEPTH) {
    snprintf(err, errlen, "the tolerance %g is too fine for this object "
             "(size %g): the octree would need %d levels, at most %d",
             e, size, depth, MAX_DEPTH);
    return MESH_ETOL;
  }
  Mesher m;
  memset(&m, 0, sizeof m);
  m.s = s;
  m.node = node;
  m.fine = depth;
  m.depth = MAX_DEPTH;
  m.h = L / ldexp(1, MAX_DEPTH);
  m.tol = e;
  m.vtol = vtol;
  m.sharp = sharp && !ms->uniform;
  m.near_exact = m.near_weld = sharp == 2;
  m.force = force;
  m.plainc = plainc;
  m.uniform = ms->uniform;
  m.rep = rep;
  m.max_cells = ms->max_cells ? ms->max_cells : (size_t)1 << 24;
  m.mem0 = mem0[0];
  m.peak0 = mem0[1];
  m.max_mem = mem0[0] ? ms->max_memory : 0;
  for (int i = 0; i < 3; i++) {
    double c = 0.5 * (lo[i] + hi[i]);
    /* off centre by a fraction of a cell unlike on each axis, so that a
       centred object's diagonals and faces miss the grid's (a plane
       through a grid point or along a tetrahedron's face is a degenerate
       case for the sharp cells) */
    static const double shift[3] = {0.1713, 0.2389, 0.3167};
    m.org[i] = c - 0.5 * L + shift[i] * ht;
    /* the clip box: the user's box where it cuts into the object's,
       else no clip (the object's box is conservative; a clip there, or
       at a face the two boxes share, would keep the cells at its faces
       from being proven plane) */
    m.clo[i] = ms->has_bounds && ms->lo[i] > olo[i] ? lo[i] : -HUGE_VAL;
    m.chi[i] = ms->has_bounds && ms->hi[i] < ohi[i] ? hi[i] : HUGE_VAL;
  }
  rep->depth = depth;
  rep->h = L / ldexp(1, depth);
  rep->deepest = depth;
  rep->vtol = vtol;
  int nsub = node - s->nodes[node].first + 1;
  m.st = malloc((size_t)nsub);
  m.one = malloc((size_t)nsub * sizeof *m.one);
  m.gst = malloc(DT_STACK_MAX * sizeof *m.gst);
  m.plmap = malloc((size_t)nsub * sizeof *m.plmap);
  m.pv = malloc((size_t)nsub);
  m.prog = malloc((size_t)nsub * sizeof *m.prog);
  m.alias = malloc((size_t)nsub * sizeof *m.alias);
  m.flip = malloc((size_t)nsub);
  m.st2 = malloc((size_t)nsub);
  m.rel = malloc((size_t)nsub);
  m.one2 = malloc((size_t)nsub * sizeof *m.one2);
  if (m.flip) { /* the subtree is contiguous, children before parents */
    int f = s->nodes[node].first;
    m.flip[nsub - 1] = 0;
    for (int x = node; x >= f; x--) {
      const ScNode *nd = &s->nodes[x];
      if (nd->kind == SC_UNION || nd->kind == SC_INTER || nd->kind == SC_DIFF) {
        m.flip[nd->a - f] = m.flip[x - f];
        m.flip[nd->b - f] = (unsigned char)(m.flip[x - f] ^ (nd->kind == SC_DIFF));
      }
    }
  }
  m.ex = malloc(sizeof *m.ex);
  m.memo = calloc(1, sizeof *m.memo); /* none: pl_eval runs every time */
  if (m.memo) m.memo->cur = 1;
  m.ray = ray_ctx_new(s, vtol);
  m.s0 = s;
  /* parents, for cell_redundant (no memory: it is left out) */
  if ((m.par = malloc((size_t)nsub * sizeof *m.par)) &&
      (m.grp = malloc((size_t)nsub * sizeof *m.grp)) && (m.frc = malloc((size_t)nsub))) {
    int f = s->nodes[node].first;
    for (int x = 0; x < nsub; x++) m.par[x] = -1;
    for (int x = f; x <= node; x++) {
      const ScNode *nd = &s->nodes[x];
      if (nd->kind == SC_UNION || nd->kind == SC_INTER || nd->kind == SC_DIFF)
        m.par[nd->a - f] = m.par[nd->b - f] = x;
    }
    /* each halfspace's group: the top of the intersections above it
       (parents before children, from the root down), or -1 */
    for (int x = node; x >= f; x--) {
      int p = m.par[x - f];
      int top = p >= 0 && s->nodes[p].kind == SC_INTER;
      m.grp[x - f] = !top ? -1 : m.grp[p - f] >= 0 ? m.grp[p - f] : p;
    }
  } else {
    free(m.par);
    free(m.grp);
    m.par = m.grp = NULL;
  }
  if (!getenv("QCS_MESH_NOPRUNE")) {
    int f = s->nodes[node].first;
    for (int x = f; x <= node; x++) m.nrnd += s->nodes[x].kind == SC_ROUNDED;
    if (m.nrnd && (m.rnd = malloc((size_t)m.nrnd * sizeof *m.rnd)) &&
        (m.plev = calloc(MAX_DEPTH + 1, sizeof *m.plev))) {
      m.nrnd = 0;
      for (int x = f; x <= node; x++)
        if (s->nodes[x].kind == SC_ROUNDED) m.rnd[m.nrnd++] = x;
    } else {
      m.nrnd = 0; /* no pruning: only slower */
    }
  }
  if (ms->has_bounds && m.flip && (m.forced = malloc((size_t)nsub))) {
    clip_forced(&m, ms->lo, ms->hi, m.forced);
    /* a face of the Bounds box that no solid lies beyond (a cube
       standing on its low face: the object's box, padded for rounding,
       reaches a little past it) clips nothing: no clip there, so that
       the cells on it can be proven plane or sharp */
    for (int i = 0; i < 6 && bounded; i++) {
      int a = i % 3, up = i >= 3;
      double *c = up ? &m.chi[a] : &m.clo[a], sl[3], sh[3];
      if (!isfinite(*c)) continue;
      memcpy(sl, olo, sizeof sl);
      memcpy(sh, ohi, sizeof sh);
      if (up) sl[a] = ms->hi[a];
      else sh[a] = ms->lo[a];
      if (solid_misses(s, node, sl, sh, m.forced)) *c = up ? HUGE_VAL : -HUGE_VAL;
    }
  }
  int rc = MESH_OK;
  if (!m.st || !m.one || !m.gst || !m.plmap || !m.pv || !m.prog || !m.alias || !m.flip || !m.st2 || !m.rel || !m.one2 || !m.ex ||
      !m.ray || (ms->has_bounds && !m.forced)) {
    rc = MESH_ENOMEM;
    goto done;
  }
  if (walk(&m, 0, 0, 0, 0) < 0 || refine_two(&m) < 0) {
    rc = m.err;
    if (rc == MESH_ELIMIT && rep->memout)
      memory_error(&m, err, errlen, 0);
    else if (rc == MESH_ELIMIT)
      snprintf(err, errlen, "the mesh needs more than %zu surface octree "
               "cells (limit max-cells): give a larger tolerance than %g",
               m.max_cells, e);
    else if (rc == MESH_ETHIN) {
      *bad_node = m.badnode;
      snprintf(err, errlen, "a part of the object is thinner than the "
               "finest cell the octree can make (side %.3g, depth %d): near "
               "(%.6g, %.6g, %.6g) its surface is not proven one sheet in a "
               "cell (two sides of a thin part, or a point where it is not "
               "smooth); nothing was written", m.h, MAX_DEPTH,
               0.5 * (m.bad[0] + m.bad[3]), 0.5 * (m.bad[1] + m.bad[4]),
               0.5 * (m.bad[2] + m.bad[5]));
    }
    goto done;
  }
  rep->leaves = (long)m.nleaves;
  /* count the triangles from the signs before any crossing is sought */
  size_t count = 0;
  for (size_t l = 0; l < m.nleaves; l++)
    if (cell(&m, l, &count) < 0) {
      rc = m.err;
      goto done;
    }
  if (ms->max_triangles && count > ms->max_triangles) {
    snprintf(err, errlen, "the mesh would have %zu triangles, over the "
             "limit of %zu (max-triangles): give a larger tolerance than %g",
             count, ms->max_triangles, e);
    rc = MESH_ELIMIT;
    goto done;
  }
  if (count == 0) {
    double thin = INFINITY; /* the box's least side: a hint, not a proof */
    for (int i = 0; i < 3; i++) thin = fmin(thin, hi[i] - lo[i]);
    if (rep->leaves > 0)
      /* every surface cell holds one sheet of each surface in it, and
         no corner is inside: the surfaces only dip into cells as caps */
      snprintf(err, errlen, "no corner of any cell is inside the object at "
               "this tolerance (%g): it is empty, or its surface only dips "
               "into cells (side %.3g) without reaching a corner; its box "
               "is %.3g thin at the least: try meshWith [Tolerance %.2g]",
               e, rep->h, thin, thin / 10);
    else
      snprintf(err, errlen, "the object is empty: every cell of its box "
               "is proven outside it");
    rc = MESH_EEMPTY;
    goto done;
  }
  if (count > (size_t)1 << 30) {
    snprintf(err, errlen, "the mesh would have %zu triangles", count);
    rc = MESH_ELIMIT;
    goto done;
  }
  if (m.max_mem) { /* before the crossings are sought */
    size_t r = resident(), grown = r > m.mem0 ? r - m.mem0 : 0;
    size_t need = grown + (count < SIZE_MAX / TRI_BYTES ? count * TRI_BYTES : SIZE_MAX / 2);
    if (need > m.max_mem) {
      rc = memory_error(&m, err, errlen, need);
      goto done;
    }
  }
  /* the sharp cells first: their crease points split the marching
     triangles next to them */
  for (int pass = 0; pass < 2; pass++) {
    for (size_t l = 0; l < m.nleaves; l++)
      if ((m.leaves[l].kind == LEAF_EXACT) == !pass && cell(&m, l, NULL) < 0) {
        rc = m.err;
        goto done;
      }
    if (!pass && face_paths(&m) < 0) {
      rc = m.err;
      goto done;
    }
  }
  if (m.ray->failed) {
    rc = MESH_ENOMEM;
    goto done;
  }
  if (weld(&m) < 0) {
    rc = MESH_ENOMEM;
    goto done;
  }
  if (over_memory(&m)) {
    rc = memory_error(&m, err, errlen, 0);
    goto done;
  }
  /* the count above is a lower bound: crease paths split a few marching
     triangles more */
  if (ms->max_triangles && m.nt > ms->max_triangles) {
    snprintf(err, errlen, "the mesh would have %zu triangles, over the "
             "limit of %zu (max-triangles): give a larger tolerance than %g",
             m.nt, ms->max_triangles, e);
    rc = MESH_ELIMIT;
    goto done;
  }
  /* the octree's maps are done with: free them before the check's
     tables are made (the peak) */
  hfree(&m.split);
  hfree(&m.pt);
  hfree(&m.vert);
  hfree(&m.crease);
  free(m.vert2.k);
  free(m.vert2.v);
  free(m.fpath.k);
  free(m.fpath.v);
  free(m.pc);
  free(m.ps);
  memset(&m.split, 0, sizeof m.split);
  memset(&m.pt, 0, sizeof m.pt);
  memset(&m.vert, 0, sizeof m.vert);
  memset(&m.crease, 0, sizeof m.crease);
  memset(&m.vert2, 0, sizeof m.vert2);
  memset(&m.fpath, 0, sizeof m.fpath);
  m.pc = NULL;
  m.ps = NULL;
  Mesh *me = malloc(sizeof *me);
  if (!me) {
    rc = MESH_ENOMEM;
    goto done;
  }
  me->nv = m.nv;
  me->nt = m.nt;
  me->rgb = NULL;
  /* the arrays grew by doubling: give back what is not used */
  double *v2 = m.nv ? realloc(m.v, 3 * m.nv * sizeof *m.v) : NULL;
  int *t2 = m.nt ? realloc(m.t, 3 * m.nt * sizeof *m.t) : NULL;
  me->v = v2 ? v2 : m.v;
  me->t = t2 ? t2 : m.t;
  m.v = NULL;
  m.t = NULL;
  /* flat regions triangulated again (mesh_merge.h), checked below with
     the rest; if the checks fail with them, the mesh as made is checked
     instead (kept aside until then) */
  Mesh *made = NULL;
  MeshMerge mm = {0};
  int *from = NULL; /* the merge's origins (mesh_merge_flat_frozen) */
  double mscale = 0;
  for (size_t i = 0; i < 3 * me->nv; i++) mscale = fmax(mscale, fabs(me->v[i]));
  double mdelta = ldexp(fmax(mscale, size), -44);
  if (!ms->uniform && !ms->keep_flat && !test_fault && me->nt &&
      4 * mdelta <= 1e-3 * e &&
      (made = mesh_copy(me)) != NULL) {
    if (mesh_merge_flat_frozen(me, mdelta, NULL, &from, &mm) < 0) { /* out of memory: as made */
      mesh_free(me);
      me = made;
      made = NULL;
      memset(&mm, 0, sizeof mm);
    } else if (!mm.regions) { /* nothing merged: no copy to keep */
      mesh_free(made);
      made = NULL;
    }
  }
  if (widen(&m, me) < 0 || widen(&m, made) < 0) {
    mesh_free(me);
    mesh_free(made);
    rc = MESH_ENOMEM;
    free(from);
    goto done;
  }
  MeshCheck ck;
  int cr = mesh_check(me, &ck);
  if (cr == -1 && made) {
    mesh_free(me);
    me = made;
    made = NULL;
    rep->flat_undone = 1;
    memset(&mm, 0, sizeof mm);
    cr = mesh_check(me, &ck);
  }
  if (cr != 0) {
    int sa = cr == -1 && m.sharp && m.plainc ? sharp_apart(&m, me, NULL) : 0;
    mesh_free(me);
    mesh_free(made);
    rc = sa < 0 ? MESH_ENOMEM : closure_failed(cr, &ck, err, errlen);
    if (sa > 0) {
      rc = MESH_RESHARP;
      rep->resharp = 1;
    }
    free(from);
    goto done;
  }
  rep->components = ck.components;
  rep->euler = ck.euler;
  if (m.near_weld && (rep->sliver_pairs || rep->sliver_caps || rep->sliver_holes) &&
      ck.euler != 2 * ck.components) {
    /* the slivers taken out can join two parts touching along a line in
       some places and leave them parted between: a handle the solid need
       not have (a 63- and a 78-sided prism edge to edge, turned twice,
       came out of genus 1). Not trusted: the mesh is made without sharp
       cells, as before the slivers were taken out */
    mesh_free(me);
    mesh_free(made);
    snprintf(err, errlen, "the slivers taken out left a mesh of genus %ld",
             (2 * ck.components - ck.euler) / 2);
    rc = MESH_EINTERNAL;
    free(from);
    goto done;
  }
  if (me->nv && (test_fault == 2 || (test_fault == 1 && sharp)))
    push_through(me);
  MeshSelfCheck sck;
  int sr = self_check(me, rep, err, errlen, &rc, &sck);
  /* the merged regions where the mesh meets itself kept as made (their
     triangles frozen) and the rest merged again, a few times, before the
     whole merge is undone below */
  unsigned char *frozen = NULL;
  for (int tries = 0; sr != 0 && made && from && rc == MESH_ESELF && tries < FLAT_TRIES;
       tries++) {
    if (!frozen && !(frozen = calloc(made->nt ? made->nt : 1, 1))) break;
    long more = 0;
    for (int k = 0; k < 2; k++) {
      int f = sck.tri[k] < me->nt ? from[sck.tri[k]] : 0;
      if (f >= 0) continue; /* a triangle as made */
      for (size_t i = 0; i < made->nt; i++)
        if (from[me->nt + i] == -1 - f && !frozen[i]) {
          frozen[i] = 1;
          more++;
        }
    }
    if (!more) break;
    Mesh *me2 = mesh_copy(made);
    int *from2 = NULL;
    MeshMerge mm2;
    MeshCheck ck2;
    if (!me2 || unwiden(&m, me2) < 0 ||
        mesh_merge_flat_frozen(me2, mdelta, frozen, &from2, &mm2) < 0 ||
        !mm2.regions || !from2 || widen(&m, me2) < 0 || mesh_check(me2, &ck2) != 0) {
      mesh_free(me2);
      free(from2);
      break;
    }
    mesh_free(me);
    me = me2;
    free(from);
    from = from2;
    mm = mm2;
    ck = ck2;
    rep->components = ck.components;
    rep->euler = ck.euler;
    rep->flat_frozen = tries + 1;
    rc = MESH_OK;
    err[0] = 0;
    sr = self_check(me, rep, err, errlen, &rc, &sck);
  }
  free(frozen);
  free(from);
  from = NULL;
  if (sr != 0 && made && rc == MESH_ESELF) {
    rep->flat_frozen = 0;
    /* the mesh as made, checked for closure and self-intersection in
       its turn */
    mesh_free(me);
    me = made;
    made = NULL;
    rep->flat_undone = 2;
    memset(&mm, 0, sizeof mm);
    rc = MESH_OK;
    err[0] = 0;
    cr = mesh_check(me, &ck);
    if (cr != 0) {
      int sa = cr == -1 && m.sharp && m.plainc ? sharp_apart(&m, me, NULL) : 0;
      mesh_free(me);
      rc = sa < 0 ? MESH_ENOMEM : closure_failed(cr, &ck, err, errlen);
      if (sa > 0) {
        rc = MESH_RESHARP;
        rep->resharp = 1;
      }
      goto done;
    }
    rep->components = ck.components;
    rep->euler = ck.euler;
    sr = self_check(me, rep, err, errlen, &rc, &sck);
  }
  mesh_free(made);
  made = NULL;
  if (sr != 0) {
    int sa = rc == MESH_ESELF && m.sharp && m.plainc && rep->sharp
                 ? sharp_apart(&m, me, &sck) : 0;
    mesh_free(me);
    if (sa < 0) rc = MESH_ENOMEM;
    if (sa > 0) {
      rc = MESH_RESHARP;
      rep->resharp = 2;
    }
    goto done;
  }
  if (over_memory(&m)) { /* the checks' peak */
    mesh_free(me);
    rc = memory_error(&m, err, errlen, 0);
    goto done;
  }
  rep->flat_regions = mm.regions;
  rep->flat_before = mm.before;
  if (mm.regions) {
    /* the surface moved by at most mm.moved (mesh_merge.h) */
    rep->certified += mm.moved;
    rep->flat_moved = mm.moved;
    m.flat_moved = mm.moved;
  }
  if (cover_check(&m, me, rep) < 0) {
    mesh_free(me);
    rc = MESH_ENOMEM;
    goto done;
  }
  if (over_memory(&m)) {
    mesh_free(me);
    rc = memory_error(&m, err, errlen, 0);
    goto done;
  }
  rep->vertices = me->nv;
  rep->triangles = me->nt;
  rep->measured = measured_error(&m, me, 2 * fmax(rep->certified, e), 1000,
                                 &rep->samples);
  *out = me;
  /* mesh again with the cells not proven split (mesh_rounds decides
     which mesh is kept) */
  if (rep->cover_more && !rep->cover_last) rc = MESH_RECOVER;
done:
  if (rc == MESH_ENOMEM) snprintf(err, errlen, "out of memory while meshing");
  free(m.forced);
  free(m.st);
  free(m.one);
  free(m.gst);
  free(m.plmap);
  free(m.pv);
  free(m.prog);
  free(m.alias);
  free(m.flip);
  free(m.st2);
  free(m.rel);
  free(m.one2);
  free(m.ex);
  free(m.memo);
  free(m.pin);
  prune_levels_free(&m);
  free(m.par);
  free(m.grp);
  free(m.frc);
  free(m.rnd);
  free(m.cls);
  free(m.pls);
  free(m.vert2.k);
  free(m.vert2.v);
  free(m.leaves);
  free(m.v);
  free(m.t);
  free(m.pc);
  free(m.ps);
  free(m.fl);
  free(m.ft);
  hfree(&m.split);
  hfree(&m.two_near);
  hfree(&m.ring);
  hfree(&m.crease);
  free(m.poly);
  free(m.fpath.k);
  free(m.fpath.v);
  free(m.fstart);
  free(m.uni);
  free(m.xact);
  hfree(&m.pt);
  hfree(&m.vert);
  if (m.ray) ray_ctx_free(m.ray);
  clock_gettime(CLOCK_MONOTONIC, &t1);
  rep->seconds = (double)(t1.tv_sec - t0.tv_sec) +
                 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
  return rc;
}

/* A copy of m's vertices and triangles (not its colours), or NULL. */
static Mesh *mesh_copy(const Mesh *m) {
  Mesh *c = calloc(1, sizeof *c);
  if (!c) return NULL;
  c->nv = m->nv;
  c->nt = m->nt;
  c->v = malloc((m->nv ? 3 * m->nv : 1) * sizeof *c->v);
  c->t = malloc((m->nt ? 3 * m->nt : 1) * sizeof *c->t);
  if (!c->v || !c->t) {
    mesh_free(c);
    return NULL;
  }
  memcpy(c->v, m->v, 3 * m->nv * sizeof *c->v);
  memcpy(c->t, m->t, 3 * m->nt * sizeof *c->t);
  return c;
}

void mesh_free(Mesh *m) {
  if (!m) return;
  free(m->rgb);
  free(m->v);
  free(m->t);
  free(m);
}

/* ---- edge counting ------------------------------------------------------ */

static int find(int *p, int x) {
  while (p[x] != x) x = p[x] = p[p[x]];
  return x;
}

/* Each vertex's wedges (one per triangle corner at it: the next vertex,
   the one after, the triangle) in one array, vertex by vertex; an edge
   a -> b is found by scanning a's wedges, and its reverse b's (a few
   each), so no hash table is needed (at 4 million triangles the hash
   tables of directed and undirected edges took 600 MB). */
int mesh_check(const Mesh *m, MeshCheck *c) {
  memset(c, 0, sizeof *c);
  size_t nv = m->nv, nt = m->nt;
  int *par = malloc((nt ? nt : 1) * sizeof *par);
  size_t *start = malloc((nv + 1) * sizeof *start);
  int *deg = calloc(nv ? nv : 1, sizeof *deg);
  int *w = malloc(9 * (nt ? nt : 1) * sizeof *w);
  long edges = 0, used = 0;
  int rc = 0;
  if (!par || !start || !deg || !w) {
    rc = -2;
    goto out;
  }
  for (size_t i = 0; i < nt; i++) {
    par[i] = (int)i;
    const int *t = m->t + 3 * i;
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) c->degenerate++;
    for (int e = 0; e < 3; e++) deg[t[e]]++;
  }
  size_t tot = 0;
  for (size_t v = 0; v < nv; v++) {
    start[v] = tot;
    tot += (size_t)deg[v];
    used += deg[v] > 0;
    deg[v] = 0; /* refilled below */
  }
  start[nv] = tot;
  for (size_t i = 0; i < nt; i++) {
    const int *t = m->t + 3 * i;
    for (int e = 0; e < 3; e++) {
      int v = t[e];
      size_t s = 3 * (start[v] + (size_t)deg[v]++);
      w[s] = t[(e + 1) % 3];
      w[s + 1] = t[(e + 2) % 3];
      w[s + 2] = (int)i;
    }
  }
  for (size_t a = 0; a < nv; a++) {
    const int *fa = w + 3 * start[a];
    int na = deg[a];
    for (int x = 0; x < na; x++) {
      int b = fa[3 * x], first = 1, n = 0;
      for (int y = 0; y < na; y++)
        if (fa[3 * y] == b) {
          first &= y >= x;
          n++;
          par[find(par, fa[3 * y + 2])] = find(par, fa[3 * x + 2]);
        }
      if (!first) continue; /* the directed edge a -> b counted once */
      int r = 0;
      const int *fb = w + 3 * start[b];
      for (int y = 0; y < deg[b]; y++)
        if (fb[3 * y] == (int)a) {
          r++;
          par[find(par, fb[3 * y + 2])] = find(par, fa[3 * x + 2]);
        }
      if (n > 1) c->nonmanifold_edges++;
      if (r != 1) c->boundary_edges++;
      edges++;
    }
  }
  edges /= 2;
  for (size_t i = 0; i < nt; i++) c->components += find(par, (int)i) == (int)i;
  /* vertex fans: around each vertex, the triangles' opposite edges must
     chain into one cycle (checked by following next-vertex links) */
  for (size_t v = 0; v < nv; v++) {
    int n = deg[v];
    if (!n) continue;
    const int *f = w + 3 * start[v];
    /* follow b -> c links from the first wedge; one cycle of n wedges */
    int cur = f[1], steps = 1, ok = 1;
    while (cur != f[0] && ok) {
      int found = -1;
      for (int q = 0; q < n; q++)
        if (f[3 * q] == cur) {
          found = q;
          break;
        }
      if (found < 0 || steps > n) ok = 0;
      else {
        cur = f[3 * found + 1];
        steps++;
      }
    }
    if (!ok || steps != n) c->nonmanifold_verts++;
  }
  c->euler = used - edges + (long)nt;
  rc = c->boundary_edges || c->nonmanifold_edges || c->nonmanifold_verts ||
               c->degenerate
           ? -1
           : 0;
out:
  free(par);
  free(start);
  free(deg);
  free(w);
  return rc;
}

/* ---- writers ------------------------------------------------------------ */

static const char *ext_of(const char *path) {
  const char *d = strrchr(path, '.');
  return d ? d + 1 : "";
}

int mesh_is_mesh_path(const char *path) {
  const char *e = ext_of(path);
  return !strcmp(e, "stl") || !strcmp(e, "obj") || !strcmp(e, "ply") ||
         !strcmp(e, "3mf");
}

/* ---- colours ------------------------------------------------------------ */

/* The top-level union's parts with their inherited Colour
   (scene_union_parts, the walk the tracer's collect_prims makes too). */
typedef struct {
  int *parts;
  const double **cols;
  int n, cap;
} Parts;

static int add_part(void *ctx, int part, const double *colour) {
  Parts *p = ctx;
  if (p->n == p->cap) {
    int nc = p->cap ? 2 * p->cap : 16;
    int *g = realloc(p->parts, (size_t)nc * sizeof *g);
    if (g) p->parts = g;
    const double **gc = realloc(p->cols, (size_t)nc * sizeof *gc);
    if (gc) p->cols = gc;
    if (!g || !gc) return -1;
    p->cap = nc;
  }
  p->parts[p->n] = part;
  p->cols[p->n++] = colour;
  return 0;
}

static int collect_parts(const Scene *s, int root, int **parts,
                         const double ***cols, int *n) {
  Parts p = {NULL, NULL, 0, 0};
  if (scene_union_parts(s, root, add_part, &p) < 0) {
    free(p.parts);
    free(p.cols);
    return -1;
  }
  *parts = p.parts;
  *cols = p.cols;
  *n = p.n;
  return 0;
}

int mesh_colour(const Scene *s, int node, Mesh *m, const double def[3],
                double inset) {
  int *parts, np;
  const double **cols;
  if (collect_parts(s, node, &parts, &cols, &np) < 0) return -1;
  double *vn = calloc(3 * (m->nv ? m->nv : 1), sizeof *vn);
  float *rgb = malloc(3 * (m->nv ? m->nv : 1) * sizeof *rgb);
  if (!vn || !rgb) {
    free(vn);
    free(rgb);
    free(parts);
    free(cols);
    return -1;
  }
  for (size_t i = 0; i < m->nt; i++) {
    const int *t = m->t + 3 * i;
    const double *a = m->v + 3 * t[0], *b = m->v + 3 * t[1], *c = m->v + 3 * t[2];
    double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]}, n[3];
    vec3_cross(u, w, n);
    for (int k = 0; k < 3; k++)
      for (int j = 0; j < 3; j++) vn[3 * (size_t)t[k] + (size_t)j] += n[j];
  }
  /* a vertex takes the colour of the first part holding a point just
     inside the surface below it */
  for (size_t i = 0; i < m->nv; i++) {
    double *n = vn + 3 * i, l = sqrt(vec3_dot(n, n)), q[3];
    for (int j = 0; j < 3; j++)
      q[j] = m->v[3 * i + (size_t)j] - (l > 0 ? inset * n[j] / l : 0);
    const double *c = def;
    for (int k = 0; k < np; k++)
      if (scene_inside(s, parts[k], q) == 1) {
        if (cols[k]) c = cols[k];
        break;
      }
    for (int j = 0; j < 3; j++) rgb[3 * i + (size_t)j] = (float)c[j];
  }
  free(vn);
  free(parts);
  free(cols);
  free(m->rgb);
  m->rgb = rgb;
  return 0;
}

typedef struct {
  char *p;
  size_t n, cap;
  int bad;
} buf;

static void put(buf *b, const void *d, size_t n) {
  if (b->bad) return;
  if (b->n + n > b->cap) {
    size_t nc = b->cap ? b->cap : 65536;
    while (nc < b->n + n) nc *= 2;
    char *g = realloc(b->p, nc);
    if (!g) {
      b->bad = 1;
      return;
    }
    b->p = g;
    b->cap = nc;
  }
  memcpy(b->p + b->n, d, n);
  b->n += n;
}

static void put_f32(buf *b, double x) {
  float f = (float)x;
  unsigned char q[4];
  uint32_t u;
  memcpy(&u, &f, 4);
  for (int i = 0; i < 4; i++) q[i] = (unsigned char)(u >> (8 * i));
  put(b, q, 4);
}

static void tri_normal(const Mesh *m, size_t i, double n[3]) {
  const int *t = m->t + 3 * i;
  const double *a = m->v + 3 * t[0], *b = m->v + 3 * t[1], *c = m->v + 3 * t[2];
  double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  vec3_cross(u, w, n);
}

static void put_le(buf *b, uint32_t u, int n) {
  unsigned char q[4];
  for (int i = 0; i < n; i++) q[i] = (unsigned char)(u >> (8 * i));
  put(b, q, (size_t)n);
}

static unsigned char vcolour(const Mesh *m, size_t v, int k) {
  static const float grey[3] = {0.80f, 0.78f, 0.72f};
  return img_srgb8(m->rgb ? m->rgb[3 * v + (size_t)k] : grey[k]);
}

/* Binary little-endian PLY: float x y z, uchar red green blue (sRGB) per
   vertex, a uchar-counted int list per face. */
static void write_ply(const Mesh *m, buf *b) {
  char head[400];
  int len = snprintf(head, sizeof head,
                     "ply\nformat binary_little_endian 1.0\ncomment written "
                     "by qcs\nelement vertex %zu\nproperty float x\nproperty "
                     "float y\nproperty float z\nproperty uchar red\nproperty "
                     "uchar green\nproperty uchar blue\nelement face %zu\n"
                     "property list uchar int vertex_indices\nend_header\n",
                     m->nv, m->nt);
  put(b, head, (size_t)len);
  for (size_t i = 0; i < m->nv; i++) {
    for (int k = 0; k < 3; k++) put_f32(b, m->v[3 * i + (size_t)k]);
    unsigned char c[3];
    for (int k = 0; k < 3; k++) c[k] = vcolour(m, i, k);
    put(b, c, 3);
  }
  for (size_t i = 0; i < m->nt; i++) {
    put(b, "\3", 1);
    for (int k = 0; k < 3; k++) put_le(b, (uint32_t)m->t[3 * i + (size_t)k], 4);
  }
}

static void put_str(buf *b, const char *s) { put(b, s, strlen(s)); }

/* 3MF (core specification): the model XML with one base material per
   distinct colour, each triangle taking its first vertex's; zipped in
   memory by libzip and written whole by img_write_bytes. */
static int write_3mf(const Mesh *m, const char *path, char *err,
                     size_t errlen) {
  buf x = {0};
  char line[200];
  /* the distinct colours */
  uint32_t *pal = NULL;
  int *tc = malloc((m->nt ? m->nt : 1) * sizeof *tc);
  size_t npal = 0, cappal = 0;
  hmap idx = {0};
  int rc = -1;
  if (!tc) goto nomem;
  for (size_t i = 0; i < m->nt; i++) {
    size_t v = (size_t)m->t[3 * i];
    uint32_t c = (uint32_t)vcolour(m, v, 0) << 16 | (uint32_t)vcolour(m, v, 1) << 8 |
                 vcolour(m, v, 2);
    int k = hget(&idx, c);
    if (k < 0) {
      if (grow((void **)&pal, &cappal, npal + 1, sizeof *pal) < 0 ||
          hput(&idx, c, (int)npal) < 0)
        goto nomem;
      pal[npal] = c;
      k = (int)npal++;
    }
    tc[i] = k;
  }
  put_str(&x, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<model unit=\""
              "millimeter\" xml:lang=\"en-US\" xmlns=\"http://schemas."
              "microsoft.com/3dmanufacturing/core/2015/02\">\n <metadata "
              "name=\"Application\">qcs</metadata>\n <resources>\n  "
              "<basematerials id=\"1\">\n");
  for (size_t i = 0; i < npal; i++) {
    snprintf(line, sizeof line, "   <base name=\"colour %zu\" displaycolor="
             "\"#%06X\" />\n", i, (unsigned)pal[i]);
    put_str(&x, line);
  }
  put_str(&x, "  </basematerials>\n  <object id=\"2\" type=\"model\" "
              "pid=\"1\" pindex=\"0\">\n   <mesh>\n    <vertices>\n");
  for (size_t i = 0; i < m->nv; i++) {
    snprintf(line, sizeof line, "     <vertex x=\"%.9g\" y=\"%.9g\" z=\"%.9g\" />\n",
             m->v[3 * i], m->v[3 * i + 1], m->v[3 * i + 2]);
    put_str(&x, line);
  }
  put_str(&x, "    </vertices>\n    <triangles>\n");
  for (size_t i = 0; i < m->nt; i++) {
    const int *t = m->t + 3 * i;
    snprintf(line, sizeof line, "     <triangle v1=\"%d\" v2=\"%d\" v3=\"%d\" "
             "pid=\"1\" p1=\"%d\" />\n", t[0], t[1], t[2], tc[i]);
    put_str(&x, line);
  }
  put_str(&x, "    </triangles>\n   </mesh>\n  </object>\n </resources>\n "
              "<build>\n  <item objectid=\"2\" />\n </build>\n</model>\n");
  if (x.bad) goto nomem;
  static const char types[] =
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<Types xmlns=\"http://"
      "schemas.openxmlformats.org/package/2006/content-types\">\n <Default "
      "Extension=\"rels\" ContentType=\"application/vnd.openxmlformats-"
      "package.relationships+xml\" />\n <Default Extension=\"model\" "
      "ContentType=\"application/vnd.ms-package.3dmanufacturing-3dmodel+xml\""
      " />\n</Types>\n";
  static const char rels[] =
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<Relationships xmlns=\""
      "http://schemas.openxmlformats.org/package/2006/relationships\">\n "
      "<Relationship Target=\"/3D/3dmodel.model\" Id=\"rel0\" Type=\"http://"
      "schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel\" />\n"
      "</Relationships>\n";
  zip_error_t ze;
  zip_error_init(&ze);
  zip_source_t *src = zip_source_buffer_create(NULL, 0, 0, &ze);
  zip_t *za = src ? zip_open_from_source(src, ZIP_TRUNCATE, &ze) : NULL;
  if (!za) {
    if (src) zip_source_free(src);
    zip_error_fini(&ze);
    goto nomem;
  }
  zip_source_keep(src);
  const char *names[3] = {"[Content_Types].xml", "_rels/.rels", "3D/3dmodel.model"};
  const void *data[3] = {types, rels, x.p};
  size_t lens[3] = {sizeof types - 1, sizeof rels - 1, x.n};
  int zok = 1;
  for (int i = 0; i < 3 && zok; i++) {
    zip_source_t *fs = zip_source_buffer(za, data[i], lens[i], 0);
    if (!fs || zip_file_add(za, names[i], fs, ZIP_FL_OVERWRITE) < 0) {
      if (fs) zip_source_free(fs);
      zok = 0;
    }
  }
  if (!zok || zip_close(za) < 0) {
    if (zok) zip_discard(za);
    else zip_discard(za);
    zip_source_free(src);
    zip_error_fini(&ze);
    goto nomem;
  }
  zip_stat_t st;
  char *bytes = NULL;
  if (zip_source_open(src) == 0) {
    if (zip_source_stat(src, &st) == 0 && (st.valid & ZIP_STAT_SIZE) &&
        (bytes = malloc(st.size ? (size_t)st.size : 1)) != NULL &&
        zip_source_read(src, bytes, st.size) == (zip_int64_t)st.size)
      rc = img_write_bytes(path, bytes, (size_t)st.size, err, errlen);
    else rc = -2;
    zip_source_close(src);
  } else rc = -2;
  free(bytes);
  zip_source_free(src);
  zip_error_fini(&ze);
  if (rc == -2) goto nomem;
  goto out;
nomem:
  snprintf(err, errlen, "cannot write %s: out of memory (or the zip "
           "library failed)", path);
  rc = -1;
out:
  free(x.p);
  free(pal);
  free(tc);
  hfree(&idx);
  return rc;
}

long mesh_float_joined(const Mesh *m) {
  hmap at = {0};
  long joined = 0;
  for (size_t v = 0; v < m->nv; v++) {
    float f[3];
    for (int a = 0; a < 3; a++) f[a] = (float)m->v[3 * v + (size_t)a];
    uint64_t k = 1469598103934665603ull;
    unsigned char b[sizeof f];
    memcpy(b, f, sizeof f);
    for (size_t i = 0; i < sizeof b; i++) k = (k ^ b[i]) * 1099511628211ull;
    int w = hget(&at, k >> 1);
    if (w >= 0) {
      int same = 1;
      for (int a = 0; a < 3; a++) same &= (float)m->v[3 * (size_t)w + (size_t)a] == f[a];
      joined += same;
      continue;
    }
    if (hput(&at, k >> 1, (int)v) < 0) {
      hfree(&at);
      return -1;
    }
  }
  hfree(&at);
  return joined;
}

int mesh_write(const Mesh *m, const char *path, char *err, size_t errlen) {
  buf b = {0};
  if (!strcmp(ext_of(path), "stl")) {
    /* its size is known: no doubling of a large buffer */
    b.cap = 84 + 50 * m->nt;
    if (!(b.p = malloc(b.cap))) b.bad = 1;
    char head[80] = "binary STL written by qcs";
    put(&b, head, 80);
    unsigned char q[4];
    for (int i = 0; i < 4; i++) q[i] = (unsigned char)(m->nt >> (8 * i));
    put(&b, q, 4);
    for (size_t i = 0; i < m->nt && !b.bad; i++) {
      /* 50 bytes a triangle, straight into the buffer sized above */
      double n[3], f[12];
      tri_normal(m, i, n);
      double l = sqrt(vec3_dot(n, n));
      for (int k = 0; k < 3; k++) f[k] = l > 0 ? n[k] / l : 0;
      for (int k = 0; k < 3; k++)
        for (int j = 0; j < 3; j++) f[3 + 3 * k + j] = m->v[3 * (size_t)m->t[3 * i + (size_t)k] + (size_t)j];
      unsigned char *o = (unsigned char *)b.p + b.n;
      for (int k = 0; k < 12; k++) {
        float x = (float)f[k];
        uint32_t u;
        memcpy(&u, &x, 4);
        for (int r = 0; r < 4; r++) o[4 * k + r] = (unsigned char)(u >> (8 * r));
      }
      o[48] = o[49] = 0;
      b.n += 50;
    }
  } else if (!strcmp(ext_of(path), "obj")) {
    double *vn = calloc(3 * (m->nv ? m->nv : 1), sizeof *vn);
    if (!vn) b.bad = 1;
    for (size_t i = 0; vn && i < m->nt; i++) {
      double n[3];
      tri_normal(m, i, n); /* area-weighted */
      for (int k = 0; k < 3; k++)
        for (int j = 0; j < 3; j++) vn[3 * (size_t)m->t[3 * i + (size_t)k] + (size_t)j] += n[j];
    }
    char line[160];
    int len = snprintf(line, sizeof line, "# written by qcs: %zu vertices, "
                       "%zu triangles\n", m->nv, m->nt);
    put(&b, line, (size_t)len);
    for (size_t i = 0; vn && i < m->nv; i++) {
      len = snprintf(line, sizeof line, "v %.17g %.17g %.17g\n", m->v[3 * i],
                     m->v[3 * i + 1], m->v[3 * i + 2]);
      put(&b, line, (size_t)len);
    }
    for (size_t i = 0; vn && i < m->nv; i++) {
      double *n = vn + 3 * i, l = sqrt(vec3_dot(n, n));
      if (!(l > 0)) l = 1;
      len = snprintf(line, sizeof line, "vn %.9g %.9g %.9g\n", n[0] / l,
                     n[1] / l, n[2] / l);
      put(&b, line, (size_t)len);
    }
    for (size_t i = 0; vn && i < m->nt; i++) {
      const int *t = m->t + 3 * i;
      len = snprintf(line, sizeof line, "f %d//%d %d//%d %d//%d\n", t[0] + 1,
                     t[0] + 1, t[1] + 1, t[1] + 1, t[2] + 1, t[2] + 1);
      put(&b, line, (size_t)len);
    }
    free(vn);
  } else if (!strcmp(ext_of(path), "ply")) {
    write_ply(m, &b);
  } else if (!strcmp(ext_of(path), "3mf")) {
    return write_3mf(m, path, err, errlen);
  } else {
    snprintf(err, errlen, "cannot write %s: a mesh is written as .stl, "
             ".obj, .ply or .3mf", path);
    return -1;
  }
  if (b.bad) {
    free(b.p);
    snprintf(err, errlen, "cannot write %s: out of memory", path);
    return -1;
  }
  int rc = img_write_bytes(path, b.p, b.n, err, errlen);
  free(b.p);
  return rc;
}

/* mesh_run, again while the proof that the surface is within the
   tolerance of the mesh finds cells it cannot prove, those cells split
   (cover_check; at most COVER_ROUNDS times). */
static int mesh_rounds(const Scene *s, int node, const MeshSettings *ms,
                       Mesh **out, MeshReport *rep, int *bad_node, char *err,
                       size_t errlen, int sharp, hmap *force, hmap *plainc,
                       const size_t mem0[2]) {
  double t = 0;
  int rc, resharp = 0;
  Mesh *prev = NULL;
  MeshReport prep;
  MeshCheck pck = {0};
  for (;;) {
    rep->cover_last = rep->cover_rounds >= COVER_ROUNDS;
    rc = mesh_run(s, node, ms, out, rep, bad_node, err, errlen, sharp, force,
                  plainc, mem0);
    t += rep->seconds;
    /* a crack or a self-intersection in a later round: that round again
       with the sharp cells about it meshed by their tetrahedra (the
       first round's go back to mesh_scene) */
    if (rc == MESH_RESHARP && prev && ++resharp < RESHARP_TRIES) continue;
    /* over max-memory in a later round: the limit is passed, so the mesh
       is refused as in the first (a later round's other limits keep the
       mesh before it, below) */
    if (rc == MESH_ELIMIT && rep->memout) {
      mesh_free(prev);
      return rc;
    }
    if (prev) {
      /* a round is kept when it proved more of the surface and left the
         mesh's components and Euler characteristic as they were:
         splitting some cells of a gap narrowing to nothing (under the
         edge of a box resting flush on another) and not others opens it
         in places and closes it between, a bubble or a tunnel (figure12's
         obj5 at 0.01 had 2 components that way). A round that proves
         every part of the surface within the tolerance is kept even when
         it changes them (an island smaller than the cells found, a thin
         part or gap opened: MeshReport.cover_topo), unless its cells were
         split as a groove (cover_wide 2: obj5 at 0.005, split round after
         round, ended proven with genus 9). A round that is
         neither but has few cells left not proven (WIDE_MAX; seed 799 at
         0.03: 11 cells, then 16, then none) leads to the next, split
         again there, with the mesh kept before it as the fallback; many
         (figure12's obj5 at 0.003: 2248, then 4735) end the rounds, which
         would cost 1.6 times the time for nothing. Else, or if the round
         failed (a limit), the mesh kept before it stays */
      MeshCheck ck = {0};
      int ok = rc == MESH_OK || rc == MESH_RECOVER;
      if (ok && mesh_check(*out, &ck) == -2) {
        mesh_free(*out);
        *out = NULL;
        mesh_free(prev);
        return MESH_ENOMEM;
      }
      int more = ok && rep->cover_unproven < prep.cover_unproven;
      int same = ck.components == pck.components && ck.euler == pck.euler;
      if (more && !same && rep->cover_unproven == 0 && rep->cover_wide != 2) {
        rep->cover_topo = 1;
        rep->first_components = pck.components;
        rep->first_euler = pck.euler;
      } else if ((!more || !same) && rc == MESH_RECOVER &&
                 rep->cover_unproven <= WIDE_MAX) {
        /* on to the next round; the kept mesh stays the fallback */
        mesh_free(*out);
        *out = NULL;
        rep->cover_rounds++;
        continue;
      } else if (!more || !same) {
        mesh_free(*out);
        *out = prev;
        int rounds = rep->cover_rounds;
        long boxes = rep->cover_boxes, split = rep->cover_split,
             columns = rep->cover_columns;
        double cs = rep->cover_seconds;
        *rep = prep;
        rep->cover_rounds = rounds;
        rep->cover_boxes = boxes;
        rep->cover_columns = columns;
        rep->cover_seconds = cs;
        rep->cover_split = split;
        rep->cover_kept = 1;
        rc = MESH_OK;
        break;
      }
      mesh_free(prev);
      prev = NULL;
    }
    if (rc != MESH_RECOVER) break;
    prev = *out;
    *out = NULL;
    prep = *rep;
    if (mesh_check(prev, &pck) == -2) {
      mesh_free(prev);
      return MESH_ENOMEM;
    }
    rep->cover_rounds++;
  }
  rep->seconds = t;
  return rc;
}

static int snap_find(int *p, int x) {
  while (p[x] != x) x = p[x] = p[p[x]];
  return x;
}

/* Plane y, turned by sg (1 or -1), within SNAP of plane x. */
static int snap_near(const ScNode *x, const ScNode *y, double sg, double r) {
  if (!(fabs(x->d - sg * y->d) <= SNAP * r)) return 0;
  for (int q = 0; q < 3; q++)
    if (!(fabs(x->n[q] - sg * y->n[q]) <= SNAP)) return 0;
  return 1;
}

/* Whether halfspaces x and y, facing apart (n_x . n_y < 0), meet in the
   tree at an intersection (a difference is one: a and not b) with both
   entering alike, or at a union with one of them complemented: between
   two such planes lies a part (or a gap) of their own, a plate or a slot,
   which joining the planes would delete, however thin. Two facing apart
   that meet at a union with both alike (or at an intersection, one
   complemented) are two operands glued face to face: joined, the face
   between them goes. pol: each node's complement parity from the
   root (a difference's right side), up: each node's parent. */
static int snap_thin(const Scene *s, int f, const int *up,
                     const unsigned char *pol, int x, int y) {
  int a = x, b = y;
  /* the lowest common ancestor: children have lower indices */
  while (a != b) {
    if (a < b) a = up[a - f];
    else b = up[b - f];
    if (a < 0 || b < 0) return 1;
  }
  ScKind k = s->nodes[a].kind;
  int alike = pol[x - f] == pol[y - f];
  return (k == SC_UNION) != alike;
}

/* The halfspaces of node's subtree that are one plane but for rounding
   made one (each takes the coefficients of its class's first node, negated
   when facing the other way), in a copy of the scene's nodes: *out shares
   everything else with s. A plane joins a class only within SNAP of the
   class's first (so no chain of near planes reaches further), never when
   it and a member would bound a part between them (snap_thin: a plate or
   a slot 1e-14 thick stays, thinner than the finest cell or not), and a
   face of the Bounds box (lo, hi; NULL without) is never moved: the clip
   box keeps it. 1 when a copy was made (free out->nodes), 0 when there
   was nothing to join, -1 out of memory. *moved: the most a plane moved
   within the box of half-side r about the origin (|Delta n|_1 r + |Delta
   d|), for the certified bound; *count: the planes moved. */
static int snap_planes(const Scene *s, int node, double r, const double *lo,
                       const double *hi, Scene *out, double *moved,
                       long *count) {
  int f = s->nodes[node].first, nh = 0, rc = 0, nsub = node - f + 1;
  *moved = 0;
  *count = 0;
  for (int x = f; x <= node; x++) nh += s->nodes[x].kind == SC_HALFSPACE;
  if (nh < 2 || !(r > 0) || !isfinite(r)) return 0;
  SnapEnt *e = malloc(2 * (size_t)nh * sizeof *e);
  int *par = malloc((size_t)nsub * sizeof *par), *up = malloc((size_t)nsub * sizeof *up),
      *nxt = malloc((size_t)nsub * sizeof *nxt); /* each class's members, a ring */
  unsigned char *pol = malloc((size_t)nsub), *fixed = calloc((size_t)nsub, 1);
  if (!e || !par || !up || !pol || !fixed || !nxt) {
    rc = -1;
    goto done;
  }
  for (int x = 0; x < nsub; x++) par[x] = nxt[x] = x, up[x] = -1;
  pol[node - f] = 0;
  for (int x = node; x >= f; x--) { /* parents before children */
    const ScNode *nd = &s->nodes[x];
    if (nd->kind != SC_UNION && nd->kind != SC_INTER && nd->kind != SC_DIFF) continue;
    up[nd->a - f] = up[nd->b - f] = x;
    pol[nd->a - f] = pol[x - f];
    pol[nd->b - f] = (unsigned char)(pol[x - f] ^ (nd->kind == SC_DIFF));
  }
  /* each plane both ways, ordered by a key that two planes within SNAP
     of each other have within (1 + c1 + c2 + c3) SNAP of each other; the
     window is twice that, for the keys' own rounding */
  const double c1 = 1.4142135623730951, c2 = 1.7320508075688772, c3 = 0.5;
  const double kw = 2 * (1 + c1 + c2 + c3) * SNAP;
  size_t ne = 0;
  for (int x = f; x <= node; x++) {
    const ScNode *nd = &s->nodes[x];
    if (nd->kind != SC_HALFSPACE) continue;
    for (int q = 0; q < 3 && lo; q++) /* a Bounds face: n = -e_q, d = -lo, or e_q, hi */
      if (nd->n[q] == -1 && nd->d == -lo[q]) fixed[x - f] = 1;
      else if (nd->n[q] == 1 && nd->d == hi[q]) fixed[x - f] = 1;
    for (int sg = -1; sg <= 1; sg += 2)
      e[ne++] = (SnapEnt){sg * (nd->n[0] + c1 * nd->n[1] + c2 * nd->n[2] +
                                c3 * nd->d / r), x, sg};
  }
  qsort(e, ne, sizeof *e, snap_cmp);
  /* copies of one plane (a grid of boxes) joined in one pass, so that the
     windows below hold distinct planes */
  size_t nk = 0;
  for (size_t i = 0; i < ne; i++) {
    const ScNode *b = &s->nodes[e[i].x];
    if (nk) {
      const ScNode *a = &s->nodes[e[nk - 1].x];
      double sa = e[nk - 1].sg, sb = e[i].sg;
      if (a->d * sa == b->d * sb && a->n[0] * sa == b->n[0] * sb &&
          a->n[1] * sa == b->n[1] * sb && a->n[2] * sa == b->n[2] * sb &&
          sa == sb) {
        int ra = snap_find(par, e[nk - 1].x - f), rb = snap_find(par, e[i].x - f);
        if (ra != rb) {
          par[ra > rb ? ra : rb] = ra < rb ? ra : rb;
          int t = nxt[ra];
          nxt[ra] = nxt[rb];
          nxt[rb] = t;
        }
        continue;
      }
    }
    e[nk++] = e[i];
  }
  int joined = 0;
  for (size_t i = 0; i < nk; i++)
    for (size_t j = i + 1; j < nk && e[j].key - e[i].key <= kw; j++) {
      int x = e[i].x, y = e[j].x;
      if (x == y || fixed[x - f] || fixed[y - f]) continue;
      const ScNode *a = &s->nodes[x], *b = &s->nodes[y];
      double sg = e[i].sg * e[j].sg;
      if (!snap_near(a, b, sg, r)) continue;
      int ra = snap_find(par, x - f), rb = snap_find(par, y - f);
      if (ra == rb) continue;
      /* the merged class within SNAP of its first, and no two of its
         members bounding a part between them */
      const ScNode *pa = &s->nodes[ra + f], *pb = &s->nodes[rb + f];
      if (!snap_near(pa, pb, vec3_dot(pa->n, pb->n) < 0 ? -1 : 1, r)) continue;
      int ok = 1, u = ra;
      do { /* exact complements are one surface already: only the others */
        int w = rb;
        const ScNode *nu = &s->nodes[u + f];
        do {
          const ScNode *nw = &s->nodes[w + f];
          if (vec3_dot(nu->n, nw->n) < 0 && !same_surface(s, u + f, w + f))
            ok = !snap_thin(s, f, up, pol, u + f, w + f);
          w = nxt[w];
        } while (w != rb && ok);
        u = nxt[u];
      } while (u != ra && ok);
      if (!ok) continue;
      par[ra > rb ? ra : rb] = ra < rb ? ra : rb;
      int t = nxt[ra]; /* the two member rings spliced */
      nxt[ra] = nxt[rb];
      nxt[rb] = t;
      joined = 1;
    }
  /* only planes whose coefficients change need the copy */
  int change = 0;
  for (int x = f; x <= node && joined && !change; x++) {
    int rt = snap_find(par, x - f) + f;
    if (rt == x) continue;
    const ScNode *a = &s->nodes[x], *b = &s->nodes[rt];
    double sg = vec3_dot(a->n, b->n) < 0 ? -1 : 1;
    for (int q = 0; q < 3; q++) change |= a->n[q] != sg * b->n[q];
    change |= a->d != sg * b->d;
  }
  if (change) {
    ScNode *nodes = malloc((size_t)s->n * sizeof *nodes);
    if (!nodes) {
      rc = -1;
      goto done;
    }
    memcpy(nodes, s->nodes, (size_t)s->n * sizeof *nodes);
    for (int x = f; x <= node; x++) {
      int rt = snap_find(par, x - f) + f;
      if (rt == x) continue;
      ScNode *a = &nodes[x];
      const ScNode *b = &s->nodes[rt];
      double sg = vec3_dot(a->n, b->n) < 0 ? -1 : 1, mv = 0;
      for (int q = 0; q < 3; q++) {
        double nq = sg * b->n[q];
        mv += fabs(nq - a->n[q]) * r;
        a->n[q] = nq;
      }
      mv += fabs(sg * b->d - a->d);
      a->d = sg * b->d;
      ray_normal_grad(a->n, 0, a->un[0]);
      ray_normal_grad(a->n, 1, a->un[1]);
      if (mv > *moved) *moved = mv;
      if (mv > 0) (*count)++;
    }
    *out = *s;
    out->nodes = nodes;
    rc = 1;
  }
done:
  free(e);
  free(par);
  free(up);
  free(nxt);
  free(pol);
  free(fixed);
  return rc;
}

int mesh_scene(const Scene *s, int node, const MeshSettings *ms, Mesh **out,
               MeshReport *rep, int *bad_node, char *err, size_t errlen) {
  hmap force = {0}, plainc = {0};
  memset(rep, 0, sizeof *rep);
  /* planes that are one plane but for rounding made one (snap_planes),
     the move in the certified bound */
  Scene snapped;
  double blo[3], bhi[3], br = 0, snap_moved = 0;
  long snap_count = 0;
  int bounded = render_node_box(s, node, blo, bhi);
  if (ms->has_bounds)
    for (int i = 0; i < 3; i++) {
      blo[i] = bounded ? fmax(blo[i], ms->lo[i]) : ms->lo[i];
      bhi[i] = bounded ? fmin(bhi[i], ms->hi[i]) : ms->hi[i];
    }
  if (bounded || ms->has_bounds)
    for (int i = 0; i < 3; i++) br = fmax(br, fmax(fabs(blo[i]), fabs(bhi[i])));
  int snap = snap_planes(s, node, br, ms->has_bounds ? ms->lo : NULL,
                         ms->has_bounds ? ms->hi : NULL, &snapped, &snap_moved,
                         &snap_count);
  if (snap < 0) {
    snprintf(err, errlen, "out of memory while meshing");
    return MESH_ENOMEM;
  }
  if (snap) s = &snapped;
  /* the resident memory now: max_memory bounds its growth */
  size_t mem0[2] = {ms->max_memory ? resident() : 0,
                    ms->max_memory ? peak_resident() : 0};
  /* sharp cells about a crack or a self-intersection meshed by their
     tetrahedra and the rest kept (sharp_apart), a few times; then every
     sharp cell given up */
  double t0 = 0;   /* the tries that failed */
  int rc, tries = 0, near = 1;
  for (;;) {
    rc = mesh_rounds(s, node, ms, out, rep, bad_node, err, errlen, near, &force,
                     &plainc, mem0);
    if (rc != MESH_RESHARP) break;
    t0 += rep->seconds;
    if (near == 1) {
      /* once, before any sharp cell is given up: the meeting points of
         near parallel planes placed exactly (ex_split) and vertices
         within the weld's distance joined though no edge joins them
         (weld): where four planes pass all but through one line (two
         prisms corner to corner, each with its two faces there), the
         perturbation's vertices 1e-16 apart, not on one edge, crossed
         (a 24-sided prism beside an 8-sided one gave up 4 sharp cells,
         20,094 triangles; a box bored by a prism of its half width, 5
         million in two minutes) */
      near = 2;
      hfree(&plainc);
      memset(&plainc, 0, sizeof plainc);
      memset(rep, 0, sizeof *rep);
      continue;
    }
    if (++tries == RESHARP_TRIES) { /* the last failure's kind */
      rc = rep->resharp == 2 ? MESH_ESELF : MESH_EINTERNAL;
      rep->seconds = 0;
      break;
    }
    memset(rep, 0, sizeof *rep);
  }
  rep->seconds += t0;
  if (rc == MESH_EINTERNAL || (rc == MESH_ESELF && (rep->sharp || tries))) {
    /* a degenerate case decided differently by two sharp cells, or a fan
       of a crease path reaching past its tetrahedron: the marching cells
       alone are closed by construction, each triangle in its own
       tetrahedron */
    double t = rep->seconds; /* the failed tries' already in it */
    int why = rc == MESH_ESELF ? 2 : 1;
    rc = mesh_rounds(s, node, ms, out, rep, bad_node, err, errlen, 0, &force,
                     &plainc, mem0);
    rep->seconds += t;
    rep->sharp_off = why;
  }
  hfree(&force);
  hfree(&plainc);
  if (snap) {
    free(snapped.nodes);
    if (rc == MESH_OK) {
      rep->certified += snap_moved;
      rep->snapped = snap_count;
      rep->snap_moved = snap_moved;
    }
  }
  if (rc == MESH_ENOMEM) snprintf(err, errlen, "out of memory while meshing");
  return rc;
}
