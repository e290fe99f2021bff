/* error.h: source positions and the one way errors leave the interpreter.
 *
 * The language layer's error style. Every token and AST node carries a
 * Pos, and every scene node a source tag (an interned Pos, see pos_tag),
 * so an error found late (while evaluating, while compiling a scene, after
 * a render) still points at the source. qcs_error() formats the message
 * and longjmps to the innermost handler (one per script item or REPL
 * entry, set with ERR_TRY); the handler prints it with the source line and
 * a caret.
 *
 * Memory: what lives in the garbage-collected heap needs nothing on the
 * way out. What does not (a malloc'd scene being built, a tape builder, a
 * ray context) is registered with err_defer, as Lua's to-be-closed
 * variables: an error runs every cleanup registered since the handler was
 * set, innermost first, before it jumps; err_release takes one back when
 * the code that registered it finishes normally. No site writes its own
 * catch-free-rethrow block.
 *
 * Threads: the handler chain and the cleanup list are thread-local: each
 * interpreter thread has its own. The tag table is shared and locked.
 *
 * The layers below (core/, scene/, render/) never use this: they return
 * codes and messages, and never print or exit. */
#ifndef QCS_ERROR_H
#define QCS_ERROR_H

#include <setjmp.h>
#include <stdarg.h>
#include <stdio.h>

/* A source text: a file, a REPL entry, the prelude, a -e expression. */
typedef struct Src {
  const char *name;
  const char *text;
  int prelude;  /* one of the prelude's sources (stdlib/prelude.qcs, kit.qcs) */
  const char **lines; /* where each line starts, made when first asked
                         (interp.c's doc comments), or NULL */
  int nlines;
} Src;

typedef struct Pos {
  const Src *src;
  int line, col;  /* 1-based; line 0 means "no position" */
} Pos;

extern const Pos pos_none;

/* A cleanup run when an error unwinds past it (see err_defer). */
typedef struct ErrCleanup {
  void (*fn)(void *arg);
  void *arg;
  struct ErrCleanup *prev;
} ErrCleanup;

typedef struct ErrFrame {
  jmp_buf jb;
  struct ErrFrame *prev;
  ErrCleanup *cleanups;  /* the cleanup list when the frame was set */
} ErrFrame;

typedef struct ErrInfo {
  Pos pos;
  char msg[1024];
  int incomplete;     /* the parser ran into the end of the text */
  char trace[2048];   /* call trace lines, filled in by the evaluator */
} ErrInfo;

/* The error that the innermost handler catches. */
ErrInfo *err_info(void);
void err_push(ErrFrame *f);
void err_pop(ErrFrame *f);

/* ERR_TRY(f) { body } else { handle: err_info() holds the error } ; the
   frame is popped in both branches by the macro's caller via err_pop. */
#define ERR_TRY(f) (err_push(&(f)), setjmp((f).jb) == 0)

/* Messages are formatted with printf; a non-finite number formatted with
   %g ("nan", "-nan", "inf", "-inf") is rewritten as the language prints
   it (NaN, Infinity, -Infinity). */
_Noreturn void qcs_error(Pos pos, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
_Noreturn void qcs_verror(Pos pos, const char *fmt, va_list ap);
/* Like qcs_error, but marks the error as "more input would help". */
/* An error whose text is given as it is (a user's `error "..."`): not
   passed through printf, and C's spellings of non-finite numbers in it
   are not rewritten (see qcs_error). */
_Noreturn void qcs_error_verbatim(Pos pos, const char *msg);
_Noreturn void qcs_error_incomplete(Pos pos, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

/* Register c (storage owned by the caller, typically on its stack) to run
   fn(arg) if an error unwinds past the caller. Cleanups nest: release
   them innermost first. */
void err_defer(ErrCleanup *c, void (*fn)(void *arg), void *arg);
/* Take back the cleanup c without running it (the code finished normally
   and now owns arg again, or has handed it on). c must be the innermost
   cleanup. */
void err_release(ErrCleanup *c);

/* Source tags: a Pos interned as a small integer, for the layers below
   the language, which carry an int instead of a pointer into the
   collected heap. Tag 0 is pos_none; the same Pos always gives the same
   tag. -1 from pos_tag when memory runs out (then callers use 0). */
int pos_tag(Pos pos);
Pos tag_pos(int tag);

/* Raise the error just caught again, unchanged, to the next handler out
   (after a handler has freed what it owned). */
_Noreturn void err_rethrow(void);

/* Print "NAME:LINE:COL: KIND: MSG", the source line and a caret. */
void err_report(FILE *out, const char *kind, Pos pos, const char *msg);
/* A warning at a position, printed at once to stderr. */
void qcs_warning(Pos pos, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

/* Levenshtein distance, for "did you mean" suggestions. */
int edit_distance(const char *a, const char *b);

#endif
