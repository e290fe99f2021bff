/* scene.h: a language value (constructor tree) compiled into a flat C
 * scene, once, for the probes and the renderer.
 *
 * The scene is a CSG tree of nodes in one array (children before
 * parents): sharp halfspaces (planes normalised), rounded density trees
 * (flat tapes, density.h), soft objects (key arrays with their index,
 * soft.h), and Union / Intersection / Difference over them. Only what the
 * scene contains is built: no density tape without a Rounded, no soft
 * machinery without a SoftObject; the bounds of a rounded node are made
 * when first asked for. Every node keeps the source position of the
 * constructor it came from, so a problem found late still points at the
 * source.
 *
 * Coercions: a density tree used where a scene object is expected is the
 * sharp polyhedron it describes (Product = Intersection, Sum and
 * DensityUnion = Union, Difference = SetDifference); `Rounded 0 t` is
 * exactly that sharp polyhedron. Inside a density tree a Halfspace is a
 * DensityHalfspace, an Intersection a Product and a Union a DensityUnion.
 *
 * Memory: scene_compile mallocs the scene; the caller owns it and frees it
 * with scene_free. Afterwards it is read-only and may be shared by
 * threads (lazily built bounds are made under a lock). Compilation errors
 * are raised with qcs_error at the offending constructor's position. */
#ifndef QCS_SCENE_H
#define QCS_SCENE_H

#include <pthread.h>

#include "csg.h"
#include "density.h"
#include "soft.h"
#include "value.h"

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
  Pos pos;
  int a, b;              /* children, for the set operations */
  double n[3], d;        /* SC_HALFSPACE: unit normal and offset */
  dt_tape *tape;         /* SC_ROUNDED */
  csg_tape *outer, *inner; /* SC_ROUNDED: bounds of the 0.5 isosurface */
  int bound_flags;       /* BND_RANGE, BND_FALLBACK (bounds.h) */
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

/* Compile a scene object. what names the role for errors ("the scene"). */
Scene *scene_compile(Interp *I, Value *obj, Pos pos);
void scene_free(Scene *s);

/* Compile a density tree alone, with radius r for its DensityHalfspaces
   (RoundedHalfspace leaves keep their own). Caller frees with
   dt_tape_free. */
dt_tape *scene_density_tape(Interp *I, Value *tree, double r, Pos pos);

/* A warning at pos, given once per source position per interpreter. */
void scene_warn_once(Interp *I, Pos pos, const char *msg);
/* 1 if the two parts of some Sum in the density tree may overlap with
   positive volume (density above 1 there, the paper's Figure 15b); parts
   that only touch do not count. */
int scene_sum_overlaps(Interp *I, Value *tree, Pos pos);

/* Figure 4, PointInObject: 1 if p is inside the compiled object. */
int scene_inside(const Scene *s, int node, const double p[3]);
#endif
