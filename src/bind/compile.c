/* compile.c: compiling constructor trees into scenes. See compile.h. */
#include "bind/compile.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/bounds.h"
#include "lang/eval.h"
#include "lang/print.h"

/* The constructors a scene is made of, recognised by name. */
typedef enum {
  K_NONE, K_UNION, K_INTER, K_SETDIFF, K_ROUNDED, K_HALFSPACE, K_SUM,
  K_PRODUCT, K_DIFFERENCE, K_DHALFSPACE, K_RHALFSPACE, K_DUNION, K_SOFT,
  K_KEY, K_QKEY, K_COLOUR, K_EMPTY, K_ALL
} ConKind;

static const struct {
  const char *name;
  ConKind kind;
} con_names[] = {
    {"Union", K_UNION},           {"Intersection", K_INTER},
    {"SetDifference", K_SETDIFF}, {"Rounded", K_ROUNDED},
    {"Halfspace", K_HALFSPACE},   {"Sum", K_SUM},
    {"Product", K_PRODUCT},       {"Difference", K_DIFFERENCE},
    {"DensityHalfspace", K_DHALFSPACE}, {"RoundedHalfspace", K_RHALFSPACE},
    {"DensityUnion", K_DUNION},   {"SoftObject", K_SOFT},
    {"Key", K_KEY},               {"QuadricKey", K_QKEY},
    {"Colour", K_COLOUR},         {"Empty", K_EMPTY},
    {"Everything", K_ALL},
};

static ConKind con_kind(Value *v) {
  if (v->kind != V_CON) return K_NONE;
  const char *name = v->u.con.con->name;
  for (size_t i = 0; i < sizeof con_names / sizeof *con_names; i++)
    if (!strcmp(name, con_names[i].name)) return con_names[i].kind;
  return K_NONE;
}

static int is_density_kind(ConKind k) {
  return k == K_SUM || k == K_PRODUCT || k == K_DIFFERENCE ||
         k == K_DHALFSPACE || k == K_RHALFSPACE || k == K_DUNION;
}

typedef struct Compile {
  Interp *I;
  Scene *s;
  dt_builder *db;     /* while compiling a density tree */
  Pos pos;            /* position of the enclosing constructor */
} Compile;

static Pos vpos(Compile *C, Value *v) {
  return v->kind == V_CON && v->u.con.pos ? *v->u.con.pos : C->pos;
}

static _Noreturn void not_a(Compile *C, Value *v, const char *want) {
  char buf[200];
  val_brief(v, buf, sizeof buf);
  qcs_error(vpos(C, v), "%s is needed here, not %s: %s", want,
            val_describe(v), buf);
}

/* A plane (n, d): n a 3-tuple, not zero, everything finite. */
static void get_plane(Compile *C, Value *v, Pos pos, double n[3], double *d) {
  v = force(C->I, v);
  if (v->kind != V_TUPLE || v->u.tup.n != 2) {
    char buf[160];
    val_brief(v, buf, sizeof buf);
    qcs_error(pos, "a plane is (normal, offset), like ((0, 1, 0), 0); "
              "not %s", buf);
  }
  force_vec3(C->I, v->u.tup.items[0], pos, "the normal of a plane", n);
  *d = force_num(C->I, v->u.tup.items[1], pos, "the offset of a plane");
  if (!isfinite(n[0]) || !isfinite(n[1]) || !isfinite(n[2]) || !isfinite(*d))
    qcs_error(pos, "a plane needs finite numbers, not ((%g, %g, %g), %g)",
              n[0], n[1], n[2], *d);
  if (n[0] == 0 && n[1] == 0 && n[2] == 0)
    qcs_error(pos, "the normal of a plane cannot be zero");
  double len = hypot(hypot(n[0], n[1]), n[2]);
  if (!isfinite(len)) { /* rescale before normalising huge normals */
    double m = fmax(fabs(n[0]), fmax(fabs(n[1]), fabs(n[2])));
    for (int i = 0; i < 3; i++) n[i] /= m;
    *d /= m;
  }
}

static double get_radius(Compile *C, Value *v, Pos pos) {
  double r = force_num(C->I, v, pos, "a radius");
  if (!isfinite(r) || r < 0)
    qcs_error(pos, "a radius must be finite and >= 0, not %g", r);
  return r;
}

/* ---- density trees ---- */

static void dt_check(Compile *C, int err, Pos pos) {
  if (err) qcs_error(pos, "%s", dt_strerror(err));
}

/* A constructor of a tree being compiled, forced, with its kind, its
   position and its arguments (NULL unless it is a constructor). */
typedef struct Node {
  Value *v;
  ConKind k;
  Pos pos;
  Value **a;
} Node;

static Node node_of(Compile *C, Value *v) {
  eval_check(C->I, C->pos);
  Node n;
  n.v = force(C->I, v);
  n.k = con_kind(n.v);
  n.pos = vpos(C, n.v);
  n.a = n.v->kind == V_CON ? n.v->u.con.args : NULL;
  return n;
}

/* Emits the density tree v in postfix order into C->db. */
static void emit_density(Compile *C, Value *v, double r) {
  Node N = node_of(C, v);
  ConKind k = N.k;
  Pos pos = N.pos;
  Value **a = N.a;
  v = N.v;
  dt_op op;
  switch (k) {
  case K_SUM: op = DT_SUM; break;
  case K_PRODUCT: case K_INTER: op = DT_PRODUCT; break;
  case K_DIFFERENCE: op = DT_DIFF; break;
  case K_DUNION: case K_UNION: op = DT_UNION; break;
  case K_DHALFSPACE: case K_HALFSPACE: {
    double n[3], d;
    get_plane(C, a[0], pos, n, &d);
    dt_check(C, dt_builder_leaf(C->db, n, d, r), pos);
    return;
  }
  case K_RHALFSPACE: {
    double rr = get_radius(C, a[0], pos);
    double n[3], d;
    get_plane(C, a[1], pos, n, &d);
    dt_check(C, dt_builder_leaf(C->db, n, d, rr), pos);
    return;
  }
  case K_SETDIFF:
    qcs_error(pos, "SetDifference is a scene operation; inside a density "
              "tree use Difference (density subtraction)");
  case K_ROUNDED:
    qcs_error(pos, "Rounded inside a density tree: the radius is given once, "
              "by the outer Rounded (use RoundedHalfspace r plane for a "
              "radius per plane)");
  case K_SOFT:
    qcs_error(pos, "a soft object cannot be part of a density tree; combine "
              "it with Union, Intersection or SetDifference");
  case K_COLOUR:
    qcs_error(pos, "Colour belongs outside a density tree: Colour c "
              "(Rounded r tree)");
  default:
    not_a(C, v, "a density tree (Sum, Product, Difference, DensityHalfspace, "
          "...)");
  }
  emit_density(C, a[0], r);
  emit_density(C, a[1], r);
  dt_check(C, dt_builder_op(C->db, op), pos);
}

static void free_builder(void *b) { dt_builder_free(b); }

static dt_tape *density_tape(Compile *C, Value *tree, double r, Pos pos) {
  C->db = dt_builder_new();
  if (!C->db) qcs_error(pos, "out of memory");
  ErrCleanup cu; /* the builder must not leak if an error unwinds */
  err_defer(&cu, free_builder, C->db);
  emit_density(C, tree, r);
  err_release(&cu);
  int err = 0;
  dt_tape *t = dt_builder_finish(C->db, &err);
  C->db = NULL;
  if (!t) qcs_error(pos, "%s", dt_strerror(err));
  return t;
}

dt_tape *compile_density_tape(Interp *I, Value *tree, double r, Pos pos) {
  Compile C = {I, NULL, NULL, pos};
  if (!isfinite(r) || r < 0)
    qcs_error(pos, "a radius must be finite and >= 0, not %g", r);
  return density_tape(&C, tree, r, pos);
}

/* ---- scene objects ---- */

static int tag_of(Pos pos) {
  int t = pos_tag(pos);
  return t < 0 ? 0 : t;
}

/* Add a node (the scene takes what it owns, or frees it here when memory
   runs out, before the error). */
static int add(Compile *C, ScNode *n, Pos pos) {
  n->tag = tag_of(pos);
  int i = scene_add(C->s, n);
  if (i < 0) {
    if (n->tape) dt_tape_free(n->tape);
    if (n->outer) csg_tape_free(n->outer);
    if (n->inner) csg_tape_free(n->inner);
    if (n->soft) soft_free(n->soft);
    qcs_error(pos, "out of memory");
  }
  return i;
}

static ScNode blank(ScKind kind) {
  ScNode n;
  memset(&n, 0, sizeof n);
  n.kind = kind;
  n.a = n.b = -1;
  return n;
}

static int add_node(Compile *C, ScKind kind, Pos pos) {
  ScNode n = blank(kind);
  return add(C, &n, pos);
}

static int compile_obj(Compile *C, Value *v);

static int set_node(Compile *C, ScKind kind, Pos pos, int a, int b) {
  ScNode n = blank(kind);
  n.a = a;
  n.b = b;
  return add(C, &n, pos);
}

/* A set operation of x and y, each compiled by f: y first, then x, in
   every build. (Written as set_node's two arguments, the order was C's
   to choose: gcc compiled y first and clang x, so the nodes' numbers,
   which the meshes' exact sides take as the planes' ranks, differed
   between builds, and so did meshes where parts touch.) */
static int set_of(Compile *C, ScKind kind, Pos pos, Value *x, Value *y,
                  int (*f)(Compile *, Value *)) {
  int b = f(C, y);
  int a = f(C, x);
  return set_node(C, kind, pos, a, b);
}

/* A density tree with no radius: the sharp polyhedron it describes. */
static int compile_sharp(Compile *C, Value *v) {
  Node N = node_of(C, v);
  ConKind k = N.k;
  Pos pos = N.pos;
  Value **a = N.a;
  switch (k) {
  case K_SUM: case K_DUNION: case K_UNION:
    return set_of(C, SC_UNION, pos, a[0], a[1], compile_sharp);
  case K_PRODUCT: case K_INTER:
    return set_of(C, SC_INTER, pos, a[0], a[1], compile_sharp);
  case K_DIFFERENCE: case K_SETDIFF:
    return set_of(C, SC_DIFF, pos, a[0], a[1], compile_sharp);
  case K_DHALFSPACE: case K_HALFSPACE: case K_RHALFSPACE: {
    double n[3], d;
    get_plane(C, a[k == K_RHALFSPACE ? 1 : 0], pos, n, &d);
    ScNode h = blank(SC_HALFSPACE);
    double len = hypot(hypot(n[0], n[1]), n[2]);
    for (int j = 0; j < 3; j++) h.n[j] = n[j] / len;
    h.d = d / len;
    return add(C, &h, pos);
  }
  default:
    return compile_obj(C, N.v);
  }
}

static int all_sharp(const dt_tape *t) { return t->rmax == 0; }

/* Once per (position, kind): the kind is folded into the remembered
   column, so different warnings about one constructor are all given. */
static void warn_once_kind(Interp *I, Pos pos, int kind, const char *msg) {
  Pos key = pos;
  key.col += kind * (1 << 24);
  for (int i = 0; i < I->nwarned; i++)
    if (I->warned[i].src == key.src && I->warned[i].line == key.line &&
        I->warned[i].col == key.col)
      return;
  if (I->nwarned < (int)(sizeof I->warned / sizeof *I->warned))
    I->warned[I->nwarned++] = key;
  qcs_warning(pos, "%s", msg);
}

void compile_warn_once(Interp *I, Pos pos, const char *msg) {
  warn_once_kind(I, pos, 0, msg);
}

/* Coordinates of size S are rounded to about eps S; a feature of size r
   (a filter radius, a key's radius) smaller than 100 eps S is then drawn
   with errors above 1% of its size, whatever the root tolerance. */
#define RESOLVE_FRAC 1e-2

static void warn_resolution(Compile *C, Pos pos, const char *what, double r,
                            double S) {
  if (!(r > 0) || !(DBL_EPSILON * S > RESOLVE_FRAC * r)) return;
  char msg[400];
  snprintf(msg, sizeof msg, "%s %.3g is too small for coordinates of %.3g: "
           "doubles resolve them only to %.2g (%.0f%% of the radius), so the "
           "shape is drawn approximately; move the object nearer the origin "
           "or use a larger radius", what, r, S, DBL_EPSILON * S,
           100 * DBL_EPSILON * S / r);
  warn_once_kind(C->I, pos, 1, msg);
}

static int compile_soft(Compile *C, Value *v, Pos pos) {
  Interp *I = C->I;
  double magic = force_num(I, v->u.con.args[0], pos, "the magic value of a "
                           "SoftObject");
  size_t n = 0;
  /* Each key goes to the builder as it is read, and the list is read as
     it is forced: nothing here holds more than one key. */
  soft_builder *b = soft_builder_new();
  if (!b) qcs_error(pos, "out of memory");
  ErrCleanup cu;
  err_defer(&cu, soft_builder_free, b);
  double wr = 0, ws = 0;  /* the key least resolved at its centre */
  double wmax = 0;
  {
    Value *l = force(I, v->u.con.args[1]);
    Sym *last = NULL;  /* the constructor of the key before, and its kind */
    ConKind lastk = K_NONE;
    soft_key key;
    while (l->kind == V_CONS) {
      eval_check(I, pos);
      Value *k = force(I, l->u.cons.head);
      ConKind kk;
      if (k->kind == V_CON && k->u.con.con == last) {
        kk = lastk;  /* no name comparisons for the next million keys */
      } else {
        kk = con_kind(k);
        if (k->kind == V_CON) last = k->u.con.con, lastk = kk;
      }
      Pos kpos = vpos(C, k);
      memset(&key, 0, sizeof key);
      if (kk == K_KEY) {
        key.kind = SOFT_SPHERE;
        force_vec3(I, k->u.con.args[0], kpos, "the centre of a Key", key.c);
      } else if (kk == K_QKEY) {
        key.kind = SOFT_QUADRIC;
        Value *m = force(I, k->u.con.args[0]);
        if (m->kind != V_TUPLE || m->u.tup.n != 4)
          qcs_error(kpos, "the matrix of a QuadricKey is four 4-tuples");
        for (int r = 0; r < 4; r++) {
          Value *row = force(I, m->u.tup.items[r]);
          if (row->kind != V_TUPLE || row->u.tup.n != 4)
            qcs_error(kpos, "the matrix of a QuadricKey is four 4-tuples");
          for (int c = 0; c < 4; c++)
            key.m[r][c] = force_num(I, row->u.tup.items[c], kpos,
                                    "a QuadricKey matrix entry");
        }
      } else {
        not_a(C, k, "a key (Key centre R weight or QuadricKey m R weight)");
      }
      key.R = force_num(I, k->u.con.args[1], kpos, "the radius of a key");
      key.w = force_num(I, k->u.con.args[2], kpos, "the weight of a key");
      if (!(key.R > 0) || !isfinite(key.R))
        qcs_error(kpos, "a key's radius must be finite and > 0, not %g",
                  key.R);
      if (soft_builder_add(b, &key)) qcs_error(pos, "out of memory");
      wmax = fmax(wmax, fabs(key.w));
      if (key.kind == SOFT_SPHERE) {
        double S = fmax(fabs(key.c[0]), fmax(fabs(key.c[1]), fabs(key.c[2])));
        if (S * wr > ws * key.R || wr == 0) wr = key.R, ws = S;
      }
      n++;
      l = force(I, l->u.cons.tail);
    }
    if (l->kind != V_NIL) not_a(C, l, "a list of keys");
  }
  err_release(&cu);
  soft_obj *obj = NULL;
  size_t bad = 0;
  int err = soft_builder_finish(b, magic, &obj, &bad);
  if (err) {
    if (bad < n)
      qcs_error(pos, "key %zu of this SoftObject: %s", bad + 1,
                soft_strerror(err));
    qcs_error(pos, "%s", soft_strerror(err));
  }
  ScNode sn = blank(SC_SOFT);
  sn.soft = obj;
  int i = add(C, &sn, pos);
  if (wr > 0) warn_resolution(C, pos, "a key radius of", wr, ws);
  /* Near the edge of a key's bound its field is (5/9) w u^2, u = 1 -
     r^2/R^2, and is summed to eps W absolute (W the largest weight), so a
     small magic m is met at u = sqrt(9 m / 5w) known only within
     [sqrt(9 (m - eps W)/5w), sqrt(9 (m + eps W)/5w)]: half that width is
     the error in r/R. */
  double ew = DBL_EPSILON * wmax;
  double placed = wmax > 0 ? 0.5 * (sqrt(1.8 * (magic + ew) / wmax) -
                                    sqrt(1.8 * fmax(0, magic - ew) / wmax)) : 0;
  if (placed > 1e-9) {
    char msg[300];
    snprintf(msg, sizeof msg, "magic %.3g is so small beside key weights up to "
             "%.3g that the surface hugs the keys' bounds and is placed only to "
             "about %.1g of their radius", magic, wmax, placed);
    warn_once_kind(C->I, pos, 2, msg);
  }
  return i;
}


/* ---- do summed parts overlap? ---- */

/* The axis-aligned box of the sharp polyhedron of a density tree:
   conservative (axis-aligned planes bound it, others do not). */
static void tree_box(Compile *C, Value *v, double lo[3], double hi[3]) {
  v = force(C->I, v);
  ConKind k = con_kind(v);
  Value **a = v->kind == V_CON ? v->u.con.args : NULL;
  for (int i = 0; i < 3; i++) lo[i] = -INFINITY, hi[i] = INFINITY;
  double la[3], ha[3], lb[3], hb[3];
  switch (k) {
  case K_PRODUCT: case K_INTER:
    tree_box(C, a[0], la, ha);
    tree_box(C, a[1], lb, hb);
    for (int i = 0; i < 3; i++) lo[i] = fmax(la[i], lb[i]), hi[i] = fmin(ha[i], hb[i]);
    return;
  case K_SUM: case K_DUNION: case K_UNION:
    tree_box(C, a[0], la, ha);
    tree_box(C, a[1], lb, hb);
    for (int i = 0; i < 3; i++) lo[i] = fmin(la[i], lb[i]), hi[i] = fmax(ha[i], hb[i]);
    return;
  case K_DIFFERENCE: case K_SETDIFF:
    tree_box(C, a[0], lo, hi);
    return;
  case K_DHALFSPACE: case K_HALFSPACE: case K_RHALFSPACE: {
    double n[3], d;
    get_plane(C, a[k == K_RHALFSPACE ? 1 : 0], C->pos, n, &d);
    int axis = -1, zeros = 0;
    for (int i = 0; i < 3; i++) {
      if (n[i] == 0) zeros++;
      else axis = i;
    }
    if (zeros != 2) return;
    if (n[axis] > 0) hi[axis] = d / n[axis];
    else lo[axis] = d / n[axis];
    return;
  }
  default:
    return;
  }
}

/* 1 if the two parts of some Sum in the tree may overlap with positive
   volume (so the density may exceed 1 there, as in Figure 15b); parts
   that only touch, like the cube and box3 of Figure 11's obj6, do not. */
static int sum_overlaps(Compile *C, Value *v) {
  v = force(C->I, v);
  ConKind k = con_kind(v);
  if (v->kind != V_CON || v->u.con.n != 2 || k == K_RHALFSPACE) return 0;
  Value **a = v->u.con.args;
  if (sum_overlaps(C, a[0]) || sum_overlaps(C, a[1])) return 1;
  if (k != K_SUM) return 0;
  double la[3], ha[3], lb[3], hb[3];
  tree_box(C, a[0], la, ha);
  tree_box(C, a[1], lb, hb);
  for (int i = 0; i < 3; i++) {
    double lo = fmax(la[i], lb[i]), hi = fmin(ha[i], hb[i]);
    double scale = 1e-12 * (1 + fabs(lo) + fabs(hi));
    if (!(hi - lo > scale)) return 0; /* no common volume */
  }
  return 1;
}

int compile_sum_overlaps(Interp *I, Value *tree, Pos pos) {
  Compile C = {I, NULL, NULL, pos};
  return sum_overlaps(&C, tree);
}

static int compile_obj(Compile *C, Value *v);

/* Rounded r tree (also a density tree used as an object: r = 0, so that
   only its RoundedHalfspace leaves are smoothed). */
static int compile_rounded(Compile *C, Value *tree, double r, Pos pos) {
  dt_tape *t = density_tape(C, tree, r, pos);
  if (all_sharp(t)) { /* Rounded 0 t: exactly the sharp polyhedron */
    dt_tape_free(t);
    return compile_sharp(C, tree);
  }
  ScNode node = blank(SC_ROUNDED), *nd = &node;
  nd->tape = t;
  /* the coordinates of the tree: its planes' offsets (a bounded
     polyhedron at distance D from the origin has a plane with |d| >=
     D / sqrt 3) */
  double wr = 0, ws = 0;
  for (int j = 0; j < t->nleaves; j++) {
    const dt_leaf *lf = &t->leaves[j];
    if (lf->r > 0 && (wr == 0 || fabs(lf->d) * wr > ws * lf->r))
      wr = lf->r, ws = fabs(lf->d);
  }
  for (int j = 0; j < t->nleaves; j++) ws = fmax(ws, fabs(t->leaves[j].d));
  warn_resolution(C, pos, "a radius of", wr, ws);
  int fo = 0, fi = 0;
  nd->outer = bnd_outer_chamfered(t, 0.5, &fo);
  nd->inner = bnd_inner(t, 0.5, &fi);
  nd->bound_flags = fo | fi;
  if (!nd->outer || !nd->inner ||
      csg_tape_share_dirs(nd->inner, nd->outer) != CSG_OK) {
    dt_tape_free(t);
    if (nd->outer) csg_tape_free(nd->outer);
    if (nd->inner) csg_tape_free(nd->inner);
    qcs_error(pos, "out of memory");
  }
  int i = add(C, nd, pos); /* the scene owns the tapes from here */
  if ((C->s->nodes[i].bound_flags & BND_RANGE) && sum_overlaps(C, tree)) {
    C->s->ill_formed = 1;
    compile_warn_once(C->I, pos, "a Sum in this density tree may exceed 1 where its "
              "parts overlap (the paper's Figure 15b): such seams bulge; "
              "the search bounds allow for it, so no crossing is lost");
  }
  return i;
}

static int compile_obj(Compile *C, Value *v) {
  Node N = node_of(C, v);
  ConKind k = N.k;
  Pos pos = N.pos;
  Value **a = N.a;
  switch (k) {
  case K_UNION:
    return set_of(C, SC_UNION, pos, a[0], a[1], compile_obj);
  case K_INTER:
    return set_of(C, SC_INTER, pos, a[0], a[1], compile_obj);
  case K_SETDIFF:
    return set_of(C, SC_DIFF, pos, a[0], a[1], compile_obj);
  case K_HALFSPACE:
    return compile_sharp(C, N.v);
  case K_ROUNDED:
    return compile_rounded(C, a[1], get_radius(C, a[0], pos), pos);
  case K_SOFT:
    return compile_soft(C, N.v, pos);
  case K_EMPTY:
    return add_node(C, SC_EMPTY, pos);
  case K_ALL:
    return add_node(C, SC_ALL, pos);
  case K_COLOUR: {
    double c[3];
    force_vec3(C->I, a[0], pos, "the colour (r, g, b)", c);
    for (int j = 0; j < 3; j++)
      if (!isfinite(c[j]) || c[j] < 0)
        qcs_error(pos, "colour components must be finite and >= 0");
    int i = compile_obj(C, a[1]);
    if (!C->s->nodes[i].has_colour) {
      C->s->nodes[i].has_colour = 1;
      memcpy(C->s->nodes[i].colour, c, sizeof c);
    }
    return i;
  }
  default:
    if (is_density_kind(k)) return compile_rounded(C, N.v, 0, pos);
    not_a(C, N.v, "a scene object (Union, Intersection, SetDifference, "
          "Rounded, Halfspace, SoftObject, or a density tree)");
  }
}

static void free_scene(void *s) { scene_free(s); }

Scene *compile_scene(Interp *I, Value *obj, Pos pos) {
  Scene *s = scene_new();
  if (!s) qcs_error(pos, "out of memory");
  Compile C = {I, s, NULL, pos};
  ErrCleanup cu;
  err_defer(&cu, free_scene, s);
  s->root = compile_obj(&C, obj);
  err_release(&cu);
  return s;
}

Pos compile_node_pos(const Scene *s, int node) {
  if (node < 0 || node >= s->n) return pos_none;
  return tag_pos(s->nodes[node].tag);
}


/* ---- pictures at the prompt ---- */

static int object_kind(ConKind k) {
  return k != K_NONE && k != K_KEY && k != K_QKEY;
}

int compile_is_object(Interp *I, Value *v) {
  v = force(I, v);
  if (v->kind == V_CON) return object_kind(con_kind(v));
  if (v->kind != V_CONS) return 0;
  /* a list of objects: every element (forced up to 1000 of them) */
  int n = 0;
  for (; v->kind == V_CONS && n < 1000; v = force(I, v->u.cons.tail), n++) {
    Value *h = force(I, v->u.cons.head);
    if (h->kind != V_CON || !object_kind(con_kind(h))) return 0;
  }
  return v->kind == V_NIL;
}

Scene *compile_scene_any(Interp *I, Value *obj, Pos pos) {
  obj = force(I, obj);
  if (obj->kind != V_CONS) return compile_scene(I, obj, pos);
  Scene *s = scene_new();
  if (!s) qcs_error(pos, "out of memory");
  Compile C = {I, s, NULL, pos};
  ErrCleanup cu;
  err_defer(&cu, free_scene, s);
  int root = -1;
  for (Value *l = obj; l->kind == V_CONS; l = force(I, l->u.cons.tail)) {
    int i = compile_obj(&C, l->u.cons.head);
    root = root < 0 ? i : set_node(&C, SC_UNION, pos, root, i);
  }
  if (root < 0) root = add_node(&C, SC_EMPTY, pos);
  s->root = root;
  err_release(&cu);
  return s;
}
