/* render_lang.c: rendering from the language and the command line.
 *
 *   render "out.png" scene
 *   renderWith [Size 600 380, Camera eye at fov, Light pos, ...] "out.exr" scene
 *
 * The settings are constructors declared in the prelude (:: Setting);
 * anything not given takes the conventions of the canonical scenes,
 * and with no Camera the scene's bounds are framed automatically. Options
 * of the command line (-o, --size, --spp, --threads) override a script's
 * own settings. The render's report goes to stderr; the value of a render
 * is the name of the file written. */
#include "bind/render_lang.h"

#include <gc.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "lang/builtins.h"
#include "lang/eval.h"
#include "render/image.h"
#include "render/render.h"
#include "bind/compile.h"
#include "bind/report.h"

_Static_assert(QCS_MAX_PIXELS_CAP == (unsigned long long)IMG_MAX_PIXELS,
               "the max-pixels limit's cap is the renderer's");

int render_writable(const char *path, char *err, size_t errlen) {
  const char *slash = strrchr(path, '/');
  char *dir = slash ? strndup(path, slash == path ? 1 : (size_t)(slash - path))
                    : strdup(".");
  if (!dir) {
    snprintf(err, errlen, "cannot write %s: out of memory", path);
    return -1;
  }
  int ok = access(dir, W_OK | X_OK) == 0;
  int e = errno;
  free(dir);
  if (!ok) {
    snprintf(err, errlen, "cannot write %s: %s", path, strerror(e));
    return -1;
  }
  if (slash && !slash[1]) {
    snprintf(err, errlen, "cannot write %s: it names a folder", path);
    return -1;
  }
  return 0;
}

/* The overrides live in the interpreter's host slot, which this layer
   owns (lang/value.h). */
static RenderOverrides *overrides_of(Interp *I) { return I->host; }

RenderOverrides *render_get_overrides(Interp *I) { return overrides_of(I); }

void render_set_overrides(Interp *I, RenderOverrides *o) { I->host = o; }

static Value *render_scene_item(Interp *I, void *ud) {
  Sym *s = sym_intern(I, "scene", 5);
  Value *v = render_value(I, NULL, ud, s->global, s->def_pos);
  RenderOverrides *ov = overrides_of(I);
  return ov && ov->capture ? NULL : v; /* a captured render wrote nothing */
}

RunStatus render_lang_scene(Interp *I, const char *path) {
  Sym *s = sym_intern(I, "scene", 5);
  if (!s->global) {
    fprintf(stderr, "qcs: error: -o %s: the scripts render nothing and "
            "define no `scene` to render\n", path);
    return RUN_ERROR;
  }
  return interp_run_item(I, s->def_pos, render_scene_item, (void *)path);
}

static int con_is(Value *v, const char *name) {
  return v->kind == V_CON && !strcmp(v->u.con.con->name, name);
}

static double arg_num(Interp *I, Value *v, int i, Pos pos, const char *what) {
  return force_num(I, v->u.con.args[i], pos, what);
}

static void arg_vec(Interp *I, Value *v, int i, Pos pos, const char *what,
                    double out[3]) {
  force_vec3(I, v->u.con.args[i], pos, what, out);
  if (!isfinite(out[0]) || !isfinite(out[1]) || !isfinite(out[2]))
    qcs_error(pos, "%s must be finite", what);
}

static int whole(double x, double lo, double hi) {
  return x == floor(x) && x >= lo && x <= hi;
}

/* Reads the settings list into rs. */
static void read_settings(Interp *I, Value *list, Pos pos, RenderSettings *rs,
                          int *quiet, int *float_pixels) {
  for (Value *l = force(I, list);; l = force(I, l->u.cons.tail)) {
    if (l->kind == V_NIL) break;
    if (l->kind != V_CONS)
      qcs_error(pos, "the settings of renderWith are a list, not %s",
                val_describe(l));
    Value *s = force(I, l->u.cons.head);
    Pos sp = s->kind == V_CON && s->u.con.pos ? *s->u.con.pos : pos;
    if (con_is(s, "Size")) {
      double w = arg_num(I, s, 0, sp, "the width"), h = arg_num(I, s, 1, sp, "the height");
      if (!whole(w, 1, IMG_MAX_SIDE) || !whole(h, 1, IMG_MAX_SIDE))
        qcs_error(sp, "Size needs whole numbers from 1 to %ld, not %g x %g",
                  IMG_MAX_SIDE, w, h);
      rs->width = (int)w;
      rs->height = (int)h;
    } else if (con_is(s, "Samples")) {
      double n = arg_num(I, s, 0, sp, "the samples per pixel");
      if (!whole(n, 1, 256))
        qcs_error(sp, "Samples needs a whole number from 1 to 256, not %g", n);
      rs->spp = (int)n;
    } else if (con_is(s, "Camera")) {
      arg_vec(I, s, 0, sp, "the camera's eye", rs->eye);
      arg_vec(I, s, 1, sp, "the point the camera looks at", rs->at);
      rs->fov = arg_num(I, s, 2, sp, "the field of view");
      rs->camera_set = 1;
    } else if (con_is(s, "Up")) {
      arg_vec(I, s, 0, sp, "the up direction", rs->up);
      if (rs->up[0] == 0 && rs->up[1] == 0 && rs->up[2] == 0)
        qcs_error(sp, "the up direction cannot be zero");
    } else if (con_is(s, "Light") || con_is(s, "PointLight")) {
      if (rs->nlights == RENDER_MAX_LIGHTS)
        qcs_error(sp, "at most %d lights", RENDER_MAX_LIGHTS);
      arg_vec(I, s, 0, sp, "the light's position", rs->lights[rs->nlights]);
      double in = con_is(s, "PointLight")
                      ? arg_num(I, s, 1, sp, "the light's intensity") : 1;
      if (!isfinite(in) || in < 0)
        qcs_error(sp, "a light's intensity must be finite and >= 0");
      rs->light_intensity[rs->nlights++] = in;
    } else if (con_is(s, "Background")) {
      arg_vec(I, s, 0, sp, "the background colour", rs->background);
    } else if (con_is(s, "ObjectColour")) {
      arg_vec(I, s, 0, sp, "the object colour", rs->object_colour);
    } else if (con_is(s, "FloorColour")) {
      arg_vec(I, s, 0, sp, "the floor colour", rs->floor_colour);
    } else if (con_is(s, "Ambient")) {
      rs->ambient = arg_num(I, s, 0, sp, "the ambient light");
      if (!isfinite(rs->ambient) || rs->ambient < 0)
        qcs_error(sp, "the ambient light must be finite and >= 0, not %g",
                  rs->ambient);
    } else if (con_is(s, "Tolerance")) {
      double t = arg_num(I, s, 0, sp, "the root tolerance");
      if (!(t > 0) || !isfinite(t))
        qcs_error(sp, "the root tolerance must be finite and > 0, not %g", t);
      rs->tol = t;
    } else if (con_is(s, "Shadows")) {
      rs->shadows = force_bool(I, s->u.con.args[0], sp, "Shadows");
    } else if (con_is(s, "Threads")) {
      double n = arg_num(I, s, 0, sp, "the thread count");
      if (!whole(n, 0, 256)) qcs_error(sp, "Threads needs 0 (all cores) to 256");
      rs->threads = (int)n;
    } else if (con_is(s, "CostChannel")) {
      rs->aovs |= IMG_COST;
    } else if (con_is(s, "FloatPixels")) {
      *float_pixels = 1;
    } else if (con_is(s, "Quiet")) {
      *quiet = 1;
    } else {
      char buf[160];
      val_brief(s, buf, sizeof buf);
      qcs_error(sp, "not a render setting: %s (see :browse! for Size, "
                "Samples, Camera, Up, Light, PointLight, Background, "
                "ObjectColour, FloorColour, Ambient, Tolerance, Shadows, "
                "Threads, CostChannel, FloatPixels, Quiet)", buf);
    }
  }
}

void render_tile_grid(int n, int w, int h, int *cols, int *rows) {
  double best = INFINITY;
  *cols = n;
  *rows = 1;
  for (int c = n; c >= 1; c--) {
    if (n % c) continue;
    int r = n / c;
    double cost = fabs(log(((double)w / c) / ((double)h / r)));
    if (cost < best - 1e-12) {
      best = cost;
      *cols = c;
      *rows = r;
    }
  }
}

int render_crop_resolve(const RenderOverrides *o, int w, int h,
                        RenderSettings *rs, char *err, size_t errlen) {
  rs->crop_x0 = rs->crop_x1 = rs->crop_y0 = rs->crop_y1 = 0;
  if (o->tile_count) {
    int cols, rows;
    render_tile_grid(o->tile_count, w, h, &cols, &rows);
    if (cols > w || rows > h) {
      snprintf(err, errlen, "--tile %d/%d: a grid of %dx%d tiles is finer "
               "than the %dx%d image", o->tile_index, o->tile_count, cols,
               rows, w, h);
      return -1;
    }
    int i = o->tile_index - 1, cx = i % cols, cy = i / cols;
    rs->crop_x0 = (int)((long)cx * w / cols);
    rs->crop_x1 = (int)((long)(cx + 1) * w / cols);
    rs->crop_y0 = (int)((long)cy * h / rows);
    rs->crop_y1 = (int)((long)(cy + 1) * h / rows);
    return 0;
  }
  if (!o->crop_set) return 0;
  int v[4];
  for (int k = 0; k < 4; k++) {
    int side = k < 2 ? w : h;
    double x = o->crop[k];
    v[k] = o->crop_frac[k] ? (int)floor(x * side + 0.5) : (int)x;
  }
  if (v[0] < 0 || v[1] > w || v[0] >= v[1] || v[2] < 0 || v[3] > h ||
      v[2] >= v[3]) {
    snprintf(err, errlen, "--crop %d,%d,%d,%d is not a part of the %dx%d "
             "image (columns x0,x1 then rows y0,y1, from 0, the ends "
             "excluded)", v[0], v[1], v[2], v[3], w, h);
    return -1;
  }
  rs->crop_x0 = v[0];
  rs->crop_x1 = v[1];
  rs->crop_y0 = v[2];
  rs->crop_y1 = v[3];
  return 0;
}

/* OUT.k.EXT for the k-th render of a script run with -o OUT.EXT. */
static void numbered_path(char *buf, size_t n, const char *out, int k) {
  const char *slash = strrchr(out, '/');
  const char *dot = strrchr(slash ? slash + 1 : out, '.');
  if (!dot) dot = out + strlen(out);
  snprintf(buf, n, "%.*s.%d%s", (int)(dot - out), out, k, dot);
}

void render_lang_settings(Interp *I, Value *settings, Pos pos,
                          RenderSettings *rs) {
  int quiet = 0, float_pixels = 0;
  render_defaults(rs);
  if (settings) read_settings(I, settings, pos, rs, &quiet, &float_pixels);
}

const char *render_frame_path(const char *path, int frame) {
  size_t len = strlen(path), hash_end = 0, hashes = 0;
  for (size_t i = len; i > 0; i--)
    if (path[i - 1] == '#') {
      hash_end = i;
      while (i > 0 && path[i - 1] == '#') i--, hashes++;
      break;
    }
  size_t before, after;
  int width;
  const char *dot = "";
  if (hashes) {
    before = hash_end - hashes;
    after = hash_end;
    width = (int)hashes;
  } else {
    const char *slash = strrchr(path, '/'), *ext = strrchr(path, '.');
    if (!ext || (slash && ext < slash) || ext == path || ext[-1] == '/')
      ext = path + len;
    before = after = (size_t)(ext - path);
    width = 4;
    dot = ".";
  }
  size_t n = len + 32 + (size_t)width;
  char *out = GC_MALLOC_ATOMIC(n);
  snprintf(out, n, "%.*s%s%0*d%s", (int)before, path, dot, width, frame,
           path + after);
  return out;
}

Value *render_value(Interp *I, Value *settings, const char *path, Value *obj,
                    Pos pos) {
  RenderSettings rs;
  pos = eval_user_pos(I, pos); /* render is renderWith [] in the prelude */
  render_defaults(&rs);
  if (isatty(2)) rs.progress = report_progress;
  int quiet = 0, float_pixels = 0;
  if (settings) read_settings(I, settings, pos, &rs, &quiet, &float_pixels);
  RenderOverrides *ov = overrides_of(I);
  if (ov && ov->skip) {
    ov->skipped++;
    return val_str(path);
  }
  char numbered[4096];
  if (ov) {
    /* -o with a script that renders several times (one frame of an
       animation counts once): out.png, out.2.png, ... never one over
       another; frames get their number instead (--frames). */
    if (ov->output && ov->renders > 0 && !ov->capture && !ov->animating) {
      numbered_path(numbered, sizeof numbered, ov->output, ov->renders + 1);
      path = numbered;
    } else if (ov->output) {
      path = ov->output;
    }
    if (ov->animating) path = render_frame_path(path, ov->frame);
    if (ov->width) rs.width = ov->width, rs.height = ov->height;
    if (ov->spp) rs.spp = ov->spp;
    if (ov->threads) rs.threads = ov->threads;
    if (ov->tol > 0) rs.tol = ov->tol;
    if (ov->cost) rs.aovs |= IMG_COST;
    if (ov->float_pixels) float_pixels = 1;
    if (ov->alpha) rs.alpha = 1;
    ov->renders++;
  }
  /* The limits: a picture's size and its samples. */
  if ((unsigned long long)rs.width * (unsigned long long)rs.height >
      I->max_pixels)
    eval_limit_error(I, pos, "max-pixels", "the image is %d x %d = %llu "
                     "pixels, over %llu", rs.width, rs.height,
                     (unsigned long long)rs.width *
                         (unsigned long long)rs.height, I->max_pixels);
  if (rs.spp > I->max_spp)
    eval_limit_error(I, pos, "max-spp", "%d samples per pixel is over %d",
                     rs.spp, I->max_spp);
  char err[512];
  if (ov && ov->capture) {
    Scene *cs = compile_scene(I, obj, pos);
    int rc = ov->capture(ov->capture_ctx, cs, &rs, path, err, sizeof err);
    if (ov->keep && !rc) {
      scene_free(ov->kept);
      ov->kept = cs;
    } else {
      scene_free(cs);
    }
    if (rc) qcs_error(pos, "%s", err);
    return val_str(path);
  }
  if (img_format(path, err, sizeof err) < 0 ||
      render_writable(path, err, sizeof err) < 0)
    qcs_error(pos, "%s", err);
  if (ov && render_crop_resolve(ov, rs.width, rs.height, &rs, err,
                                sizeof err))
    qcs_error(pos, "%s", err);
  if (ov && ov->skip_existing && access(path, F_OK) == 0) {
    if (!quiet)
      fprintf(stderr, "%s exists: not rendered again (--skip-existing)\n",
              path);
    return val_str(path);
  }
  Scene *s = compile_scene(I, obj, pos);
  RenderReport rep;
  Image *im = render_scene(s, &rs, &rep, &qcs_interrupted, err, sizeof err);
  if (im && rep.unresolved > 0 && rep.unresolved_node >= 0)
    qcs_warning(compile_node_pos(s, rep.unresolved_node),
                "the root search left %ld segment%s of this object "
                "undecided (rays that run within rounding of its surface "
                "for a long stretch): a part that only touches those rays "
                "may be missing from %s", rep.unresolved,
                rep.unresolved == 1 ? "" : "s", path);
  scene_free(s);
  if (!im) {
    if (rep.interrupted) {
      qcs_interrupted = 0;
      qcs_error(pos, "render interrupted; %s was not written", path);
    }
    qcs_error(pos, "%s", err);
  }
  /* Which render of the script (of the frame, in an animation) this is,
     and the frame: the same frame rendered alone or in the whole run
     makes the same file. */
  char nth[16], fr[16];
  snprintf(nth, sizeof nth, "%d", ov ? ov->renders - ov->frame_renders : 1);
  snprintf(fr, sizeof fr, "%d", ov ? ov->frame : 0);
  if (img_set_attr(im, "qcs.render", nth) ||
      (ov && ov->animating && img_set_attr(im, "qcs.frame", fr))) {
    img_free(im);
    qcs_error(pos, "out of memory for %s", path);
  }
  ImgWriteOptions wo = {0};
  wo.float_pixels = float_pixels;
  wo.alpha = rs.alpha;
  wo.threads = rs.threads;
  struct timespec w0, w1;
  clock_gettime(CLOCK_MONOTONIC, &w0);
  int wr = img_write(im, path, &wo, err, sizeof err);
  clock_gettime(CLOCK_MONOTONIC, &w1);
  img_free(im);
  if (wr) qcs_error(pos, "%s", err);
  if (!quiet) {
    report_render(stderr, &rep, path);
    report_written(stderr, (double)(w1.tv_sec - w0.tv_sec) +
                               1e-9 * (double)(w1.tv_nsec - w0.tv_nsec));
  }
  return val_str(path);
}

/* renderWith settings file scene */
static Value *bi_render_with(Interp *I, Value **args, Pos pos) {
  const char *path = force_str(I, args[1], pos, "the output file name");
  return render_value(I, args[0], path, args[2], pos);
}

static const Builtin render_builtins[] = {
    {"renderWith", 3, bi_render_with,
     "renderWith settings file scene: render to file (.exr, .png, .ppm); "
     "e.g. renderWith [Size 60 38, Quiet] \"cube.png\" (Rounded 0.1 UnitCube)"},
};

void render_install(Interp *I) {
  for (size_t i = 0; i < sizeof render_builtins / sizeof *render_builtins; i++)
    builtin_define(I, &render_builtins[i]);
}
