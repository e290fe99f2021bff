/* mesh_float.h: a mesh as the file's floats keep it.
 *
 * STL, PLY and 3MF keep a vertex's coordinates as floats. Where the mesh
 * has a feature below 2^-24 of its coordinates (a sliver or a gap 1e-16
 * wide that the exact construction leaves where planes all but meet),
 * two vertices round to one place, and the file is not the mesh that
 * was checked: an edge used three times, a triangle of two places.
 * mesh_to_floats makes the floats' mesh a mesh again: vertices on one
 * place joined (each to the least index there), triangles with a vertex
 * twice dropped, then pairs of triangles on one vertex set facing apart
 * (a fin) dropped. The result, at the floats, is kept only if it passes
 * the checks the doubles' mesh passed: closed, consistently oriented, a
 * 2-manifold (mesh_check), no two triangles meeting other than in what
 * they share (mesh_self_check, exact on the floats), and the same
 * number of components and Euler characteristic.
 *
 * Nothing here prints. */
#ifndef QCS_MESH_FLOAT_H
#define QCS_MESH_FLOAT_H

#include "render/mesh.h"

enum { MF_BEFORE = 1, /* the doubles' mesh was no closed 2-manifold */
       MF_CLOSURE,     /* the floats' mesh is not */
       MF_SELF,        /* the floats' mesh intersects itself */
       MF_TOPOLOGY,    /* its components or Euler characteristic differ */
       MF_FANS };      /* a fan to part had no normal */

typedef struct MeshFloatReport {
  long joined;   /* vertices that fell on another's place */
  long closed;   /* triangles with a vertex twice, dropped */
  long pairs;    /* pairs on one vertex set facing apart, dropped */
  long parted;   /* fans given their own vertex where the joining made
                    two or more meet at one */
  int ok;        /* the floats' mesh passed the checks and replaced m */
  int kept_apart;/* by the other way: nothing joined, the vertices on
                    one float place each moved into its own part */
  int why;       /* else the check it failed (MF_*), 0 if none ran */
  int why_apart; /* and the other way's (MF_FANS: no normal, or the
                    move would pass maxmove; MF_SELF) */
  long boundary, nonmanifold; /* its edge counts, when MF_CLOSURE */
  double moved;  /* the largest distance from a vertex to the float
                    place it went to (when ok) */
} MeshFloatReport;

/* When some of m's vertices fall on one place as floats: the floats'
   mesh made and checked as above, and m replaced by it when it passes
   (r->ok; its vertices then hold float values). Nothing changes when no
   vertices join (r->joined 0) or the checks fail (r->ok 0). 0, or -1
   out of memory (m unchanged). */
int mesh_to_floats(Mesh *m, double maxmove, MeshFloatReport *r);

#endif
