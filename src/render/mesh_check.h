/* mesh_check.h: exact self-intersection check of a triangle mesh.
 *
 * Two closed triangles of a mesh may meet only in what they share: the
 * vertex, the edge, or nothing. mesh_self_check tests every pair whose
 * boxes overlap (a uniform grid over the triangles' boxes, each pair
 * tested once, in the first grid cell both boxes reach) with exact
 * orientation predicates: a floating-point filter with Shewchuk's proven
 * error bound for orient3d and orient2d ("Adaptive Precision
 * Floating-Point Arithmetic and Fast Robust Geometric Predicates", 1997,
 * the A bounds), and where the filter cannot decide the sign, the same
 * determinant in GMP integers (every double is an integer times a power
 * of two, so the arithmetic is exact). Coplanar overlaps count, two
 * triangles on one edge folded onto each other count, two triangles
 * touching where they share nothing count; a zero-area triangle (three
 * collinear vertices) is the segment it spans and is tested as such.
 *
 * Nothing here prints; the mesh is only read. */
#ifndef QCS_MESH_CHECK_H
#define QCS_MESH_CHECK_H

#include <stddef.h>

struct Mesh;

typedef struct MeshSelfCheck {
  long pairs;         /* pairs of triangles whose boxes overlap: tested */
  long exact;         /* predicate signs the filter left to GMP */
  long bad;           /* intersecting pairs found */
  size_t tri[2];      /* the first intersecting pair (in the grid's order) */
  double at[3];       /* the centre of the first pair's shared box */
  double seconds;
} MeshSelfCheck;

/* 0 when no two triangles of m meet other than in what they share, 1 when
   some do (c->bad, c->tri, c->at), -1 on a vertex that is not finite or a
   vertex index out of range, -2 out of memory. */
int mesh_self_check(const struct Mesh *m, MeshSelfCheck *c);

/* The pair test alone: 1 if triangles i and j of m meet other than in the
   vertices (by index) they share. */
int mesh_tri_pair(const struct Mesh *m, size_t i, size_t j);
/* The same answer by the path mesh_self_check takes: each triangle's
   plane made once, the common cases first (to test it against
   mesh_tri_pair). */
int mesh_tri_pair_fast(const struct Mesh *m, size_t i, size_t j);

/* The exact predicates. orient3d: the sign of det [a - d; b - d; c - d]
   (positive when d is below the plane of a, b, c seen counter-clockwise
   from above). orient2d: the sign of det [a - c; b - c] on the
   coordinates x = axis i, y = axis j. exact, when not NULL, counts the
   signs decided in GMP. */
int mesh_orient3d(const double a[3], const double b[3], const double c[3],
                  const double d[3], long *exact);
int mesh_orient2d(const double a[3], const double b[3], const double c[3],
                  int i, int j, long *exact);
/* orient3d(a, b, c, d) as the fast path takes it: the plane of a, b, c
   made once, its own proven filter, then orient3d (to test it). */
int mesh_orient3d_plane(const double a[3], const double b[3],
                        const double c[3], const double d[3], long *exact);
/* Frees the calling thread's scratch integers of the exact evaluations
   (kept between calls; mesh_self_check releases its own). */
void mesh_check_release(void);
#endif
