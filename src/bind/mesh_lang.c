/* mesh_lang.c: mesh and meshWith (see mesh_lang.h). */
#include "bind/mesh_lang.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bind/compile.h"
#include "bind/render_lang.h"
#include "lang/builtins.h"
#include "lang/eval.h"
#include "lang/print.h"
#include "render/mesh.h"
#include "render/mesh_float.h"
#include "render/render.h"

/* The default tolerance: this fraction of the object's largest side. */
#define MESH_DEFAULT_REL 0.01
#define MESH_DEFAULT_MAX_TRIANGLES 20000000

static void report(FILE *f, const MeshReport *r, const char *path, double e) {
  fprintf(f, "qcs: mesh %s: %zu triangles, %zu vertices in %.2f s\n", path,
          r->triangles, r->vertices, r->seconds);
  fprintf(f, "  octree: %ld cells visited, %ld proven empty, %ld proven "
          "full, %ld surface cells meshed: %ld proven one plane, %ld proven "
          "smooth enough, %ld sharp (a CSG of planes, meshed exactly), %ld at "
          "the finest level (depth %d, cell %.4g) or below\n",
          r->cells, r->empty, r->full, r->leaves, r->planar, r->smooth,
          r->sharp, r->leaves - r->planar - r->smooth - r->sharp, r->depth,
          r->h);
  if (r->sharp_pruned)
    fprintf(f, "  sharp cells: %ld of them without the planes crossing them "
            "whose faces do not reach them (a many-sided prism's sides near "
            "its rim)\n", r->sharp_pruned);
  if (r->flat_regions && r->flat_frozen)
    fprintf(f, "  flat parts: %ld regions in one plane triangulated again "
            "without their inner vertices, %zu -> %zu triangles (done %d "
            "time%s more: where the new triangles met others, within "
            "rounding, those regions were kept as made)\n",
            r->flat_regions, r->flat_before, r->triangles, r->flat_frozen,
            r->flat_frozen == 1 ? "" : "s");
  else if (r->flat_regions)
    fprintf(f, "  flat parts: %ld regions in one plane triangulated again "
            "without their inner vertices, %zu -> %zu triangles\n",
            r->flat_regions, r->flat_before, r->triangles);
  else if (r->flat_undone)
    fprintf(f, "  flat parts: triangulated again, the mesh failed its %s "
            "check; the mesh as made was kept\n",
            r->flat_undone == 1 ? "closure" : "self-intersection");
  if (r->thin)
    fprintf(f, "  thin parts: %ld cells split below the finest level (a "
            "surface in them, or the solid where surfaces meet, not proven "
            "one sheet), down to depth %d (cell "
            "%.4g)\n", r->thin, r->deepest, ldexp(r->h, r->depth - r->deepest));
  if (r->two) {
    char of[48] = "the finest level's";
    if (r->two_side < r->h)
      snprintf(of, sizeof of, "1/%.0f of the finest", r->h / r->two_side);
    fprintf(f, "  two surfaces: %ld cells (side up to %.4g, %s) hold two "
            "surfaces, each one sheet, not proven one sheet together: a part "
            "or gap between them thinner than the cell may be lost or closed "
            "there (the first at (%.6g, %.6g, %.6g))\n",
            r->two, r->two_side, of, r->two_at[0], r->two_at[1], r->two_at[2]);
  }
  if (r->welded)
    fprintf(f, "  degenerate points: %ld triangles of no area dropped where "
            "three planes meet in a line or four in a point, or all but "
            "(sides decided exactly, ties by a symbolic perturbation; "
            "edges shorter than 2^-46 of the object's size collapsed, the "
            "certified bound grown by the largest move)\n", r->welded);
  if (r->sliver_pairs || r->sliver_caps || r->sliver_holes)
    fprintf(f, "  slivers: where planes all but meet in a line, once their "
            "vertices within 2^-39 of the object's size were joined, %ld "
            "pair%s of triangles on the same vertices facing apart dropped, "
            "%ld triangle%s with three vertices all but on one line taken "
            "out and the edges left along the line zipped (a triangle "
            "across split at each vertex on its side), %ld hole%s along the "
            "line closed (the certified bound grown by the largest "
            "height)\n", r->sliver_pairs, r->sliver_pairs == 1 ? "" : "s",
            r->sliver_caps, r->sliver_caps == 1 ? "" : "s", r->sliver_holes,
            r->sliver_holes == 1 ? "" : "s");
  if (r->snapped)
    fprintf(f, "  planes joined: %ld plane%s within 2^-46 of another (of "
            "the object's size) made that plane, faces glued face to face or "
            "flush one plane but for rounding (moved at most %.3g; in the "
            "certified bound)\n", r->snapped, r->snapped == 1 ? "" : "s",
            r->snap_moved);
  if (r->pinches)
    fprintf(f, "  pinches: %ld vert%s where two parts of the solid touch "
            "or all but touch (at a point or along a line) parted, each "
            "part's vertex moved "
            "into it by 2^-18 of the object's size (at most a sixteenth of "
            "the tolerance; in the certified bound), so that the parts stay "
            "apart in an STL's floats\n", r->pinches,
            r->pinches == 1 ? "ex" : "ices");
  if (r->sharp_apart && !r->sharp_off)
    fprintf(f, "  sharp cells given up locally: %ld about a crack or a "
            "self-intersection that two sharp cells left between them were "
            "meshed again by their tetrahedra (their edges there within the "
            "tolerance, not exact); the other sharp cells were kept\n",
            r->sharp_apart);
  if (r->sharp_off == 1)
    fprintf(f, "  sharp cells given up: two of them decided a degenerate "
            "case apart; the mesh was made again without them\n");
  else if (r->sharp_off)
    fprintf(f, "  sharp cells given up: the mesh made with them intersected "
            "itself; it was made again without them\n");
  if (r->float_joined && r->float_apart)
    fprintf(f, "  floats: %ld vert%s that the file's floats put on another's "
            "place (a sliver or gap below 2^-24 of the coordinates) kept "
            "apart, each moved into its own part by at most %.3g (in the "
            "certified bound); the floats' mesh checked again: no "
            "self-intersections\n", r->float_joined,
            r->float_joined == 1 ? "ex" : "ices", r->float_moved);
  else if (r->float_joined)
    fprintf(f, "  floats: %ld vert%s that the file's floats put on "
            "another's place joined (a sliver or gap below 2^-24 of the "
            "coordinates), %ld triangle%s that closed up and %ld pair%s "
            "facing apart dropped, %ld vert%s where the joined fans met at a "
            "point parted, each vertex moved at most %.3g (in the certified "
            "bound); the floats' mesh checked again: closed, oriented, no "
            "self-intersections, the same topology\n",
            r->float_joined, r->float_joined == 1 ? "ex" : "ices",
            r->float_closed, r->float_closed == 1 ? "" : "s", r->float_pairs,
            r->float_pairs == 1 ? "" : "s", r->float_parted,
            r->float_parted == 1 ? "ex" : "ices", r->float_moved);
  /* a closed orientable surface of c components has Euler
     characteristic 2c - 2g, g the sum of their genera */
  fprintf(f, "  topology: %ld component%s, Euler characteristic %ld (genus "
          "%ld in all); the object's own is not proven: where it is thinner "
          "than about twice the tolerance the mesh can pinch it or leave "
          "islands\n", r->components, r->components == 1 ? "" : "s",
          r->euler, r->components - r->euler / 2);
  if (r->cover_topo)
    fprintf(f, "  topology changed by the rounds: the mesh first made had %ld "
            "component%s, Euler characteristic %ld, and parts of the surface "
            "not proven within the tolerance of it; this one, made with those "
            "cells split, has every part proven: a part or gap thinner than "
            "the first cells was found (an island, a thin sheet) or opened "
            "in places\n", r->first_components,
            r->first_components == 1 ? "" : "s", r->first_euler);
  fprintf(f, "  checked: no self-intersections, %ld triangle pairs tested "
          "exactly (%ld signs in exact arithmetic) in %.2f s\n", r->pairs,
          r->pairs_exact, r->check_seconds);
  fprintf(f, "  distance to the surface: certified <= %.4g (requested %.4g; vertices within "
          "%.2g of the surface); measured %.3g (the largest distance to "
          "the surface along the normal or an axis from %d points of the triangles)\n", r->certified, e, r->vtol,
          r->measured, r->samples);
  if (r->cover_unproven)
    fprintf(f, "  surface to mesh: NOT proven within %.4g of the mesh in %ld "
            "cells, where a part or gap thinner than the cells may be lost or "
            "closed (the first near (%.6g, %.6g, %.6g)); every other part "
            "proven within it", e, r->cover_unproven, r->cover_at[0],
            r->cover_at[1], r->cover_at[2]);
  else
    fprintf(f, "  surface to mesh: every part proven within %.4g of the mesh",
            r->cover);
  fprintf(f, " (%ld smooth cells by %ld columns, the rest by %ld boxes; %.2f s",
          r->cover_colcells, r->cover_columns, r->cover_boxes, r->cover_seconds);
  if (r->cover_rounds && !r->cover_kept)
    fprintf(f, "; meshed %d more time%s, %ld cells split where it was not "
            "proven%s", r->cover_rounds, r->cover_rounds == 1 ? "" : "s",
            r->cover_split, r->cover_wide == 2 ? ", beside cells with "
            "two surfaces too, a groove (kept: its topology is the first "
            "mesh's)" : r->cover_wide ? ", beside cells with two surfaces "
            "too" : "");
  else if (r->cover_rounds)
    fprintf(f, "; meshed %d more time%s with the cells not proven split "
            "(%ld in the last), the last not kept: it proved no more, or "
            "changed the components or Euler characteristic (a thin part "
            "or gap opened in some cells and not beside them), or failed "
            "its checks",
            r->cover_rounds, r->cover_rounds == 1 ? "" : "s", r->cover_split);
  fprintf(f, ")\n");
  fprintf(f, "  crossings: %ld by ray spans, %ld by bisection\n",
          r->crossings - r->bisected, r->bisected);
}

/* The scene with its root intersected with the box [lo, hi] as six
   sharp halfspaces, appended to a copy of the node array (the nodes'
   tapes and soft objects stay the scene's: free only out->nodes). The
   box's faces are then planes of the mesher's sharp and plane cells, so
   a cut through the object has its edges and corners exact, where a
   clip box splits the cells along them to the finest level. 0, or -1
   out of memory or when the root is not the last node (its subtree
   and the box's would not be contiguous). */
static int box_scene(const Scene *s, const double lo[3], const double hi[3],
                     Scene *out) {
  *out = *s;
  out->nodes = NULL;
  if (s->root != s->n - 1) return -1;
  out->cap = s->n + 12;   /* 6 halfspaces, 6 intersections: no realloc */
  out->nodes = malloc((size_t)out->cap * sizeof *out->nodes);
  if (!out->nodes) return -1;
  memcpy(out->nodes, s->nodes, (size_t)s->n * sizeof *s->nodes);
  int root = s->root, tag = s->nodes[root].tag, box = -1;
  for (int k = 0; k < 6; k++) {
    ScNode h;
    memset(&h, 0, sizeof h);
    h.kind = SC_HALFSPACE;
    h.a = h.b = -1;
    h.tag = tag;
    int a = k % 3;
    h.n[a] = k < 3 ? -1 : 1;   /* -x < -lo, that is x > lo; x < hi */
    h.d = k < 3 ? -lo[a] : hi[a];
    int i = scene_add(out, &h);
    box = box < 0 ? i : scene_add_op(out, SC_INTER, box, i, tag);
  }
  scene_add_op(out, SC_INTER, root, box, tag);
  return 0;
}

static int do_mesh(const struct Scene *s0, const MeshSettings *ms,
                   const char *path, int quiet, int *bad, char *err,
                   size_t errlen) {
  Mesh *m;
  MeshReport rep;
  MeshSettings m2 = *ms;
  /* with Bounds, the box's faces as sharp planes (box_scene); the
     colours are still the object's parts' */
  Scene boxed;
  const Scene *s = s0;
  if (ms->has_bounds && box_scene(s0, ms->lo, ms->hi, &boxed) == 0) s = &boxed;
  int rc = 0;
  if (m2.tol < 0) { /* the default: relative to the object's box */
    double lo[3], hi[3], size = 0;
    int bounded = render_node_box(s0, s0->root, lo, hi);
    if (!bounded && m2.has_bounds) {
      memcpy(lo, m2.lo, sizeof lo);
      memcpy(hi, m2.hi, sizeof hi);
      bounded = 1;
    }
    for (int i = 0; bounded && i < 3; i++)
      if (isfinite(hi[i] - lo[i])) size = fmax(size, hi[i] - lo[i]);
    m2.tol = size > 0 ? MESH_DEFAULT_REL * size : 1;
  }
  rc = mesh_scene(s, s->root, &m2, &m, &rep, bad, err, errlen);
  if (rc) goto out;
  size_t pl = strlen(path);
  /* STL, PLY and 3MF keep floats: where they join vertices, the mesh
     they hold made a mesh again and checked (mesh_float.h) */
  MeshFloatReport fr = {0};
  if (pl > 4 && strcmp(path + pl - 4, ".obj") && mesh_to_floats(m, m2.tol / 16, &fr) < 0) {
    mesh_free(m);
    snprintf(err, errlen, "out of memory while rounding the mesh to floats");
    rc = -1;
    goto out;
  }
  if (fr.ok) {
    rep.triangles = m->nt;
    rep.vertices = m->nv;
    rep.certified += fr.moved;
    rep.float_joined = fr.joined;
    rep.float_closed = fr.closed;
    rep.float_pairs = fr.pairs;
    rep.float_moved = fr.moved;
    rep.float_apart = fr.kept_apart;
    rep.float_parted = fr.parted;
  }
  if (pl > 4 && (!strcmp(path + pl - 4, ".ply") || !strcmp(path + pl - 4, ".3mf"))) {
    /* the renderer's default object colour where no Colour is given */
    static const double grey[3] = {0.80, 0.78, 0.72};
    if (mesh_colour(s, s0->root, m, grey, 4 * rep.vtol) < 0) {
      mesh_free(m);
      snprintf(err, errlen, "out of memory while colouring the mesh");
      rc = -1;
      goto out;
    }
  }
  rc = mesh_write(m, path, err, errlen) ? -1 : 0;
  long joined = pl > 4 && strcmp(path + pl - 4, ".obj") ? mesh_float_joined(m) : 0;
  mesh_free(m);
  if (!rc && !quiet) report(stderr, &rep, path, m2.tol);
  if (!rc && joined > 0)
    fprintf(stderr, "qcs: warning: %s keeps floats, and %ld of the mesh's "
            "vertices fall%s on another's place in them (a feature below "
            "2^-24 of its coordinates, a sliver or gap about 1e-7 of them "
            "wide): the file is not the closed mesh that was checked; a .obj "
            "keeps the checked one to the bit\n", path, joined,
            joined == 1 ? "s" : "");
out:
  if (s == &boxed) free(boxed.nodes);
  return rc;
}

/* Appends to err (of errlen bytes) a box to give an unbounded object,
   in the command line's form (cli) or as Bounds, when one is found. */
static void suggest_bounds(const Scene *s, int cli, char *err, size_t errlen) {
  double lo[3], hi[3];
  int r = mesh_suggest_bounds(s, s->root, lo, hi);
  if (!r) return;
  char v[6][32];
  for (int k = 0; k < 3; k++) {
    format_real(v[k], lo[k]);
    format_real(v[3 + k], hi[k]);
  }
  size_t len = strlen(err);
  if (cli)
    snprintf(err + len, errlen - len, ", e.g. --bounds %s,%s,%s,%s,%s,%s",
             v[0], v[1], v[2], v[3], v[4], v[5]);
  else
    snprintf(err + len, errlen - len, ", e.g. Bounds (%s, %s, %s) "
             "(%s, %s, %s)", v[0], v[1], v[2], v[3], v[4], v[5]);
  static const char *face[6] = {"low x", "low y", "low z",
                                "high x", "high y", "high z"};
  len = strlen(err);
  snprintf(err + len, errlen - len, " (the box of the bounded parts, padded");
  for (int k = 0, first = 1; k < 6; k++)
    if (r >> 1 >> k & 1) {
      len = strlen(err);
      snprintf(err + len, errlen - len, "%s %s", first ? "; its" : ",", face[k]);
      first = 0;
    }
  len = strlen(err);
  snprintf(err + len, errlen - len, "%s)",
           r >> 1 ? " face on the unbounded part's plane" : "");
}

int mesh_lang_capture(void *ctx, const struct Scene *s,
                      const struct RenderSettings *rs, const char *path,
                      char *err, size_t errlen) {
  const MeshCli *cli = ctx;
  MeshSettings ms = {0};
  ms.tol = -1;
  ms.max_triangles = MESH_DEFAULT_MAX_TRIANGLES;
  if (cli) { /* qcs -o: main.c */
    if (cli->I) ms.max_memory = cli->I->max_memory;
    if (cli->tol > 0) ms.tol = cli->tol;
    if (cli->has_bounds) {
      ms.has_bounds = 1;
      memcpy(ms.lo, cli->lo, sizeof ms.lo);
      memcpy(ms.hi, cli->hi, sizeof ms.hi);
    }
  }
  int bad;
  char e2[400];
  int rc = do_mesh(s, &ms, path, 0, &bad, e2, sizeof e2);
  if (rc == 0) return 0;
  if (rc == MESH_EUNBOUNDED) { /* the command line's way to give the box */
    snprintf(e2, sizeof e2, "the object is unbounded (it has no finite "
             "box): give --bounds X0,Y0,Z0,X1,Y1,Z1 to mesh the part inside "
             "a box");
    suggest_bounds(s, 1, e2, sizeof e2);
  }
  if (bad >= 0) {
    Pos p = compile_node_pos(s, bad);
    if (p.src)
      snprintf(err, errlen, "%s (the %s part: %s:%d:%d)", e2,
               rc == MESH_EUNBOUNDED ? "unbounded" : "thin", p.src->name,
               p.line, p.col);
    else snprintf(err, errlen, "%s", e2);
  } else {
    snprintf(err, errlen, "%s", e2);
  }
  return -1;
}

static int con_is(Value *v, const char *name) {
  return v->kind == V_CON && !strcmp(v->u.con.con->name, name);
}

/* meshWith settings file obj */
static Value *bi_mesh_with(Interp *I, Value **args, Pos pos) {
  pos = eval_user_pos(I, pos); /* mesh is meshWith [] in the prelude */
  const char *path = force_str(I, args[1], pos, "the output file name");
  MeshSettings ms = {0};
  ms.tol = -1;
  ms.max_triangles = MESH_DEFAULT_MAX_TRIANGLES;
  ms.max_memory = I->max_memory; /* the values' limit bounds a mesh too */
  int quiet = 0;
  for (Value *l = force(I, args[0]);; l = force(I, l->u.cons.tail)) {
    if (l->kind == V_NIL) break;
    if (l->kind != V_CONS)
      qcs_error(pos, "the settings of meshWith are a list, not %s",
                val_describe(l));
    Value *s = force(I, l->u.cons.head);
    Pos sp = s->kind == V_CON && s->u.con.pos ? *s->u.con.pos : pos;
    if (con_is(s, "Tolerance")) {
      double t = force_num(I, s->u.con.args[0], sp, "the mesh tolerance");
      if (!(t > 0) || !isfinite(t))
        qcs_error(sp, "the mesh tolerance must be finite and > 0, not %g", t);
      ms.tol = t;
    } else if (con_is(s, "Bounds")) {
      force_vec3(I, s->u.con.args[0], sp, "the low corner", ms.lo);
      force_vec3(I, s->u.con.args[1], sp, "the high corner", ms.hi);
      for (int i = 0; i < 3; i++)
        if (!isfinite(ms.lo[i]) || !isfinite(ms.hi[i]) || !(ms.lo[i] < ms.hi[i]))
          qcs_error(sp, "Bounds lo hi needs finite corners with lo < hi on "
                    "every axis");
      ms.has_bounds = 1;
    } else if (con_is(s, "MaxTriangles")) {
      double n = force_num(I, s->u.con.args[0], sp, "the triangle limit");
      if (!(n >= 1) || n > 1e9 || n != floor(n))
        qcs_error(sp, "MaxTriangles needs a whole number from 1 to 10^9");
      ms.max_triangles = (size_t)n;
    } else if (con_is(s, "Quiet")) {
      quiet = 1;
    } else if (con_is(s, "Uniform")) {
      ms.uniform = 1;
    } else {
      char buf[160];
      val_brief(s, buf, sizeof buf);
      qcs_error(sp, "not a mesh setting: %s (meshWith takes Tolerance, "
                "Bounds, MaxTriangles, Quiet, Uniform)", buf);
    }
  }
  if (!mesh_is_mesh_path(path))
    qcs_error(pos, "cannot write %s: a mesh is written as .stl, .obj, .ply "
              "or .3mf", path);
  char err[512];
  if (render_writable(path, err, sizeof err) < 0) qcs_error(pos, "%s", err);
  Scene *s = compile_scene(I, args[2], pos);
  int bad = -1;
  int rc = do_mesh(s, &ms, path, quiet, &bad, err, sizeof err);
  Pos bp = bad >= 0 ? compile_node_pos(s, bad) : pos;
  if (rc == MESH_EUNBOUNDED) suggest_bounds(s, 0, err, sizeof err);
  scene_free(s);
  if (rc) {
    if (bad >= 0 && bp.src)
      qcs_error(bp, "%s: %s", path, err);
    qcs_error(pos, "%s: %s", path, err);
  }
  return val_str(path);
}

static const Builtin mesh_builtins[] = {
    {"meshWith", 3, bi_mesh_with,
     "meshWith settings file object: a closed triangle mesh (.stl, .obj, "
     ".ply, .3mf) "
     "within Tolerance e; e.g. meshWith [Tolerance 0.05, Quiet] "
     "\"cube.obj\" (Rounded 0.1 UnitCube)"},
};

void mesh_lang_install(Interp *I) {
  for (size_t i = 0; i < sizeof mesh_builtins / sizeof *mesh_builtins; i++)
    builtin_define(I, &mesh_builtins[i]);
}
