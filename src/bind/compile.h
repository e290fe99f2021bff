/* compile.h: language values (constructor trees) compiled into scenes.
 *
 * The one place where the language's constructors meet the scene program
 * (scene/scene.h): a Value that is a scene object is forced, checked and
 * turned into scene nodes, once; a density tree alone into a density tape.
 *
 * Coercions: a density tree used where a scene object is expected is the
 * sharp polyhedron it describes (Product = Intersection, Sum and
 * DensityUnion = Union, Difference = SetDifference); `Rounded 0 t` is
 * exactly that sharp polyhedron. Inside a density tree a Halfspace is a
 * DensityHalfspace, an Intersection a Product and a Union a DensityUnion.
 *
 * Source positions: each node's tag is its constructor's position,
 * interned with pos_tag (lang/error.h); tag_pos gives it back.
 *
 * Errors are raised with qcs_error at the offending constructor's
 * position (the interpreter's error style); whatever was allocated for a
 * half-built scene is freed on the way out (the error frame's cleanup
 * list). Memory: compile_scene mallocs the scene; the caller frees it with
 * scene_free. */
#ifndef QCS_COMPILE_H
#define QCS_COMPILE_H

#include "lang/value.h"
#include "scene/scene.h"

/* Compile a scene object; pos is where it is used, for errors with no
   constructor position at hand. */
Scene *compile_scene(Interp *I, Value *obj, Pos pos);

/* Compile a density tree alone, with radius r for its DensityHalfspaces
   (RoundedHalfspace leaves keep their own). Caller frees with
   dt_tape_free. */
dt_tape *compile_density_tape(Interp *I, Value *tree, double r, Pos pos);

/* A warning at pos, given once per source position per interpreter. */
void compile_warn_once(Interp *I, Pos pos, const char *msg);

/* 1 if the two parts of some Sum in the density tree may overlap with
   positive volume (density above 1 there, the paper's Figure 15b); parts
   that only touch do not count. */
int compile_sum_overlaps(Interp *I, Value *tree, Pos pos);

/* 1 if v (forced here) is a scene object or density tree, or a finite
   list of them (at most 1000): what the REPL shows as a picture. */
int compile_is_object(Interp *I, Value *v);

/* compile_scene, also for a list of objects (their Union; [] is empty). */
Scene *compile_scene_any(Interp *I, Value *obj, Pos pos);

/* The source position of a scene node (pos_none if it has none). */
Pos compile_node_pos(const Scene *s, int node);
#endif
