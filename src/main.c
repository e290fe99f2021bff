/* main.c: the command line.
 *
 *   qcs                  the REPL
 *   qcs FILE...          run scripts in order, stopping at the first error
 *   qcs -e EXPR          evaluate EXPR (prelude loaded), print it, exit
 *   qcs tradeoff FILE    error against run time over root tolerances
 *   qcs convolution      the quasi-convolution against the true one
 *
 * The interpreter runs on a thread of its own with a large stack, so that
 * deep (non-tail) recursion in user programs is limited by a clear
 * "recursion too deep" error rather than by the 8 MB default stack. */
#include <gc.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "image.h"
#include "interp.h"
#include "render_lang.h"
#include "repl.h"
#include "tradeoff.h"

#define STACK_SIZE ((size_t)512 << 20) /* reserved, touched only as used */
#define STACK_USE ((size_t)256 << 20)  /* ~350000 nested calls */
#define FALLBACK_STACK_USE ((size_t)6 << 20)

typedef struct Options {
  const char *exprs[64];
  int nexprs;
  const char *sets[64];
  int nsets;
  char **files;
  int nfiles;
  unsigned long long max_steps;
  long long max_memory_mb; /* -1: the default */
  int status;
  size_t stack_use;
  RenderOverrides render;
  int tradeoff;            /* qcs tradeoff: files[0] is the script */
  TradeoffOptions topt;
} Options;

static void usage(FILE *out) {
  fprintf(out,
          "usage: qcs [options] [FILE...]\n"
          "\n"
          "  qcs                 start the REPL\n"
          "  qcs FILE...         run scripts (top-level expressions are printed)\n"
          "  qcs -e EXPR         evaluate EXPR with the prelude loaded and print it\n"
          "\n"
          "options:\n"
          "  -e, --eval EXPR     evaluate and print EXPR (after any FILEs)\n"
          "  --set NAME=VALUE    replace the top-level definition NAME before\n"
          "                      the scripts run (VALUE is a qcs expression)\n"
          "  -o FILE             render to FILE (.exr, .png or .ppm): what the\n"
          "                      scripts render, or else their `scene`\n"
          "  --size WxH          image size, overriding the scripts' own\n"
          "  --spp N             samples per pixel (1, 4, 9, ...: n x n strata)\n"
          "  --threads N         render threads (default: all cores)\n"
          "  --tolerance T       root tolerance, a distance (default 1e-9)\n"
          "  --cost              add the root-finder cost channel to an EXR\n"
          "  --float             EXR colour as 32-bit floats (default half)\n"
          "  --max-steps N       stop an evaluation after N steps\n"
          "  --max-memory MB     stop an evaluation whose values pass MB megabytes\n"
          "                      (default 8192; 0 for no limit)\n"
          "  -h, --help          this help\n"
          "  -V, --version       the version\n"
          "\n"
          "The language is described in lang/ (lang/manual.md); `man qcs`.\n");
}

static void *run(void *arg) {
  Options *o = arg;
  Interp *I = interp_new();
  render_set_overrides(I, &o->render);
  char probe;
  interp_set_stack(I, &probe, o->stack_use);
  if (o->max_steps) interp_set_max_steps(I, o->max_steps);
  if (o->max_memory_mb >= 0)
    interp_set_max_memory(I, (size_t)o->max_memory_mb << 20);
  for (int i = 0; i < o->nsets; i++) {
    const char *eq = strchr(o->sets[i], '=');
    char name[256];
    size_t n = (size_t)(eq - o->sets[i]);
    if (n >= sizeof name) n = sizeof name - 1;
    memcpy(name, o->sets[i], n);
    name[n] = 0;
    if (interp_set_override(I, name, eq + 1) != RUN_OK) {
      o->status = 1;
      return NULL;
    }
  }
  if (o->tradeoff) {
    o->status = tradeoff_file(I, o->files[0], &o->topt);
    return NULL;
  }
  for (int i = 0; i < o->nfiles; i++)
    if (interp_run_file(I, o->files[i]) != RUN_OK) {
      o->status = 1;
      return NULL;
    }
  for (int i = 0; i < o->nexprs; i++)
    if (interp_eval_print(I, o->exprs[i]) != RUN_OK) {
      o->status = 1;
      return NULL;
    }
  /* -o with scripts that render nothing: render their `scene`. */
  if (o->render.output && o->render.renders == 0) {
    if (!interp_has_global(I, "scene")) {
      fprintf(stderr, "qcs: error: -o %s: the scripts render nothing and "
              "define no `scene` to render\n", o->render.output);
      o->status = 1;
      return NULL;
    }
    if (interp_eval_print(I, "renderWith [] \"-o\" scene") != RUN_OK) {
      o->status = 1;
      return NULL;
    }
  }
  if (o->nfiles == 0 && o->nexprs == 0) o->status = repl_run(I);
  return NULL;
}

/* ---- qcs tradeoff / qcs convolution (issue 6) ---- */

static void tradeoff_usage(FILE *out) {
  fputs("usage: qcs tradeoff [--size WxH] [--threads N] [--repeats N] "
        "[-o PLOT.svg] FILE.qcs\n"
        "       qcs convolution\n"
        "\n"
        "tradeoff: render what FILE renders (or its `scene`) at root "
        "tolerances\n1e-2 ... 1e-12, best of --repeats runs (default 3) "
        "each; print time,\nevaluations and error against the 1e-12 rung; "
        "plot error against time\n(default tradeoff.svg).\n"
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

int main(int argc, char **argv) {
  static Options o;
  o.max_memory_mb = -1;
  o.files = calloc((size_t)argc + 1, sizeof(char *));
  if (argc > 1 && !strcmp(argv[1], "convolution")) {
    int help = argc == 3 && !strcmp(argv[2], "--help");
    if (argc > 2) {
      tradeoff_usage(help ? stdout : stderr);
      return help ? 0 : 1;
    }
    return conv_report(stdout) ? 1 : 0;
  }
  int sub = argc > 1 && !strcmp(argv[1], "tradeoff");
  if (sub) {
    int rc = tradeoff_args(argc, argv, &o);
    if (rc) return rc < 0 ? 1 : 0;
  }
  for (int i = 1; i < argc && !sub; i++) {
    const char *a = argv[i];
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
    } else if (!strcmp(a, "--max-memory")) {
      char *end;
      long long mb = i + 1 < argc ? strtoll(argv[i + 1], &end, 10) : -1;
      if (i + 1 >= argc || *end || mb < 0 || mb > (1LL << 40)) {
        fprintf(stderr, "qcs: error: --max-memory needs megabytes, a whole "
                "number >= 0\n");
        return 1;
      }
      o.max_memory_mb = mb;
      i++;
    } else if (!strcmp(a, "--max-steps")) {
      char *end;
      if (i + 1 >= argc || !(o.max_steps = strtoull(argv[i + 1], &end, 10)) ||
          *end) {
        fprintf(stderr, "qcs: error: --max-steps needs a positive whole "
                "number\n");
        return 1;
      }
      i++;
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
    } else if (!strcmp(a, "--cost")) {
      o.render.cost = 1;
    } else if (!strcmp(a, "--float")) {
      o.render.float_pixels = 1;
    } else if (a[0] == '-' && a[1]) {
      fprintf(stderr, "qcs: error: unknown option '%s' (see qcs --help)\n", a);
      return 1;
    } else {
      o.files[o.nfiles++] = argv[i];
    }
  }
  if (o.render.output && o.nfiles == 0 && o.nexprs == 0) {
    fprintf(stderr, "qcs: error: -o needs a scene file to render\n");
    return 1;
  }
  if (o.render.output) {
    char err[300];
    if (img_format(o.render.output, err, sizeof err) < 0) {
      fprintf(stderr, "qcs: error: -o: %s\n", err);
      return 1;
    }
  }
  GC_INIT();
  GC_allow_register_threads();
  /* Ctrl-C ends a script's evaluation or render with "interrupted" (no
     partial image is ever left); the REPL installs its own handling. */
  if (o.nfiles || o.nexprs || o.tradeoff) repl_install_sigint();
  pthread_attr_t attr;
  pthread_attr_init(&attr);
  pthread_attr_setstacksize(&attr, STACK_SIZE);
  pthread_t th;
  o.stack_use = STACK_USE;
  if (pthread_create(&th, &attr, run, &o) != 0) {
    /* No big stack to be had: run here with the default one. */
    o.stack_use = FALLBACK_STACK_USE;
    run(&o);
  } else {
    pthread_join(th, NULL);
  }
  fflush(stdout);
  return o.status;
}
