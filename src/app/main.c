/* main.c: the command line.
 *
 *   qcs                  the REPL
 *   qcs FILE...          run scripts in order, stopping at the first error
 *   qcs -e EXPR          evaluate EXPR (prelude loaded), print it, exit
 *   qcs tradeoff FILE    error against run time over root tolerances
 *   qcs convolution      the quasi-convolution against the true one
 *   qcs --show FILE...   draw what the scripts render in the terminal
 *   qcs view FILE        a live viewer in the browser (app/view.h)
 *
 * The interpreter runs on a thread of its own with a large stack, so that
 * deep (non-tail) recursion in user programs is limited by a clear
 * "recursion too deep" error rather than by the 8 MB default stack. */
#include <gc.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "render/image.h"
#include "bind/bind.h"
#include "lang/interp.h"
#include "bind/render_lang.h"
#include "bind/mesh_lang.h"
#include "render/mesh.h"
#include "app/preview.h"
#include "app/repl.h"
#include "app/view.h"
#include "bind/report.h"
#include "study/tradeoff.h"

#include <time.h>

#define STACK_SIZE ((size_t)512 << 20) /* reserved, touched only as used */
#define STACK_USE ((size_t)256 << 20)  /* ~350000 nested calls: max-stack */
#define FALLBACK_STACK_USE ((size_t)6 << 20)

typedef struct Options {
  const char *exprs[64];
  int nexprs;
  const char *sets[64];
  int nsets;
  char **files;
  int nfiles;
  const char *limit_names[16]; /* --max-NAME VALUE, checked, in order */
  const char *limit_values[16];
  int nlimits;
  unsigned long long max_spp, max_pixels; /* as given, or the defaults */
  int status;
  int digits;              /* --digits N, or -1 */
  size_t stack_use, stack_reserved;
  RenderOverrides render;
  int tradeoff;            /* qcs tradeoff: files[0] is the script */
  TradeoffOptions topt;
  int show;                /* --show: renders are drawn in the terminal */
  PreviewMode preview;     /* --preview MODE (default auto) */
  int cells_w, cells_h;    /* --cells CxR (0: from the terminal) */
  int timings;             /* --timings: when the pictures came */
  double t_start;
  int view;                /* qcs view: files[0] is followed */
  ViewOptions vopt;
  char *stack_base;        /* the interpreter thread's, for qcs view */
  int params;              /* qcs params: files[0]'s parameters */
  int frames;              /* --frames A-B[:STEP] given */
  int f_first, f_last, f_step;
  int animation;           /* --animation F-L given (else: --frames A-B) */
  int a_first, a_last;
  int tiles;               /* --tiles N (with --index-env) */
  int index_env;           /* --index-env */
  MeshCli mesh;            /* --mesh-tolerance, --bounds (-o part.stl) */
  const char *mesh_opt;    /* the first of them given, for its error */
} Options;

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

/* --show: a render of the scripts is drawn progressively in the terminal
   instead of being written. */
static int show_capture(void *ctx, const Scene *s, const RenderSettings *rs,
                        const char *path, char *err, size_t errlen) {
  Options *o = ctx;
  static int asked;
  if (o->preview == PREVIEW_AUTO && !asked++)
    preview_query_terminal(STDIN_FILENO, STDOUT_FILENO, 150);
  PreviewMode m = preview_resolve(o->preview, STDOUT_FILENO);
  char line[512];
  report_scene(line, sizeof line, s, path);
  printf("%s\n", line);
  fflush(stdout);
  if (m == PREVIEW_OFF) {
    snprintf(err, errlen, "--show: standard output is not a terminal (give "
             "--preview symbols, sixel, kitty or iterm to draw anyway)");
    return -1;
  }
  double t0 = now();
  PreviewOptions po = {m, o->cells_w, o->cells_h, STDOUT_FILENO,
                       isatty(STDIN_FILENO) ? STDIN_FILENO : -1,
                       &qcs_interrupted};
  PreviewResult res;
  if (preview_show(stdout, s, rs, &po, &res, err, errlen)) return -1;
  if (res.rungs && !res.stopped && res.rep.primary > 0 && res.rep.hits == 0)
    printf("nothing hit: 0 of %ld primary rays met a surface\n",
           res.rep.primary);
  fflush(stdout);
  if (o->timings)
    fprintf(stderr, "%s: %dx%d pixels, %d picture%s; scene ready %.4f s after "
            "start, first picture %.4f s later, full %.4f s later\n", path,
            res.width, res.height, res.rungs, res.rungs == 1 ? "" : "s",
            t0 - o->t_start, res.t_first, res.t_full);
  return 0;
}

static void usage(FILE *out) {
  fprintf(out,
          "usage: qcs [options] [FILE...]\n"
          "\n"
          "  qcs                 start the REPL\n"
          "  qcs FILE...         run scripts (top-level expressions are printed)\n"
          "  qcs -e EXPR         evaluate EXPR with the prelude loaded and print it\n"
          "  qcs view FILE       a live view in the browser (qcs view --help)\n"
          "  qcs params FILE     list FILE's parameters (for --set)\n"
          "  qcs merge OUT PART...  assemble tiles into the whole picture\n"
          "\n"
          "options:\n"
          "  -e, --eval EXPR     evaluate and print EXPR (after any FILEs)\n"
          "  --set NAME=VALUE    replace the top-level definition NAME before\n"
          "                      the scripts run (VALUE is a qcs expression)\n"
          "  --digits N          print Reals to N significant digits (0, the\n"
          "                      default: the shortest that reads back); wins\n"
          "                      over a script's :set digits\n"
          "  -o FILE             render to FILE (.exr, .png, .ppm), or mesh to it\n"
          "                      (.stl, .obj, .ply, .3mf): what the scripts\n"
          "                      render, or else their `scene`\n"
          "  --mesh-tolerance E  with -o FILE.stl (.obj, .ply, .3mf): the\n"
          "                      mesh's tolerance, a distance (default 1/100\n"
          "                      of the object's largest side)\n"
          "  --bounds X0,Y0,Z0,X1,Y1,Z1  with a mesh -o: mesh the part inside\n"
          "                      this box, closed by its faces (a scene\n"
          "                      with a floor needs one)\n"
          "  --size WxH          image size, overriding the scripts' own\n"
          "  --spp N             samples per pixel (1, 4, 9, ...: n x n strata)\n"
          "  --threads N         render threads (default: all cores)\n"
          "  --tolerance T       root tolerance, a distance (default 1e-9)\n"
          "  --cost              add the root-finder cost channel to an EXR\n"
          "  --float             EXR colour as 32-bit floats (default half)\n"
          "  --frames A-B[:STEP] render frames A to B of an animation (frame\n"
          "                      and clock); -o out.####.png numbers the files\n"
          "  --animation F-L     the whole animation's frames, over which clock\n"
          "                      runs from 0 to 1 (default: the --frames range)\n"
          "  --alpha             transparent background (RGBA 0 where nothing is hit)\n"
          "  --crop X0,X1,Y0,Y1  render a part: columns, rows (ends excluded) or\n"
          "                      fractions (0.5,1.0,0,0.5); an EXR keeps its window\n"
          "  --tile I/N          render tile I (1..N) of a near-square grid of N\n"
          "  --tiles N --index-env  the tile from the job array's index\n"
          "                      (SLURM_ARRAY_TASK_ID, JOB_COMPLETION_INDEX,\n"
          "                      AWS_BATCH_JOB_ARRAY_INDEX, PARALLEL_SEQ)\n"
          "  --frames A-B --index-env  task k renders the k-th frame (from 0);\n"
          "                      with --tiles N too: frame k / N, tile k %% N + 1\n"
          "  --skip-existing     do not render a file that exists (retries)\n"
          "  --show              draw what the scripts render in the terminal,\n"
          "                      coarse first, instead of writing files\n"
          "  --preview MODE      how: auto (default), kitty, iterm, sixel,\n"
          "                      symbols (auto draws nothing to a pipe)\n"
          "  --cells CxR         the picture's size in character cells\n"
          "  --timings           say when the first and the full picture came\n"
          "\n"
          "limits (an evaluation or render that passes one stops with an error;\n"
          "in the REPL, :set lists and changes them):\n"
          "  --max-stack SIZE    stack for nested calls, i.e. recursion depth\n"
          "                      (default 256M; SIZE is a number with K, M, G)\n"
          "  --max-steps N       evaluation steps of one top-level expression\n"
          "                      (default 10000000000; 0 for no limit)\n"
          "  --max-list N        elements of one list (default 10000000; 0: none)\n"
          "  --max-memory SIZE   memory for values, and a mesh's growth (default\n"
          "                      8G, or half the RAM if less; a bare number is\n"
          "                      megabytes; 0: no limit)\n"
          "  --max-pixels N|WxH  pixels of one image (default 4096x4096)\n"
          "  --max-spp N         samples per pixel (default 64, at most 256)\n"
          "  -h, --help          this help\n"
          "  -V, --version       the version\n"
          "\n"
          "The language is described in lang/ (lang/manual.md); `man qcs`.\n");
}

/* A new interpreter set up as the options say (stack, limits, --set);
   NULL (the error reported) if an option is refused. */
static Interp *configured_interp(Options *o) {
  Interp *I = bind_interp_new();
  interp_set_stack(I, o->stack_base, o->stack_use);
  interp_set_stack_reserved(I, o->stack_reserved);
  if (o->digits >= 0) {
    I->digits = o->digits;
    I->digits_fixed = 1;
  }
  for (int i = 0; i < o->nlimits; i++) {
    char err[300];
    if (strcmp(o->limit_names[i], "max-stack") &&
        interp_set_limit(I, o->limit_names[i], o->limit_values[i], err,
                         sizeof err)) {
      fprintf(stderr, "qcs: error: --%s\n", err);
      return NULL;
    }
  }
  for (int i = 0; i < o->nsets; i++) {
    const char *eq = strchr(o->sets[i], '=');
    char name[256];
    size_t n = (size_t)(eq - o->sets[i]);
    if (n >= sizeof name) n = sizeof name - 1;
    memcpy(name, o->sets[i], n);
    name[n] = 0;
    if (interp_set_override(I, name, eq + 1) != RUN_OK) return NULL;
  }
  return I;
}

static Interp *view_interp(void *ud) {
  Interp *I = configured_interp(ud);
  return I ? I : bind_interp_new();
}

/* ---- animation: --frames A-B[:STEP], --animation F-L ---- */

/* "A-B[:STEP]" (or "A") into first, last, step; -1 if malformed. */
static int parse_frames(const char *t, int *first, int *last, int *step,
                        int allow_step) {
  char *end;
  long a = strtol(t, &end, 10), b = a, s = 1;
  if (end == t || a < 0 || a > 999999999) return -1;
  if (*end == '-') {
    const char *u = end + 1;
    b = strtol(u, &end, 10);
    if (end == u || b < 0 || b > 999999999) return -1;
  }
  if (*end == ':' && allow_step) {
    const char *u = end + 1;
    s = strtol(u, &end, 10);
    if (end == u || s < 1 || s > 999999999) return -1;
  }
  if (*end || b < a) return -1;
  *first = (int)a;
  *last = (int)b;
  *step = (int)s;
  return 0;
}

/* Parses --frames or --animation's argument into o; 0, or -1 (said). */
static int frames_option(Options *o, const char *opt, const char *arg) {
  int frames = !strcmp(opt, "--frames"), step = 1;
  if (!arg || parse_frames(arg, frames ? &o->f_first : &o->a_first,
                           frames ? &o->f_last : &o->a_last, &step,
                           frames)) {
    fprintf(stderr, "qcs: error: %s needs %s, like %s, not '%s'\n", opt,
            frames ? "FIRST-LAST[:STEP] (frame numbers, LAST >= FIRST)"
                   : "FIRST-LAST (frame numbers, LAST >= FIRST)",
            frames ? "1-100 or 1-100:5" : "1-100", arg ? arg : "nothing");
    return -1;
  }
  if (frames) o->frames = 1, o->f_step = step;
  else o->animation = 1;
  return 0;
}

/* After all options: the frames rendered must lie in the animation. */
static int frames_check(Options *o) {
  if (o->animation && !o->frames) {
    o->frames = 1;
    o->f_first = o->a_first;
    o->f_last = o->a_last;
    o->f_step = 1;
  }
  if (!o->frames) return 0;
  if (!o->animation) o->a_first = o->f_first, o->a_last = o->f_last;
  if (o->f_first < o->a_first || o->f_last > o->a_last) {
    fprintf(stderr, "qcs: error: --frames %d-%d is not within the animation's "
            "frames %d-%d (--animation)\n", o->f_first, o->f_last,
            o->a_first, o->a_last);
    return -1;
  }
  if (o->nfiles == 0) {
    fprintf(stderr, "qcs: error: --frames needs a scene file\n");
    return -1;
  }
  o->render.animating = 1;
  return 0;
}

/* Runs the scripts (and -e) once per frame: the first frame evaluates
   them; later ones re-bind frame and clock and evaluate again what depends
   on them, then every top-level expression. 0, or 1 after an error. */
static int run_scripts(Options *o, Interp *I) {
  int first = o->frames ? o->f_first : 0, last = o->frames ? o->f_last : 0;
  int step = o->frames ? o->f_step : 1;
  for (int f = first; f <= last; f += step) {
    int before = o->render.renders;
    o->render.frame_renders = before;
    if (o->frames) {
      double clock = o->a_last == o->a_first ? 0.0 :
          (double)(f - o->a_first) / (double)(o->a_last - o->a_first);
      o->render.frame = f;
      interp_set_frame(I, (double)f, clock);
    }
    if (f == first) {
      for (int i = 0; i < o->nfiles; i++)
        if (interp_run_file(I, o->files[i]) != RUN_OK) return 1;
    } else if (interp_rerun(I) != RUN_OK) {
      return 1;
    }
    for (int i = 0; i < o->nexprs; i++)
      if (interp_eval_print(I, o->exprs[i]) != RUN_OK) return 1;
    /* -o or --show with scripts that render nothing: their `scene`. */
    if ((o->render.output || o->show) && o->render.renders == before &&
        render_lang_scene(I, o->render.output ? o->render.output : "scene") !=
            RUN_OK)
      return 1;
  }
  return 0;
}

static void *run_body(void *arg) {
  Options *o = arg;
  char probe;
  o->stack_base = &probe;
  if (o->view) {
    o->vopt.new_interp = view_interp;
    o->vopt.ud = o;
    o->status = view_file(o->files[0], &o->vopt);
    return NULL;
  }
  Interp *I = configured_interp(o);
  if (!I) {
    o->status = 1;
    return NULL;
  }
  render_set_overrides(I, &o->render);
  if (o->tradeoff) {
    o->status = tradeoff_file(I, o->files[0], &o->topt);
    return NULL;
  }
  if (o->show) {
    o->render.capture = show_capture;
    o->render.capture_ctx = o;
  } else if (o->render.output && mesh_is_mesh_path(o->render.output)) {
    o->render.capture = mesh_lang_capture; /* -o part.stl: mesh, not render */
    o->mesh.I = I;                          /* its max-memory */
    o->render.capture_ctx = &o->mesh;
  }
  if (o->params) {
    o->status = interp_params(I, o->files[0], stdout) != RUN_OK;
    return NULL;
  }
  if (run_scripts(o, I)) {
    o->status = 1;
    return NULL;
  }
  if (o->nfiles == 0 && o->nexprs == 0 && !o->show) o->status = repl_run(I);
  return NULL;
}

/* The evaluator's thread: run_body, then the main thread told it is
   done. The main thread leaves the collector before it waits (libgc
   allows the main thread to unregister once), so its stack is not
   scanned while it waits: the words libgc's start-up left in its
   registers and frames (addresses inside the first heap section it
   made, such as 0x...b12000) were spilled into the waiting frames and
   scanned, and when a cell of a stream being consumed later began at
   such an address, it and every cell made after it stayed alive
   (`length [1 .. 3000000]` under --max-memory 32M failed in every run
   with GC_MARKERS=1 on one machine, 4 in 30 without: a search of the
   process's memory under gdb found the oldest live cell referenced only
   from the main thread's stack). Options is static, so what the
   evaluator keeps in it is still scanned. */
static struct {
  pthread_mutex_t mu;
  pthread_cond_t cv;
  int done;
} run_done = {PTHREAD_MUTEX_INITIALIZER, PTHREAD_COND_INITIALIZER, 0};

static void *run(void *arg) {
  run_body(arg);
  pthread_mutex_lock(&run_done.mu);
  run_done.done = 1;
  pthread_cond_signal(&run_done.cv);
  pthread_mutex_unlock(&run_done.mu);
  return NULL;
}

static void wait_run(void) {
  pthread_mutex_lock(&run_done.mu);
  while (!run_done.done) pthread_cond_wait(&run_done.cv, &run_done.mu);
  pthread_mutex_unlock(&run_done.mu);
}

/* ---- qcs tradeoff / qcs convolution (issue 6) ---- */

static void tradeoff_usage(FILE *out) {
  fputs("usage: qcs tradeoff [--spp | --mesh] [--size WxH] [--threads N] "
        "[--repeats N]\n                    [-o PLOT.svg] FILE.qcs\n"
        "       qcs convolution\n"
        "\n"
        "tradeoff: render what FILE renders (or its `scene`) at root "
        "tolerances\n1e-2 ... 1e-12, best of --repeats runs (default 3) "
        "each; print time,\nevaluations and error against the 1e-12 rung; "
        "plot error against time\n(default tradeoff.svg). With --spp: "
        "render it at 1, 4, 16, 64 samples per pixel\nagainst a 256-sample "
        "reference (the script's size capped to 160 wide unless\n--size) "
        "and plot RMS RGB error against time. With --mesh: mesh its bounded "
        "part\nat 1/10, 1/20, 1/40, 1/80 of its size (best of --repeats, "
        "default 1):\ntriangles, time, certified and sampled distance to "
        "the surface.\n"
        "convolution: the quasi-convolutional surface against the true\n"
        "convolution of the polyhedron with the ball, on canonical "
        "objects.\n", out);
}

/* Parses the subcommand's arguments into o; -1: exit with status 1,
   1: exit with status 0, 0: run. */
static int tradeoff_args(int argc, char **argv, Options *o) {
  o->tradeoff = 1;
  for (int i = 2; i < argc; i++) {
    const char *a = argv[i];
    int w, h;
    long n;
    char c, *end;
    if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
      tradeoff_usage(stdout);
      return 1;
    } else if (!strcmp(a, "--spp")) {
      o->topt.spp_ladder = 1;
    } else if (!strcmp(a, "--mesh")) {
      o->topt.mesh_ladder = 1;
    } else if (!strcmp(a, "--size") && i + 1 < argc &&
               sscanf(argv[i + 1], "%dx%d%c", &w, &h, &c) == 2 && w > 0 &&
               h > 0) {
      o->topt.width = w;
      o->topt.height = h;
      i++;
    } else if ((!strcmp(a, "--threads") || !strcmp(a, "--repeats")) &&
               i + 1 < argc && (n = strtol(argv[i + 1], &end, 10)) >= 1 &&
               n <= 256 && !*end) {
      if (a[2] == 't') o->topt.threads = (int)n;
      else o->topt.repeats = (int)n;
      i++;
    } else if (!strcmp(a, "-o") && i + 1 < argc) {
      o->topt.svg = argv[++i];
    } else if (a[0] == '-' && a[1]) {
      fprintf(stderr, "qcs: error: tradeoff: bad option or argument '%s'\n", a);
      tradeoff_usage(stderr);
      return -1;
    } else {
      o->files[o->nfiles++] = argv[i];
    }
  }
  if (o->nfiles != 1) {
    fprintf(stderr, "qcs: error: tradeoff needs one scene file\n");
    tradeoff_usage(stderr);
    return -1;
  }
  return 0;
}

static void view_usage(FILE *out) {
  fputs("usage: qcs view [--listen ADDR:PORT] [--threads N] [--set NAME=VALUE] "
        "FILE.qcs\n"
        "\n"
        "Serve a live view of what FILE renders (or its `scene`) in the "
        "browser:\nopen the printed URL. The picture follows the file on "
        "every save; drag to\norbit, shift-drag to pan, wheel to zoom, "
        "click to probe a pixel; the file's\nparameters (`param`) get "
        "sliders, whose values stay over saves. Listens on\n127.0.0.1 and a free port "
        "unless --listen says otherwise. Ctrl-C stops it.\n", out);
}

/* qcs view's arguments into o; -1: exit 1, 1: exit 0, 0: run. */
static int view_args(int argc, char **argv, Options *o) {
  o->view = 1;
  for (int i = 2; i < argc; i++) {
    const char *a = argv[i];
    char err[200], *end;
    long n;
    if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
      view_usage(stdout);
      return 1;
    } else if (!strcmp(a, "--listen") && i + 1 < argc) {
      if (view_parse_listen(argv[i + 1], err, sizeof err)) {
        fprintf(stderr, "qcs: error: view: %s\n", err);
        return -1;
      }
      o->vopt.listen = argv[++i];
    } else if (!strcmp(a, "--threads") && i + 1 < argc &&
               (n = strtol(argv[i + 1], &end, 10)) >= 1 && n <= 256 && !*end) {
      o->vopt.threads = (int)n;
      i++;
    } else if (!strcmp(a, "--set") && i + 1 < argc &&
               strchr(argv[i + 1], '=') && o->nsets < 64) {
      o->sets[o->nsets++] = argv[++i];
    } else if (a[0] == '-' && a[1]) {
      fprintf(stderr, "qcs: error: view: bad option or argument '%s'\n", a);
      view_usage(stderr);
      return -1;
    } else {
      o->files[o->nfiles++] = argv[i];
    }
  }
  if (o->nfiles != 1) {
    fprintf(stderr, "qcs: error: view needs one scene file\n");
    view_usage(stderr);
    return -1;
  }
  return 0;
}

/* qcs params FILE: the table of FILE's parameters. -1: exit 1, 1: exit
   0, 0: run. */
static int params_args(int argc, char **argv, Options *o) {
  if (argc == 3 && strcmp(argv[2], "-h") && strcmp(argv[2], "--help")) {
    o->params = 1;
    o->files[o->nfiles++] = argv[2];
    return 0;
  }
  int help = argc == 3;
  fputs("usage: qcs params FILE.qcs\n\nList the parameters FILE declares "
        "(`param NAME = DEFAULT in [LOW, HIGH] \"DOC\"`),\nwhich --set "
        "NAME=VALUE may change: name, default, range, doc.\n",
        help ? stdout : stderr);
  return help ? 1 : -1;
}

/* ---- partial renders and farms (issue 17) ---- */

/* --crop X0,X1,Y0,Y1: four numbers, a decimal point making one a
   fraction of its side. 0 or -1. */
static int parse_crop(const char *arg, RenderOverrides *r) {
  const char *p = arg;
  for (int k = 0; k < 4; k++) {
    char *end;
    double v = strtod(p, &end);
    if (end == p || !(v >= 0) || v > IMG_MAX_SIDE) return -1;
    int frac = memchr(p, '.', (size_t)(end - p)) != NULL;
    if (frac ? v > 1 : v != (double)(long)v) return -1;
    r->crop[k] = v;
    r->crop_frac[k] = frac;
    if (k < 3 && *end != ',') return -1;
    p = end + (k < 3);
    if (k == 3 && *end) return -1;
  }
  r->crop_set = 1;
  return 0;
}

/* The farm options at argv[*i]: 1 if taken (and *i moved past a value),
   0 if not one of them, -1 after an error message. */
static int farm_option(int argc, char **argv, int *i, Options *o) {
  const char *a = argv[*i], *v = *i + 1 < argc ? argv[*i + 1] : NULL;
  if (!strcmp(a, "--crop")) {
    if (!v || parse_crop(v, &o->render)) {
      fprintf(stderr, "qcs: error: --crop needs X0,X1,Y0,Y1: pixel columns "
              "and rows from 0, the ends excluded, or fractions of the "
              "picture (0.0 to 1.0), like 0,320,0,240 or 0.5,1.0,0.0,0.5\n");
      return -1;
    }
  } else if (!strcmp(a, "--tile")) {
    int t, n;
    char c;
    if (!v || sscanf(v, "%d/%d%c", &t, &n, &c) != 2 || n < 1 || n > 65536 ||
        t < 1 || t > n) {
      fprintf(stderr, "qcs: error: --tile needs I/N with 1 <= I <= N, like "
              "3/16 (tile 3 of a grid of 16)\n");
      return -1;
    }
    o->render.tile_index = t;
    o->render.tile_count = n;
  } else if (!strcmp(a, "--tiles")) {
    char *end;
    long n = v ? strtol(v, &end, 10) : 0;
    if (!v || *end || n < 1 || n > 65536) {
      fprintf(stderr, "qcs: error: --tiles needs a count from 1 to 65536\n");
      return -1;
    }
    o->tiles = (int)n;
  } else if (!strcmp(a, "--index-env")) {
    o->index_env = 1;
    return 1;
  } else if (!strcmp(a, "--alpha")) {
    o->render.alpha = 1;
    return 1;
  } else if (!strcmp(a, "--skip-existing")) {
    o->render.skip_existing = 1;
    return 1;
  } else {
    return 0;
  }
  (*i)++;
  return 1;
}

/* The task index a job array gives its task (0-based), from the first of
   these that is set: Slurm (less SLURM_ARRAY_TASK_MIN), Kubernetes
   Indexed Jobs, AWS Batch array jobs (0-based), GNU parallel (1-based).
   -1 with a message when none is, or it is not a number. */
static long farm_task_index(const char **from) {
  static const char *const vars[] = {"SLURM_ARRAY_TASK_ID",
                                     "JOB_COMPLETION_INDEX",
                                     "AWS_BATCH_JOB_ARRAY_INDEX",
                                     "PARALLEL_SEQ"};
  for (size_t k = 0; k < sizeof vars / sizeof *vars; k++) {
    const char *v = getenv(vars[k]);
    if (!v || !*v) continue;
    char *end;
    long i = strtol(v, &end, 10);
    if (*end || i < 0) {
      fprintf(stderr, "qcs: error: --index-env: %s=%s is not a task index\n",
              vars[k], v);
      return -1;
    }
    if (k == 0 && getenv("SLURM_ARRAY_TASK_MIN"))
      i -= strtol(getenv("SLURM_ARRAY_TASK_MIN"), NULL, 10);
    if (k == 3) i--;
    *from = vars[k];
    return i;
  }
  fprintf(stderr, "qcs: error: --index-env: none of SLURM_ARRAY_TASK_ID, "
          "JOB_COMPLETION_INDEX, AWS_BATCH_JOB_ARRAY_INDEX, PARALLEL_SEQ is "
          "set\n");
  return -1;
}

/* --index-env: the job array's task k renders, with --tiles N alone,
   tile k + 1 of N; with --frames A-B[:STEP] alone, the k-th frame of the
   range (from 0); with both, frame k / N of the range and tile k % N + 1.
   The animation (clock) stays the whole range, or --animation. 0 or -1. */
static int farm_resolve(Options *o) {
  if (o->tiles && o->render.tile_count) {
    fprintf(stderr, "qcs: error: give --tile I/N or --tiles N, not both\n");
    return -1;
  }
  if (o->render.crop_set && (o->tiles || o->render.tile_count)) {
    fprintf(stderr, "qcs: error: give --crop or a tile, not both\n");
    return -1;
  }
  if (o->tiles && !o->index_env) {
    fprintf(stderr, "qcs: error: --tiles N takes the tile from the job's "
            "index: add --index-env (or give --tile I/N)\n");
    return -1;
  }
  if (o->index_env && !o->tiles && !o->frames) {
    fprintf(stderr, "qcs: error: --index-env needs --tiles N (how many "
            "tasks share the picture), --frames A-B[:STEP] (one frame a "
            "task), or both\n");
    return -1;
  }
  if (!o->index_env) return 0;
  const char *from = NULL;
  long k = farm_task_index(&from);
  if (k < 0) return -1;
  long tiles = o->tiles ? o->tiles : 1;
  long nframes = o->frames ? (o->f_last - o->f_first) / o->f_step + 1 : 1;
  if (k >= tiles * nframes) {
    if (o->frames && o->tiles)
      fprintf(stderr, "qcs: error: --index-env: task %ld (from %s) is past "
              "the last of %ld tasks (%ld frames x %d tiles; tasks count "
              "from 0)\n", k, from, tiles * nframes, nframes, o->tiles);
    else if (o->frames)
      fprintf(stderr, "qcs: error: --index-env: task %ld (from %s) is past "
              "the last of %ld frames of --frames %d-%d:%d (tasks count "
              "from 0)\n", k, from, nframes, o->f_first, o->f_last,
              o->f_step);
    else
      fprintf(stderr, "qcs: error: --index-env: task %ld (from %s) is past "
              "the last of %d tiles (tasks count from 0)\n", k, from,
              o->tiles);
    return -1;
  }
  if (o->frames) {
    int f = o->f_first + (int)(k / tiles) * o->f_step;
    o->f_first = o->f_last = f;
    o->f_step = 1;
  }
  if (o->tiles) {
    o->render.tile_index = (int)(k % tiles) + 1;
    o->render.tile_count = o->tiles;
  }
  return 0;
}

/* qcs merge OUT PART...: exit status. */
static int merge_main(int argc, char **argv) {
  if (argc == 3 && (!strcmp(argv[2], "-h") || !strcmp(argv[2], "--help"))) {
    puts("usage: qcs merge OUT.exr|OUT.png PART...\n\n"
         "Assemble the parts of one render (qcs --tile I/N or --crop, .exr "
         "or .png)\ninto OUT, the single render's file bit for bit. Every "
         "part must be of the\nsame render; together they must cover the "
         "picture once.");
    return 0;
  }
  if (argc < 4) {
    fprintf(stderr, "qcs: error: merge needs OUT and at least one part "
            "(qcs merge --help)\n");
    return 1;
  }
  char err[1024];
  const char *out = argv[2];
  if (img_format(out, err, sizeof err) < 0 ||
      render_writable(out, err, sizeof err) < 0) {
    fprintf(stderr, "qcs: error: merge: %s\n", err);
    return 1;
  }
  Image *im = img_merge((const char *const *)argv + 3, argc - 3, err,
                        sizeof err);
  if (!im) {
    fprintf(stderr, "qcs: error: merge: %s; %s not written\n", err, out);
    return 1;
  }
  ImgWriteOptions wo = {0};
  wo.float_pixels = im->float_pixels;
  const char *al = img_get_attr(im, "qcs.alpha");
  wo.alpha = al && !strcmp(al, "on");
  int rc = img_write(im, out, &wo, err, sizeof err);
  img_free(im);
  if (rc) {
    fprintf(stderr, "qcs: error: merge: %s\n", err);
    return 1;
  }
  return 0;
}

int main(int argc, char **argv) {
  static Options o;
  o.t_start = now();
  o.digits = -1;
  o.preview = PREVIEW_AUTO;
  o.max_spp = QCS_DEFAULT_MAX_SPP;
  o.max_pixels = QCS_DEFAULT_MAX_PIXELS;
  o.files = calloc((size_t)argc + 1, sizeof(char *));
  if (argc > 1 && !strcmp(argv[1], "convolution")) {
    int help = argc == 3 && !strcmp(argv[2], "--help");
    if (argc > 2) {
      tradeoff_usage(help ? stdout : stderr);
      return help ? 0 : 1;
    }
    return conv_report(stdout) ? 1 : 0;
  }
  if (argc > 1 && !strcmp(argv[1], "params")) {
    int rc = params_args(argc, argv, &o);
    if (rc) return rc < 0 ? 1 : 0;
  }
  if (argc > 1 && !strcmp(argv[1], "merge")) return merge_main(argc, argv);
  int sub = argc > 1 && !strcmp(argv[1], "tradeoff");
  if (sub) {
    int rc = tradeoff_args(argc, argv, &o);
    if (rc) return rc < 0 ? 1 : 0;
  }
  if (argc > 1 && !strcmp(argv[1], "view")) {
    int rc = view_args(argc, argv, &o);
    if (rc) return rc < 0 ? 1 : 0;
    sub = 1;
  }
  if (o.params) sub = 1;
  for (int i = 1; i < argc && !sub; i++) {
    const char *a = argv[i];
    int fr;
    if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
      usage(stdout);
      return 0;
    } else if (!strcmp(a, "-V") || !strcmp(a, "--version")) {
      printf("qcs %s\n", interp_version());
      return 0;
    } else if (!strcmp(a, "-e") || !strcmp(a, "--eval")) {
      if (i + 1 >= argc) {
        fprintf(stderr, "qcs: error: %s needs an expression\n", a);
        return 1;
      }
      if (o.nexprs == 64) {
        fprintf(stderr, "qcs: error: too many -e options\n");
        return 1;
      }
      o.exprs[o.nexprs++] = argv[++i];
    } else if (!strcmp(a, "--digits")) {
      char *end = NULL;
      long d = i + 1 < argc ? strtol(argv[i + 1], &end, 10) : -1;
      if (!end || end == argv[i + 1] || *end || d < 0 || d > 17) {
        fprintf(stderr, "qcs: error: --digits needs 0 (shortest that reads "
                "back) to 17%s%s%s\n", end ? ", not '" : "",
                end ? argv[i + 1] : "", end ? "'" : "");
        return 1;
      }
      o.digits = (int)d;
      i++;
    } else if (!strcmp(a, "--set")) {
      if (i + 1 >= argc || !strchr(argv[i + 1], '=')) {
        fprintf(stderr, "qcs: error: --set needs NAME=VALUE\n");
        return 1;
      }
      if (o.nsets == 64) {
        fprintf(stderr, "qcs: error: too many --set options\n");
        return 1;
      }
      o.sets[o.nsets++] = argv[++i];
    } else if (!strncmp(a, "--max-", 6)) {
      /* --max-NAME VALUE or --max-NAME=VALUE */
      char name[32], err[300];
      const char *eq = strchr(a, '='), *val;
      size_t n = eq ? (size_t)(eq - a - 2) : strlen(a + 2);
      if (n >= sizeof name) n = sizeof name - 1;
      memcpy(name, a + 2, n);
      name[n] = 0;
      if (eq) val = eq + 1;
      else if (i + 1 < argc) val = argv[++i];
      else val = NULL;
      unsigned long long v;
      if (interp_limit_parse(name, val ? val : "", &v, err, sizeof err)) {
        if (!strncmp(err, "unknown", 7)) {
          const char *dym = strstr(err, "(did you mean ");
          if (dym)
            fprintf(stderr, "qcs: error: unknown option '%.*s' (did you "
                    "mean --%s\n", (int)(eq ? eq - a : (int)strlen(a)), a,
                    dym + 14);
          else
            fprintf(stderr, "qcs: error: unknown option '%.*s' (see qcs "
                    "--help)\n", (int)(eq ? eq - a : (int)strlen(a)), a);
        } else if (!val) {
          fprintf(stderr, "qcs: error: --%s needs a value\n", name);
        } else {
          fprintf(stderr, "qcs: error: --%s\n", err);
        }
        return 1;
      }
      if (o.nlimits == 16) {
        fprintf(stderr, "qcs: error: too many --max options\n");
        return 1;
      }
      if (!strcmp(name, "max-stack")) o.stack_use = (size_t)v;
      if (!strcmp(name, "max-spp")) o.max_spp = v;
      if (!strcmp(name, "max-pixels")) o.max_pixels = v;
      char *keep = malloc(strlen(name) + 1);
      if (!keep) return 1;
      strcpy(keep, name);
      o.limit_names[o.nlimits] = keep;
      o.limit_values[o.nlimits++] = val;
    } else if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
      if (i + 1 >= argc) {
        fprintf(stderr, "qcs: error: %s needs a file name\n", a);
        return 1;
      }
      o.render.output = argv[++i];
    } else if (!strcmp(a, "--size")) {
      int w, h;
      char c;
      if (i + 1 >= argc || sscanf(argv[i + 1], "%dx%d%c", &w, &h, &c) != 2 ||
          w < 1 || h < 1) {
        fprintf(stderr, "qcs: error: --size needs WxH, like 600x380\n");
        return 1;
      }
      o.render.width = w;
      o.render.height = h;
      i++;
    } else if (!strcmp(a, "--spp") || !strcmp(a, "--threads")) {
      char *end;
      long n = i + 1 < argc ? strtol(argv[i + 1], &end, 10) : -1;
      if (i + 1 >= argc || *end || n < (a[2] == 's' ? 1 : 1) || n > 256) {
        fprintf(stderr, "qcs: error: %s needs a whole number from 1 to 256\n", a);
        return 1;
      }
      if (a[2] == 's') o.render.spp = (int)n;
      else o.render.threads = (int)n;
      i++;
    } else if (!strcmp(a, "--tolerance")) {
      char *end;
      double t = i + 1 < argc ? strtod(argv[i + 1], &end) : 0;
      if (i + 1 >= argc || *end || !(t > 0) || t > 1e300) {
        fprintf(stderr, "qcs: error: --tolerance needs a distance > 0\n");
        return 1;
      }
      o.render.tol = t;
      i++;
    } else if (!strcmp(a, "--mesh-tolerance")) {
      char *end;
      double t = i + 1 < argc ? strtod(argv[i + 1], &end) : 0;
      if (i + 1 >= argc || *end || !(t > 0) || !isfinite(t)) {
        fprintf(stderr, "qcs: error: --mesh-tolerance needs a distance > 0, "
                "like 0.001\n");
        return 1;
      }
      o.mesh.tol = t;
      if (!o.mesh_opt) o.mesh_opt = a;
      i++;
    } else if (!strcmp(a, "--bounds")) {
      double v[6];
      int k = 0;
      const char *p = i + 1 < argc ? argv[i + 1] : "";
      for (; k < 6; k++) { /* six numbers, a comma between each two */
        char *end;
        v[k] = strtod(p, &end);
        if (end == p || !isfinite(v[k]) || *end != (k < 5 ? ',' : '\0')) break;
        p = end + 1;
      }
      if (k < 6 || !(v[0] < v[3] && v[1] < v[4] && v[2] < v[5])) {
        fprintf(stderr, "qcs: error: --bounds needs X0,Y0,Z0,X1,Y1,Z1, the "
                "box's low and high corners, finite, with X0 < X1, Y0 < Y1 "
                "and Z0 < Z1\n");
        return 1;
      }
      o.mesh.has_bounds = 1;
      memcpy(o.mesh.lo, v, sizeof o.mesh.lo);
      memcpy(o.mesh.hi, v + 3, sizeof o.mesh.hi);
      if (!o.mesh_opt) o.mesh_opt = a;
      i++;
    } else if (!strcmp(a, "--cost")) {
      o.render.cost = 1;
    } else if (!strcmp(a, "--show")) {
      o.show = 1;
    } else if (!strcmp(a, "--timings")) {
      o.timings = 1;
    } else if (!strcmp(a, "--preview")) {
      if (i + 1 >= argc || preview_mode_parse(argv[i + 1], &o.preview) ||
          o.preview == PREVIEW_OFF) {
        fprintf(stderr, "qcs: error: --preview needs auto, kitty, iterm, "
                "sixel or symbols\n");
        return 1;
      }
      i++;
    } else if (!strcmp(a, "--cells")) {
      int w, h;
      char c;
      if (i + 1 >= argc || sscanf(argv[i + 1], "%dx%d%c", &w, &h, &c) != 2 ||
          w < 1 || h < 1 || w > PREVIEW_MAX_COLS || h > PREVIEW_MAX_ROWS) {
        fprintf(stderr, "qcs: error: --cells needs COLUMNSxROWS, at most "
                "%dx%d\n", PREVIEW_MAX_COLS, PREVIEW_MAX_ROWS);
        return 1;
      }
      o.cells_w = w;
      o.cells_h = h;
      i++;
    } else if (!strcmp(a, "--float")) {
      o.render.float_pixels = 1;
    } else if (!strcmp(a, "--frames") || !strcmp(a, "--animation")) {
      if (frames_option(&o, a, i + 1 < argc ? argv[i + 1] : NULL)) return 1;
      i++;
    } else if (!strncmp(a, "--", 2) && (fr = farm_option(argc, argv, &i, &o))) {
      if (fr < 0) return 1;
    } else if (a[0] == '-' && a[1]) {
      fprintf(stderr, "qcs: error: unknown option '%s' (see qcs --help)\n", a);
      return 1;
    } else {
      o.files[o.nfiles++] = argv[i];
    }
  }
  if (!sub && frames_check(&o)) return 1;
  if (!sub && farm_resolve(&o)) return 1;
  if (o.render.output && o.nfiles == 0 && o.nexprs == 0) {
    fprintf(stderr, "qcs: error: -o needs a scene file to render\n");
    return 1;
  }
  if (o.mesh_opt && !sub &&
      !(o.render.output && mesh_is_mesh_path(o.render.output))) {
    fprintf(stderr, "qcs: error: %s is for a mesh: it needs -o FILE.stl "
            "(.obj, .ply, .3mf)\n", o.mesh_opt);
    return 1;
  }
  if (o.render.output) {
    char err[300];
    if ((!mesh_is_mesh_path(o.render.output) &&
         img_format(o.render.output, err, sizeof err) < 0) ||
        render_writable(o.render.output, err, sizeof err) < 0) {
      fprintf(stderr, "qcs: error: -o: %s\n", err);
      return 1;
    }
  }
  /* Options that pass a limit are refused before anything runs. */
  if (o.render.spp && (unsigned long long)o.render.spp > o.max_spp) {
    fprintf(stderr, "qcs: error: --spp %d is over %llu samples per pixel "
            "(limit max-spp; raise it with --max-spp N)\n", o.render.spp,
            o.max_spp);
    return 1;
  }
  if (o.render.width && (unsigned long long)o.render.width *
                                (unsigned long long)o.render.height >
                            o.max_pixels) {
    fprintf(stderr, "qcs: error: --size %dx%d is %llu pixels, over %llu "
            "(limit max-pixels; raise it with --max-pixels N)\n",
            o.render.width, o.render.height,
            (unsigned long long)o.render.width *
                (unsigned long long)o.render.height, o.max_pixels);
    return 1;
  }
  interp_gc_init();
  GC_allow_register_threads();
  /* Ctrl-C ends a script's evaluation or render with "interrupted" (no
     partial image is ever left); the REPL installs its own handling. */
  if (o.nfiles || o.nexprs || o.tradeoff) repl_install_sigint();
  pthread_attr_t attr;
  pthread_attr_init(&attr);
  /* The stack reserved is a third more than max-stack allows, so that
     what runs below the checks has room; :set max-stack may raise the
     limit up to three quarters of it. */
  int asked = o.stack_use != 0;
  if (!asked) o.stack_use = STACK_USE;
  o.stack_reserved = o.stack_use / 3 * 4;
  if (o.stack_reserved < STACK_SIZE) o.stack_reserved = STACK_SIZE;
  pthread_attr_setstacksize(&attr, o.stack_reserved);
  pthread_t th;
  if (pthread_create(&th, &attr, run, &o) != 0) {
    if (asked) {
      char sz[32];
      interp_format_size(sz, sizeof sz, o.stack_use);
      fprintf(stderr, "qcs: error: --max-stack %s: cannot reserve a stack "
              "that large\n", sz);
      return 1;
    }
    /* No big stack to be had: run here with the default one. */
    o.stack_use = o.stack_reserved = FALLBACK_STACK_USE;
    run(&o);
  } else {
    GC_unregister_my_thread();
    wait_run();
    pthread_join(th, NULL);
  }
  fflush(stdout);
  return o.status;
}
