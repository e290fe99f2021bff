/* ast.h: the syntax tree of qcs programs.
 *
 * Expressions, patterns and definitions, each carrying the Pos of the
 * source that made it. Names are interned Syms (see value.h), so the
 * evaluator compares pointers.
 *
 * Owner: the parser makes the nodes, in the GC heap; nothing frees them
 * (closures made on one REPL line keep pointing at that line's AST).
 * After parsing, one pass writes to them (resolve.h): it rewrites a
 * where/let block whose `C x = e` is a constructor's pattern binding, and
 * fills in each E_VAR's vdepth/vslot. From then on the AST is read-only:
 * the evaluator never changes it.
 *
 * Invariants: the parser shares no node between two places in the tree
 * (the resolver's slot for an E_VAR depends on where it stands; a node it
 * reaches twice in different scopes is marked RES_SCAN, looked up by
 * name). Zeroed fields mean "absent" (GC_MALLOC zeroes): vslot 0 is "not
 * resolved", guard_pos.line 0 "no guard". Every Def has >= 1 clause, and
 * every clause of a Def has its arity in patterns (merge_clause checks).
 *
 * Threads: as the Interp that parsed it; an AST is not shared between
 * interpreters. */
#ifndef QCS_AST_H
#define QCS_AST_H

#include "lang/error.h"
#include "lang/lex.h"

typedef struct Sym Sym;
typedef struct Expr Expr;
typedef struct Pat Pat;
typedef struct Def Def;

typedef enum {
  E_NUM, E_STR, E_BOOL, E_VAR, E_APP, E_LAMBDA, E_LET, E_IF, E_TUPLE,
  E_LIST, E_RANGE, E_BINOP, E_NEG, E_WILD, E_DEFBODY
} ExprKind;

/* A qualifier of a list comprehension: a generator `pat <- e` or a guard. */
typedef struct Qual {
  Pat *pat; /* NULL for a guard */
  Expr *e;
} Qual;

struct Expr {
  ExprKind kind;
  Pos pos;
  struct Value *lit;  /* E_NUM, E_STR: the value, made on first use and
                         shared (a Real or String value is never changed) */
  union {
    double num;
    const char *str;
    int b;
    /* E_VAR: the name, and where resolve.c found its binding: vslot > 0,
       binding vslot - 1 of the frame vdepth up the Env chain; RES_GLOBAL,
       the global; 0 (not resolved) or RES_SCAN, look it up by name. */
    struct { Sym *var; int vdepth, vslot; };
    struct { Expr *fn; int n; Expr **args; } app;
    Def *lambda;                                  /* one clause, no name */
    struct { int n; Def **defs; Expr *body; } let;
    struct { Expr *c, *t, *f; } cond;
    struct { int n; Expr **items; } tuple;        /* E_TUPLE and E_LIST */
    struct { Expr *from, *then, *to; } range;     /* then, to may be NULL */
    struct { TokKind op; Expr *a, *b; } bin;
    Expr *neg;
    Def *def;             /* E_DEFBODY: a 0-ary binding's clauses */
  } u;
};

typedef enum {
  P_VAR, P_WILD, P_NUM, P_STR, P_BOOL, P_CON, P_TUPLE, P_NIL, P_CONS, P_LIST
} PatKind;

struct Pat {
  PatKind kind;
  Pos pos;
  union {
    Sym *var;
    double num;
    const char *str;
    int b;
    struct { Sym *con; int n; Pat **args; } con;  /* resolved when matched */
    struct { int n; Pat **items; } tuple;         /* P_TUPLE and P_LIST */
    struct { Pat *head, *tail; } cons;
  } u;
};

/* One clause: patterns, then guarded bodies (guard NULL = unconditional),
   with where-bindings in scope of guards and bodies. */
typedef struct Clause {
  Pos pos;
  int npats;
  Pat **pats;
  int nbodies;
  Expr **guards;
  Expr **bodies;
  int nwhere;
  Def **where;
  /* eval.c's select_clause: 0 not yet looked at; else 1 + the number of
     variables its patterns bind, if every pattern is a variable, _, a
     Real or Bool literal, [], or a [h : t], constructor or tuple pattern
     whose parts are variables or _; -1 if not */
  int simple;
  /* eval.c's select_clause, set with simple: the first pattern that can
     fail, if it is a constructor's with only variables and _ before it,
     is argument quick_col - 1 and its constructor quick_con (0 if not):
     an argument already seen to be another constructor skips the clause
     before anything is bound */
  int quick_col;
  Sym *quick_con;
  /* eval.c's select_clause: for a clause without where bindings whose
     patterns bind variables, the names its frame binds, in order (a match
     that succeeds binds the same every time), shared by all its frames;
     such a frame is made full (cap == n), so env_bind never writes here */
  Sym **frame_names;
} Clause;

/* A definition: a named function or value with one or more clauses, or a
   pattern binding `(a, b) = e` (pat != NULL, one clause, no patterns). */
struct Def {
  Sym *name;     /* NULL for lambdas and pattern bindings */
  Pos pos;
  int arity;
  int nclauses;
  Clause **clauses;
  Pat *pat;      /* pattern binding */
  const char *sig; /* its type signature's text, if one was given */
  /* A where/let binding `C args = e` with C capitalised is parsed as the
     function C. If C is a constructor when the program is checked, it
     becomes the pattern binding `C args` (interp.c, settle_defs);
     guard_pos is then where its first guard's '|' stood, if it has one (a
     pattern binding takes none). */
  Pos guard_pos;
  /* A top-level definition: the globals its clauses name (resolve.c), so
     that an animation re-evaluates only what depends on frame and clock. */
  int nuses;
  Sym **uses;
  /* resolve.c: 1 if no variable in its clauses is bound outside them (it
     captures nothing: eval.c's closures of it keep no frame), 2 if one
     is, 0 not resolved yet (taken as 2) */
  int closed;
};

/* Type declarations: constructors with their arities. */
typedef struct ConDecl {
  Sym *name;
  Pos pos;
  int arity;
} ConDecl;

typedef enum {
  ITEM_DEF, ITEM_EXPR, ITEM_TYPE, ITEM_SIG, ITEM_IMPORT, ITEM_SET
} ItemKind;

/* `param NAME = DEFAULT [in [LO, HI]] ["DOC"]`: an ITEM_DEF of NAME with
   this attached (interp.c checks --set values against it). */
typedef struct Param {
  Expr *lo, *hi;      /* the range, or NULL */
  const char *doc;    /* the doc string, or NULL */
  const char *text;   /* the default's source text, for qcs params */
} Param;

typedef struct Item {
  ItemKind kind;
  Pos pos;
  Def *def;
  Expr *expr;
  Sym *type;          /* ITEM_TYPE: the type's name */
  int ncons;          /* ITEM_TYPE: 0 for a synonym */
  ConDecl *cons;
  Sym *signame;       /* ITEM_SIG */
  const char *sigtext;
  Param *param;       /* ITEM_DEF made by `param` */
  const char *import; /* ITEM_IMPORT: the path as written */
  Sym *import_as;     /* ITEM_IMPORT: `as Name`, or NULL */
  int digits;         /* ITEM_SET: `:set digits N` */
} Item;

#endif
