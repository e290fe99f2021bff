/* value.h: the runtime values of qcs and the interpreter's state.
 *
 * Values are lazy: a field of a tuple, list or constructor, an argument,
 * a binding, may be a thunk (an expression with its environment) until
 * something forces it. Forcing overwrites the thunk in place with its
 * weak-head normal form, so each thunk runs at most once (call by need).
 * All values live in the Boehm GC heap: no ownership to track, cycles
 * (a list defined in terms of itself) are fine.
 *
 * Environments: an Env frame is made per clause applied (its pattern
 * variables, then its where bindings) and per let, and only there (eval.c);
 * resolve.c predicts each variable's frame and slot from the same rules,
 * so the two must change together (see resolve.h). Frames only grow while
 * being filled, before anything reads them by slot.
 *
 * The Interp here is the whole state of one interpreter: the symbol table
 * (globals, constructors, signatures), the limits, the call trace and the
 * stack of thunks being forced. It is used by one thread at a time; only
 * qcs_interrupted (a global, not a field) is written from elsewhere. */
#ifndef QCS_VALUE_H
#define QCS_VALUE_H

#include <signal.h>
#include <stdatomic.h>
#include <stddef.h>

#include "lang/ast.h"

typedef struct Value Value;
typedef struct Env Env;
typedef struct Interp Interp;
typedef struct Builtin Builtin;

/* An interned name. Global bindings hang off the symbol itself. */
struct Sym {
  const char *name;
  Sym *next;           /* hash chain */
  Value *global;       /* top-level value, or NULL */
  Value *prelude_value;/* its value as the prelude defined it: what the
                          prelude's own code sees, whatever users define */
  Def *def;            /* its definition (for :browse), or NULL */
  int con_arity;       /* >= 0: a constructor of this arity; -1: not one */
  Sym *con_type;       /* the type a constructor belongs to */
  Value *con_value;    /* the constructor as a value */
  int user;            /* defined outside the prelude */
  int overridden;      /* fixed by --set: later definitions are ignored */
  const char *sig;     /* type signature text */
  Pos def_pos;         /* where it was defined (for "already defined") */
  const char *def_file;/* which run defined it */
  const char *doc;     /* one line for :doc and :info ("// doc:" above the
                          definition, or a built-in's table entry) */
  const char *example; /* an expression showing it ("// e.g."), or NULL */
  int builtin;         /* a built-in (written in C) */
  int shadow_warned;   /* a user definition that shadows a built-in or a
                          prelude name has been warned about */
  /* As the prelude left them, for :unload of a file that shadowed it. */
  Def *prelude_def;
  const char *prelude_sig, *prelude_doc, *prelude_example;
  Pos prelude_pos;
  const struct Param *param; /* declared with `param` (ast.h), or NULL */
  const char *imported;/* the file an import defined it from, or NULL */
  Expr *set_expr;      /* --set NAME=EXPR: the expression */
  int set_checked;     /* --set NAME matched a declared parameter */
  int anim_mark;       /* interp_set_frame's walk: epoch * 2 + depends */
  const char *ambiguous; /* defined by two imports: "A.x (a.qcs:1:1) and
                          B.x (b.qcs:2:1)"; a use of the bare name is an
                          error that lists them */
  Sym *alias_of;       /* Parts.x: the Sym holding that import's x (the
                          resolver puts it in the code's place) */
  struct LazyDef *lazy;/* a definition of the prelude's not read yet: the
                          text it is in (interp.c reads it when the name
                          is first needed: interp_materialize) */
};

typedef enum {
  V_NUM, V_BOOL, V_STR, V_TUPLE, V_NIL, V_CONS, V_CON,
  V_FUNC, V_PAP, V_THUNK, V_APTHUNK, V_PATSEL, V_BLACKHOLE, V_FOREIGN
} VKind;

typedef enum { F_DEF, F_BUILTIN, F_CON } FnKind;

typedef Value *(*BuiltinFn)(Interp *I, Value **args, Pos pos);

struct Builtin {
  const char *name;
  int arity;
  BuiltinFn fn;
  const char *doc;
};

struct Value {
  unsigned char kind;
  union {
    double num;
    int b;
    /* V_STR: len bytes, no NUL among them. Flat: s holds them (with a
       NUL after). A rope (s == NULL): the bytes of left then right, two
       V_STRs of at least one byte each; ++ on Strings makes one in O(1)
       and val_str_chars flattens it, once, when the bytes are wanted. */
    struct { const char *s; Value *left, *right; size_t len; } str;
    struct { int n; Value **items; } tup;
    /* tail first: the collector marks an object's last pointer first, so
       a long list's spine is followed before its elements are and its
       mark stack does not overflow on a million cells held whole */
    struct { Value *tail, *head; } cons;
    struct { Sym *con; int n; Value **args; const Pos *pos; } con; /* pos: where it was built, or NULL */
    struct {
      FnKind kind;
      int arity;
      union { Def *def; const Builtin *bi; Sym *con; } u;
      Env *env;
    } fn;
    struct { Value *fn; int n; Value **args; } pap; /* V_PAP, V_APTHUNK */
    struct { Expr *e; Env *env; const Pos *origin; } thunk; /* origin: see Interp.origin */
    struct { Pat *pat; Sym *var; Value *whole; } patsel;
    struct { void *ptr; const char *tag; } foreign;
  } u;
};

/* A new, zeroed Value cell from the collected heap. Cells come in batches
   from GC_malloc_many, which costs far less per cell than GC_MALLOC; the
   batch waits in a static list (a root the collector scans), so Values
   must be allocated by one thread at a time, the interpreter's. */
Value *val_cell(void);

/* A zeroed block of the collected heap for an array, a frame or a
   position: batched like val_cell below 256 bytes (and so for the
   interpreter's thread only), GC_MALLOC above. */
void *val_small(size_t bytes);

/* A frame of local bindings; `up` is the enclosing scope. */
struct Env {
  Env *up;
  int n, cap;
  Sym **names;
  Value **vals;
};

/* One entry of the call trace shown with runtime errors. */
typedef struct TraceEntry {
  const char *name;
  Pos pos;
} TraceEntry;

/* A thunk being forced, with its contents, to restore after an error. */
typedef struct Forcing {
  Value *v;
  Value saved;
} Forcing;

#define TRACE_MAX 4096

struct Interp {
  Sym **symtab;
  size_t symcap, nsyms;
  /* Resource limits (see interp_set_limit); 0 means no limit where a
     limit may be switched off. */
  char *stack_base;          /* for the recursion-depth check */
  size_t stack_limit;        /* max-stack: bytes of C stack evaluation and
                                parsing may use */
  size_t stack_reserved;     /* the stack the thread has (max-stack's cap) */
  unsigned long long steps;  /* evaluation steps of the current item */
  unsigned long long max_steps; /* max-steps, per top-level expression */
  size_t max_memory;         /* max-memory: bytes of values allowed */
  unsigned memcheck;         /* steps since the memory was last checked */
  unsigned long long max_list; /* max-list: elements of one list */
  unsigned long long max_pixels; /* max-pixels: of one rendered image */
  int max_spp;               /* max-spp: samples per pixel of a render */
  int digits;                /* :set digits: significant digits of printed
                                Reals; 0 = the shortest that reads back */
  int digits_fixed;          /* --digits N given: a script's :set digits
                                does not change digits */
  const Pos *origin;         /* the call from the user's code that led
                                into the prelude code now running (a
                                thunk made by the prelude keeps the one in
                                force when it was made): errors raised in
                                the prelude are reported there */
  Pos item_pos;              /* the top-level item being run, for errors
                                found where no position is at hand */
  TraceEntry trace[TRACE_MAX];
  int ntrace;                /* entries in use (may exceed TRACE_MAX) */
  Forcing *forcing;
  int nforcing, capforcing;
  /* Set by a front end that can show values (the REPL's pictures): called
     with each value of a REPL entry, it returns 1 if it showed the value,
     which is then not printed. */
  int (*show)(Interp *I, Value *v, Pos pos, void *ud);
  void *show_ud;
  void *host;                /* state of the layer that installed its
                                built-ins (bind/): opaque here */
  Pos warned[64];            /* warnings already given (said once each) */
  int nwarned;
  const char *run_name;      /* the file currently being run */
  int warn_shadow;           /* warn of definitions that shadow a
                                built-in or prelude name (the REPL) */
  int loading_prelude;
  Value *v_true, *v_false, *v_nil;
  /* Parameters, imports and animation (interp.c). */
  Sym **params;              /* declared parameters, in order */
  int nparams, capparams;
  int sets_pending;          /* --set given and not yet checked */
  Sym *set_syms[64];         /* the names given to --set */
  int nset_syms;
  const char **files;        /* the files being run (real paths), for
                                import cycles: the importer last */
  const char **shown;        /* the same, as the user wrote them */
  int nfiles, capfiles;
  const char **imported;     /* files imported so far (real paths) */
  int nimported, capimported;
  struct ImportedDefs *importdefs; /* per imported file (parallel to
                                imported): the Syms its definitions hold */
  Sym **quals;               /* qualifiers in use (Parts of Parts.x) ... */
  const char **qual_files;   /* ... and the file (real path) each names */
  int nquals, capquals;
  Sym *cur_qual;              /* the qualifier of the import being run */
  Sym **rename_from, **rename_to; /* while an import is resolved: its own */
  int nrename, caprename;    /* names taken by another import, renamed to
                                its qualified ones (resolve.c) */
  const char **readfiles;    /* every file an import read, as the importer
                                named it, in order, a failed one too */
  int nreadfiles, capreadfiles;
  int declare_only;          /* qcs params: top-level expressions not run */
  Item **anim;               /* the scripts' top-level expressions, run */
  int nanim, capanim;        /* again for each frame of an animation */
  int anim_epoch;
  /* Shared symbols the evaluator looks for. */
  Sym *s_otherwise;
};

/* Set by SIGINT (or another thread) to stop the running evaluation and
   any render it started: lock-free, so a signal handler may store to it,
   and read by render workers without a race. */
extern atomic_int qcs_interrupted;

Sym *sym_intern(Interp *I, const char *name, int len);

/* The prelude's definitions are read when first needed: the parser and
   the resolver see one only once it is. interp_materialize(I, s) reads
   s's (and installs it as the prelude would have) if s->lazy is set and
   its reading has not begun; a no-op otherwise. interp_lazy_pending(s):
   s is the prelude's, read or not (the resolver counts it as defined). */
void interp_materialize(Interp *I, Sym *s);
int interp_lazy_pending(const Sym *s);

Value *val_num(double x);
Value *val_bool(Interp *I, int b);
Value *val_str(const char *s);
/* The rope of two Strings, each at least one byte long (a String of
   la + lb bytes; the caller checks that the sum neither overflows nor
   passes the memory limit). Short flat sides are copied into a flat
   String instead. */
Value *val_str_concat(Value *a, Value *b);
/* The bytes of the String v, NUL-terminated: a rope is flattened (once:
   v becomes flat and lets go of its parts), iteratively, so a rope of any
   depth needs no C stack. NULL when the memory for it runs out. */
const char *val_str_chars(Value *v);
Value *val_tuple(int n, Value **items);
Value *val_tuple3(double x, double y, double z);
Value *val_cons(Value *head, Value *tail);
Value *val_nil(Interp *I);
Value *val_con(Sym *con, int n, Value **args);
Value *val_builtin(const Builtin *b);
Value *val_foreign(void *ptr, const char *tag);
Value **val_array(int n);

Env *env_new(Env *up, int cap);
void env_bind(Env *env, Sym *name, Value *v);

/* "a number", "a list", "constructor Sum", ... for error messages. */
const char *val_describe(Value *v);
#endif
