/* render_lang.h: the render builtins of the language (renderWith; the
 * prelude defines render = renderWith []), and the command line's
 * overrides of a script's own render settings. */
#ifndef QCS_RENDER_LANG_H
#define QCS_RENDER_LANG_H

#include "lang/interp.h"
#include "lang/value.h"

struct Scene;
struct RenderSettings;

/* A capture hook (see RenderOverrides.capture): called with the compiled
   scene and the settings in force instead of rendering and writing. The
   scene and settings are only borrowed for the call. Returns 0, or -1
   with a message in err (raised as a qcs error at the render). */
typedef int (*RenderCapture)(void *ctx, const struct Scene *s,
                             const struct RenderSettings *rs,
                             const char *path, char *err, size_t errlen);

typedef struct RenderOverrides {
  const char *output;   /* -o FILE: replaces every render's file name */
  int width, height;    /* --size WxH (0: the script's) */
  int spp;              /* --spp N */
  int threads;          /* --threads N */
  double tol;           /* --tolerance T (0: the script's) */
  int cost;             /* --cost: add the root-finder cost channel */
  int float_pixels;     /* --float: EXR RGBA as 32-bit floats */
  int renders;          /* renders done so far; with output, render k > 1
                           writes OUT.k.EXT (out.2.png, ...) */
  /* Partial renders (a farm's tasks): --crop X0,X1,Y0,Y1 (pixels, end
     excluded; a value with a decimal point is a fraction of the side, as
     POV-Ray's +SC/+EC) or --tile I/N (1 <= I <= N, a grid of N cells
     chosen near square from the picture's size; render_tile_grid). */
  int crop_set;
  double crop[4];
  int crop_frac[4];
  int tile_index, tile_count;
  int alpha;            /* --alpha: transparent background (render.h) */
  int skip_existing;    /* --skip-existing: a render whose file exists is
                           not done (the writers are atomic: a file there
                           is whole) */
  RenderCapture capture;  /* non-NULL: renders call this instead (qcs
                             tradeoff); nothing is written */
  void *capture_ctx;
  int keep;             /* with capture: keep the scene captured last in
                           kept (the previous one is freed); the caller
                           owns kept and frees it with scene_free (qcs
                           view) */
  struct Scene *kept;
  int skip;             /* renders do nothing but count themselves in
                           skipped and give their file name (the REPL's
                           :reload) */
  int skipped;
  int animating;        /* --frames: every file name gets the frame's number */
  int frame;            /* the frame being rendered */
  int frame_renders;    /* renders done before this frame began */
} RenderOverrides;

/* An animation's file name for a frame: the last run of '#' in path
   replaced by the frame number, zero-padded to the run's length
   (out.####.png, frame 5: out.0005.png); a path without '#' gets
   .NNNN before its extension (out.png: out.0005.png). In the GC heap. */
const char *render_frame_path(const char *path, int frame);

void render_install(Interp *I);
/* The grid of --tile I/N for a w x h picture: cols x rows = n, the cells
   nearest square (ties: more columns). */
void render_tile_grid(int n, int w, int h, int *cols, int *rows);
/* The crop the overrides ask of a w x h picture, into rs's crop_* (left
   all 0 when none). 0, or -1 with a message. */
int render_crop_resolve(const RenderOverrides *o, int w, int h,
                        struct RenderSettings *rs, char *err, size_t errlen);
/* The conventions (render_defaults) with a settings list applied (NULL:
   none); errors raised at pos. FloatPixels and Quiet are accepted and
   mean nothing here. */
void render_lang_settings(Interp *I, Value *settings, Pos pos,
                          struct RenderSettings *rs);
/* 0 if a file can be made at path (its folder exists and may be written
   in), else -1 with "cannot write PATH: REASON" in err, so that a bad
   output name is refused before a long render rather than after it. As
   root a folder's permissions are not enforced; the write itself may
   still fail, and then leaves nothing behind (see image.h). */
int render_writable(const char *path, char *err, size_t errlen);
/* The overrides stay owned by the caller and must outlive I's use. */
void render_set_overrides(Interp *I, RenderOverrides *o);
/* The overrides in force (NULL: none). */
RenderOverrides *render_get_overrides(Interp *I);
/* Render the top-level `scene` to path (qcs -o FILE with scripts that
   render nothing); errors point at scene's definition. */
RunStatus render_lang_scene(Interp *I, const char *path);
/* Render obj to path with settings (a qcs list, or NULL for none); the
   value is the file name. Errors are raised with qcs_error at pos. */
Value *render_value(Interp *I, Value *settings, const char *path, Value *obj,
                    Pos pos);
#endif
