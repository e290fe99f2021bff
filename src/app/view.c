/* view.c: the live viewer in the browser. See view.h.
 *
 * The protocol (every request needs ?t=TOKEN; GET only, except /save):
 *   GET  /                  the page
 *   GET  /state?since=V     JSON: version, error, size, the scene's own
 *                           camera; waits up to 10 s for a version != V
 *   GET  /frame?CAM&step=S  a PNG finer than rung S (16: any) at camera
 *                           CAM; waits up to 5 s; headers X-Step, X-Version
 *                           409: another camera was asked for meanwhile
 *   GET  /probe?CAM&x=&y=   JSON: the probes of pixel (x, y)'s ray
 *   POST /save?CAM&fmt=png|exr  the full picture into the scene's folder
 *   POST /param?name=N&value=X  the declared parameter N set to the number
 *                           X (a slider): re-evaluated on the interpreter's
 *                           thread, /state then answers the new version
 *   POST /param?reset=1     every parameter back to the command line's
 * CAM is own=1 (the scene's camera) or eye=X,Y,Z&at=X,Y,Z&up=X,Y,Z&fov=F,
 * plus shadows=0|1 and ch=colour|depth|normal|cost. */
#include "app/view.h"

#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <microhttpd.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/inotify.h>
#include <sys/random.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "app/dynlib.h"
#include "bind/bind.h"
#include "bind/compile.h"
#include "bind/render_lang.h"
#include "core/density.h"
#include "core/lg.h"
#include "core/soft.h"
#include "lang/error.h"
#include "render/camera.h"
#include "render/image.h"
#include "render/render.h"
#include "scene/ray.h"

#include "view_page.inc"

/* libmicrohttpd is loaded when a viewer starts (app/dynlib.h): the
   functions this file calls, through a table of their own types. */
#define MHD_FUNCS(X)                                                          \
  X(MHD_start_daemon) X(MHD_stop_daemon) X(MHD_get_daemon_info)               \
  X(MHD_lookup_connection_value) X(MHD_lookup_connection_value_n)           \
  X(MHD_create_response_from_buffer)           \
  X(MHD_add_response_header) X(MHD_queue_response) X(MHD_destroy_response)
static struct {
#define X(f) __typeof__(f) *f;
  MHD_FUNCS(X)
#undef X
} mhd;
static int mhd_loaded;
static int mhd_load(void) {
  static const char *const sonames[] = {"libmicrohttpd.so.12",
                                        "libmicrohttpd.so", NULL};
  if (DYNLIB_LOAD(mhd, MHD_FUNCS, sonames, "libmicrohttpd12", "error: view"))
    return -1;
  mhd_loaded = 1;
  return 0;
}
#define MHD_start_daemon (mhd.MHD_start_daemon)
#define MHD_stop_daemon (mhd.MHD_stop_daemon)
#define MHD_get_daemon_info (mhd.MHD_get_daemon_info)
#define MHD_lookup_connection_value (mhd.MHD_lookup_connection_value)
#define MHD_lookup_connection_value_n (mhd.MHD_lookup_connection_value_n)
#define MHD_create_response_from_buffer (mhd.MHD_create_response_from_buffer)
#define MHD_add_response_header (mhd.MHD_add_response_header)
#define MHD_queue_response (mhd.MHD_queue_response)
#define MHD_destroy_response (mhd.MHD_destroy_response)

#define VIEW_CONN_MEMORY ((size_t)64 << 10)
#define RUNGS 4
static const int rung_step[RUNGS] = {8, 4, 2, 1};
#define MAX_EVENTS 4000   /* trace events kept for one probe */
#define PLOT_SAMPLES 200
#define MAX_PARAMS 64     /* parameters shown as controls */
#define PARAM_NAME 64     /* bytes of a parameter's name, with its 0 */

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

/* ---- a growable text buffer (malloc) ---- */

typedef struct Buf {
  char *p;
  size_t n, cap;
  int failed;
} Buf;

static void buf_printf(Buf *b, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
static void buf_printf(Buf *b, const char *fmt, ...) {
  if (b->failed) return;
  for (;;) {
    va_list ap;
    va_start(ap, fmt);
    size_t room = b->cap - b->n;
    int k = vsnprintf(b->p ? b->p + b->n : NULL, b->p ? room : 0, fmt, ap);
    va_end(ap);
    if (k < 0) {
      b->failed = 1;
      return;
    }
    if (b->p && (size_t)k < room) {
      b->n += (size_t)k;
      return;
    }
    size_t cap = b->cap ? b->cap * 2 : 1024;
    while (cap < b->n + (size_t)k + 1) cap *= 2;
    char *q = realloc(b->p, cap);
    if (!q) {
      b->failed = 1;
      return;
    }
    b->p = q;
    b->cap = cap;
  }
}

/* A JSON string literal of s. */
static void buf_json_str(Buf *b, const char *s) {
  buf_printf(b, "\"");
  for (; s && *s; s++) {
    unsigned char c = (unsigned char)*s;
    if (c == '"' || c == '\\') buf_printf(b, "\\%c", c);
    else if (c == '\n') buf_printf(b, "\\n");
    else if (c < 0x20) buf_printf(b, "\\u%04x", c);
    else buf_printf(b, "%c", c);
  }
  buf_printf(b, "\"");
}

static void buf_num(Buf *b, double x) {
  if (isfinite(x)) buf_printf(b, "%.17g", x);
  else buf_printf(b, "null");
}

static void buf_vec(Buf *b, const double v[3]) {
  buf_printf(b, "[");
  for (int i = 0; i < 3; i++) {
    if (i) buf_printf(b, ",");
    buf_num(b, v[i]);
  }
  buf_printf(b, "]");
}

/* ---- snapshots of the scene ---- */

typedef struct Snap {
  Scene *s;
  RenderSettings rs;       /* the scene's own settings */
  char **where;            /* per node: "FILE:LINE:COL" or NULL */
  unsigned gen;
  int refs;                /* under View.mu */
  double eye[3], at[3], up[3], fov; /* the scene's own camera, resolved */
} Snap;

static void snap_free(Snap *sn) {
  if (!sn) return;
  if (sn->where)
    for (int i = 0; i < sn->s->n; i++) free(sn->where[i]);
  free(sn->where);
  scene_free(sn->s);
  free(sn);
}

/* ---- the viewer's shared state ---- */

enum { CH_COLOUR, CH_DEPTH, CH_NORMAL, CH_COST, CH_N };
static const char *const ch_names[CH_N] = {"colour", "depth", "normal",
                                           "cost"};

typedef struct Key {
  int own;                 /* the scene's own camera */
  double eye[3], at[3], up[3], fov;
  int shadows;             /* 0, 1 */
  int ch;
} Key;

typedef struct Frame {
  unsigned char *png;
  size_t len;
} Frame;

/* A declared parameter as the page shows it (a slider or a number box). */
typedef struct VParam {
  char name[PARAM_NAME];
  char text[80];           /* the default's source text */
  char doc[300];
  int has_range, numeric;
  double lo, hi, value;    /* value: the one the picture was made with */
} VParam;

/* A value asked for by the page, kept across saves of the file. */
typedef struct Wish {
  char name[PARAM_NAME];
  double x;
} Wish;

typedef struct View {
  pthread_mutex_t mu;
  pthread_cond_t cv;       /* anything changed: a frame, a version, quit */
  pthread_cond_t work;     /* the render thread's: a new wish */
  Snap *snap;              /* the last good scene, or NULL */
  unsigned version;        /* bumped by every evaluation, good or bad */
  char *error;             /* the last evaluation's error text, or NULL */
  char file[4096];         /* the file followed ("" for :view) */
  char dir[4096];          /* its folder: where saves go */
  char stem[256];
  char **deps;             /* the files the last evaluation imported */
  int ndeps;
  Key want;                /* what the render thread should render */
  int have_want;
  Key cur;                 /* what frames[] hold ... */
  unsigned cur_gen;        /* ... of this snapshot */
  int cur_valid;
  Frame frames[RUNGS];
  char frame_err[300];     /* a rung that failed (not cancelled) */
  atomic_int cancel;
  int quit;
  int threads;
  char token[33];
  char host_ok[3][80];     /* Host headers accepted */
  int port;
  pthread_mutex_t save_mu;
  int saves;
  atomic_long requests, refused;
  VParam params[MAX_PARAMS]; /* of the last good evaluation */
  int nparams;
  Wish wish[MAX_PARAMS];   /* the page's values, applied by evaluate */
  int nwish;
  int wish_dirty;          /* the page asked since the last evaluate */
  int wish_reset;          /* ... for the command line's values again */
  int wake[2];             /* a pipe: wakes the interpreter's thread */
  Interp *live;            /* the interpreter of the last good evaluation
                              (the interpreter's thread only) */
} View;

static void snap_release(View *v, Snap *sn) {
  if (!sn) return;
  pthread_mutex_lock(&v->mu);
  int last = --sn->refs == 0;
  pthread_mutex_unlock(&v->mu);
  if (last) snap_free(sn);
}

static Snap *snap_acquire(View *v) {
  pthread_mutex_lock(&v->mu);
  Snap *sn = v->snap;
  if (sn) sn->refs++;
  pthread_mutex_unlock(&v->mu);
  return sn;
}

static void frames_clear(View *v) {
  for (int i = 0; i < RUNGS; i++) {
    free(v->frames[i].png);
    v->frames[i].png = NULL;
    v->frames[i].len = 0;
  }
  v->frame_err[0] = 0;
}

static int key_eq(const Key *a, const Key *b) {
  if (a->own != b->own || a->shadows != b->shadows || a->ch != b->ch)
    return 0;
  if (a->own) return 1;
  for (int i = 0; i < 3; i++)
    if (a->eye[i] != b->eye[i] || a->at[i] != b->at[i] || a->up[i] != b->up[i])
      return 0;
  return a->fov == b->fov;
}

/* The settings of a frame at key k from the snapshot's own. */
static void key_settings(const View *v, const Snap *sn, const Key *k,
                         RenderSettings *rs) {
  *rs = sn->rs;
  rs->progress = NULL;
  if (v->threads) rs->threads = v->threads;
  if (!k->own) {
    rs->camera_set = 1;
    memcpy(rs->eye, k->eye, sizeof rs->eye);
    memcpy(rs->at, k->at, sizeof rs->at);
    memcpy(rs->up, k->up, sizeof rs->up);
    rs->fov = k->fov;
  }
  rs->shadows = k->shadows;
  rs->aovs = IMG_Z | IMG_N | (k->ch == CH_COST ? IMG_COST : 0);
}

/* A false-colour ramp (dark blue, cyan, yellow, red) at u in [0, 1], as
   linear values for the sRGB writer. */
static void ramp(double u, float out[3]) {
  static const double stops[5][3] = {{0.05, 0.03, 0.25}, {0.1, 0.45, 0.85},
                                     {0.2, 0.85, 0.6},   {0.95, 0.85, 0.2},
                                     {0.85, 0.15, 0.1}};
  if (!(u >= 0)) u = 0;
  if (u > 1) u = 1;
  double x = u * 4;
  int i = (int)x;
  if (i > 3) i = 3;
  double f = x - i;
  for (int c = 0; c < 3; c++)
    out[c] = (float)img_srgb_decode(stops[i][c] * (1 - f) + stops[i + 1][c] * f);
}

/* The channel ch of im as colours, in place. */
static void false_colour(Image *im, int ch) {
  size_t n = (size_t)im->width * (size_t)im->height;
  double lo = INFINITY, hi = -INFINITY;
  for (size_t i = 0; i < n; i++) {
    double x = ch == CH_DEPTH && im->z ? im->z[i]
               : ch == CH_COST && im->cost ? log1p(im->cost[i]) : 0;
    if (isfinite(x)) {
      if (x < lo) lo = x;
      if (x > hi) hi = x;
    }
  }
  for (size_t i = 0; i < n; i++) {
    float *p = im->rgba + 4 * i;
    p[3] = 1;
    if (ch == CH_NORMAL && im->n) {
      const float *nn = im->n + 3 * i;
      int zero = nn[0] == 0 && nn[1] == 0 && nn[2] == 0;
      for (int c = 0; c < 3; c++)
        p[c] = zero ? 0 : (float)img_srgb_decode(0.5 * nn[c] + 0.5);
    } else {
      double x = ch == CH_DEPTH && im->z ? im->z[i]
                 : ch == CH_COST && im->cost ? log1p(im->cost[i]) : 0;
      if (!isfinite(x)) {
        p[0] = p[1] = p[2] = 0;
        continue;
      }
      double u = hi > lo ? (x - lo) / (hi - lo) : 0;
      ramp(ch == CH_DEPTH ? 1 - u : u, p);
    }
  }
}

/* im as PNG bytes (the writer of qcs -o, into memory). */
static int png_bytes(const Image *im, unsigned char **out, size_t *len,
                     char *err, size_t errlen) {
  char *p = NULL;
  size_t n = 0;
  FILE *f = open_memstream(&p, &n);
  if (!f) {
    snprintf(err, errlen, "out of memory for the picture");
    return -1;
  }
  ImgWriteOptions wo = {0};
  int rc = img_write_png(im, f, &wo, "the frame", err, errlen);
  if (fclose(f) != 0 && !rc) {
    snprintf(err, errlen, "out of memory for the picture");
    rc = -1;
  }
  if (rc) {
    free(p);
    return -1;
  }
  *out = (unsigned char *)p;
  *len = n;
  return 0;
}

/* ---- the render thread: the rungs of the wished-for key ---- */

static void *render_main(void *arg) {
  View *v = arg;
  pthread_mutex_lock(&v->mu);
  for (;;) {
    /* Something to do: a wish not yet rendered in full. */
    int rung = -1;
    while (!v->quit) {
      if (v->have_want && v->snap) {
        if (!v->cur_valid || !key_eq(&v->cur, &v->want) ||
            v->cur_gen != v->snap->gen) {
          frames_clear(v);
          v->cur = v->want;
          v->cur_gen = v->snap->gen;
          v->cur_valid = 1;
          pthread_cond_broadcast(&v->cv);
        }
        for (int r = 0; r < RUNGS && rung < 0; r++)
          if (!v->frames[r].png) rung = r;
        if (v->frame_err[0]) rung = -1;
        if (rung >= 0) break;
      }
      pthread_cond_wait(&v->work, &v->mu);
    }
    if (v->quit) break;
    Key k = v->cur;
    Snap *sn = v->snap;
    sn->refs++;
    atomic_store(&v->cancel, 0);
    pthread_mutex_unlock(&v->mu);

    RenderSettings rs;
    key_settings(v, sn, &k, &rs);
    int step = rung_step[rung];
    rs.width = (sn->rs.width + step - 1) / step;
    rs.height = (sn->rs.height + step - 1) / step;
    if (step > 1) rs.spp = 1;
    RenderReport rep;
    char err[300] = "";
    Image *im = render_scene(sn->s, &rs, &rep, &v->cancel, err, sizeof err);
    unsigned char *png = NULL;
    size_t len = 0;
    if (im) {
      if (k.ch != CH_COLOUR) false_colour(im, k.ch);
      if (png_bytes(im, &png, &len, err, sizeof err)) png = NULL;
      img_free(im);
    }
    unsigned gen = sn->gen;
    snap_release(v, sn);
    pthread_mutex_lock(&v->mu);
    if (v->cur_valid && key_eq(&v->cur, &k) && v->cur_gen == gen) {
      if (png) {
        v->frames[rung].png = png;
        v->frames[rung].len = len;
        png = NULL;
      } else if (!rep.interrupted || !atomic_load(&v->cancel)) {
        snprintf(v->frame_err, sizeof v->frame_err, "%s",
                 err[0] ? err : "the render failed");
      }
      pthread_cond_broadcast(&v->cv);
    }
    free(png);
  }
  pthread_mutex_unlock(&v->mu);
  return NULL;
}

/* ---- publishing a scene (the interpreter's thread) ---- */

static const char *kind_name(ScKind k) {
  switch (k) {
  case SC_HALFSPACE: return "Halfspace";
  case SC_ROUNDED: return "Rounded";
  case SC_SOFT: return "SoftObject";
  case SC_UNION: return "Union";
  case SC_INTER: return "Intersection";
  case SC_DIFF: return "SetDifference";
  case SC_EMPTY: return "Empty";
  case SC_ALL: return "Everything";
  }
  return "?";
}

/* Makes a snapshot of s (taken) and publishes it; the node positions are
   read here, on the interpreter's thread. */
static int publish(View *v, Scene *s, const RenderSettings *rs,
                   const VParam *params, int nparams) {
  Snap *sn = calloc(1, sizeof *sn);
  if (!sn) {
    scene_free(s);
    return -1;
  }
  sn->s = s;
  sn->rs = *rs;
  sn->rs.progress = NULL;
  sn->refs = 1;
  sn->where = calloc((size_t)(s->n > 0 ? s->n : 1), sizeof *sn->where);
  if (!sn->where) {
    snap_free(sn);
    return -1;
  }
  for (int i = 0; i < s->n; i++) {
    Pos p = compile_node_pos(s, i);
    if (p.line > 0 && p.src && p.src->name) {
      char tmp[600];
      snprintf(tmp, sizeof tmp, "%s:%d:%d", p.src->name, p.line, p.col);
      sn->where[i] = strdup(tmp);
    }
  }
  /* The own camera, resolved as the renderer resolves it. */
  double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  int hb = camera_scene_box(s, lo, hi);
  Camera cam;
  char err[200];
  if (hb < 0 || camera_setup(&cam, &sn->rs, hb > 0, lo, hi, err, sizeof err)) {
    memcpy(sn->eye, rs->eye, sizeof sn->eye);
    memcpy(sn->at, rs->at, sizeof sn->at);
  } else {
    memcpy(sn->eye, cam.eye, sizeof sn->eye);
    for (int i = 0; i < 3; i++)
      sn->at[i] = rs->camera_set ? rs->at[i] : cam.centre[i];
  }
  memcpy(sn->up, rs->up, sizeof sn->up);
  sn->fov = rs->fov;
  pthread_mutex_lock(&v->mu);
  Snap *old = v->snap;
  sn->gen = old ? old->gen + 1 : 1;
  v->snap = sn;
  v->version++;
  if (nparams > MAX_PARAMS) nparams = MAX_PARAMS;
  if (nparams > 0) memcpy(v->params, params, (size_t)nparams * sizeof *params);
  v->nparams = nparams;
  free(v->error);
  v->error = NULL;
  atomic_store(&v->cancel, 1);
  pthread_cond_broadcast(&v->work);
  pthread_cond_broadcast(&v->cv);
  pthread_mutex_unlock(&v->mu);
  if (old) snap_release(v, old);
  return 0;
}

static void publish_error(View *v, const char *msg) {
  pthread_mutex_lock(&v->mu);
  free(v->error);
  v->error = strdup(msg[0] ? msg : "error");
  v->version++;
  pthread_cond_broadcast(&v->cv);
  pthread_mutex_unlock(&v->mu);
}

/* ---- evaluating the file ---- */

typedef struct Capture {
  RenderSettings rs;
  int got;
} Capture;

static int capture(void *ctx, const Scene *s, const RenderSettings *rs,
                   const char *path, char *err, size_t errlen) {
  Capture *c = ctx;
  c->rs = *rs;
  c->got = 1;
  return 0;
}

/* Run FILE in a fresh interpreter with stderr into a temporary file;
   publish the scene it renders (or its `scene`), or the error text. */
static void add_dep(const char *path, void *ud) {
  View *v = ud;
  char **d = realloc(v->deps, (size_t)(v->ndeps + 1) * sizeof *d);
  if (!d) return;
  v->deps = d;
  if ((d[v->ndeps] = strdup(path))) v->ndeps++;
}

static void deps_clear(View *v) {
  for (int i = 0; i < v->ndeps; i++) free(v->deps[i]);
  free(v->deps);
  v->deps = NULL;
  v->ndeps = 0;
}

/* Runs the file (or, rerun, the scripts' expressions again) in I with
   the renders captured and stderr into text; the scene is ov->kept. */
static RunStatus run_captured(View *v, Interp *I, int rerun, Capture *cap,
                              RenderOverrides *ov, char *text, size_t len) {
  memset(cap, 0, sizeof *cap);
  memset(ov, 0, sizeof *ov);
  ov->capture = capture;
  ov->capture_ctx = cap;
  ov->keep = 1;
  render_set_overrides(I, ov);
  fflush(stderr);
  int saved = dup(2);
  FILE *tmp = tmpfile();
  if (tmp && saved >= 0) dup2(fileno(tmp), 2);
  RunStatus st = rerun ? interp_rerun(I) : interp_run_file(I, v->file);
  if (st == RUN_OK && ov->renders == 0) {
    if (interp_has_global(I, "scene"))
      st = render_lang_scene(I, "view.png");
    else {
      fprintf(stderr, "%s: error: the file renders nothing and defines no "
              "`scene` to show\n", v->file);
      st = RUN_ERROR;
    }
  }
  fflush(stderr);
  if (tmp && saved >= 0) dup2(saved, 2);
  if (saved >= 0) close(saved);
  size_t have = strlen(text);
  if (tmp) {
    rewind(tmp);
    size_t n = fread(text + have, 1, len - 1 - have, tmp);
    text[have + n] = 0;
    fclose(tmp);
  }
  render_set_overrides(I, NULL);
  return st;
}

/* The parameters I declares, for the page; their number. */
static int param_table(Interp *I, VParam *out) {
  InterpParam ip[MAX_PARAMS];
  int n = interp_param_list(I, ip, MAX_PARAMS);
  if (n > MAX_PARAMS) n = MAX_PARAMS;
  for (int i = 0; i < n; i++) {
    VParam *p = &out[i];
    memset(p, 0, sizeof *p);
    snprintf(p->name, sizeof p->name, "%s", ip[i].name);
    snprintf(p->text, sizeof p->text, "%s", ip[i].text ? ip[i].text : "");
    snprintf(p->doc, sizeof p->doc, "%s", ip[i].doc ? ip[i].doc : "");
    p->has_range = ip[i].has_range;
    p->lo = ip[i].lo;
    p->hi = ip[i].hi;
    p->numeric = ip[i].numeric;
    p->value = ip[i].value;
  }
  return n < 0 ? 0 : n;
}

/* Applies the page's values to I (interp_set_param: what depends on them
   is evaluated again, lazily). A value I no longer takes (the parameter
   is gone from the file, or its range no longer holds it) is dropped,
   with a line saying so. A value the parameter already has is left
   alone (what depends on it keeps its values). Returns how many were
   applied. */
static int apply_wishes(View *v, Interp *I) {
  Wish w[MAX_PARAMS];
  pthread_mutex_lock(&v->mu);
  int n = v->nwish;
  memcpy(w, v->wish, (size_t)n * sizeof *w);
  pthread_mutex_unlock(&v->mu);
  InterpParam now[MAX_PARAMS];
  int nnow = n > 0 ? interp_param_list(I, now, MAX_PARAMS) : 0;
  if (nnow > MAX_PARAMS) nnow = MAX_PARAMS;
  int applied = 0;
  for (int i = 0; i < n; i++) {
    char err[300];
    int same = 0;
    for (int j = 0; j < nnow; j++)
      if (!strcmp(now[j].name, w[i].name))
        same = now[j].numeric && now[j].value == w[i].x;
    if (same) continue;
    if (interp_set_param(I, w[i].name, w[i].x, err, sizeof err) == RUN_OK) {
      applied++;
      continue;
    }
    printf("qcs view: %s: the page's %s = %.17g no longer applies (%s)\n",
           v->file, w[i].name, w[i].x, err);
    pthread_mutex_lock(&v->mu);
    for (int j = 0; j < v->nwish; j++)
      if (!strcmp(v->wish[j].name, w[i].name)) {
        v->wish[j] = v->wish[--v->nwish];
        break;
      }
    pthread_mutex_unlock(&v->mu);
  }
  return applied;
}

/* Evaluates the file and publishes the scene it renders (or its
   `scene`), or the error text. fresh: the file changed (or the page
   asked for the command line's values): a new interpreter runs it, then
   the page's values are applied. Otherwise (a slider moved) the live
   interpreter re-binds the parameters and runs the scripts' expressions
   again: only the definitions that depend on them are evaluated anew. */
static void evaluate(View *v, const ViewOptions *o, int fresh) {
  pthread_mutex_lock(&v->mu);
  v->wish_dirty = 0;
  if (v->wish_reset) {
    v->wish_reset = 0;
    v->nwish = 0;
    fresh = 1;
  }
  int nwish = v->nwish;
  pthread_mutex_unlock(&v->mu);
  if (!v->live) fresh = 1;
  Interp *I = fresh ? (o->new_interp ? o->new_interp(o->ud)
                                     : bind_interp_new())
                    : v->live;
  Capture cap;
  RenderOverrides ov;
  char text[8192] = "";
  RunStatus st;
  if (fresh) {
    st = run_captured(v, I, 0, &cap, &ov, text, sizeof text);
    deps_clear(v);
    interp_files_read(I, add_dep, v);
    if (st == RUN_OK && nwish > 0 && apply_wishes(v, I) > 0) {
      scene_free(ov.kept);
      st = run_captured(v, I, 1, &cap, &ov, text, sizeof text);
    }
  } else {
    apply_wishes(v, I);
    st = run_captured(v, I, 1, &cap, &ov, text, sizeof text);
  }
  if (text[0] && !o->quiet) fputs(text, stderr);
  if (st == RUN_OK && ov.kept && cap.got) {
    static VParam params[MAX_PARAMS];
    int np = param_table(I, params);
    publish(v, ov.kept, &cap.rs, params, np);
    if (I != v->live) {
      if (v->live) interp_free(v->live);
      v->live = I;
    }
    printf("qcs view: %s: shown (version %u)\n", v->file, v->version);
  } else {
    scene_free(ov.kept);
    if (st == RUN_OK) snprintf(text, sizeof text, "%s: error: no scene", v->file);
    publish_error(v, text);
    /* A file in error has no live interpreter: a slider then runs the
       file again, and shows its error again. */
    if (fresh) {
      if (v->live && v->live != I) interp_free(v->live);
      interp_free(I);
      v->live = NULL;
    }
    int had = v->snap != NULL; /* written by this thread only */
    printf("qcs view: %s: error (%s)\n", v->file,
           had ? "the last good picture stays" : "no picture yet");
  }
  fflush(stdout);
}

/* ---- requests ---- */

/* The query argument name, or NULL: absent, or with a NUL byte inside
   (%00: its C string would say less than the request did). */
static const char *arg(struct MHD_Connection *c, const char *name) {
  const char *val = NULL;
  size_t len = 0;
  if (MHD_lookup_connection_value_n(c, MHD_GET_ARGUMENT_KIND, name,
                                    strlen(name), &val, &len) != MHD_YES ||
      !val || strlen(val) != len)
    return NULL;
  return val;
}

static int parse_vec(const char *s, double out[3]) {
  if (!s) return -1;
  char *end;
  for (int i = 0; i < 3; i++) {
    out[i] = strtod(s, &end);
    if (end == s || !isfinite(out[i])) return -1;
    s = end;
    if (i < 2) {
      if (*s != ',') return -1;
      s++;
    }
  }
  return *s ? -1 : 0;
}

/* The key of a request; -1 with a message for a bad camera. */
static int parse_key(struct MHD_Connection *c, const Snap *sn, Key *k,
                     char *err, size_t errlen) {
  memset(k, 0, sizeof *k);
  const char *own = arg(c, "own"), *sh = arg(c, "shadows"), *ch = arg(c, "ch");
  k->shadows = sh ? strcmp(sh, "0") != 0 : sn->rs.shadows;
  k->ch = CH_COLOUR;
  if (ch) {
    k->ch = -1;
    for (int i = 0; i < CH_N; i++)
      if (!strcmp(ch, ch_names[i])) k->ch = i;
    if (k->ch < 0) {
      snprintf(err, errlen, "bad channel: colour, depth, normal or cost");
      return -1;
    }
  }
  if (own && !strcmp(own, "1")) {
    k->own = 1;
    return 0;
  }
  const char *fov = arg(c, "fov");
  char *end = NULL;
  k->fov = fov ? strtod(fov, &end) : NAN;
  if (parse_vec(arg(c, "eye"), k->eye) || parse_vec(arg(c, "at"), k->at) ||
      parse_vec(arg(c, "up"), k->up) || !fov || *end) {
    snprintf(err, errlen, "bad camera: give own=1, or eye, at and up as "
             "three finite numbers X,Y,Z and fov");
    return -1;
  }
  if (!(k->fov > 0.01 && k->fov < 179)) {
    snprintf(err, errlen, "bad camera: the field of view must be between "
             "0.01 and 179 degrees");
    return -1;
  }
  /* What camera_setup would refuse, refused here with its words. */
  RenderSettings rs;
  render_defaults(&rs);
  rs.camera_set = 1;
  memcpy(rs.eye, k->eye, sizeof rs.eye);
  memcpy(rs.at, k->at, sizeof rs.at);
  memcpy(rs.up, k->up, sizeof rs.up);
  rs.fov = k->fov;
  Camera cam;
  double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  char e[200];
  if (camera_setup(&cam, &rs, 0, lo, hi, e, sizeof e)) {
    snprintf(err, errlen, "bad camera: %s", e);
    return -1;
  }
  return 0;
}

static enum MHD_Result send_buf(struct MHD_Connection *c, unsigned status,
                                const char *type, const void *data,
                                size_t len, const char *step,
                                const char *version) {
  struct MHD_Response *r = MHD_create_response_from_buffer(
      len, (void *)data, MHD_RESPMEM_MUST_COPY);
  if (!r) return MHD_NO;
  MHD_add_response_header(r, "Content-Type", type);
  MHD_add_response_header(r, "Cache-Control", "no-store");
  MHD_add_response_header(r, "X-Content-Type-Options", "nosniff");
  MHD_add_response_header(r, "Referrer-Policy", "no-referrer");
  if (step) MHD_add_response_header(r, "X-Step", step);
  if (version) MHD_add_response_header(r, "X-Version", version);
  enum MHD_Result rc = MHD_queue_response(c, status, r);
  MHD_destroy_response(r);
  return rc;
}

static enum MHD_Result send_text(struct MHD_Connection *c, unsigned status,
                                 const char *msg) {
  char line[1100];
  snprintf(line, sizeof line, "qcs view: %.1000s\n", msg);
  return send_buf(c, status, "text/plain; charset=utf-8", line, strlen(line),
                  NULL, NULL);
}

static enum MHD_Result send_json(struct MHD_Connection *c, Buf *b) {
  enum MHD_Result rc =
      b->failed ? send_text(c, 500, "out of memory")
                : send_buf(c, 200, "application/json", b->p, b->n, NULL, NULL);
  free(b->p);
  return rc;
}

static void deadline_ts(struct timespec *ts, double secs) {
  clock_gettime(CLOCK_REALTIME, ts);
  double t = (double)ts->tv_sec + (double)ts->tv_nsec * 1e-9 + secs;
  ts->tv_sec = (time_t)t;
  ts->tv_nsec = (long)((t - (double)ts->tv_sec) * 1e9);
}

static enum MHD_Result do_state(View *v, struct MHD_Connection *c) {
  const char *since = arg(c, "since");
  char *end = NULL;
  long want = since ? strtol(since, &end, 10) : -1;
  pthread_mutex_lock(&v->mu);
  if (since && !*end) {
    struct timespec ts;
    deadline_ts(&ts, 10);
    while (!v->quit && (long)v->version == want)
      if (pthread_cond_timedwait(&v->cv, &v->mu, &ts) == ETIMEDOUT) break;
  }
  Buf b = {0};
  buf_printf(&b, "{\"version\":%u,\"file\":", v->version);
  buf_json_str(&b, v->file);
  buf_printf(&b, ",\"error\":");
  if (v->error) buf_json_str(&b, v->error);
  else buf_printf(&b, "null");
  Snap *sn = v->snap;
  if (sn) {
    buf_printf(&b, ",\"width\":%d,\"height\":%d,\"shadows\":%d,\"eye\":",
               sn->rs.width, sn->rs.height, sn->rs.shadows);
    buf_vec(&b, sn->eye);
    buf_printf(&b, ",\"at\":");
    buf_vec(&b, sn->at);
    buf_printf(&b, ",\"up\":");
    buf_vec(&b, sn->up);
    buf_printf(&b, ",\"fov\":");
    buf_num(&b, sn->fov);
  }
  buf_printf(&b, ",\"params\":[");
  for (int i = 0; i < v->nparams; i++) {
    const VParam *p = &v->params[i];
    buf_printf(&b, "%s{\"name\":", i ? "," : "");
    buf_json_str(&b, p->name);
    buf_printf(&b, ",\"default\":");
    buf_json_str(&b, p->text);
    buf_printf(&b, ",\"doc\":");
    buf_json_str(&b, p->doc);
    buf_printf(&b, ",\"numeric\":%d,\"value\":", p->numeric);
    buf_num(&b, p->value);
    if (p->has_range) {
      buf_printf(&b, ",\"lo\":");
      buf_num(&b, p->lo);
      buf_printf(&b, ",\"hi\":");
      buf_num(&b, p->hi);
    }
    buf_printf(&b, "}");
  }
  buf_printf(&b, "],\"set\":%d}", v->nwish);
  pthread_mutex_unlock(&v->mu);
  return send_json(c, &b);
}

static enum MHD_Result do_frame(View *v, struct MHD_Connection *c) {
  char err[300];
  Key k;
  const char *st = arg(c, "step");
  int have = st ? atoi(st) : 16;
  Snap *sn = snap_acquire(v);
  if (!sn) return send_text(c, 503, "no picture yet: see /state's error");
  int bad = parse_key(c, sn, &k, err, sizeof err);
  snap_release(v, sn);
  if (bad) return send_text(c, 400, err);
  pthread_mutex_lock(&v->mu);
  if (!v->have_want || !key_eq(&v->want, &k)) {
    v->want = k;
    v->have_want = 1;
    atomic_store(&v->cancel, 1);
    pthread_cond_signal(&v->work);
  }
  struct timespec ts;
  deadline_ts(&ts, 5);
  for (;;) {
    if (v->quit) break;
    if (!key_eq(&v->want, &k)) {
      pthread_mutex_unlock(&v->mu);
      return send_text(c, 409, "stale: another camera was asked for");
    }
    if (v->cur_valid && key_eq(&v->cur, &k) && v->snap &&
        v->cur_gen == v->snap->gen) {
      for (int r = RUNGS - 1; r >= 0; r--)
        if (v->frames[r].png && rung_step[r] < have) {
          char step[16], ver[16];
          snprintf(step, sizeof step, "%d", rung_step[r]);
          snprintf(ver, sizeof ver, "%u", v->version);
          /* copied under the lock: the frame may be cleared next */
          struct MHD_Response *resp = MHD_create_response_from_buffer(
              v->frames[r].len, v->frames[r].png, MHD_RESPMEM_MUST_COPY);
          pthread_mutex_unlock(&v->mu);
          if (!resp) return MHD_NO;
          MHD_add_response_header(resp, "Content-Type", "image/png");
          MHD_add_response_header(resp, "Cache-Control", "no-store");
          MHD_add_response_header(resp, "X-Step", step);
          MHD_add_response_header(resp, "X-Version", ver);
          enum MHD_Result rc = MHD_queue_response(c, 200, resp);
          MHD_destroy_response(resp);
          return rc;
        }
      if (v->frame_err[0]) {
        snprintf(err, sizeof err, "%s", v->frame_err);
        pthread_mutex_unlock(&v->mu);
        return send_text(c, 500, err);
      }
    }
    if (pthread_cond_timedwait(&v->cv, &v->mu, &ts) == ETIMEDOUT) break;
  }
  pthread_mutex_unlock(&v->mu);
  return send_text(c, 503, "no frame in time; ask again");
}

/* ---- the probe of one pixel ---- */

typedef struct Events {
  lg_trace_event *ev;
  int n, dropped;
} Events;

static void on_event(void *ctx, const lg_trace_event *ev) {
  Events *e = ctx;
  if (e->n < MAX_EVENTS) e->ev[e->n++] = *ev;
  else e->dropped++;
}

static enum MHD_Result do_probe(View *v, struct MHD_Connection *c) {
  char err[300];
  Key k;
  Snap *sn = snap_acquire(v);
  if (!sn) return send_text(c, 503, "no picture yet");
  const char *xs = arg(c, "x"), *ys = arg(c, "y");
  char *e1 = NULL, *e2 = NULL;
  double px = xs ? strtod(xs, &e1) : NAN, py = ys ? strtod(ys, &e2) : NAN;
  if (parse_key(c, sn, &k, err, sizeof err)) {
    snap_release(v, sn);
    return send_text(c, 400, err);
  }
  if (!xs || !ys || *e1 || *e2 || !(px >= 0 && px < sn->rs.width) ||
      !(py >= 0 && py < sn->rs.height)) {
    snap_release(v, sn);
    return send_text(c, 400, "bad pixel: x and y must lie in the picture");
  }
  RenderSettings rs;
  key_settings(v, sn, &k, &rs);
  const Scene *s = sn->s;
  double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, o[3], d[3];
  int hb = camera_scene_box(s, lo, hi);
  Camera cam;
  if (hb < 0 || camera_setup(&cam, &rs, hb > 0, lo, hi, err, sizeof err)) {
    snap_release(v, sn);
    return send_text(c, 400, hb < 0 ? "out of memory" : err);
  }
  /* The pixel's centre, as the renderer's one-sample ray. */
  double fx = floor(px) + 0.5, fy = floor(py) + 0.5;
  camera_ray(&cam, fx, fy, d);
  memcpy(o, cam.eye, sizeof o);
  Buf b = {0};
  buf_printf(&b, "{\"x\":%d,\"y\":%d,\"origin\":", (int)floor(px),
             (int)floor(py));
  buf_vec(&b, o);
  buf_printf(&b, ",\"dir\":");
  buf_vec(&b, d);
  /* Roots, as the prompt's Roots obj o d (tolerance 1e-10). */
  RayCtx *rc = ray_ctx_new(s, 1e-10);
  Events ev = {malloc(MAX_EVENTS * sizeof(lg_trace_event)), 0, 0};
  if (!rc || !ev.ev) {
    ray_ctx_free(rc);
    free(ev.ev);
    free(b.p);
    snap_release(v, sn);
    return send_text(c, 500, "out of memory");
  }
  csg_span *sp;
  int n = ray_spans(s, s->root, o, d, 0, INFINITY, rc, &sp);
  double thit = INFINITY;
  int node = -1;
  buf_printf(&b, ",\"roots\":[");
  int first = 1;
  for (int i = 0; n > 0 && i < n; i++) {
    if (sp[i].id0 >= 0 && sp[i].t0 >= 0) {
      buf_printf(&b, "%s", first ? "" : ",");
      buf_num(&b, sp[i].t0);
      first = 0;
      if (sp[i].t0 < thit) thit = sp[i].t0, node = sp[i].id0;
    }
    if (sp[i].id1 >= 0 && isfinite(sp[i].t1)) {
      buf_printf(&b, "%s", first ? "" : ",");
      buf_num(&b, sp[i].t1);
      first = 0;
      if (sp[i].t1 < thit) thit = sp[i].t1, node = sp[i].id1;
    }
  }
  buf_printf(&b, "]");
  if (n < 0) buf_printf(&b, ",\"failed\":\"out of memory tracing the ray\"");
  if (node >= 0 && node < s->n) {
    const ScNode *nd = &s->nodes[node];
    double p[3];
    for (int i = 0; i < 3; i++) p[i] = o[i] + thit * d[i];
    buf_printf(&b, ",\"hit\":{\"t\":");
    buf_num(&b, thit);
    buf_printf(&b, ",\"point\":");
    buf_vec(&b, p);
    buf_printf(&b, ",\"node\":%d,\"kind\":\"%s\",\"where\":", node,
               kind_name(nd->kind));
    if (sn->where[node]) buf_json_str(&b, sn->where[node]);
    else buf_printf(&b, "null");
    if (nd->kind == SC_ROUNDED && nd->tape) {
      double g[3];
      double rho = dt_density(nd->tape, p);
      dt_density_grad(nd->tape, p, g);
      buf_printf(&b, ",\"density\":");
      buf_num(&b, rho);
      buf_printf(&b, ",\"gradient\":");
      buf_vec(&b, g);
      /* The search of this leaf alone, traced: Trace leaf o d. */
      lg_hook hook = {on_event, &ev};
      RayCtx *tc = ray_ctx_new(s, 1e-10);
      if (tc) {
        tc->hook = &hook;
        csg_span *tsp;
        ray_spans(s, node, o, d, 0, INFINITY, tc, &tsp);
        ray_ctx_free(tc);
      }
      double a = INFINITY, z = -INFINITY;
      buf_printf(&b, ",\"segments\":[");
      for (int i = 0; i < ev.n; i++) {
        const lg_trace_event *e = &ev.ev[i];
        buf_printf(&b, "%s{\"t0\":", i ? "," : "");
        buf_num(&b, e->t0);
        buf_printf(&b, ",\"t1\":");
        buf_num(&b, e->t1);
        buf_printf(&b, ",\"f0\":");
        buf_num(&b, e->f0);
        buf_printf(&b, ",\"f1\":");
        buf_num(&b, e->f1);
        buf_printf(&b, ",\"L\":");
        buf_num(&b, e->L);
        buf_printf(&b, ",\"G\":");
        buf_num(&b, e->G);
        buf_printf(&b, ",\"lhs\":");
        buf_num(&b, e->lhs);
        buf_printf(&b, ",\"decision\":%d,\"depth\":%d,\"roots\":%d}",
                   e->decision, e->depth, e->nroots);
        if (isfinite(e->t0) && e->t0 < a) a = e->t0;
        if (isfinite(e->t1) && e->t1 > z) z = e->t1;
      }
      buf_printf(&b, "],\"dropped\":%d", ev.dropped);
      if (a < z) {
        buf_printf(&b, ",\"plot\":{\"t0\":");
        buf_num(&b, a);
        buf_printf(&b, ",\"t1\":");
        buf_num(&b, z);
        buf_printf(&b, ",\"rho\":[");
        for (int i = 0; i <= PLOT_SAMPLES; i++) {
          double t = a + (z - a) * i / PLOT_SAMPLES, q[3];
          for (int j = 0; j < 3; j++) q[j] = o[j] + t * d[j];
          buf_printf(&b, "%s", i ? "," : "");
          buf_num(&b, dt_density(nd->tape, q));
        }
        buf_printf(&b, "]}");
      }
    } else if (nd->kind == SC_SOFT && nd->soft) {
      buf_printf(&b, ",\"field\":");
      buf_num(&b, soft_field(nd->soft, p));
    }
    buf_printf(&b, "}");
  }
  buf_printf(&b, "}");
  ray_ctx_free(rc);
  free(ev.ev);
  snap_release(v, sn);
  return send_json(c, &b);
}

/* ---- save ---- */

static enum MHD_Result do_save(View *v, struct MHD_Connection *c) {
  char err[600];
  Key k;
  const char *fmt = arg(c, "fmt");
  if (!fmt || (strcmp(fmt, "png") && strcmp(fmt, "exr")))
    return send_text(c, 400, "fmt must be png or exr");
  Snap *sn = snap_acquire(v);
  if (!sn) return send_text(c, 503, "no picture yet");
  if (parse_key(c, sn, &k, err, sizeof err)) {
    snap_release(v, sn);
    return send_text(c, 400, err);
  }
  RenderSettings rs;
  key_settings(v, sn, &k, &rs);
  rs.aovs = IMG_Z | IMG_N | IMG_COST;
  pthread_mutex_lock(&v->save_mu);
  char path[4400];
  int i = ++v->saves;
  snprintf(path, sizeof path, "%s/%s-view-%d.%s", v->dir, v->stem, i, fmt);
  RenderReport rep;
  atomic_int never = 0;
  Image *im = render_scene(sn->s, &rs, &rep, &never, err, sizeof err);
  snap_release(v, sn);
  int rc = -1;
  if (im) {
    if (k.ch != CH_COLOUR && !strcmp(fmt, "png")) false_colour(im, k.ch);
    rc = img_write(im, path, NULL, err, sizeof err);
    img_free(im);
  }
  pthread_mutex_unlock(&v->save_mu);
  if (rc) return send_text(c, 500, err);
  Buf b = {0};
  buf_printf(&b, "{\"saved\":");
  buf_json_str(&b, path);
  buf_printf(&b, "}");
  printf("qcs view: saved %s\n", path);
  fflush(stdout);
  return send_json(c, &b);
}

/* ---- a parameter's value from the page ---- */

static void wake_main(View *v) {
  char c = 1;
  if (v->wake[1] >= 0) {
    ssize_t w = write(v->wake[1], &c, 1); /* full: a wake-up is pending */
    (void)w;
  }
}

static enum MHD_Result do_param(View *v, struct MHD_Connection *c) {
  const char *reset = arg(c, "reset"), *name = arg(c, "name"),
             *val = arg(c, "value");
  if (v->wake[1] < 0)
    return send_text(c, 404, "this view has no parameters (qcs view FILE "
                     "has: :view shows one scene)");
  if (reset) {
    if (strcmp(reset, "1") || name || val)
      return send_text(c, 400, "reset=1 alone");
    pthread_mutex_lock(&v->mu);
    v->wish_reset = 1;
    v->wish_dirty = 1;
    pthread_mutex_unlock(&v->mu);
    wake_main(v);
    return send_buf(c, 200, "application/json", "{\"reset\":1}", 11, NULL,
                    NULL);
  }
  if (!name || !val || strlen(name) >= PARAM_NAME || strlen(val) > 40)
    return send_text(c, 400, "give name=NAME (a declared parameter) and "
                     "value=NUMBER");
  char *end;
  double x = strtod(val, &end);
  if (end == val || *end || !isfinite(x))
    return send_text(c, 400, "value must be a finite number");
  char err[400];
  pthread_mutex_lock(&v->mu);
  const VParam *p = NULL;
  for (int i = 0; i < v->nparams && !p; i++)
    if (!strcmp(v->params[i].name, name)) p = &v->params[i];
  if (!p) {
    pthread_mutex_unlock(&v->mu);
    return send_text(c, 400, "no such parameter: the file declares none of "
                     "that name");
  }
  if (!p->numeric) {
    snprintf(err, sizeof err, "parameter %s does not take a number (its "
             "default is %.80s)", p->name, p->text);
    pthread_mutex_unlock(&v->mu);
    return send_text(c, 400, err);
  }
  if (p->has_range && !(x >= p->lo && x <= p->hi)) {
    snprintf(err, sizeof err, "%.17g is outside the range [%.17g, %.17g] of "
             "parameter %s", x, p->lo, p->hi, p->name);
    pthread_mutex_unlock(&v->mu);
    return send_text(c, 400, err);
  }
  int i = 0;
  while (i < v->nwish && strcmp(v->wish[i].name, name)) i++;
  if (i == v->nwish) {
    if (v->nwish == MAX_PARAMS) { /* cannot be: names are the table's */
      pthread_mutex_unlock(&v->mu);
      return send_text(c, 500, "too many parameters");
    }
    snprintf(v->wish[i].name, sizeof v->wish[i].name, "%s", name);
    v->nwish++;
  }
  v->wish[i].x = x;
  v->wish_dirty = 1;
  unsigned ver = v->version;
  pthread_mutex_unlock(&v->mu);
  wake_main(v);
  Buf b = {0};
  buf_printf(&b, "{\"asked\":%u}", ver);
  return send_json(c, &b);
}

/* ---- the gate: every request passes here ---- */

static int token_ok(const View *v, const char *t) {
  if (!t || strlen(t) != 32) return 0;
  unsigned diff = 0;
  for (int i = 0; i < 32; i++) diff |= (unsigned)(t[i] ^ v->token[i]);
  return diff == 0;
}

static int host_ok(const View *v, const char *h) {
  for (int i = 0; i < 3; i++)
    if (v->host_ok[i][0] && !strcasecmp(h, v->host_ok[i])) return 1;
  return 0;
}

static int body_marker;

static enum MHD_Result handle(void *cls, struct MHD_Connection *c,
                              const char *url, const char *method,
                              const char *version, const char *upload,
                              size_t *upload_size, void **req) {
  View *v = cls;
  if (!*req) {
    *req = (void *)1;
    return MHD_YES;
  }
  if (*upload_size) { /* no request has a body */
    *upload_size = 0;
    *req = &body_marker;
    return MHD_YES;
  }
  atomic_fetch_add(&v->requests, 1);
  const char *host = MHD_lookup_connection_value(c, MHD_HEADER_KIND, "Host");
  const char *origin =
      MHD_lookup_connection_value(c, MHD_HEADER_KIND, "Origin");
  char o_ok[128];
  int origin_ok = !origin;
  for (int i = 0; origin && i < 3; i++)
    if (v->host_ok[i][0]) {
      snprintf(o_ok, sizeof o_ok, "http://%s", v->host_ok[i]);
      if (!strcasecmp(origin, o_ok)) origin_ok = 1;
    }
  if (!host || !host_ok(v, host) || !origin_ok) {
    atomic_fetch_add(&v->refused, 1);
    return send_text(c, 403, "forbidden: this server answers only its own "
                     "address (Host and Origin headers)");
  }
  if (!token_ok(v, arg(c, "t"))) {
    atomic_fetch_add(&v->refused, 1);
    return send_text(c, 403, "forbidden: the URL's token is missing or wrong "
                     "(use the URL qcs view printed)");
  }
  if (*req == &body_marker)
    return send_text(c, 413, "requests carry no body");
  int get = !strcmp(method, MHD_HTTP_METHOD_GET);
  int post = !strcmp(method, MHD_HTTP_METHOD_POST);
  if (!strcmp(url, "/save")) {
    if (!post) return send_text(c, 405, "/save wants POST");
    return do_save(v, c);
  }
  if (!strcmp(url, "/param")) {
    if (!post) return send_text(c, 405, "/param wants POST");
    return do_param(v, c);
  }
  if (!get) return send_text(c, 405, "only GET (and POST /save, /param)");
  if (!strcmp(url, "/"))
    return send_buf(c, 200, "text/html; charset=utf-8", qcs_view_page,
                    sizeof qcs_view_page - 1, NULL, NULL);
  if (!strcmp(url, "/state")) return do_state(v, c);
  if (!strcmp(url, "/frame")) return do_frame(v, c);
  if (!strcmp(url, "/probe")) return do_probe(v, c);
  return send_text(c, 404, "not found");
}

static void mhd_log(void *cls, const char *fmt, va_list ap) {
  (void)cls;
  (void)fmt;
  (void)ap; /* connection errors (a client gone) are not news */
}

/* ---- starting and stopping ---- */

int view_parse_listen(const char *s, char *err, size_t errlen) {
  const char *colon = s ? strrchr(s, ':') : NULL;
  char addr[64];
  struct in_addr ia;
  char *end;
  long port = colon ? strtol(colon + 1, &end, 10) : -1;
  if (!colon || (size_t)(colon - s) >= sizeof addr || colon == s ||
      !colon[1] || *end || port < 0 || port > 65535) {
    snprintf(err, errlen, "--listen needs ADDR:PORT, like 127.0.0.1:8080");
    return -1;
  }
  memcpy(addr, s, (size_t)(colon - s));
  addr[colon - s] = 0;
  if (inet_pton(AF_INET, addr, &ia) != 1) {
    snprintf(err, errlen, "--listen: '%s' is not an IPv4 address", addr);
    return -1;
  }
  return 0;
}

/* Set by SIGINT or SIGTERM, which may be delivered to any thread (a
   server or render thread too): an atomic, lock-free and so safe in a
   handler, not a plain sig_atomic_t (a data race between threads). */
static atomic_int stop_flag;
static void on_signal(int sig) {
  (void)sig;
  atomic_store(&stop_flag, 1);
}

static struct MHD_Daemon *start(View *v, const ViewOptions *o) {
  if (!mhd_loaded && mhd_load()) return NULL;
  struct sockaddr_in sa;
  memset(&sa, 0, sizeof sa);
  sa.sin_family = AF_INET;
  char addr[64] = "127.0.0.1";
  int port = 0;
  if (o->listen) {
    const char *colon = strrchr(o->listen, ':');
    memcpy(addr, o->listen, (size_t)(colon - o->listen));
    addr[colon - o->listen] = 0;
    port = atoi(colon + 1);
  }
  inet_pton(AF_INET, addr, &sa.sin_addr);
  sa.sin_port = htons((uint16_t)port);
  unsigned char rnd[16];
  if (getrandom(rnd, sizeof rnd, 0) != (ssize_t)sizeof rnd) {
    fprintf(stderr, "qcs: error: view: no random numbers for the token\n");
    return NULL;
  }
  for (int i = 0; i < 16; i++) snprintf(v->token + 2 * i, 3, "%02x", rnd[i]);
  /* The socket is bound here, not by the daemon, so that the port, the
     token and the Host names accepted are written before the first server
     thread exists (they are read by every request without a lock). */
  int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  int one = 1;
  if (fd < 0 || setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one) ||
      bind(fd, (struct sockaddr *)&sa, sizeof sa) || listen(fd, 64)) {
    fprintf(stderr, "qcs: error: view: cannot listen on %s:%d: %s\n", addr,
            port, strerror(errno));
    if (fd >= 0) close(fd);
    return NULL;
  }
  struct sockaddr_in bound;
  socklen_t blen = sizeof bound;
  v->port = getsockname(fd, (struct sockaddr *)&bound, &blen) == 0
                ? ntohs(bound.sin_port)
                : port;
  snprintf(v->host_ok[0], sizeof v->host_ok[0], "%s:%d", addr, v->port);
  snprintf(v->host_ok[1], sizeof v->host_ok[1], "localhost:%d", v->port);
  if (strcmp(addr, "127.0.0.1"))
    snprintf(v->host_ok[2], sizeof v->host_ok[2], "127.0.0.1:%d", v->port);
  struct MHD_Daemon *d = MHD_start_daemon(
      MHD_USE_THREAD_PER_CONNECTION | MHD_USE_INTERNAL_POLLING_THREAD |
          MHD_USE_ERROR_LOG,
      0, NULL, NULL, handle, v, MHD_OPTION_LISTEN_SOCKET, fd,
      MHD_OPTION_CONNECTION_LIMIT, (unsigned)VIEW_MAX_CLIENTS,
      MHD_OPTION_PER_IP_CONNECTION_LIMIT, (unsigned)VIEW_MAX_CLIENTS,
      MHD_OPTION_CONNECTION_TIMEOUT, (unsigned)30,
      MHD_OPTION_CONNECTION_MEMORY_LIMIT, VIEW_CONN_MEMORY,
      MHD_OPTION_THREAD_STACK_SIZE, (size_t)(512 << 10),
      MHD_OPTION_EXTERNAL_LOGGER, mhd_log, NULL, MHD_OPTION_END);
  if (!d) {
    fprintf(stderr, "qcs: error: view: cannot serve on %s:%d: %s\n", addr,
            v->port, strerror(errno));
    close(fd);
    return NULL;
  }
  /* 127.0.0.0/8 is this machine's loopback: no one else reaches it. */
  if ((ntohl(sa.sin_addr.s_addr) >> 24) != 127)
    fprintf(stderr, "qcs: warning: view: listening on %s, not only on this "
            "machine: anyone who can reach it and has the URL can look at "
            "the scene and save pictures into its folder\n", addr);
  printf("qcs view: http://%s:%d/?t=%s\n",
         strcmp(addr, "0.0.0.0") ? addr : "127.0.0.1", v->port, v->token);
  fflush(stdout);
  return d;
}

static void view_init(View *v, const ViewOptions *o) {
  memset(v, 0, sizeof *v);
  pthread_mutex_init(&v->mu, NULL);
  pthread_mutex_init(&v->save_mu, NULL);
  pthread_cond_init(&v->cv, NULL);
  pthread_cond_init(&v->work, NULL);
  v->threads = o->threads;
  v->wake[0] = v->wake[1] = -1;
}

static void view_finish(View *v, struct MHD_Daemon *d, pthread_t *rt) {
  pthread_mutex_lock(&v->mu);
  v->quit = 1;
  atomic_store(&v->cancel, 1);
  pthread_cond_broadcast(&v->cv);
  pthread_cond_broadcast(&v->work);
  pthread_mutex_unlock(&v->mu);
  if (d) MHD_stop_daemon(d);
  if (rt) pthread_join(*rt, NULL);
  frames_clear(v);
  deps_clear(v);
  if (v->live) interp_free(v->live);
  v->live = NULL;
  if (v->wake[0] >= 0) close(v->wake[0]);
  if (v->wake[1] >= 0) close(v->wake[1]);
  if (v->snap) snap_free(v->snap);
  free(v->error);
  pthread_mutex_destroy(&v->mu);
  pthread_mutex_destroy(&v->save_mu);
  pthread_cond_destroy(&v->cv);
  pthread_cond_destroy(&v->work);
}

/* The files followed besides the main one: the imports of the last
   evaluation, by their folder's watch and their name in it. */
typedef struct Watched {
  int wd;
  char name[256];
} Watched;

#define MAX_WATCHED 256
#define WATCH_MASK (IN_CLOSE_WRITE | IN_MOVED_TO | IN_CREATE | IN_DELETE | \
                    IN_MOVED_FROM | IN_ATTRIB)

/* Watch the folders of the files the last evaluation imported (a folder
   already watched gives its old descriptor back). */
static int watch_deps(View *v, int ino, Watched *w) {
  int n = 0;
  for (int i = 0; i < v->ndeps && n < MAX_WATCHED; i++) {
    const char *p = v->deps[i], *slash = strrchr(p, '/');
    char dir[4096];
    if (slash) snprintf(dir, sizeof dir, "%.*s", (int)(slash - p), p);
    else snprintf(dir, sizeof dir, ".");
    if (!dir[0]) snprintf(dir, sizeof dir, "/");
    int wd = inotify_add_watch(ino, dir, WATCH_MASK);
    if (wd < 0) {
      fprintf(stderr, "qcs: warning: view: cannot watch %s: %s\n", dir,
              strerror(errno));
      continue;
    }
    w[n].wd = wd;
    snprintf(w[n].name, sizeof w[n].name, "%s", slash ? slash + 1 : p);
    n++;
  }
  return n;
}

int view_file(const char *file, const ViewOptions *o) {
  static View v;
  view_init(&v, o);
  snprintf(v.file, sizeof v.file, "%s", file);
  const char *slash = strrchr(file, '/');
  if (slash) snprintf(v.dir, sizeof v.dir, "%.*s", (int)(slash - file), file);
  else snprintf(v.dir, sizeof v.dir, ".");
  if (!v.dir[0]) snprintf(v.dir, sizeof v.dir, "/");
  const char *base = slash ? slash + 1 : file;
  snprintf(v.stem, sizeof v.stem, "%s", base);
  char *dot = strrchr(v.stem, '.');
  if (dot && dot != v.stem) *dot = 0;
  struct stat fst;
  int bad = stat(file, &fst) != 0 ? errno : S_ISREG(fst.st_mode) ? 0 : -1;
  if (bad) {
    fprintf(stderr, "qcs: error: view: %s: %s\n", file,
            bad == ENOENT ? "no such file (qcs view follows an existing "
                            "scene file)"
            : bad < 0     ? "not a regular file"
                          : strerror(bad));
    return 1;
  }
  int ino = inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
  int main_wd = ino < 0 ? -1 : inotify_add_watch(ino, v.dir, WATCH_MASK);
  if (ino < 0 || main_wd < 0) {
    fprintf(stderr, "qcs: error: view: cannot watch %s: %s\n", v.dir,
            strerror(errno));
    if (ino >= 0) close(ino);
    return 1;
  }
  if (pipe(v.wake) || fcntl(v.wake[0], F_SETFL, O_NONBLOCK) ||
      fcntl(v.wake[1], F_SETFL, O_NONBLOCK) ||
      fcntl(v.wake[0], F_SETFD, FD_CLOEXEC) ||
      fcntl(v.wake[1], F_SETFD, FD_CLOEXEC)) {
    fprintf(stderr, "qcs: error: view: %s\n", strerror(errno));
    close(ino);
    return 1;
  }
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_signal;
  sigaction(SIGINT, &sa, NULL);
  sigaction(SIGTERM, &sa, NULL);
  signal(SIGPIPE, SIG_IGN);
  atomic_store(&stop_flag, 0);
  pthread_t rt;
  if (pthread_create(&rt, NULL, render_main, &v)) {
    fprintf(stderr, "qcs: error: view: cannot start a thread\n");
    close(ino);
    return 1;
  }
  struct MHD_Daemon *d = start(&v, o);
  if (!d) {
    view_finish(&v, NULL, &rt);
    close(ino);
    return 1;
  }
  static Watched watched[MAX_WATCHED];
  evaluate(&v, o, 1);
  int nwatched = watch_deps(&v, ino, watched);
  double pending = 0; /* when a change was seen, 0: none */
  int gone = 0;
  while (!atomic_load(&stop_flag)) {
    struct pollfd pfd[2] = {{ino, POLLIN, 0}, {v.wake[0], POLLIN, 0}};
    poll(pfd, 2, pending > 0 ? 10 : 200);
    char drain[64];
    while (read(v.wake[0], drain, sizeof drain) > 0) {
    }
    pthread_mutex_lock(&v.mu);
    int asked = v.wish_dirty;
    pthread_mutex_unlock(&v.mu);
    /* The page's values: applied at once, unless a save is pending (its
       evaluation applies them too). */
    if (asked && pending == 0) evaluate(&v, o, 0);
    char buf[8192] __attribute__((aligned(__alignof__(struct inotify_event))));
    ssize_t n;
    while ((n = read(ino, buf, sizeof buf)) > 0) {
      for (char *p = buf; p < buf + n;) {
        struct inotify_event *e = (struct inotify_event *)(void *)p;
        if (e->len && e->wd == main_wd && !strcmp(e->name, base))
          pending = now();
        for (int i = 0; i < nwatched; i++)
          if (e->len && e->wd == watched[i].wd &&
              !strcmp(e->name, watched[i].name))
            pending = now();
        if ((e->mask & IN_IGNORED) && e->wd == main_wd) {
          publish_error(&v, "the file's folder is gone: nothing to follow");
          gone = 1;
        }
        p += sizeof *e + e->len;
      }
    }
    /* The editor's dance is over once the name has been quiet 30 ms. */
    if (pending > 0 && now() - pending > 0.03) {
      pending = 0;
      struct stat st;
      if (stat(v.file, &st) != 0) {
        char msg[4400];
        snprintf(msg, sizeof msg, "%s: error: the file is gone (deleted or "
                 "renamed); waiting for it to come back", v.file);
        publish_error(&v, msg);
      } else {
        evaluate(&v, o, 1);
        nwatched = watch_deps(&v, ino, watched);
      }
    }
    (void)gone;
  }
  printf("qcs view: stopped after %ld requests (%ld refused)\n",
         atomic_load(&v.requests), atomic_load(&v.refused));
  fflush(stdout);
  view_finish(&v, d, &rt);
  close(ino);
  signal(SIGINT, SIG_DFL);
  signal(SIGTERM, SIG_DFL);
  return 0;
}

int view_scene(Interp *src_I, Scene *s, const RenderSettings *rs,
               const ViewOptions *o) {
  (void)src_I;
  static View v;
  view_init(&v, o);
  snprintf(v.dir, sizeof v.dir, ".");
  snprintf(v.stem, sizeof v.stem, "qcs");
  pthread_t rt;
  if (pthread_create(&rt, NULL, render_main, &v)) {
    scene_free(s);
    return -1;
  }
  struct MHD_Daemon *d = start(&v, o);
  if (!d) {
    scene_free(s);
    view_finish(&v, NULL, &rt);
    return -1;
  }
  publish(&v, s, rs, NULL, 0);
  printf("press Enter (or Ctrl-C) to stop serving\n");
  fflush(stdout);
  struct sigaction sa, old_int;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_signal;
  sigaction(SIGINT, &sa, &old_int);
  atomic_store(&stop_flag, 0);
  while (!atomic_load(&stop_flag)) {
    struct pollfd pfd = {0, POLLIN, 0};
    if (poll(&pfd, 1, 200) > 0) {
      char line[256];
      if (!fgets(line, sizeof line, stdin)) break;
      break;
    }
  }
  sigaction(SIGINT, &old_int, NULL);
  view_finish(&v, d, &rt);
  return 0;
}

/* ---- :view EXPR ---- */

/* The expression is evaluated as typed (an error points into it, named
   ":view"), then rendered (captured) as `render` would. */
static Value *view_item(Interp *I, void *ud) {
  Value *obj = interp_eval_expr(I, ":view", (const char *)ud);
  Pos none = {0};
  if (!compile_is_object(I, obj))
    qcs_error(none, ":view shows a scene object (Union, Rounded, Halfspace, "
              "SoftObject or a density tree); %.200s is "
              "not one", (const char *)ud);
  render_value(I, NULL, "view.png", obj, none);
  return NULL;
}

int view_expr(Interp *I, const char *expr, const ViewOptions *o) {
  if (strlen(expr) > 4000) {
    fprintf(stderr, "error: :view: the expression is too long\n");
    return -1;
  }
  if (!strcmp(expr, "scene") && !interp_has_global(I, "scene")) {
    fprintf(stderr, "error: :view: no `scene` is defined: define one, or "
            "give the object to show (:view EXPR)\n");
    return -1;
  }
  RenderOverrides *old = render_get_overrides(I), ov;
  Capture cap = {0};
  if (old) ov = *old;
  else memset(&ov, 0, sizeof ov);
  ov.output = NULL;
  ov.capture = capture;
  ov.capture_ctx = &cap;
  ov.keep = 1;
  ov.kept = NULL;
  render_set_overrides(I, &ov);
  Pos none = {0};
  RunStatus st = interp_run_item(I, none, view_item, (void *)expr);
  render_set_overrides(I, old);
  if (st != RUN_OK || !ov.kept || !cap.got) {
    scene_free(ov.kept);
    return -1;
  }
  return view_scene(I, ov.kept, &cap.rs, o);
}
