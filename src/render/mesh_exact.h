/* mesh_exact.h: the sharp cells' signs, exact and symbolically perturbed.
 *
 * A sharp cell (mesh.c, exact_tet) splits each plane's polygon in a
 * tetrahedron by the other planes and asks, of every corner of every
 * piece, on which side of a plane it lies. Decided in rounded doubles,
 * a corner that lies on the plane (three planes through one line, as a
 * polygon's mirror-image sides make on its plane of symmetry; four
 * planes through one point) went one way in one tetrahedron and the other
 * way in the next, and the mesh cracked there. These predicates answer
 * every such question exactly (a double filter with a proven error bound,
 * then rational arithmetic, GMP's mpq, when the filter cannot decide), and
 * decide a true tie by a symbolic perturbation (Edelsbrunner and Muecke's
 * simulation of simplicity): every scene plane n . x = d is moved to
 * n . x = d - eps_r, eps_r > 0 infinitesimal and eps_r much larger than
 * eps_s when rank r < s. The perturbed planes are in general position
 * with the tetrahedra's faces, edges and corners, so every answer is the
 * same wherever it is asked: a corner exactly on a plane is outside it
 * (n . x - d + eps > 0, as a plain "< 0" test says), and where three
 * planes share a line a fourth meets them in points an infinitesimal
 * apart, whose order every tetrahedron agrees on.
 *
 * The answers are 1 for inside (the perturbed n . x - d below 0), else 0.
 * A point found exactly on a plane has no unique name (several triples
 * of planes meet there, an infinitesimal apart once perturbed); the
 * positions below round such a point the same way whichever names it,
 * so that the mesher can weld them into one vertex.
 */
#ifndef QCS_RENDER_MESH_EXACT_H
#define QCS_RENDER_MESH_EXACT_H

#include <math.h>

typedef struct {
  const double *pts[3]; /* the plane through three points (never
                           perturbed: a tetrahedron's face), or NULL */
  double n[3], d;       /* else n . x = d */
  long rank;            /* the perturbation's order: smaller moves more;
                           -1 for a plane not perturbed */
  double l1, dl;        /* for mx_box_in (mx_plane_prep): |n|_1 and
                           2^-50 |d| */
  double ne[3], de;     /* through points (mx_plane_prep): n and d
                           rounded, and these bounds of their errors */
} MxPlane;

/* Fill in p's l1 and dl (a plane n . x = d), or for a plane through
   points its n, d, ne and de. */
void mx_plane_prep(MxPlane *p);

/* Plane p at the point x. */
int mx_point_in(const MxPlane *p, const double x[3], int *tie);

/* Plane j at the crossing of segment a - b with plane i (a and b on
   different sides of i, a inside it when a_in). i and j perturbed. */
int mx_edge_in(const double a[3], const double b[3], int a_in,
               const MxPlane *i, const MxPlane *j, int *tie);

/* Plane j at the point where the three planes p[0..2] meet (their
   normals independent). j perturbed. */
int mx_three_in(const MxPlane *const p[3], const MxPlane *j, int *tie);

/* (Each sets *tie to 1 when the point lies exactly on plane j, or p,
   before the perturbation: a degenerate point, else to 0.) */

/* The crossing of segment a - b with plane i, and the meeting point of
   planes p[0..2] (-1 if they have no single one), exactly, each
   coordinate rounded toward 0: one point has one position, whichever
   planes name it. */
void mx_edge_point(const double a[3], const double b[3], const MxPlane *i,
                   double x[3]);
int mx_three_point(const MxPlane *const p[3], double x[3]);

/* A box about a point (centre x, half-sides r) that holds it for sure:
   the crossing of segment a - b with a plane whose n . x - d is within
   ea of sa at a and within eb of sb at b, the meeting point of p[0..2];
   -1 when the doubles cannot bound it. Plane j over it: 1 all
   inside, 0 all outside, -1 undecided. A point asked about many planes
   is boxed once and each answer is then a dot product; the predicates
   above answer what a box leaves undecided (and every tie). */
typedef struct {
  double x[3], r[3];
  double q;             /* max r_k + 2^-50 max |x_k| */
} MxBox;
int mx_edge_box(const double a[3], const double b[3], double sa, double ea,
                double sb, double eb, MxBox *out);
int mx_three_box(const MxPlane *const p[3], MxBox *out);

static inline int mx_box_in(const MxBox *b, const MxPlane *j) {
  /* j a plane n . x = d (not through points; mx_plane_prep'd): s =
     n . x - d in doubles is within 4 ulps of the permanent (2^-50 (|n|_1
     max |x_k| + |d|) bounds that) of the exact value at the box's
     centre, which is within |n|_1 max r_k of the value anywhere in the
     box; 1 + 2^-30 for the bound's own rounding */
  const double *n = j->n, *x = b->x;
  double s = n[0] * x[0] + n[1] * x[1] + n[2] * x[2] - j->d;
  double e = (j->l1 * b->q + j->dl) * (1 + 0x1p-30);
  return s > e ? 0 : s < -e ? 1 : -1;
}

#endif
