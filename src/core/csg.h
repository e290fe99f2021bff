/* csg.h: sharp CSG objects as flat tapes: point classification and the
 * inside spans of a ray (Roth, "Ray Casting for Modelling Solids", 1982).
 *
 * Leaves are sharp halfspaces n.x < d (n normalised when the leaf is
 * added) or the constants Empty and Everything; ops are Union,
 * Intersection and Difference.  Constants are folded as the tape is
 * built, and finishing reorders it (Sethi-Ullman, tape.h) so evaluation
 * needs at most CSG_STACK_MAX stack slots.  The bounds of bounds.h are csg tapes.
 *
 * Memory: csg_builder_new returns a builder owned by the caller, consumed
 * by csg_builder_finish (always) or freed by csg_builder_free; the
 * finished tape is owned by the caller and freed with csg_tape_free.  A
 * finished tape is immutable and may be shared by threads.  Ray queries
 * never allocate: they use a caller-provided scratch array of
 * csg_scratch_spans(tape) spans (or, for small tapes, an internal one). */
#ifndef QCS_CSG_H
#define QCS_CSG_H

#define CSG_STACK_MAX 64
#define CSG_LOCAL_SPANS 256   /* internal scratch when the caller gives none */
#define CSG_DIRS_MAX 64       /* directions a tape's dot table may hold */

typedef enum {
  CSG_PLANE,   /* planes[arg] */
  CSG_EMPTY,
  CSG_ALL,     /* everything */
  CSG_UNION,
  CSG_INTER,
  CSG_DIFF,    /* x y -> x - y (y on top of the stack) */
  CSG_RDIFF,   /* x y -> y - x (made by the reordering) */
  CSG_CONVEX   /* only in a tape's ray program: groups[arg] */
} csg_op;

enum { CSG_OK = 0, CSG_EPLANE, CSG_EOP, CSG_EUNBALANCED, CSG_ENOMEM };

typedef struct csg_plane { double n[3], d; } csg_plane;
typedef struct csg_instr { int op, arg; } csg_instr;

typedef struct csg_tape {
  int ncode;
  csg_instr *code;
  int nplanes;
  csg_plane *planes;
  int depth;     /* stack slots needed */
  int nleaves;   /* planes and constants in the code */
  /* The ray program, made by csg_builder_finish for csg_ray_spans: code
   * with every subtree that only intersects planes (a convex polyhedron,
   * the usual piece of a bound) replaced by one CSG_CONVEX instruction,
   * whose span is clipped plane by plane without span-list merges.
   * Group g holds the planes gplane[gstart[g] .. gstart[g + 1]), in code
   * order, copied to gpl with their indices. */
  int nrcode;
  csg_instr *rcode;
  int ngroups;
  int *gstart, *gplane;
  struct csg_gplane { double n[3], d; int id, u; } *gpl;
  /* The groups' plane normals, for dot products a ray computes once per
   * direction (csg_ray_dots): dir[0 .. ndirs) directions, gpl[k].u the
   * place of gpl[k]'s dot products in csg_ray_dots' table (those of a
   * direction, or of its negation, that give the plane's values: see
   * dot_slot in csg.c).  dir is NULL when the groups need more than
   * CSG_DIRS_MAX directions (no table).  A tape linked to another by
   * csg_tape_share_dirs starts its table with the other's (dirs_of is
   * that tape): one csg_ray_dots serves both. */
  int ndirs;
  double (*dir)[3];
  const struct csg_tape *dirs_of;
} csg_tape;

/* One inside interval of a ray, t0 < t1.  id0/id1 name the plane whose
 * surface bounds the span at t0/t1 (-1: the end of the query range or a
 * constant); the solid's outward normal there is planes[id].n, negated
 * when flip0/flip1 is set (a surface of a subtracted object). */
typedef struct csg_span {
  double t0, t1;
  int id0, id1;
  unsigned char flip0, flip1;
} csg_span;

typedef struct csg_builder csg_builder;

csg_builder *csg_builder_new(void);
/* Append the sharp halfspace n.x < d (n is normalised here). */
int csg_builder_plane(csg_builder *b, const double n[3], double d);
/* Append CSG_EMPTY or CSG_ALL. */
int csg_builder_const(csg_builder *b, csg_op c);
/* Append CSG_UNION, CSG_INTER, CSG_DIFF or CSG_RDIFF. */
int csg_builder_op(csg_builder *b, csg_op op);
csg_tape *csg_builder_finish(csg_builder *b, int *err);
void csg_builder_free(csg_builder *b);
void csg_tape_free(csg_tape *t);
const char *csg_strerror(int err);

/* Constant tapes (if the whole object folded to one). */
int csg_is_empty(const csg_tape *t);
int csg_is_all(const csg_tape *t);

/* Point classification (Figure 4, PointInObject for sharp objects): 1 if
 * p is strictly inside. */
int csg_inside(const csg_tape *t, const double p[3]);

/* The tape over the box [lo, hi]: CSG_BOX_OUT if no point of the box is
   inside, CSG_BOX_IN if every point is, else CSG_BOX_MIX (undecided: the
   box is classified plane by plane, so a box can be MIX and still all on
   one side). */
enum { CSG_BOX_OUT = 0, CSG_BOX_IN = 1, CSG_BOX_MIX = 2 };
int csg_box_class(const csg_tape *t, const double lo[3], const double hi[3]);

/* The specialisation of t to the box [lo, hi], for csg_box_class on boxes
 * inside it: each plane whose range over the box is wholly on one side
 * becomes Everything or Empty, and the constants are folded (a union
 * with Everything is Everything, with Empty its other operand, ...), in
 * the three-valued logic csg_box_class uses, so the view classifies
 * every box inside [lo, hi] as t does (where a plane's range over the
 * inner box is computed within [lo, hi]'s). Writes at most t->ncode + 1
 * instructions to buf (the view's code); *view borrows buf and t's
 * planes, and has no ray program: only csg_box_class, csg_inside and
 * csg_is_empty / csg_is_all may be asked of it. Returns the code length. */
int csg_prune_box(const csg_tape *t, const double lo[3], const double hi[3],
                  csg_instr *buf, csg_tape *view);

/* Scratch spans a ray query on t needs. */
static inline int csg_scratch_spans(const csg_tape *t) {
  return 2 * t->nleaves + 2;
}

/* The inside spans of the ray o + s*d for s in [s0, s1], sorted and
 * disjoint, written to out (at most maxout).  d may have any non-zero
 * length; rays parallel to a plane are classified by their origin.
 * scratch may be NULL when csg_scratch_spans(t) <= CSG_LOCAL_SPANS (a tape
 * that is one convex polyhedron needs none).
 * Returns the number of spans, or -1 if out or scratch is too small. */
int csg_ray_spans(const csg_tape *t, const double o[3], const double d[3],
                  double s0, double s1, csg_span *out, int maxout,
                  csg_span *scratch, int nscratch);

/* Make t's direction table begin with base's (t->dirs_of = base), so
 * that csg_ray_dots(t, ...) serves ray queries on both (an inner bound
 * and its outer bound share their planes' normals).  Without effect
 * (dirs_of stays NULL) if either has no table or the union would exceed
 * CSG_DIRS_MAX.  Returns CSG_OK or CSG_ENOMEM (t unchanged). */
int csg_tape_share_dirs(csg_tape *t, const csg_tape *base);

/* The dot products of t's directions with o and d: dots[4u] = dir[u].o,
 * dots[4u + 1] = dir[u].d (as vec3_dot has them), dots[4u + 2] and
 * dots[4u + 3] their negations.  t->dir must not be NULL; dots holds
 * 4 * t->ndirs. */
void csg_ray_dots(const csg_tape *t, const double o[3], const double d[3],
                  double *dots);

/* csg_ray_spans with the dot products of csg_ray_dots(x, o, d, dots)
 * where x is t or t->dirs_of: the same spans, bit for bit. */
int csg_ray_spans_dots(const csg_tape *t, const double *dots,
                       const double o[3], const double d[3], double s0,
                       double s1, csg_span *out, int maxout,
                       csg_span *scratch, int nscratch);

/* Span-list set operations (Roth).  Inputs sorted and disjoint; out must
 * hold na + nb spans.  Return the output count. */
int csg_spans_union(const csg_span *a, int na, const csg_span *b, int nb,
                    csg_span *out);
int csg_spans_inter(const csg_span *a, int na, const csg_span *b, int nb,
                    csg_span *out);
int csg_spans_diff(const csg_span *a, int na, const csg_span *b, int nb,
                   csg_span *out);

#endif
