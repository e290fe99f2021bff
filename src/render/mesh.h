/* mesh.h: a compiled scene as a closed triangle mesh (issue 16).
 *
 * Method. An octree over the object's box (its conservative bounds, or
 * the user's) is walked from the root; each cell is classified by proofs
 * over the whole closed cell, never by samples: a sharp halfspace exactly
 * (its signed distance ranges over the box), a rounded density tree by
 * interval arithmetic on its tape (interval.h) and by its outer and inner
 * bound solids (bounds.h), a soft object by interval bounds on each key's
 * field (soft_field_box), and the set operations by three-valued logic
 * that also notes when one node alone decides the solid in the cell, or
 * sharp halfspaces alone. A cell proven inside or outside is dropped. An
 * undecided cell becomes a surface leaf, at any size, when its error is
 * proven within the tolerance: one plane (a halfspace, or a rounded tree
 * with one live leaf), a rounded node or a soft object whose gradient
 * bound over the cell grown by the tolerance bounds its triangles'
 * distance (mesh.c, grad_box; core/soft.h, soft_grad_box), or a CSG
 * of at most MESH_PLANES_MAX planes (a sharp cell, meshed exactly);
 * else it is split, down to the finest level whose side the tolerance
 * fixes. There, and below it, a cell is kept only when each surface in
 * it is proven one sheet (mesh.c, settled: every line along one
 * direction meets it once, after Plantinga and Vegter), where two or
 * more surfaces cross it the solid's own boundary is (solid_sheet: every
 * node, complemented where a difference complements it, growing along
 * one direction), and no two undecided planes cross it without meeting
 * in it; else it splits again (a part thinner than the cell), down to
 * depth 19, where MESH_ETHIN refuses naming the place and the node. A
 * cell where only the solid is not proven one sheet splits at most
 * TWO_LEVELS more when that settles it and every such cell beside it
 * (refine_two), and is counted (MeshReport.two) where it does not.
 *
 * The leaves of all sizes are cut into tetrahedra that meet face to face
 * (the Kuhn split where a cell's faces are plain, else a centre point and
 * fans through the corners of smaller cells), so the surface is closed
 * across cells of different sizes. Sharp cells are meshed exactly in each
 * tetrahedron (the planes' polygons split by each other, kept where the
 * solid changes across them): their edges and corners are the solid's.
 * The others by marching tetrahedra: corner signs from scene_inside, one
 * vertex per sign-changing edge at a crossing found by the scene's exact
 * ray spans along the edge (scene/ray.h), bisection as the fallback; a
 * marching triangle edge on a face where a sharp neighbour's surface runs
 * through crease points is split along that path.
 *
 * Error. Each triangle is certified by its cell's proof (mesh.c,
 * tri_bound): the vertices' tolerance vtol in plane and sharp cells, the
 * gradient bound in smooth cells, vtol plus the triangle's covering radius
 * in finest cells; the report gives the largest, and a measured error
 * (sample points to the surface along the normal or an axis). That every part of
 * the surface is near the mesh is proven in plane and sharp cells by
 * construction, and in the smooth cells (by columns along the gradient)
 * and the finest cells (box by box) after the mesh is made
 * (mesh_cover.h); cells where that proof gives up, and the leaves
 * beside them, are split and the object meshed again, a round kept
 * when it proves more and keeps the mesh's topology, or proves every part
 * (MeshReport.cover_topo when that changed the topology).
 * The flat regions of the mesh made (a sharp face, a flat middle) are then
 * triangulated again without their inner vertices (mesh_merge.h; the
 * surface moves by at most flat_moved, added to the certified bound;
 * MeshSettings.keep_flat leaves them). Closure is checked by edge
 * counting before anything is returned, and
 * then self-intersection, exactly (mesh_check.h: every pair of triangles
 * whose boxes overlap, by exact orientation predicates); a failure of
 * either with sharp cells (two of them deciding a degenerate case apart,
 * or a crease fan reaching through a neighbour) remakes the mesh with
 * the sharp cells about the place meshed by their tetrahedra
 * (MeshReport.sharp_apart), up to six times, then without any sharp cell
 * (MeshReport.sharp_off); every mesh is checked again.
 *
 * Memory: mesh_scene mallocs the mesh (mesh_free). Nothing here prints.
 * The scene is only read. */
#ifndef QCS_MESH_H
#define QCS_MESH_H

#include <stddef.h>

#include "scene/scene.h"

/* The most distinct planes a sharp cell holds (meshed exactly). */
#define MESH_PLANES_MAX 32

typedef struct MeshSettings {
  double tol;              /* the requested error, scene units (> 0) */
  int has_bounds;          /* mesh inside [lo, hi] only (an unbounded
                              object needs it) */
  double lo[3], hi[3];
  size_t max_triangles;    /* refuse a mesh with more (0: no limit) */
  size_t max_cells;        /* refuse an octree with more surface cells */
  size_t max_memory;       /* refuse when meshing would grow the process's
                              resident memory by more (an estimate from
                              the triangles before the crossings are
                              sought, then measured as the work goes on;
                              0: no limit; Linux's /proc, else none) */
  int uniform;             /* every surface cell at the finest level, no
                              sharp cells: the uniform grid, to compare */
  int keep_flat;           /* do not triangulate flat regions again
                              (mesh_merge.h): the octree's triangles, to
                              compare */
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
                              CSG of at most MESH_PLANES_MAX planes
                              (edges and corners kept) */
  long sharp_pruned;       /* of them, cells whose other planes do not
                              reach the solid there (mesh.c,
                              cell_redundant) */
  long welded;             /* triangles of no area dropped where the
                              sharp cells met a degenerate point */
  long sliver_pairs;       /* in the second try, pairs of triangles on
                              one vertex set facing apart dropped, and */
  long sliver_caps;        /* caps (three vertices all but on one line)
                              taken out and the line zipped: a sliver
                              1e-16 wide once its vertices were joined
                              (mesh.c, drop_slivers) */
  long sliver_holes;       /* holes all but on one line the zip left,
                              closed by a fan (mesh.c, fill_slivers) */
  long snapped;            /* planes moved onto another that is the same
                              plane but for rounding (mesh.c, snap_planes) */
  double snap_moved;       /* the most one moved in the object's box (in
                              the certified bound) */
  long pinches;            /* vertices where two parts of the solid touch
                              (at a point or along a line), parted
                              (mesh.c, part_contacts) */
  long sharp_apart;        /* sharp cells meshed by their tetrahedra's
                              crossings instead, where two sharp cells
                              left a crack or a self-intersection between
                              them (the rest stay sharp; see mesh.c) */
  int sharp_off;           /* sharp cells were given up (see mesh.c): 1
                              closure failed with them, 2 the mesh made
                              with them intersected itself */
  int depth;               /* finest level (the tolerance's) */
  double h;                /* finest cell side */
  long thin;               /* cells at or below the finest level split
                              because a surface in them was not proven
                              one sheet (a part thinner than the cell) */
  int deepest;             /* the deepest level of a surface cell */
  long two;                /* cells meshed with two surfaces in them, each
                              one sheet, not proven one sheet together
                              (mesh.c, TWO_LEVELS below the finest) */
  double two_side;         /* the side of the largest */
  double two_at[3];        /* the lowest corner of the first */
  double vtol;             /* the vertices' distance bound */
  double certified;        /* the proven bound, see above */
  double measured;         /* the largest distance from sample points of
                              the triangles to the surface along the
                              normal or an axis, the least of the four
                              (INFINITY: none within reach) */
  int samples;             /* the sample points used */
  long crossings, bisected;/* edge vertices; of them found by bisection */
  size_t vertices, triangles;
  long flat_regions;       /* flat regions triangulated again
                              (mesh_merge.h) */
  size_t flat_before;      /* the triangles before that */
  double flat_moved;       /* how far that moved the surface at most
                              (added to certified) */
  int flat_undone;         /* the checks failed with them: 1 closure, 2
                              self-intersection (the mesh as made kept) */
  int flat_frozen;         /* else: the merges it took, the regions where
                              the mesh met itself kept as made */
  long components;         /* the mesh's connected components and Euler */
  long euler;              /* characteristic (mesh_check) */
  long pairs;              /* the self-intersection check (mesh_check.h):
                              triangle pairs tested exactly */
  long pairs_exact;        /* predicate signs decided in GMP */
  double check_seconds;    /* its time */
  double cover;            /* every part of the surface proven within
                              cover of the mesh (mesh_cover.h; vtol where
                              no cell needs the proof: plane and sharp
                              cells are the surface) */
  long cover_boxes;        /* boxes of the proof */
  long cover_unproven;     /* cells where it failed in the last round */
  long cover_columns;      /* columns of the proof (smooth cells) */
  long cover_colcells;     /* smooth cells proven by columns */
  double cover_at[3];      /* a place in the first */
  double cover_seconds;    /* its time, over every round */
  long cover_more;         /* cells of the last round split for the next */
  int cover_rounds;        /* rounds meshed again with cells split */
  long cover_split;        /* cells split for the proof in the last round
                              meshed (kept or not) */
  int cover_last;          /* this round is the last (mesh.c, mesh_rounds) */
  int cover_wide;          /* this mesh's round split the cells not
                              proven beside cells with two surfaces too
                              (no others were left: 1 few, 2 a groove
                              of more, kept only with the first mesh's
                              topology: mesh.c, cover_check) */
  int cover_wide_next;     /* the next round will (internal) */
  int cover_topo;          /* this mesh's round proved every part of the
                              surface and changed the components or Euler
                              characteristic of the mesh before the
                              rounds, which were: */
  long first_components, first_euler;
  int memout;              /* MESH_ELIMIT came from max_memory (internal) */
  int resharp;             /* mesh.c's MESH_RESHARP came from a crack (1)
                              or a self-intersection (2) (internal) */
  int cover_kept;          /* the last round was not kept (it proved no
                              more, or changed the topology, or failed):
                              the mesh is the round's before */
  long float_joined;       /* the file's floats' mesh made a mesh again
                              (mesh_float.h, by the writer's caller):
                              vertices joined, */
  long float_closed;       /* triangles that closed up, */
  long float_pairs;        /* pairs facing apart dropped, */
  long float_parted;       /* fans given their own vertex, */
  double float_moved;      /* the largest move (added to certified); */
  int float_apart;         /* or, the other way, the vertices kept apart */
  double seconds;
} MeshReport;

enum {
  MESH_OK = 0,
  MESH_ENOMEM = 1,
  MESH_EUNBOUNDED,         /* no Bounds and the node is unbounded */
  MESH_EEMPTY,             /* the object has no inside in its box */
  MESH_ETOL,               /* the tolerance is not usable */
  MESH_ELIMIT,             /* max_triangles or max_cells */
  MESH_EINTERNAL,          /* the result failed its own closure check */
  MESH_ETHIN,              /* a part thinner than the deepest cell */
  MESH_ESELF               /* the mesh intersects itself (after the
                              remake without sharp cells) */
};

/* Mesh node of s. On failure returns a MESH_E* code with a message in err;
   *bad_node is set to the node at fault (MESH_EUNBOUNDED) or -1. */
int mesh_scene(const Scene *s, int node, const MeshSettings *ms, Mesh **out,
               MeshReport *rep, int *bad_node, char *err, size_t errlen);
void mesh_free(Mesh *m);
/* For the error of an unbounded object: a box that makes it bounded, into
   lo, hi, and 1; 0 if none is found. The box of the parts a union holds
   beside its unbounded halfspaces, each side padded by 2% of it out to
   round decimals, with a face on each axis-aligned halfspace's plane
   that cuts that padding (a floor under objects standing on it: the
   floor is then left out, as Bounds does). Returns 0, or 1 plus twice a
   mask of the faces put on a plane (bit k: low face of axis k, bit 3 + k:
   high face). */
int mesh_suggest_bounds(const Scene *s, int node, double lo[3], double hi[3]);

/* Edge counting on the mesh alone. */
typedef struct MeshCheck {
  long boundary_edges;     /* directed edges without their reverse */
  long nonmanifold_edges;  /* directed edges used more than once */
  long nonmanifold_verts;  /* vertices whose triangles are not one fan */
  long degenerate;         /* triangles with a repeated vertex */
  long components;         /* connected components (of triangles) */
  long euler;              /* V - E + F over the used vertices */
} MeshCheck;

/* For tests only: from the next call on, each mesh made with sharp cells
   (fault 1), or each mesh (fault 2), has one vertex pushed through the
   solid (reflected through the vertices' centroid, half as far again)
   just before its self-intersection check, so that the check's failure
   paths run: the remake without sharp cells, and the error that writes
   nothing. 0 (the default) turns it off. Not thread-safe. */
void mesh_test_fault(int fault);

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
/* How many of m's vertices fall on another's place when rounded to
   floats, as STL, PLY and 3MF keep them (features below 2^-24 of the
   coordinates: a sliver 1e-9 wide); -1 out of memory. */
long mesh_float_joined(const Mesh *m);
#endif
