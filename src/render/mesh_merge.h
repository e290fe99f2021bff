/* mesh_merge.h: flat parts of a closed mesh triangulated again with fewer
 * triangles (issue 16).
 *
 * A sharp CSG face, or the flat middle of a rounded polyhedron's face,
 * comes out of the octree as many triangles, cut by the cells and their
 * tetrahedra. mesh_merge_flat finds the regions of edge-adjacent
 * triangles whose vertices all lie within delta of one plane (with
 * normals on the same side; a region whose boundary has more than 96
 * edges is taken in patches of at most 64 triangles, grown breadth
 * first: a polygon of many boundary vertices and none inside would be
 * cut into long thin triangles across it, whose boxes meet many others
 * in the self-intersection check), drops their interior vertices, drops the
 * vertices on a straight edge between two such regions (within delta of
 * the chord between the edge's ends, used by those two regions alone),
 * and triangulates each region's boundary again by ear clipping in the
 * plane, with exact orientation predicates (mesh_check.h): an ear is
 * strictly convex and holds no other vertex of the polygon, inside or on
 * its edges; then Lawson's flips, each keeping both triangles strictly
 * convex, make the fans of the clipping fatter. A region with holes has each hole joined to the outside by a
 * bridge that crosses no edge. A region whose boundary is not simple
 * (a vertex twice), or that the clipping cannot finish, keeps its
 * triangles; one that had lost a straight vertex gives it back (on both
 * sides) and the regions are done again (after 8 such passes, with no
 * vertex removed). An ear that is a sliver (twice its area under 1e-10
 * of its longest side squared: vertices on one straight edge, not
 * exactly collinear once rounded) is not taken.
 *
 * What it keeps. Every boundary edge between regions that are not both
 * merged stays as it was, and a removed straight vertex is removed from
 * both sides, so the mesh stays closed and manifold with the same
 * components and Euler characteristic. The surface moves by at most
 * 2 sqrt(3) delta (a new triangle's points and the old ones project to
 * the same polygon along the axis the plane is most across, both within
 * delta of the plane) and by delta at a removed straight vertex: the
 * caller adds the returned bound to its error. Triangles of a region
 * triangulated in its plane do not overlap each other; the caller still
 * checks the result (closure and self-intersection).
 *
 * Memory: malloc'd scratch; m's arrays are replaced in place (realloc'd,
 * vertex indices compacted). Nothing here prints. */
#ifndef QCS_MESH_MERGE_H
#define QCS_MESH_MERGE_H

#include <stddef.h>

struct Mesh;

typedef struct MeshMerge {
  long regions;        /* flat regions of two or more triangles, or with a
                          straight vertex removed, triangulated again */
  long kept;           /* such regions left as they were (not simple, or
                          the clipping could not finish) */
  size_t before, after;/* triangles */
  double moved;        /* the bound on how far the surface moved */
} MeshMerge;

/* Merge the flat regions of the closed mesh m (counter-clockwise seen from
   outside). delta > 0: the flatness allowed, in scene units. 0 on
   success (m may be unchanged), -2 out of memory (m unchanged). */
int mesh_merge_flat(struct Mesh *m, double delta, MeshMerge *st);

/* The same with the triangles i of m where frozen[i] (NULL: none) each a
   region of its own, left as they are. from, if not NULL: *from is set
   to a malloc'd array (NULL when nothing was merged) of m->nt (after) +
   nt (before) ints: for each triangle of the result, the triangle of m
   it was (>= 0) or -1 - r for a new one of region r; then for each
   triangle of m as given, its region r when that was merged, else -1.
   (A caller whose result intersects itself freezes the regions there
   and merges again: mesh.c.) */
int mesh_merge_flat_frozen(struct Mesh *m, double delta,
                           const unsigned char *frozen, int **from,
                           MeshMerge *st);

#endif
