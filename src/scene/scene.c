/* scene.c: the compiled scene's storage and point classification. See
 * scene.h. */
#include "scene/scene.h"

#include "scene/ray.h"

#include <stdlib.h>
#include <string.h>

Scene *scene_new(void) {
  Scene *s = calloc(1, sizeof *s);
  if (s) s->root = -1;
  return s;
}

int scene_add(Scene *s, const ScNode *node) {
  if (s->n == s->cap) {
    int cap = s->cap ? s->cap * 2 : 16;
    ScNode *nodes = realloc(s->nodes, sizeof(ScNode) * (size_t)cap);
    if (!nodes) return -1;
    s->nodes = nodes;
    s->cap = cap;
  }
  int i = s->n++;
  ScNode *n = &s->nodes[i];
  *n = *node;
  n->first = i;
  if (n->a >= 0 && s->nodes[n->a].first < n->first) n->first = s->nodes[n->a].first;
  if (n->b >= 0 && s->nodes[n->b].first < n->first) n->first = s->nodes[n->b].first;
  switch (n->kind) {
  case SC_HALFSPACE:
    s->flags |= SCENE_HAS_HALFSPACE;
    ray_normal_grad(n->n, 0, n->un[0]);   /* once, not per hit */
    ray_normal_grad(n->n, 1, n->un[1]);
    break;
  case SC_ROUNDED: s->flags |= SCENE_HAS_ROUNDED; break;
  case SC_SOFT:
    s->flags |= SCENE_HAS_SOFT;
    if (n->soft && soft_nkeys(n->soft) > s->max_keys) s->max_keys = soft_nkeys(n->soft);
    break;
  default: break;
  }
  s->root = i;
  return i;
}

int scene_add_op(Scene *s, ScKind k, int a, int b, int tag) {
  ScNode n;
  memset(&n, 0, sizeof n);
  n.kind = k;
  n.a = a;
  n.b = b;
  n.tag = tag;
  return scene_add(s, &n);
}

void scene_free(Scene *s) {
  if (!s) return;
  for (int i = 0; i < s->n; i++) {
    if (s->nodes[i].tape) dt_tape_free(s->nodes[i].tape);
    if (s->nodes[i].outer) csg_tape_free(s->nodes[i].outer);
    if (s->nodes[i].inner) csg_tape_free(s->nodes[i].inner);
    if (s->nodes[i].soft) soft_free(s->nodes[i].soft);
  }
  free(s->nodes);
  free(s);
}

static int leaf_inside(const ScNode *n, const double p[3]) {
  switch (n->kind) {
  case SC_HALFSPACE:
    return n->n[0] * p[0] + n->n[1] * p[1] + n->n[2] * p[2] < n->d;
  case SC_ROUNDED:
    return dt_density(n->tape, p) > 0.5;
  case SC_SOFT:
    return soft_field(n->soft, p) > soft_magic(n->soft);
  case SC_ALL:
    return 1;
  default:
    return 0;
  }
}

int scene_union_parts(const Scene *s, int node,
                      int (*fn)(void *ctx, int part, const double *colour),
                      void *ctx) {
  typedef struct { int node; const double *colour; } Item;
  Item local[32], *st = local;
  size_t cap = 32, n = 0;
  int r = 0;
  st[n++] = (Item){node, NULL};
  while (n && !r) {
    Item it = st[--n];
    const ScNode *nd = &s->nodes[it.node];
    const double *colour = nd->has_colour ? nd->colour : it.colour;
    if (nd->kind == SC_UNION) {
      if (n + 2 > cap) {
        Item *g = st == local ? malloc(2 * cap * sizeof *g)
                              : realloc(st, 2 * cap * sizeof *g);
        if (!g) {
          r = -1;
          break;
        }
        if (st == local) memcpy(g, local, sizeof local);
        st = g;
        cap *= 2;
      }
      st[n++] = (Item){nd->b, colour};
      st[n++] = (Item){nd->a, colour};
    } else if (nd->kind != SC_EMPTY) {
      r = fn(ctx, it.node, colour);
    }
  }
  if (st != local) free(st);
  return r;
}

int scene_inside(const Scene *s, int node, const double p[3]) {
  const ScNode *nd = &s->nodes[node];
  if (nd->first == node) return leaf_inside(nd, p);
  /* The subtree lies in first .. node, children before parents: one pass
     fills in every node's answer. */
  unsigned char local[256], *in = local;
  size_t count = (size_t)(node - nd->first + 1);
  if (count > sizeof local && !(in = malloc(count))) return -1;
  const int base = nd->first;
  unsigned char r = 0; /* the last node's answer is node's */
  for (int i = base; i <= node; i++) {
    const ScNode *n = &s->nodes[i];
    switch (n->kind) {
    case SC_UNION: r = in[n->a - base] || in[n->b - base]; break;
    case SC_INTER: r = in[n->a - base] && in[n->b - base]; break;
    case SC_DIFF: r = in[n->a - base] && !in[n->b - base]; break;
    default: r = (unsigned char)leaf_inside(n, p); break;
    }
    in[i - base] = r;
  }
  if (in != local) free(in);
  return r;
}
