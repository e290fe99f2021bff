/* mesh.h: a compiled scene as a closed triangle mesh (issue 16, first part).
 *
 * Method. An octree over the object's box (its conservative bounds, or
 * the user's) is walked from the root; each cell is classified by proofs
 * over the whole closed cell, never by samples: a sharp halfspace exactly
 * (its signed distance ranges over the box), a rounded density tree by
 * interval arithmetic on its tape (interval.h) and by its outer and inner
 * bound solids (bounds.h), a soft object by interval bounds on each key's
 * field (soft_field_box), and the set operations by three-valued logic
 * (inside / outside / undecided). A cell proven inside or outside holds
 * no surface and is not visited further; undecided cells are split down
 * to one finest level, whose side h follows from the tolerance.
 *
 * Surface extraction is marching tetrahedra on the Kuhn (Freudenthal)
 * split of every finest cell into 6 tetrahedra around its main diagonal:
 * the corner signs come from scene_inside (Figure 4), and each edge whose
 * ends differ gets one vertex at a crossing found by the scene's exact
 * ray spans along the edge (scene/ray.h: the guaranteed root search for
 * rounded trees, the polynomial crossings of soft objects, planes
 * exactly), with bisection on scene_inside as the fallback. Why this and
 * not dual contouring: the result is the level set of a piecewise-linear
 * sign function on a conforming tetrahedral mesh, so it is a closed,
 * consistently oriented 2-manifold without self-intersections whatever
 * the vertex positions on the edges (each piece lies in its own closed
 * tetrahedron and neighbours share exactly the crossings of their common
 * face); dual contouring keeps sharp edges but needs extra machinery to
 * stay manifold. Sharp edges are therefore not reproduced exactly yet.
 *
 * Error. Every vertex lies within vtol (the root tolerance) of the
 * surface; every point of a triangle lies within the triangle's covering
 * radius by its vertices (its circumradius if it is not obtuse, half its
 * longest side otherwise) of a vertex. The certified error reported is
 * the largest covering radius over all triangles plus vtol, computed on
 * the mesh itself; the grid is chosen so that it is at most the requested
 * tolerance. The other direction (every surface point near the mesh) is
 * not proven: a surface feature smaller than a finest cell whose corners
 * all agree is missed.
 *
 * Memory: mesh_scene mallocs the mesh (mesh_free). Nothing here prints.
 * The scene is only read. */
#ifndef QCS_MESH_H
#define QCS_MESH_H

#include <stddef.h>

#include "scene/scene.h"

typedef struct MeshSettings {
  double tol;              /* the requested error, scene units (> 0) */
  int has_bounds;          /* mesh inside [lo, hi] only (an unbounded
                              object needs it) */
  double lo[3], hi[3];
  size_t max_triangles;    /* refuse a mesh with more (0: no limit) */
  size_t max_cells;        /* refuse an octree with more surface cells */
  int uniform;             /* every surface cell at the finest level, no
                              sharp cells: the uniform grid, to compare */
} MeshSettings;

typedef struct Mesh {
  size_t nv, nt;
  double *v;               /* 3 nv coordinates */
  int *t;                  /* 3 nt vertex indices, counter-clockwise seen
                              from outside */
  float *rgb;              /* 3 nv linear colours (mesh_colour), or NULL */
} Mesh;

typedef struct MeshReport {
  long cells;              /* octree cells visited */
  long empty, full;        /* of them proven outside / inside */
  long leaves;             /* surface cells meshed (at any level) */
  long planar, smooth;     /* of them kept above the finest level: the
                              surface proven one plane, or proven close
                              enough by the gradient bound */
  long sharp;              /* of them meshed exactly: the solid there is a
                              CSG of at most 8 planes (edges and corners
                              kept) */
  int sharp_off;           /* sharp cells were given up (see mesh.c) */
  int depth;               /* finest level */
  double h;                /* finest cell side */
  double vtol;             /* the vertices' distance bound */
  double certified;        /* the proven bound, see above */
  double measured;         /* the largest distance along the normal from
                              sample points of the triangles to the
                              surface (INFINITY: none within reach) */
  int samples;             /* the sample points used */
  long crossings, bisected;/* edge vertices; of them found by bisection */
  size_t vertices, triangles;
  double seconds;
} MeshReport;

enum {
  MESH_OK = 0,
  MESH_ENOMEM = 1,
  MESH_EUNBOUNDED,         /* no Bounds and the node is unbounded */
  MESH_EEMPTY,             /* the object has no inside in its box */
  MESH_ETOL,               /* the tolerance is not usable */
  MESH_ELIMIT,             /* max_triangles or max_cells */
  MESH_EINTERNAL           /* the result failed its own closure check */
};

/* Mesh node of s. On failure returns a MESH_E* code with a message in err;
   *bad_node is set to the node at fault (MESH_EUNBOUNDED) or -1. */
int mesh_scene(const Scene *s, int node, const MeshSettings *ms, Mesh **out,
               MeshReport *rep, int *bad_node, char *err, size_t errlen);
void mesh_free(Mesh *m);

/* Edge counting on the mesh alone. */
typedef struct MeshCheck {
  long boundary_edges;     /* directed edges without their reverse */
  long nonmanifold_edges;  /* directed edges used more than once */
  long nonmanifold_verts;  /* vertices whose triangles are not one fan */
  long degenerate;         /* triangles with a repeated vertex */
  long components;         /* connected components (of triangles) */
  long euler;              /* V - E + F over the used vertices */
} MeshCheck;

/* Returns 0 when the mesh is a closed, consistently oriented 2-manifold,
   else -1 (details in *c); -2 when memory runs out. */
int mesh_check(const Mesh *m, MeshCheck *c);

/* Colours m's vertices: each takes the Colour of the first part of the
   scene's top-level union that holds the point inset below it along the
   vertex normal (def where no part has a Colour). 0, or -1 out of memory. */
int mesh_colour(const Scene *s, int node, Mesh *m, const double def[3],
                double inset);

/* 1 if the file name asks for a mesh (.stl, .obj, .ply, .3mf), else 0. */
int mesh_is_mesh_path(const char *path);
/* Writes m to path by extension: binary STL, OBJ with vertex normals,
   binary PLY with per-vertex sRGB colour, or 3MF (a zip made in memory by
   libzip, one base material per colour); whole or not at all (a
   temporary file renamed into place). */
int mesh_write(const Mesh *m, const char *path, char *err, size_t errlen);
#endif
