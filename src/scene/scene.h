/* scene.h: the compiled scene, the one program every tool reads.
 *
 * What it owns. A scene is a CSG tree of nodes in one array, children
 * before parents: sharp halfspaces (planes normalised), rounded density
 * tapes with their outer and inner bounds (core/density.h, core/bounds.h),
 * soft objects (core/soft.h), and Union / Intersection / Difference over
 * them. Only what the scene contains is built: no density tape without a
 * rounded node, no soft machinery without a soft object.
 *
 * Source tags. A node does not know the language: it carries an integer
 * `tag`, which the layer that built it (bind/compile.h) can turn back into
 * a source position, so a problem found late (a render that left a
 * segment undecided) still points at the user's code. Tag 0 means "no
 * position".
 *
 * Invariants. For every node i, its children a and b are < i, so a loop
 * over 0..n-1 visits children first and no walk needs recursion whose
 * depth follows the tree (scene_inside, the tracer's span program). The
 * root is the last node.
 *
 * Memory and threads. scene_new mallocs; nodes are added with scene_add
 * (which hands ownership of the tapes and soft object to the scene) and
 * the scene is freed, with all it owns, by scene_free. Once built it is
 * never written again and any number of threads may read it at once.
 *
 * Failure. scene_add returns -1 when memory runs out (the caller still
 * owns nothing it passed in: the scene frees them with itself only once
 * added); nothing here prints or exits. */
#ifndef QCS_SCENE_H
#define QCS_SCENE_H

#include <stddef.h>

#include "core/csg.h"
#include "core/density.h"
#include "core/soft.h"

typedef enum {
  SC_HALFSPACE, /* n.x < d */
  SC_ROUNDED,   /* a density tape: inside where density > 0.5 */
  SC_SOFT,      /* a soft object: inside where field > magic */
  SC_UNION,
  SC_INTER,
  SC_DIFF,      /* a - b */
  SC_EMPTY,     /* nothing */
  SC_ALL        /* everything */
} ScKind;

typedef struct ScNode {
  ScKind kind;
  int tag;               /* source tag (0: none), see above */
  int a, b;              /* children, for the set operations (< own index) */
  int first;             /* the lowest index in this node's subtree: the
                            subtree lies in first .. own index */
  double n[3], d;        /* SC_HALFSPACE: unit normal and offset */
  double un[2][3];       /* SC_HALFSPACE: ray_normal's normal for flip 0
                            and flip != 0 (set by scene_add) */
  dt_tape *tape;         /* SC_ROUNDED */
  csg_tape *outer, *inner; /* SC_ROUNDED: bounds of the 0.5 isosurface */
  int bound_flags;       /* BND_RANGE, BND_FALLBACK (core/bounds.h) */
  soft_obj *soft;        /* SC_SOFT */
  int has_colour;
  double colour[3];      /* from a Colour wrapper, linear RGB */
} ScNode;

enum { SCENE_HAS_HALFSPACE = 1, SCENE_HAS_ROUNDED = 2, SCENE_HAS_SOFT = 4 };

typedef struct Scene {
  ScNode *nodes;
  int n, cap;
  int root;
  unsigned flags;        /* SCENE_HAS_... */
  size_t max_keys;       /* largest soft object, for per-thread scratch */
  int ill_formed;        /* some density tree can exceed 1 (Figure 15b) */
} Scene;

/* An empty scene (n = 0), or NULL when memory runs out. */
Scene *scene_new(void);

/* Append a node (a copy of *node, whose a and b must name earlier nodes):
   its index, which is also the scene's root from now on, or -1 when
   memory runs out. The scene takes the node's tape, bounds and soft
   object; scene->flags is updated from its kind. */
int scene_add(Scene *s, const ScNode *node);

/* A node of kind k with children a, b (-1 for none) and a source tag. */
int scene_add_op(Scene *s, ScKind k, int a, int b, int tag);

/* Free the scene and every tape and soft object it owns. NULL is fine. */
void scene_free(Scene *s);

/* The parts of node's top-level union, as the tracer and the mesher's
   colouring see them: the union is flattened (any depth, a before b),
   each other node is a part (SC_EMPTY parts are skipped), and each part
   carries the Colour of its nearest coloured ancestor-or-self in the
   union (NULL: none). fn is called once per part in that order; a
   nonzero return stops the walk and is returned. -1 if memory runs out
   (a union deeper than 32 levels needs a stack). The tracer's primitives
   (render/render.c) and the mesher's colouring both come from it, so a
   part is coloured the same in a picture and in a .ply or .3mf. */
int scene_union_parts(const Scene *s, int node,
                      int (*fn)(void *ctx, int part, const double *colour),
                      void *ctx);

/* Figure 4, PointInObject: 1 if p is inside node, 0 if not, -1 if memory
   runs out (a subtree of more than 256 nodes needs a byte per node).
   Iterative: the subtree's nodes are visited once each, children first. */
int scene_inside(const Scene *s, int node, const double p[3]);
#endif
