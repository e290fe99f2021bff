/* interp.h: one qcs interpreter, the face the front end (main, repl) sees.
 *
 * An Interp holds the global environment (the prelude's definitions and the
 * user's) and runs source text: definitions are added, and every top-level
 * expression that is not a definition is evaluated and printed on stdout in
 * the language's own syntax. Errors go to stderr as
 * "FILE:LINE:COL: error: MESSAGE", the source line and a caret, and a short
 * call trace; an error abandons the current item but never the definitions
 * made before it.
 *
 * A run goes: parse (defines nothing, see parse.h), install the type
 * declarations' constructors, resolve and check every name (resolve.h;
 * nothing has run yet if this fails), install the definitions, evaluate
 * the expressions in order.
 *
 * Memory: values, ASTs and source texts live in the garbage-collected heap
 * (Boehm GC); nothing handed out here needs freeing by the caller.
 *
 * Failure modes: every entry point that runs code catches the language's
 * errors itself (error.h), reports them, undoes the half-forced thunks and
 * returns RUN_ERROR; none returns with an error frame or a cleanup left
 * behind. Only running out of memory in the collector, or the prelude
 * failing to load (exit 2), ends the process.
 *
 * Threads: an Interp is used by one thread, the one whose stack it was
 * given (interp_set_stack). Two Interps must not evaluate at the same time
 * either: values come from one batch shared by the process (val_cell in
 * value.h). Only interp_request_interrupt may be called from elsewhere (a
 * signal handler, another thread). */
#ifndef QCS_INTERP_H
#define QCS_INTERP_H

#include <stdio.h>

#include "lang/error.h"

typedef struct Interp Interp;

typedef enum {
  RUN_OK = 0,         /* everything ran */
  RUN_ERROR = 1,      /* an error was reported on stderr */
  RUN_INCOMPLETE = 2  /* REPL mode only: the text ends inside an unfinished
                         item (open bracket, trailing operator, ...); nothing
                         was run, the caller should read more lines */
} RunStatus;

typedef enum {
  MODE_SCRIPT, /* a file: items end at ';' or at a line starting in column 1;
                  the whole file is checked and run in order, stopping at the
                  first error */
  MODE_REPL    /* one REPL entry: items end at ';' or at the end of the text */
} RunMode;

/* A new interpreter with the language's own built-ins, then install(I)
   (may be NULL: the built-ins of the layers above, which the language does
   not know, such as the probes and the renderer; see bind/bind.h), then
   the prelude. Calls interp_gc_init on first use. */
Interp *interp_new(void (*install)(Interp *I));

/* Starts the collector the way qcs needs it (once; later calls do
   nothing): its heap and free-space settings, and its roots without the
   collector's own static data (see interp.c). main calls it before any
   thread is made; interp_new calls it too, for tests and tools. */
void interp_gc_init(void);

/* Run source text; name is used in error positions ("<stdin>", a path). */
RunStatus interp_run_string(Interp *I, const char *name, const char *text,
                            RunMode mode);

/* Read and run a file as a script (MODE_SCRIPT). A missing or unreadable
   file is an error reported with the path. */
RunStatus interp_run_file(Interp *I, const char *path);

/* Evaluate one expression given as text and print its value (qcs -e). */
RunStatus interp_eval_print(Interp *I, const char *text);

/* Run fn(I, ud) as one top-level item: errors it raises are reported and
   unwound as a script item's are; the value it returns, unless NULL, is
   printed on stdout. pos is the item's position, for errors found where
   no position is at hand. For the layers above, which add items of their
   own (bind/: qcs -o FILE rendering the script's `scene`). */
struct Value;
RunStatus interp_run_item(Interp *I, Pos pos,
                          struct Value *(*fn)(Interp *I, void *ud), void *ud);

/* Replace (or add) the top-level definition NAME = VALUE-TEXT before a
   script runs (qcs --set NAME=VALUE). The script's own definition of NAME
   is then ignored. */
RunStatus interp_set_override(Interp *I, const char *name, const char *expr);

/* qcs params FILE: declares what FILE (and what it imports) defines,
   running none of its top-level expressions, and prints a table of its
   parameters (`param`): name, default, range, doc. */
RunStatus interp_params(Interp *I, const char *path, FILE *out);

/* Every file the runs so far imported (the path as found, relative to the
   working directory or absolute), each once, in the order they were read;
   an import that failed (unreadable, an error inside) is listed too. The
   file given to interp_run_file itself is not. For qcs view, which
   follows them. */
void interp_files_read(Interp *I, void (*emit)(const char *path, void *ud),
                       void *ud);

/* Animation: binds the globals frame and clock and re-evaluates the
   top-level definitions that depend on them (through any chain of
   globals); the others keep their values. Before the scripts run, it only
   binds the two. */
void interp_set_frame(Interp *I, double frame, double clock);
/* Evaluates the scripts' top-level expressions again, in order (the next
   frame of an animation); they were recorded as the scripts ran. */
RunStatus interp_rerun(Interp *I);

/* A declared parameter, as a front end shows it (qcs view's sliders):
   strings belong to the interpreter's heap and live as long as it. */
typedef struct InterpParam {
  const char *name, *text, *doc; /* text: the default's source; doc or NULL */
  int has_range;
  double lo, hi;                 /* the range, when has_range */
  int numeric;                   /* the current value is a number ... */
  double value;                  /* ... this one */
} InterpParam;
/* The parameters the scripts run so far declared, in order: up to max
   into out; returns their number (-1: an error evaluating a range or a
   value, reported). */
int interp_param_list(Interp *I, InterpParam *out, int max);
/* Re-binds the declared parameter name to the number x and re-evaluates
   the top-level definitions that depend on it, as interp_set_frame does
   for frame (the others keep their values); interp_rerun then runs the
   scripts' expressions again. x must be finite, within the parameter's
   range, and the parameter's value a number. RUN_ERROR with the reason in
   err (nothing changed) otherwise. */
RunStatus interp_set_param(Interp *I, const char *name, double x, char *err,
                           size_t errlen);
/* Frees an interpreter (its values are collected once unreachable). */
void interp_free(Interp *I);

/* Show values instead of printing them: show(I, v, pos, ud) is called for
   each value of a MODE_REPL entry and returns 1 if it showed it (the REPL's
   pictures of scene objects); NULL: print everything. */
struct Value;
void interp_set_show(Interp *I,
                     int (*show)(Interp *I, struct Value *v, Pos pos, void *ud),
                     void *ud);

/* Parse, check and evaluate text as one expression, inside an item that is
   already running (a show hook, a host's item): errors are raised, not
   reported. name names the source in positions. */
struct Value *interp_eval_expr(Interp *I, const char *name, const char *text);

/* Name completion: calls emit for every global name (prelude, builtins and
   user definitions) that begins with prefix. */
void interp_complete(Interp *I, const char *prefix,
                     void (*emit)(const char *name, void *ud), void *ud);

/* List the user's definitions (not the prelude's), one per line, with
   their type signature when one was given, to out (":browse"). With
   all != 0, list the prelude and built-ins too. */
void interp_browse(Interp *I, FILE *out, int all);

/* Where the C stack of the thread running the interpreter begins and how
   much of it evaluation may use before "recursion too deep" (the limit
   max-stack; this also makes limit the most :set max-stack may give). */
void interp_set_stack(Interp *I, char *base, size_t limit);
/* The stack the thread really has, when more than the limit in force:
   :set max-stack may then raise the limit up to it, less a margin. */
void interp_set_stack_reserved(Interp *I, size_t reserved);

/* Stop evaluations after this many steps with a clear error (0: never). */
void interp_set_max_steps(Interp *I, unsigned long long steps);

/* Stop evaluations with a clear error when the values in memory exceed
   this many bytes (0: no limit; the default is 8 GB). */
void interp_set_max_memory(Interp *I, size_t bytes);

/* ---- resource limits, by name ----
 *
 *   max-stack   SIZE  C stack for nested evaluation and parsing (recursion
 *                     depth); default 256M
 *   max-steps   N     evaluation steps of one top-level expression;
 *                     default 10000000000, 0 for none
 *   max-list    N     elements of one list built by a range or forced by
 *                     length, sum, printing, ...; default 10000000, 0 none
 *   max-memory  SIZE  memory for values (and, read by bind/mesh_lang.c,
 *                     a mesh's growth); default 8G, 0 for none
 *   max-pixels  N     pixels of one rendered image (N or WxH); default
 *                     4096x4096, at most 8192x8192
 *   max-spp     N     samples per pixel of a render; default 64, at most 256
 *
 * SIZE is a whole number with K, M, G or T (binary: 1K = 1024 bytes); a
 * bare number is megabytes. A limit that is hit stops the evaluation or
 * render with an error naming the limit and how to raise it. */

#define QCS_DEFAULT_MAX_STEPS 10000000000ULL
#define QCS_DEFAULT_MAX_LIST 10000000ULL
#define QCS_DEFAULT_MAX_PIXELS (4096ULL * 4096ULL)
#define QCS_DEFAULT_MAX_SPP 64
/* The most max-pixels may be raised to: the renderer's own cap
   (render/image.h, IMG_MAX_PIXELS; bind/render_lang.c checks they agree). */
#define QCS_MAX_PIXELS_CAP (8192ULL * 8192ULL)

/* The names of the limits, NULL-terminated. */
extern const char *const interp_limit_names[];

/* Checks text as a value for the limit name (the command line checks its
   options before an interpreter exists): 0 with *out set, or -1 with a
   message in err. The stack's cap is not checked here. */
int interp_limit_parse(const char *name, const char *text,
                       unsigned long long *out, char *err, size_t errlen);

/* Sets a limit from text (":set max-steps 1000000", --max-steps): 0, or -1
   with a message in err naming what is wrong. */
int interp_set_limit(Interp *I, const char *name, const char *text,
                     char *err, size_t errlen);

/* bytes as "256M", "8G", or a plain number when not whole K. */
void interp_format_size(char *buf, size_t n, unsigned long long bytes);

/* One line per limit: name, value, what it bounds (":set"). */
void interp_list_limits(Interp *I, FILE *out);

const char *interp_version(void);

/* :info NAME: what kind of name it is (constructor, built-in, prelude
   function, your definition), its arity, where it was defined, its
   signature, doc and example, to out. :doc NAME: the signature, doc and
   example only. An unknown name: a message on stderr and -1. */
int interp_info(Interp *I, FILE *out, const char *name);
int interp_doc(Interp *I, FILE *out, const char *name);
/* Forget the definitions that the run of file (a path as given to
   interp_run_file) made: a name that shadowed a built-in or the prelude's
   gets the original back; the others are undefined (code still using
   them says "unknown name" when it runs). Type declarations' constructors
   stay. Returns how many names were removed. */
int interp_unload(Interp *I, const char *file);
/* The signature written for name (name :: type), or NULL. */
const char *interp_signature(Interp *I, const char *name);
/* What can be known of a value's type, forcing it to weak-head normal
   form (and a list's first element): "a Real", "a 3-tuple", "a function
   of 2 arguments (f)", "a SceneObject, made by the constructor Rounded".
   qcs is dynamically typed: this is the value's kind, not a static type.
   Raises errors (call it inside an item, e.g. interp_run_item). */
struct Value;
void interp_describe(Interp *I, struct Value *v, char *buf, size_t n);

/* Warn, once per name, when a definition shadows a built-in or prelude
   name (the REPL turns it on; scripts run by qcs FILE stay quiet). */
void interp_set_warn_shadow(Interp *I, int on);

/* Is there a top-level value called name? */
int interp_has_global(Interp *I, const char *name);

/* Ask a running evaluation to stop with "interrupted" at its next step.
   Async-signal-safe: meant to be called from a SIGINT handler. */
void interp_request_interrupt(void);
/* Forget a pending interrupt (before starting a new REPL entry). */
void interp_clear_interrupt(void);

#endif
