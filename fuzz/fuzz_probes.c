/* fuzz_probes: generated scenes and rays through the probes and the
 * renderer. The input bytes drive a small generator that writes a qcs
 * expression: a random CSG scene of rounded density trees, halfspaces and
 * soft objects (sphere, quadric and negative keys), with numbers drawn
 * from a table of hard cases (0, tiny and huge radii, 1e8 coordinates,
 * infinities and NaN made by arithmetic) or taken raw from the input, and
 * one probe over it: Roots, Trace, Density, Gradient, PointInObject,
 * Field, OuterBounds, InnerBounds, LG, Displacement, or a 12 x 8 render
 * (through a capture hook: nothing is written). Whatever the numbers, the
 * answer must be a value or a clean error. */
#include "fuzz.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>

#include "render/render.h"
#include "bind/render_lang.h"

typedef struct {
  const uint8_t *p;
  size_t n;
  char *out;
  size_t len, cap;
} Gen;

static unsigned byte(Gen *g) {
  if (!g->n) return 0;
  g->n--;
  return *g->p++;
}

static void emit(Gen *g, const char *fmt, ...) {
  va_list ap;
  for (;;) {
    va_start(ap, fmt);
    int k = vsnprintf(g->out + g->len, g->cap - g->len, fmt, ap);
    va_end(ap);
    if (k < 0) abort();
    if (g->len + (size_t)k < g->cap) { g->len += (size_t)k; return; }
    g->cap = 2 * g->cap + (size_t)k + 64;
    g->out = realloc(g->out, g->cap);
    if (!g->out) abort();
  }
}

static const char *const special[] = {
  "0", "1", "(-1)", "0.5", "0.25", "2", "1e-12", "1e-6", "1e3", "1e6", "1e8",
  "(-1e8)", "1e-300", "5e-324", "1e308", "(1e308 * 10)", "(-1e308 * 10)",
  "((1e308 * 10) - (1e308 * 10))", "0.1", "0.07", "0.9999999999999999",
  "1.0000000000000002", "(1 / 3)", "(sqrt 2)", "(-0.5)", "(-0)", "3", "1.75"};
#define NSPECIAL (sizeof special / sizeof *special)

/* Mostly ordinary numbers (quarters from -4 to 4), often a hard case from
   the table, now and then any double at all. */
static void number(Gen *g) {
  unsigned b = byte(g);
  if (b < 150) { emit(g, "(%g)", ((int)(b % 33) - 16) / 4.0); return; }
  if (b < 230) { emit(g, "%s", special[b % NSPECIAL]); return; }
  if (b < 240) { emit(g, "(%d)", (int)byte(g) - 128); return; }
  uint64_t u = 0;
  for (int i = 0; i < 8; i++) u = u << 8 | byte(g);
  double x;
  memcpy(&x, &u, sizeof x);
  if (isnan(x)) emit(g, "((1e308 * 10) - (1e308 * 10))");
  else if (isinf(x)) emit(g, x > 0 ? "(1e308 * 10)" : "(-1e308 * 10)");
  else emit(g, "(%.17g)", x);
}

static void vec(Gen *g) {
  emit(g, "(");
  number(g); emit(g, ", ");
  number(g); emit(g, ", ");
  number(g); emit(g, ")");
}

static void plane(Gen *g) {
  emit(g, "(");
  vec(g); emit(g, ", ");
  number(g); emit(g, ")");
}

static void tree(Gen *g, int depth);
static void obj(Gen *g, int depth);

static void key(Gen *g) {
  switch (byte(g) % 3) {
  case 0: emit(g, "Key "); vec(g); emit(g, " "); number(g); emit(g, " ");
          number(g); break;
  case 1: emit(g, "Ellipsoid "); vec(g); emit(g, " "); vec(g); emit(g, " ");
          number(g); break;
  default:
    emit(g, "QuadricKey (");
    for (int i = 0; i < 4; i++) {
      emit(g, i ? ", (" : "(");
      for (int j = 0; j < 4; j++) { if (j) emit(g, ", "); number(g); }
      emit(g, ")");
    }
    emit(g, ") "); number(g); emit(g, " "); number(g);
  }
}

static void transform(Gen *g, unsigned k) {
  static const char *const ax[] = {"\"x\"", "\"y\"", "\"z\""};
  if (k == 0) { emit(g, "Shift "); vec(g); }
  else if (k == 1) { emit(g, "Scale "); vec(g); }
  else { emit(g, "Rotate %s ", ax[byte(g) % 3]); number(g); }
}

static void tree(Gen *g, int depth) {
  unsigned k = byte(g) % (depth > 0 ? 12 : 4);
  emit(g, "(");
  switch (k) {
  case 0: emit(g, "UnitCube"); break;
  case 1: emit(g, "DensityHalfspace "); plane(g); break;
  case 2: emit(g, "RoundedHalfspace "); number(g); emit(g, " "); plane(g);
          break;
  case 3: emit(g, "Box "); vec(g); emit(g, " "); vec(g); break;
  case 4: case 5: case 6: case 7: {
    static const char *const op[] = {"Sum", "Product", "Difference",
                                     "DensityUnion"};
    emit(g, "%s ", op[k - 4]);
    tree(g, depth - 1); emit(g, " "); tree(g, depth - 1);
    break;
  }
  default:
    transform(g, k - 8);
    emit(g, " ");
    tree(g, depth - 1);
  }
  emit(g, ")");
}

static void obj(Gen *g, int depth) {
  unsigned k = byte(g) % (depth > 0 ? 13 : 6);
  emit(g, "(");
  switch (k) {
  case 0: case 1: emit(g, "Rounded "); number(g); emit(g, " "); tree(g, 2);
          break;
  case 2: emit(g, "Halfspace "); plane(g); break;
  case 3: {
    int n = (int)(byte(g) % 5);
    emit(g, "SoftObject "); number(g); emit(g, " [");
    for (int i = 0; i < n; i++) { if (i) emit(g, ", "); key(g); }
    emit(g, "]");
    break;
  }
  case 4: emit(g, byte(g) & 1 ? "Empty" : "Everything"); break;
  case 5: emit(g, "Rounded 0 UnitCube"); break;
  case 6: case 7: case 8: {
    static const char *const op[] = {"Union", "Intersection", "SetDifference"};
    emit(g, "%s ", op[k - 6]);
    obj(g, depth - 1); emit(g, " "); obj(g, depth - 1);
    break;
  }
  case 9: emit(g, "Colour "); vec(g); emit(g, " "); obj(g, depth - 1); break;
  default:
    transform(g, k - 10);
    emit(g, " ");
    obj(g, depth - 1);
  }
  emit(g, ")");
}

static void probe(Gen *g) {
  switch (byte(g) % 11) {
  case 0: emit(g, "Roots "); obj(g, 3); emit(g, " "); vec(g); emit(g, " ");
          vec(g); break;
  case 1: emit(g, "Trace "); obj(g, 2); emit(g, " "); vec(g); emit(g, " ");
          vec(g); break;
  case 2: emit(g, "Density "); number(g); emit(g, " "); vec(g); emit(g, " ");
          tree(g, 3); break;
  case 3: emit(g, "Gradient "); number(g); emit(g, " "); vec(g);
          emit(g, " "); tree(g, 3); break;
  case 4: emit(g, "PointInObject "); vec(g); emit(g, " "); obj(g, 3); break;
  case 5: emit(g, "Field "); vec(g); emit(g, " (SoftObject "); number(g);
          emit(g, " ["); key(g); emit(g, ", "); key(g); emit(g, "])"); break;
  case 6: emit(g, "OuterBounds "); number(g); emit(g, " "); number(g);
          emit(g, " "); tree(g, 3); break;
  case 7: emit(g, "InnerBounds "); number(g); emit(g, " "); number(g);
          emit(g, " "); tree(g, 3); break;
  case 8: emit(g, "LG "); number(g); emit(g, " "); tree(g, 3); emit(g, " ");
          vec(g); emit(g, " "); vec(g); emit(g, " ("); number(g);
          emit(g, ", "); number(g); emit(g, ")"); break;
  case 9: emit(g, "Displacement "); number(g); emit(g, " "); number(g);
          break;
  default:
    emit(g, "renderWith [Quiet, Tolerance "); number(g);
    emit(g, "] \"fuzz.png\" "); obj(g, 3);
  }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  static Interp *I;
  static RenderOverrides ov;
  if (!I) {
    I = bind_interp_new();
    ov.capture = fuzz_tiny_render;
    render_set_overrides(I, &ov);
    fuzz_limits(I);
  }
  FUZZ_STACK(I);
  Gen g = {data, size, malloc(256), 0, 256};
  if (!g.out) abort();
  probe(&g);
  emit(&g, "\n");
  /* QCS_FUZZ_SHOW=1: print the generated expression (to reproduce it). */
  if (getenv("QCS_FUZZ_SHOW")) fprintf(stderr, "%s", g.out);
  interp_run_string(I, "<fuzz>", g.out, MODE_SCRIPT);
  free(g.out);
  return 0;
}
