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
 * A box given with a field (MeshField: a smooth cell, where the surface
 * is one node's level set and that node's gradient is bounded) is proven
 * by columns instead, whose number does not grow with the box's area
 * over e^2. Take a frame (e1, e2, n0), n0 the direction of the gradient's
 * bound over the box, and a rectangle D of (s, t) holding the box's
 * projection. For a rectangle, the column c + s e1 + t e2 + tau n0 over
 * it is done when either the classifier finds no surface where it meets
 * the box, or a prism Q over it of height h < e (tau within h / 2 of the
 * field's root on its centre line) has: grad . n0 > 0 over a box holding
 * Q and the column's part in the box (so the field rises along every
 * line of the column there, and crosses its level at most once); the
 * field below its level on all of Q's bottom face and above it on all of
 * its top face (its value at the face's centre, bounded over a box
 * holding that point, moved by at most the face's radius times the bound
 * of the gradient across n0); no triangle within the margin of either
 * face (a separating-axis test), so that the mesh's inside is the same
 * over each face; and an odd number of the mesh's crossings on the
 * centre line between the faces (exact orientations, mesh_check.h's; a
 * line through an edge or a vertex fails the prism). Then every line of the column crosses the mesh inside Q,
 * at most h from its one surface point, which lies in Q. Else the
 * rectangle is quartered, down to a side of e / 16 and within a budget
 * of columns, where the proof gives up on the box.
 *
 * Nothing here prints. The mesh and boxes are only read. */
#ifndef QCS_MESH_COVER_H
#define QCS_MESH_COVER_H

#include <stddef.h>

#include "render/mesh.h"

/* 0: no surface in the box (proven), 1: maybe. */
typedef int (*MeshCoverClass)(void *ctx, const double lo[3],
                              const double hi[3]);

/* One node's field for the column proof: f its value less its level
   (positive on one side of the surface, either), ctx a classifier
   context. */
typedef struct MeshField {
  const int *node;         /* per given box: the node whose level set is
                              the surface there, or -1 for the box proof */
  /* f at p, as computed (to place a column) */
  double (*value)(void *ctx, int node, const double p[3]);
  /* bounds [*l, *h] of f over the closed box */
  void (*range)(void *ctx, int node, const double lo[3], const double hi[3],
                double *l, double *h);
  /* over the closed box, for the unit vector u: grad . u >= *gmin,
     |grad - (grad . u) u| <= *wperp, |grad . u| <= *gmax; with u NULL,
     g0 gets the middle of the gradient's bound. 0, or -1 (no bound). */
  int (*grad)(void *ctx, int node, const double lo[3], const double hi[3],
              const double *u, double *gmin, double *wperp, double *gmax,
              double g0[3]);
} MeshField;

typedef struct MeshCover {
  double bound;            /* every point of the surface in the proven
                              boxes lies within bound of the mesh (<= e) */
  long boxes;              /* boxes tested (at every level) */
  long unproven;           /* given boxes with a part not proven */
  double at[3];            /* the centre of the first such part */
  double seconds;
  long columns;            /* columns tested (the field boxes) */
  long col_boxes;          /* field boxes proven by columns */
} MeshCover;

/* Proves for each box i (boxes[6 i .. 6 i + 5]: lo then hi) that every
   surface point in it lies within e of the mesh. margin bounds the
   rounding of a computed distance (absolute). ctx holds nctx classifier
   contexts (one per thread, 1 or 2). bad, if not NULL, gets 1 for each
   box not proven, else 0. fld, if not NULL, names the boxes proven by
   columns (a box whose columns fail gets the box proof, in its budget);
   the columns' parity argument needs a closed mesh (every edge, by its
   ends' coordinates, in an even number of triangles: mesh.c checks that
   before) and a margin at least 2^-46 times the coordinates' scale (a
   box with less gets the box proof). 0, or -1 when memory runs out. */
int mesh_cover(const Mesh *me, const double *boxes, size_t nboxes, double e,
               double margin, MeshCoverClass cl, void **ctx, int nctx,
               const MeshField *fld, unsigned char *bad, MeshCover *out);

/* For tests: the distance from p to the nearest triangle of me (brute
   force is the reference), through the hierarchy. -1 out of memory. */
int mesh_cover_nearest(const Mesh *me, const double *p, size_t np,
                       double *dist);

#endif
