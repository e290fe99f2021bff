/* mesh_cover.h: proof that every part of a surface lies within a distance
 * of a mesh (issue 16), a posteriori, over boxes that hold the surface.
 *
 * The surface is given only by a classifier: for a closed box it answers
 * "wholly outside", "wholly inside" (no surface in the box) or "undecided",
 * and must be sound (never a wrong "outside" or "inside"). For each box
 * the proof recurses: a box whose centre has a triangle within e - r of it
 * (r the box's half diagonal) has every point within e of the mesh; a box
 * the classifier decides holds no surface; any other box is split into
 * eighths, down to a side of e / 1024 (within a budget of boxes that
 * grows with the given box's area over e^2), where the proof gives up on
 * it. The nearest triangle comes from a bounding volume hierarchy over
 * the triangles sorted by their centroids' Morton codes and split where
 * the codes' highest differing bit turns on; each distance is to a point
 * kept a convex combination of the triangle's vertices, with a margin
 * added for its rounding. Boxes are taken by up to two threads, each
 * with its own classifier context.
 *
 * Nothing here prints. The mesh and boxes are only read. */
#ifndef QCS_MESH_COVER_H
#define QCS_MESH_COVER_H

#include <stddef.h>

#include "render/mesh.h"

/* 0: no surface in the box (proven), 1: maybe. */
typedef int (*MeshCoverClass)(void *ctx, const double lo[3],
                              const double hi[3]);

typedef struct MeshCover {
  double bound;            /* every point of the surface in the proven
                              boxes lies within bound of the mesh (<= e) */
  long boxes;              /* boxes tested (at every level) */
  long unproven;           /* given boxes with a part not proven */
  double at[3];            /* the centre of the first such part */
  double seconds;
} MeshCover;

/* Proves for each box i (boxes[6 i .. 6 i + 5]: lo then hi) that every
   surface point in it lies within e of the mesh. margin bounds the
   rounding of a computed distance (absolute). ctx holds nctx classifier
   contexts (one per thread, 1 or 2). bad, if not NULL, gets 1 for each
   box not proven, else 0. 0, or -1 when memory runs out. */
int mesh_cover(const Mesh *me, const double *boxes, size_t nboxes, double e,
               double margin, MeshCoverClass cl, void **ctx, int nctx,
               unsigned char *bad, MeshCover *out);

/* For tests: the distance from p to the nearest triangle of me (brute
   force is the reference), through the hierarchy. -1 out of memory. */
int mesh_cover_nearest(const Mesh *me, const double *p, size_t np,
                       double *dist);

#endif
