/* eval.c: the lazy evaluator. See eval.h. */
#include "lang/eval.h"

#include <gc.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "lang/builtins.h"
#include "lang/parse.h"
#include "lang/print.h"
#include "lang/resolve.h"

/* ---- checks ---- */

/* Zeroes STACK_SCRUB bytes of the C stack below the caller's frame. The
   collector scans the whole stack of the thread it interrupts, and a frame
   of a later call may leave slots unwritten that still hold pointers from
   earlier, deeper calls: to one cell of a list being consumed, say, which
   then keeps every cell after it alive (`length [1 .. 10^7]` in a script
   held 1 GB so). Called every 4096 steps. */
#define STACK_SCRUB 16384
static __attribute__((noinline)) void scrub_stack(void) {
  volatile char pad[STACK_SCRUB];
  memset((char *)pad, 0, sizeof pad);
  __asm__ volatile("" : : "r"(pad) : "memory");
}

/* Zeroes SCRUB_NEAR bytes below the caller's frame, where the next call's
   frames will lie (see eval's E_APP). */
#define SCRUB_NEAR 1024
static __attribute__((noinline)) void scrub_near(void) {
  volatile char pad[SCRUB_NEAR];
  memset((char *)pad, 0, sizeof pad);
  __asm__ volatile("" : : "r"(pad) : "memory");
}

/* Error paths that need a text buffer are functions of their own, never
   inlined: a buffer in a hot recursive frame (eval, call, select_clause)
   is never written on the paths that run, so whatever an earlier, deeper
   call left at those addresses stays there, and the collector, which
   scans the stack conservatively, keeps it alive: pipeline's xs
   (bench/hugs) kept 13,700 consumed cells so, from a stale Env in
   eval's unused 120-byte buffer. */
#define COLD __attribute__((noinline, cold))

/* Zeroes the registers a callee saves (and so keeps, in its frame or
   unchanged, through the whole call): whatever the caller held there
   that it no longer needs (env, in eval's E_APP) would otherwise stay
   visible to the collector, which scans registers as it does the stack.
   The compiler saves around it what is still live. x86-64 and AArch64;
   elsewhere nothing (a possible leak, not an error). */
#if defined(__x86_64__) && defined(__GNUC__)
#define CLEAR_CALLEE_SAVED()                                                 \
  __asm__ volatile("xor %%ebx, %%ebx\n\txor %%r12d, %%r12d\n\t"             \
                   "xor %%r13d, %%r13d\n\txor %%r14d, %%r14d\n\t"            \
                   "xor %%r15d, %%r15d"                                     \
                   : : : "rbx", "r12", "r13", "r14", "r15")
#elif defined(__aarch64__) && defined(__GNUC__)
#define CLEAR_CALLEE_SAVED()                                                 \
  __asm__ volatile("mov x19, xzr\n\tmov x20, xzr\n\tmov x21, xzr\n\t"      \
                   "mov x22, xzr\n\tmov x23, xzr\n\tmov x24, xzr\n\t"      \
                   "mov x25, xzr\n\tmov x26, xzr\n\tmov x27, xzr\n\t"      \
                   "mov x28, xzr"                                           \
                   : : : "x19", "x20", "x21", "x22", "x23", "x24", "x25",   \
                     "x26", "x27", "x28")
#else
#define CLEAR_CALLEE_SAVED() ((void)0)
#endif

/* eval_check (eval.h) found something to do: I->steps is counted and,
   unless a check before failed, I->memcheck too. No system calls, no
   allocation. */
static _Noreturn COLD void memory_error(Interp *I, Pos pos,
                                       const char *would) {
  char sz[32];
  interp_format_size(sz, sizeof sz, I->max_memory);
  eval_limit_error(I, pos, "max-memory", "evaluation stopped: values "
                   "%suse more than %s of memory", would, sz);
}

void eval_check_slow(Interp *I, Pos pos) {
  char probe;
  if (atomic_load_explicit(&qcs_interrupted, memory_order_relaxed)) {
    atomic_store(&qcs_interrupted, 0);
    qcs_error(pos.line ? pos : I->item_pos, "interrupted");
  }
  if ((size_t)(I->stack_base - &probe) > I->stack_limit)
    eval_stack_error(I, pos, "recursion too deep: nested calls use",
                     "; is a base case missing?");
  if (I->steps > I->max_steps && I->max_steps)
    eval_limit_error(I, pos, "max-steps", "evaluation stopped after %llu steps",
                     I->max_steps);
  if (I->memcheck >= 4096) {
    I->memcheck = 0;
    if ((size_t)(I->stack_base - &probe) + 2 * STACK_SCRUB < I->stack_reserved)
      scrub_stack();
  }
  if (I->max_memory && I->memcheck == 0) {
    size_t used = GC_get_heap_size() - GC_get_free_bytes();
    if (used > I->max_memory) {
      GC_gcollect();
      used = GC_get_heap_size() - GC_get_free_bytes();
      if (used > I->max_memory) memory_error(I, pos, "");
    }
  }
}

void eval_alloc_check(Interp *I, Pos pos, size_t bytes) {
  if (!I->max_memory) return;
  size_t used = GC_get_heap_size() - GC_get_free_bytes();
  if (bytes > I->max_memory || used + bytes > I->max_memory) {
    GC_gcollect();
    used = GC_get_heap_size() - GC_get_free_bytes();
    if (bytes > I->max_memory || used + bytes > I->max_memory)
      memory_error(I, pos, "would ");
  }
}

void eval_list_limit(Interp *I, Pos pos, unsigned long long n) {
  eval_limit_error(I, pos, "max-list", "a list longer than %llu elements",
                   n - 1);
}

/* ---- trace ---- */

static void trace_set(Interp *I, int depth, const char *name, Pos pos) {
  if (depth < TRACE_MAX) {
    I->trace[depth].name = name;
    I->trace[depth].pos = pos;
  }
  I->ntrace = depth + 1;
}

/* ---- variables ---- */

static _Noreturn void unknown_name(Interp *I, Sym *s, Env *env, Pos pos) {
  const char *best = NULL;
  int bestd = 3;
  for (Env *e = env; e; e = e->up)
    for (int i = 0; i < e->n; i++) {
      int d = edit_distance(s->name, e->names[i]->name);
      if (d < bestd) bestd = d, best = e->names[i]->name;
    }
  resolve_unknown_name(I, s, best, bestd, pos);
}

Value *eval_con_value(Interp *I, Sym *s) {
  if (!s->con_value) {
    if (s->con_arity == 0) {
      s->con_value = val_con(s, 0, NULL);
    } else {
      Value *v = val_cell();
      v->kind = V_FUNC;
      v->u.fn.kind = F_CON;
      v->u.fn.arity = s->con_arity;
      v->u.fn.u.con = s;
      s->con_value = v;
    }
  }
  return s->con_value;
}

/* A local binding of e (an E_VAR) in env, or NULL if it has none (a
   global). Resolved variables (resolve.h) go straight to their frame and
   slot; the name there is checked, and a variable that was not resolved,
   or whose slot holds another name, is found by scanning as before. */
static inline Value *lookup_local(Expr *e, Env *env) {
  int slot = e->u.vslot;
  if (slot == RES_GLOBAL) return NULL;
  Sym *s = e->u.var;
  if (slot > 0) {
    Env *f = env;
    for (int d = e->u.vdepth; d > 0 && f; d--) f = f->up;
    if (f && slot <= f->n && f->names[slot - 1] == s) return f->vals[slot - 1];
  }
  for (Env *f = env; f; f = f->up)
    for (int i = f->n - 1; i >= 0; i--)
      if (f->names[i] == s) return f->vals[i];
  return NULL;
}

/* lookup() of a global, a constructor or a name not found: out of line,
   as the error path makes a frame that a local's lookup need not pay. */
static __attribute__((noinline)) Value *lookup_global(Interp *I, Expr *e,
                                                      Env *env) {
  Sym *s = e->u.var;
  if (e->u.vslot != RES_GLOBAL) /* not resolved, or not in its slot */
    for (Env *f = env; f; f = f->up)
      for (int i = f->n - 1; i >= 0; i--)
        if (f->names[i] == s) return f->vals[i];
  if (s->con_arity >= 0) return eval_con_value(I, s);
  /* The prelude's code sees the prelude's definitions, so a user's own
     `floor` (the scenes' name for the ground plane) cannot break fract. */
  if (e->pos.src && e->pos.src->prelude && s->prelude_value)
    return s->prelude_value;
  if (s->global) return s->global;
  if (s->lazy) { /* the prelude's, not read yet (code never resolved) */
    interp_materialize(I, s);
    if (!s->lazy) return lookup_global(I, e, env);
  }
  unknown_name(I, s, env, e->pos);
}

/* The value e (an E_VAR) names in env: a local from its resolved frame
   and slot (the name there checked) without a call, else lookup_global. */
static inline Value *lookup(Interp *I, Expr *e, Env *env) {
  int slot = e->u.vslot;
  if (slot > 0) {
    Env *f = env;
    for (int d = e->u.vdepth; d > 0 && f; d--) f = f->up;
    if (f && slot <= f->n && f->names[slot - 1] == e->u.var)
      return f->vals[slot - 1];
  } else if (slot == RES_GLOBAL && e->u.var->con_arity < 0) {
    /* a global: as lookup_global finds it, when it is defined */
    Sym *s = e->u.var;
    Value *v = e->pos.src && e->pos.src->prelude && s->prelude_value
                   ? s->prelude_value
                   : s->global;
    if (v) return v;
  }
  return lookup_global(I, e, env);
}

/* ---- thunks ---- */

/* A thunk of the prelude's code remembers the user's call it was made
   under (Interp.origin), to report its errors there when it is forced
   later, from elsewhere. */
static Value *mk_thunk(Interp *I, Expr *e, Env *env) {
  Value *v = val_cell();
  v->kind = V_THUNK;
  v->u.thunk.e = e;
  v->u.thunk.env = env;
  if (I->origin && e->pos.src && e->pos.src->prelude) v->u.thunk.origin = I->origin;
  return v;
}

/* Cheap eagerness: the value of e if it is arithmetic on Reals that are
   already known (literals, variables bound to evaluated Reals). Computing
   it now cannot fail or loop, so laziness is unchanged, and an accumulator
   such as `count (n - 1) (acc + 1)` stays a number instead of growing a
   chain of a million thunks that would then be forced recursively. */
/* What e, an E_VAR, is bound to now, as lookup() finds it, or NULL
   (a constructor, or a name not defined: lookup() reports that). */
static Value *known_var(Expr *e, Env *env) {
  Value *v = lookup_local(e, env);
  if (v) return v;
  Sym *s = e->u.var;
  if (s->con_arity >= 0) return NULL;
  if (e->pos.src && e->pos.src->prelude && s->prelude_value)
    return s->prelude_value;
  return s->global;
}

static int known_num(Interp *I, Expr *e, Env *env, double *out);

/* How many calls of defined functions known_num looks into, nested: a
   function whose body calls itself is not unfolded without end. */
#define KNOWN_CALL_DEPTH 4
static _Thread_local int known_calls;

/* known_num (known_bool, known_vec: want) of f applied to the arguments
   of e (an E_APP), when f is a defined function (a lambda, say) of one
   clause taking exactly those arguments with variable patterns, or tuple
   patterns of variables given known tuples of Reals (known_bind), no
   guard and no where: its body, in a frame binding those variables to the
   arguments' present values as select_clause would, is arithmetic on
   known Reals. The frame lives on the C stack only while known_num reads
   it: nothing is made, so a body that is not such arithmetic costs no
   more than the look. soft-cloud's keys, Key (fract3 (...) * l) 0.6 1,
   thus get their centres as they are made: no thunk, no call's frame, no
   tuple but the last (24% of the instructions of 100,000 keys). */
static Value *lit_num(Expr *e);
static int known_bool(Interp *I, Expr *e, Env *env, int *out);
/* With bout non-NULL, the body must be a known comparison (known_bool),
   its value put there, and out is not used. */
/* The most Reals in a tuple that the known_* paths and vec_block handle. */
#define VEC_BLOCK_MAX 4
static int known_vec(Interp *I, Expr *e, Env *env, double *out);

/* The most variables a known call binds, and so the most Reals it holds
   for them in cells of its own (known_bind). */
#define KNOWN_BIND_MAX 8

/* Binds pattern p to argument a, as select_clause would, in names/vals
   (*nv of them so far), when what a stands for is known now: a variable's
   present value, or for a tuple pattern of variables a tuple of Reals
   known as known_vec finds one, whose Reals go in cells[] (as many as
   names). 0 when it is not so (or does not fit): the caller leaves the
   call to eval. */
static int known_bind(Interp *I, Pat *p, Expr *a, Env *env, Sym **names,
                      Value **vals, Value *cells, int *nv) {
  if (p->kind == P_VAR) {
    if (*nv == KNOWN_BIND_MAX) return 0;
    names[*nv] = p->u.var;
    if (a->kind == E_NUM) vals[*nv] = lit_num(a);
    else if (a->kind != E_VAR || !(vals[*nv] = known_var(a, env))) return 0;
    ++*nv;
    return 1;
  }
  if (p->kind != P_TUPLE || p->u.tuple.n > VEC_BLOCK_MAX) return 0;
  int m = p->u.tuple.n;
  for (int i = 0; i < m; i++)
    if (p->u.tuple.items[i]->kind != P_VAR && p->u.tuple.items[i]->kind != P_WILD)
      return 0;
  if (*nv + m > KNOWN_BIND_MAX) return 0;
  Value *t = a->kind == E_VAR ? known_var(a, env) : NULL;
  double x[VEC_BLOCK_MAX];
  if (t) { /* a tuple bound to a name: its items as they are */
    if (t->kind != V_TUPLE || t->u.tup.n != m) return 0;
    for (int i = 0; i < m; i++)
      if (t->u.tup.items[i]->kind != V_NUM) return 0;
  } else if (known_vec(I, a, env, x) != m) {
    return 0;
  }
  for (int i = 0; i < m; i++) {
    Pat *q = p->u.tuple.items[i];
    if (q->kind == P_WILD) continue;
    names[*nv] = q->u.var;
    if (t) {
      vals[*nv] = t->u.tup.items[i];
    } else {
      cells[*nv].kind = V_NUM;
      cells[*nv].u.num = x[i];
      vals[*nv] = &cells[*nv];
    }
    ++*nv;
  }
  return 1;
}

typedef enum { KNOWN_NUM, KNOWN_BOOL, KNOWN_VEC } KnownWant;

/* Whether known_call can look into d applied to n arguments at all: one
   clause taking exactly those, no pattern binding, guard or where. */
static inline int known_call_may(const Def *d, int n) {
  if (d->arity != n || d->nclauses != 1 || d->pat || n > 4) return 0;
  const Clause *c = d->clauses[0];
  return c->nbodies == 1 && !c->guards[0] && !c->nwhere;
}

static int known_call(Interp *I, Expr *e, Env *env, Value *f, double *out,
                      int *bout, KnownWant want) {
  Def *d = f->u.fn.u.def;
  int n = e->u.app.n;
  if (!known_call_may(d, n) || known_calls >= KNOWN_CALL_DEPTH) return 0;
  Clause *c = d->clauses[0];
  /* a tuple is not a Real nor a Bool: known before binding anything */
  if (want != KNOWN_VEC && c->bodies[0]->kind == E_TUPLE) return 0;
  Sym *names[KNOWN_BIND_MAX];
  Value *vals[KNOWN_BIND_MAX];
  Value cells[KNOWN_BIND_MAX]; /* Reals of tuples taken apart: read only
                                  while the body is looked at, kept by
                                  nothing (known_* make no values) */
  int nv = 0;
  for (int i = 0; i < n; i++)
    if (!known_bind(I, c->pats[i], e->u.app.args[i], env, names, vals, cells,
                    &nv))
      return 0;
  Env frame = {f->u.fn.env, nv, nv, names, vals};
  known_calls++;
  int ok = want == KNOWN_BOOL ? known_bool(I, c->bodies[0], &frame, bout)
         : want == KNOWN_NUM ? known_num(I, c->bodies[0], &frame, out)
         : known_vec(I, c->bodies[0], &frame, out);
  known_calls--;
  return ok;
}

/* known_num (known_vec) with a literal or a name (most operands) looked
   at here, without the call and its stack check. */
static inline int known_num_at(Interp *I, Expr *e, Env *env, double *out) {
  if (e->kind == E_NUM) {
    *out = e->u.num;
    return 1;
  }
  if (e->kind == E_VAR) {
    Value *v = known_var(e, env);
    if (!v || v->kind != V_NUM) return 0;
    *out = v->u.num;
    return 1;
  }
  return known_num(I, e, env, out);
}
/* known_vec of e, an E_VAR: the Reals of the tuple it is bound to now,
   if it is one of Reals already evaluated; its size, or 0. */
static inline int known_var_vec(Expr *e, Env *env, double *out) {
    Value *v = known_var(e, env);
    if (!v || v->kind != V_TUPLE || v->u.tup.n > VEC_BLOCK_MAX) return 0;
    for (int i = 0; i < v->u.tup.n; i++) {
      Value *x = v->u.tup.items[i];
      if (x->kind != V_NUM) return 0;
      out[i] = x->u.num;
    }
    return v->u.tup.n;
}
static inline int known_vec_at(Interp *I, Expr *e, Env *env, double *out) {
  if (e->kind == E_VAR) return known_var_vec(e, env, out);
  return known_vec(I, e, env, out);
}

/* known_num of e, an E_APP of f, a function value that is not a
   defined one: a built-in defined on every Real (floor x, min a b) given
   known Reals. */
static int known_builtin_num(Interp *I, Expr *e, Env *env, Value *f,
                             double *out) {
  if (e->u.app.n > 2 || f->u.fn.kind != F_BUILTIN || f->u.fn.arity != e->u.app.n)
    return 0;
  if (e->u.app.n == 2 && builtin_is_vec_num(f->u.fn.u.bi)) {
    /* dot n v of tuples of Reals known: what the built-in would give */
    double a[VEC_BLOCK_MAX], b[VEC_BLOCK_MAX];
    int na = known_vec_at(I, e->u.app.args[0], env, a);
    if (!na) return 0;
    int nb = known_vec_at(I, e->u.app.args[1], env, b);
    return nb && builtin_vec_num(f->u.fn.u.bi, a, na, b, nb, out);
  }
  double x[2];
  for (int i = 0; i < e->u.app.n; i++)
    if (!known_num(I, e->u.app.args[i], env, &x[i])) return 0;
  return builtin_num(f->u.fn.u.bi, e->u.app.n, x, out);
}

static int known_num(Interp *I, Expr *e, Env *env, double *out) {
  char probe; /* a chain of a million '+' is left to eval, which checks */
  if ((size_t)(I->stack_base - &probe) > I->stack_limit / 2) return 0;
  switch (e->kind) {
  case E_NUM:
    *out = e->u.num;
    return 1;
  case E_VAR: {
    Value *v = known_var(e, env);
    if (!v || v->kind != V_NUM) return 0;
    *out = v->u.num;
    return 1;
  }
  case E_APP: { /* floor x, min a b, ...: built-ins defined on every Real;
                   (\x -> x * 3) y: see known_call */
    if (e->u.app.fn->kind != E_VAR) return 0;
    Value *f = known_var(e->u.app.fn, env);
    if (!f || f->kind != V_FUNC) return 0;
    if (f->u.fn.kind == F_DEF)
      return known_call(I, e, env, f, out, NULL, KNOWN_NUM);
    return known_builtin_num(I, e, env, f, out);
  }
  case E_NEG:
    if (!known_num(I, e->u.neg, env, out)) return 0;
    *out = -*out;
    return 1;
  case E_BINOP: {
    double a, b;
    TokKind op = e->u.bin.op;
    if (op != T_PLUS && op != T_MINUS && op != T_STAR && op != T_SLASH &&
        op != T_CARET)
      return 0;
    if (!known_num_at(I, e->u.bin.a, env, &a) ||
        !known_num_at(I, e->u.bin.b, env, &b))
      return 0;
    *out = op == T_PLUS ? a + b : op == T_MINUS ? a - b : op == T_STAR ? a * b
         : op == T_SLASH ? a / b : pow(a, b);
    return 1;
  }
  default:
    return 0;
  }
}

/* A comparison of Reals already known (x > 10), or a call as known_call
   takes whose body is one (p x with p = \x -> x > 10): its truth in
   *out, as binop and values_equal would find it; 0 if e is not such. For
   guards and conditions, which are forced at once anyway: this spares the
   call's frame and the Bool's cell. */
static int known_bool(Interp *I, Expr *e, Env *env, int *out) {
  if (e->kind == E_APP) {
    if (e->u.app.fn->kind != E_VAR) return 0;
    Value *f = known_var(e->u.app.fn, env);
    if (!f || f->kind != V_FUNC || f->u.fn.kind != F_DEF) return 0;
    return known_call(I, e, env, f, NULL, out, KNOWN_BOOL);
  }
  if (e->kind != E_BINOP) return 0;
  TokKind op = e->u.bin.op;
  double a, b;
  if (op != T_LT && op != T_LE && op != T_GT && op != T_GE && op != T_EQ &&
      op != T_NE)
    return 0;
  /* only a name or a literal on each side: a look deeper (mod x 3 == 1)
     fails as often as not and then costs more than it spares */
  Expr *l = e->u.bin.a, *r = e->u.bin.b;
  if ((l->kind != E_VAR && l->kind != E_NUM) || (r->kind != E_VAR && r->kind != E_NUM))
    return 0;
  if (!known_num(I, e->u.bin.a, env, &a) || !known_num(I, e->u.bin.b, env, &b))
    return 0;
  *out = op == T_LT ? a < b : op == T_LE ? a <= b : op == T_GT ? a > b
       : op == T_GE ? a >= b : op == T_EQ ? a == b : a != b;
  return 1;
}

/* The value of a literal, one per place it is written. */
static Value *lit_num(Expr *e) {
  if (!e->lit) e->lit = val_num(e->u.num);
  return e->lit;
}
static Value *lit_str(Expr *e) {
  if (!e->lit) e->lit = val_str(e->u.str);
  return e->lit;
}

/* A tuple of at most VEC_BLOCK_MAX Reals known the same way (literals,
   variables bound to evaluated ones, and the tuple arithmetic of arith()
   on them when the sizes agree): its size, with the Reals in out[], or 0.
   The arithmetic is arith()'s own (num_op), so the values are the same. */
static double num_op(TokKind op, double x, double y);
static Value *vec_block(int n, const double *x);

static int known_vec(Interp *I, Expr *e, Env *env, double *out) {
  char probe;
  if ((size_t)(I->stack_base - &probe) > I->stack_limit / 2) return 0;
  switch (e->kind) {
  case E_VAR:
    return known_var_vec(e, env, out);
  case E_TUPLE: {
    int n = e->u.tuple.n;
    if (n > VEC_BLOCK_MAX) return 0;
    for (int i = 0; i < n; i++)
      if (!known_num_at(I, e->u.tuple.items[i], env, &out[i])) return 0;
    return n;
  }
  case E_NEG: { /* as eval's: (-1) * t */
    int n = known_vec(I, e->u.neg, env, out);
    for (int i = 0; i < n; i++) out[i] = num_op(T_STAR, -1, out[i]);
    return n;
  }
  case E_BINOP: {
    TokKind op = e->u.bin.op;
    double a[VEC_BLOCK_MAX], b[VEC_BLOCK_MAX], s;
    if (op == T_PLUS || op == T_MINUS) {
      int n = known_vec(I, e->u.bin.a, env, a);
      if (!n || known_vec(I, e->u.bin.b, env, b) != n) return 0;
      for (int i = 0; i < n; i++) out[i] = num_op(op, a[i], b[i]);
      return n;
    }
    if (op == T_STAR && e->u.bin.a->kind != E_TUPLE &&
        known_num(I, e->u.bin.a, env, &s)) {
      int n = known_vec(I, e->u.bin.b, env, b);
      for (int i = 0; i < n; i++) out[i] = num_op(op, s, b[i]);
      return n;
    }
    if (op == T_STAR || op == T_SLASH) {
      int n = known_vec(I, e->u.bin.a, env, a);
      if (!n || !known_num(I, e->u.bin.b, env, &s)) return 0;
      for (int i = 0; i < n; i++) out[i] = num_op(op, a[i], s);
      return n;
    }
    return 0;
  }
  case E_APP: { /* fract3 p with fract3 (x, y, z) = (fract x, ...): see
                   known_call */
    if (e->u.app.fn->kind != E_VAR) return 0;
    Value *f = known_var(e->u.app.fn, env);
    if (!f || f->kind != V_FUNC || f->u.fn.kind != F_DEF) return 0;
    return known_call(I, e, env, f, out, NULL, KNOWN_VEC);
  }
  default:
    return 0;
  }
}

static Value *mk_fn(Def *d, Env *env);

/* A constructor applied to all its arguments, in the user's code, is
   built at once: that cannot fail, and its arguments stay delayed. */
static Value *known_con(Interp *I, Expr *e, Env *env) {
  Expr *fe = e->u.app.fn;
  if (fe->kind != E_VAR || !e->pos.src || e->pos.src->prelude) return NULL;
  Sym *c = fe->u.var;
  if (c->con_arity != e->u.app.n || c->con_arity <= 0) return NULL;
  if (lookup_local(fe, env)) return NULL; /* a local of that name */
  int n = e->u.app.n;
  /* the value and its arguments' array in one block: one allocation, one
     object to mark, 16 bytes less (a soft-cloud key is one) */
  Value *v = val_small(sizeof(Value) + sizeof(Value *) * (size_t)n);
  Value **args = (Value **)(v + 1);
  v->kind = V_CON;
  v->u.con.con = c;
  v->u.con.n = n;
  v->u.con.args = args;
  v->u.con.pos = &e->pos;
  for (int i = 0; i < n; i++) args[i] = delay(I, e->u.app.args[i], env);
  return v;
}

/* delay() of anything but a variable: out of line, so that delay() of a
   variable (most arguments) is a lookup without a frame. */
static __attribute__((noinline)) Value *delay_slow(Interp *I, Expr *e,
                                                   Env *env) {
  double x, t[VEC_BLOCK_MAX];
  int n;
  switch (e->kind) {
  case E_BINOP: case E_NEG:
    if (known_num(I, e, env, &x)) return val_num(x);
    if ((n = known_vec(I, e, env, t)) > 0) return vec_block(n, t);
    break;
  case E_TUPLE:
    if ((n = known_vec(I, e, env, t)) > 0) return vec_block(n, t);
    break;
  case E_APP: {
    /* what known_num, known_con and known_vec would each try, with the
       function looked up once: most arguments that are calls (Shift v a,
       Union (...) (...)) name a function of several clauses or a
       constructor, and fail at the first look */
    Expr *fe = e->u.app.fn;
    if (fe->kind != E_VAR) break;
    Value *f = known_var(fe, env);
    if (!f) { /* a constructor (or a name not defined) */
      Value *c = known_con(I, e, env);
      if (c) return c;
      break;
    }
    if (f->kind != V_FUNC) break;
    if (f->u.fn.kind == F_DEF) {
      Def *d = f->u.fn.u.def;
      if (!known_call_may(d, e->u.app.n)) break;
      /* a body that is a tuple (ShiftPlane's) is no Real, and a literal
         no tuple: the look that cannot succeed is not taken */
      ExprKind bk = d->clauses[0]->bodies[0]->kind;
      if (bk != E_TUPLE && known_call(I, e, env, f, &x, NULL, KNOWN_NUM))
        return val_num(x);
      if (bk != E_NUM && (n = known_call(I, e, env, f, t, NULL, KNOWN_VEC)) > 0)
        return vec_block(n, t);
    } else if (known_builtin_num(I, e, env, f, &x)) {
      return val_num(x);
    }
    break;
  }
  default:
    break;
  }
  switch (e->kind) {
  case E_NUM: return lit_num(e);
  case E_STR: return lit_str(e);
  case E_BOOL: return val_bool(I, e->u.b);
  case E_VAR: return lookup(I, e, env);
  case E_LAMBDA: return mk_fn(e->u.lambda, env); /* as eval makes it */
  default: return mk_thunk(I, e, env);
  }
}

Value *delay(Interp *I, Expr *e, Env *env) {
  if (e->kind == E_VAR) return lookup(I, e, env);
  return delay_slow(I, e, env);
}

Value *eval_builtin_value(const Builtin *b) {
  Value *v = GC_MALLOC_UNCOLLECTABLE(sizeof *v);
  *v = *val_builtin(b);
  return v;
}

Value *delay_apply(Value *f, int n, Value **args) {
  Value *v = val_cell();
  v->kind = V_APTHUNK;
  v->u.pap.fn = f;
  v->u.pap.n = n;
  v->u.pap.args = args;
  return v;
}

static void forcing_push(Interp *I, Value *v) {
  if (I->nforcing == I->capforcing) {
    int cap = I->capforcing ? I->capforcing * 2 : 256;
    Forcing *f = GC_MALLOC(sizeof(Forcing) * (size_t)cap);
    if (I->nforcing) memcpy(f, I->forcing, sizeof(Forcing) * (size_t)I->nforcing);
    I->forcing = f;
    I->capforcing = cap;
  }
  I->forcing[I->nforcing].v = v;
  I->forcing[I->nforcing].saved = *v;
  I->nforcing++;
}

static int match(Interp *I, Pat *p, Value *v, Env *frame);

void eval_restore(Interp *I, int nforcing) {
  while (I->nforcing > nforcing) {
    I->nforcing--;
    *I->forcing[I->nforcing].v = I->forcing[I->nforcing].saved;
  }
}

static _Noreturn COLD void patsel_error(Interp *I, Pat *pat, Value *whole) {
  char buf[200];
  val_brief(force(I, whole), buf, sizeof buf);
  qcs_error(pat->pos, "the pattern does not match the value %s", buf);
}

static Value *force_patsel(Interp *I, Value *v) {
  Pat *pat = v->u.patsel.pat;
  Sym *var = v->u.patsel.var;
  Value *whole = v->u.patsel.whole;
  Env *tmp = env_new(NULL, 4);
  if (!match(I, pat, whole, tmp)) patsel_error(I, pat, whole);
  for (int i = 0; i < tmp->n; i++)
    if (tmp->names[i] == var) return force(I, tmp->vals[i]);
  qcs_error(pat->pos, "internal error: pattern variable lost");
}

/* Where the thunk saved in f was written, or a no-position: a delayed
   application (V_APTHUNK, made by ++, ranges and built-ins) has none. */
static Pos forcing_pos(const Forcing *f) {
  if (f->saved.kind == V_THUNK) return f->saved.u.thunk.e->pos;
  if (f->saved.kind == V_PATSEL) return f->saved.u.patsel.pat->pos;
  return pos_none;
}

/* v, a V_BLACKHOLE, is being forced again while its own forcing is under
   way. A blackhole keeps the union of what it was, but not its kind: the
   kind is in the forcing stack, whose entries from v's up to the top are
   the cycle. The error points at the first of them written in the user's
   code, else at any with a position (the prelude's), else at the item. */
static _Noreturn void cycle_error(Interp *I, Value *v) {
  int k = I->nforcing - 1;
  while (k >= 0 && I->forcing[k].v != v) k--;
  Pos pos = pos_none, any = pos_none;
  for (int i = k < 0 ? 0 : k; i < I->nforcing && !pos.line; i++) {
    Pos p = forcing_pos(&I->forcing[i]);
    if (!p.line) continue;
    if (!any.line) any = p;
    if (!p.src || !p.src->prelude) pos = p;
  }
  if (!pos.line) pos = any.line ? any : I->item_pos;
  qcs_error(pos, "this value depends on itself (an infinite loop)");
}

/* force() of a thunk or a blackhole: out of line, so that force() of a
   value already evaluated (most calls) costs a compare and no frame. */
static __attribute__((noinline)) Value *force_slow(Interp *I, Value *v) {
  switch (v->kind) {
  case V_THUNK:
  case V_APTHUNK:
  case V_PATSEL: {
    forcing_push(I, v);
    Value saved = *v;
    v->kind = V_BLACKHOLE;
    Value *r;
    const Pos *origin = I->origin;
    if (saved.kind == V_THUNK) {
      I->origin = saved.u.thunk.origin;
      r = eval(I, saved.u.thunk.e, saved.u.thunk.env);
      I->origin = origin;
    }
    else if (saved.kind == V_APTHUNK)
      r = apply(I, saved.u.pap.fn, saved.u.pap.n, saved.u.pap.args, pos_none);
    else {
      v->u = saved.u;
      r = force_patsel(I, v);
    }
    *v = *r;
    /* the entry's copy would keep the thunk's environment alive */
    I->nforcing--;
    I->forcing[I->nforcing] = (Forcing){0};
    return v;
  }
  case V_BLACKHOLE:
    cycle_error(I, v);
  default:
    return v;
  }
}

Value *force(Interp *I, Value *v) {
  if (v->kind >= V_THUNK && v->kind <= V_BLACKHOLE) return force_slow(I, v);
  return v;
}

/* ---- checked forcing ---- */

static _Noreturn COLD void type_error(Interp *I, Value *v, Pos pos, const char *want,
                                 const char *what) {
  char buf[160];
  val_brief(v, buf, sizeof buf);
  qcs_error(pos, "%s must be %s, not %s: %s", what, want, val_describe(v), buf);
}

double force_num(Interp *I, Value *v, Pos pos, const char *what) {
  v = force(I, v);
  if (v->kind != V_NUM) type_error(I, v, pos, "a Real", what);
  return v->u.num;
}

int force_bool(Interp *I, Value *v, Pos pos, const char *what) {
  v = force(I, v);
  if (v->kind != V_BOOL) type_error(I, v, pos, "a Bool", what);
  return v->u.b;
}

const char *eval_str_chars(Interp *I, Value *v, Pos pos) {
  if (v->u.str.s) return v->u.str.s;
  eval_alloc_check(I, pos, v->u.str.len + 1);
  const char *s = val_str_chars(v);
  if (!s) qcs_error(pos, "out of memory for a string of %zu bytes",
                    v->u.str.len + 1);
  return s;
}

const char *force_str(Interp *I, Value *v, Pos pos, const char *what) {
  v = force(I, v);
  if (v->kind != V_STR) type_error(I, v, pos, "a String", what);
  return eval_str_chars(I, v, pos);
}

void force_vec3(Interp *I, Value *v, Pos pos, const char *what, double out[3]) {
  v = force(I, v);
  if (v->kind != V_TUPLE || v->u.tup.n != 3)
    type_error(I, v, pos, "a 3-tuple of Reals", what);
  for (int i = 0; i < 3; i++)
    out[i] = force_num(I, v->u.tup.items[i], pos, what);
}

/* ---- pattern matching ---- */

/* env_bind, without the call while the frame has room. */
static inline void bind_var(Env *frame, Sym *name, Value *v) {
  if (frame->n < frame->cap) {
    frame->names[frame->n] = name;
    frame->vals[frame->n++] = v;
  } else {
    env_bind(frame, name, v);
  }
}

/* match() of each of ps against vals, left to right; a variable or _
   without the call. */
static int match_parts(Interp *I, int n, Pat **ps, Value **vals, Env *frame) {
  for (int i = 0; i < n; i++) {
    Pat *q = ps[i];
    if (q->kind == P_VAR) bind_var(frame, q->u.var, vals[i]);
    else if (q->kind != P_WILD && !match(I, q, vals[i], frame)) return 0;
  }
  return 1;
}

static int match(Interp *I, Pat *p, Value *v, Env *frame) {
  switch (p->kind) {
  case P_VAR:
    bind_var(frame, p->u.var, v);
    return 1;
  case P_WILD:
    return 1;
  case P_NUM:
    v = force(I, v);
    return v->kind == V_NUM && v->u.num == p->u.num;
  case P_STR:
    v = force(I, v);
    return v->kind == V_STR && !strcmp(eval_str_chars(I, v, p->pos), p->u.str);
  case P_BOOL:
    v = force(I, v);
    return v->kind == V_BOOL && v->u.b == p->u.b;
  case P_CON: {
    Sym *c = p->u.con.con;
    if (c->con_arity < 0)
      qcs_error(p->pos, "'%s' in a pattern is not a constructor", c->name);
    if (c->con_arity != p->u.con.n)
      qcs_error(p->pos, "constructor %s takes %d argument%s, this pattern "
                "gives %d", c->name, c->con_arity,
                c->con_arity == 1 ? "" : "s", p->u.con.n);
    v = force(I, v);
    if (v->kind != V_CON || v->u.con.con != c) return 0;
    return match_parts(I, p->u.con.n, p->u.con.args, v->u.con.args, frame);
  }
  case P_TUPLE:
    v = force(I, v);
    if (v->kind != V_TUPLE || v->u.tup.n != p->u.tuple.n) return 0;
    return match_parts(I, p->u.tuple.n, p->u.tuple.items, v->u.tup.items,
                       frame);
  case P_NIL:
    v = force(I, v);
    return v->kind == V_NIL;
  case P_CONS:
    v = force(I, v);
    if (v->kind != V_CONS) return 0;
    return match(I, p->u.cons.head, v->u.cons.head, frame) &&
           match(I, p->u.cons.tail, v->u.cons.tail, frame);
  case P_LIST:
    for (int i = 0; i < p->u.tuple.n; i++) {
      v = force(I, v);
      if (v->kind != V_CONS) return 0;
      if (!match(I, p->u.tuple.items[i], v->u.cons.head, frame)) return 0;
      v = v->u.cons.tail;
    }
    return force(I, v)->kind == V_NIL;
  }
  return 0;
}

/* ---- definitions and clauses ---- */

static void pat_bind_vars(Pat *p, Value *whole, Env *frame, Pat *top) {
  switch (p->kind) {
  case P_VAR: {
    Value *v = val_cell();
    v->kind = V_PATSEL;
    v->u.patsel.pat = top;
    v->u.patsel.var = p->u.var;
    v->u.patsel.whole = whole;
    env_bind(frame, p->u.var, v);
    break;
  }
  case P_CON:
    for (int i = 0; i < p->u.con.n; i++)
      pat_bind_vars(p->u.con.args[i], whole, frame, top);
    break;
  case P_TUPLE:
  case P_LIST:
    for (int i = 0; i < p->u.tuple.n; i++)
      pat_bind_vars(p->u.tuple.items[i], whole, frame, top);
    break;
  case P_CONS:
    pat_bind_vars(p->u.cons.head, whole, frame, top);
    pat_bind_vars(p->u.cons.tail, whole, frame, top);
    break;
  default:
    break;
  }
}

/* A function that captures nothing (Def.closed) keeps no frame: a lambda
   given to map inside `let xs = [1 .. 10^6] in ...` would otherwise keep
   the let's frame, and so all of xs, alive while map walks it. */
static Value *mk_fn(Def *d, Env *env) {
  if (d->closed == 1) env = NULL;
  Value *v = val_cell();
  v->kind = V_FUNC;
  v->u.fn.kind = F_DEF;
  v->u.fn.arity = d->arity;
  v->u.fn.u.def = d;
  v->u.fn.env = env;
  return v;
}

static Expr *defbody_expr(Def *d) {
  Expr *e = GC_MALLOC(sizeof *e);
  e->kind = E_DEFBODY;
  e->pos = d->pos;
  e->u.def = d;
  return e;
}

/* Bind local definitions (where, let) in frame; they may refer to each
   other and to themselves. */
static void bind_defs(Interp *I, int n, Def **defs, Env *frame) {
  for (int i = 0; i < n; i++) {
    Def *d = defs[i];
    if (d->pat) {
      Value *whole = mk_thunk(I, defbody_expr(d), frame);
      pat_bind_vars(d->pat, whole, frame, d->pat);
    } else if (d->arity > 0) {
      env_bind(frame, d->name, mk_fn(d, frame));
    } else {
      Clause *c = d->clauses[0];
      Expr *body = (d->nclauses == 1 && c->nbodies == 1 && !c->guards[0] &&
                    c->nwhere == 0)
                       ? c->bodies[0]
                       : defbody_expr(d);
      env_bind(frame, d->name, mk_thunk(I, body, frame));
    }
  }
}

Value *eval_global_value(Interp *I, Def *d) {
  if (d->arity > 0) return mk_fn(d, NULL);
  return mk_thunk(I, defbody_expr(d), NULL);
}

/* Forces v a few levels deep for an error message; an error on the way
   is swallowed (the value then shows as "..." where it failed). */
static void force_some(Interp *I, Value *v, int depth) {
  if (depth <= 0) return;
  int nforcing = I->nforcing, ntrace = I->ntrace;
  ErrInfo saved = *err_info();
  ErrFrame f;
  if (ERR_TRY(f)) {
    force(I, v); /* in place: v is not assigned after the setjmp */
    err_pop(&f);
  } else {
    err_pop(&f);
    eval_restore(I, nforcing);
    I->ntrace = ntrace;
    *err_info() = saved;
    return;
  }
  *err_info() = saved;
  if (v->kind == V_TUPLE)
    for (int i = 0; i < v->u.tup.n; i++) force_some(I, v->u.tup.items[i], depth - 1);
  else if (v->kind == V_CON)
    for (int i = 0; i < v->u.con.n; i++) force_some(I, v->u.con.args[i], depth - 1);
  else if (v->kind == V_CONS)
    force_some(I, v->u.cons.head, depth - 1);
}

static void brief_args(Interp *I, int n, Value **args, char *buf, size_t size) {
  size_t len = 0;
  buf[0] = 0;
  for (int i = 0; i < n && len + 4 < size; i++) {
    if (i) {
      snprintf(buf + len, size - len, ", ");
      len = strlen(buf);
    }
    force_some(I, args[i], 3);
    val_brief(args[i], buf + len, size - len);
    len = strlen(buf);
  }
}

/* Clause.simple and Clause.quick_col, quick_con (ast.h) of cl, found on
   first use. A simple clause's patterns are variables, _, Real or Bool
   literals, [], or a [h : t], constructor or tuple pattern whose parts
   are all variables or _. */
static int pat_is_var(const Pat *p) { return p->kind == P_VAR || p->kind == P_WILD; }
static int pats_vars(int n, Pat **ps, int *vars) {
  for (int i = 0; i < n; i++) {
    if (!pat_is_var(ps[i])) return 0;
    *vars += ps[i]->kind == P_VAR;
  }
  return 1;
}
static int clause_simple(Clause *cl) {
  if (cl->simple) return cl->simple;
  for (int i = 0; i < cl->npats; i++) {
    Pat *p = cl->pats[i];
    if (pat_is_var(p)) continue;
    if (p->kind == P_CON) {
      cl->quick_col = i + 1;
      cl->quick_con = p->u.con.con;
    }
    break;
  }
  int vars = 0;
  for (int i = 0; i < cl->npats; i++) {
    Pat *p = cl->pats[i];
    int ok;
    switch (p->kind) {
    case P_VAR: vars++; ok = 1; break;
    case P_WILD: case P_NIL: case P_NUM: case P_BOOL: ok = 1; break;
    case P_CONS: ok = pats_vars(1, &p->u.cons.head, &vars) &&
                      pats_vars(1, &p->u.cons.tail, &vars); break;
    case P_CON: ok = pats_vars(p->u.con.n, p->u.con.args, &vars); break;
    case P_TUPLE: ok = pats_vars(p->u.tuple.n, p->u.tuple.items, &vars); break;
    default: ok = 0; break;
    }
    if (!ok) return cl->simple = -1;
  }
  if (cl->nwhere == 0 && vars > 0) { /* match_simple's order */
    Sym **names = GC_MALLOC(sizeof(Sym *) * (size_t)vars);
    int k = 0;
    for (int i = 0; i < cl->npats; i++) {
      Pat *p = cl->pats[i], **ps = &p;
      int n = 1;
      if (p->kind == P_CONS) ps = &p->u.cons.head, n = 2;
      else if (p->kind == P_CON) ps = p->u.con.args, n = p->u.con.n;
      else if (p->kind == P_TUPLE) ps = p->u.tuple.items, n = p->u.tuple.n;
      for (int j = 0; j < n; j++) {
        Pat *q = p->kind == P_CONS ? (j ? p->u.cons.tail : p->u.cons.head) : ps[j];
        if (q->kind == P_VAR) names[k++] = q->u.var;
      }
    }
    cl->frame_names = names;
  }
  return cl->simple = vars + 1;
}

/* The values a simple clause's patterns bind (match_simple's second
   pass), in vals, in match()'s order; args are forced where looked into. */
static inline void simple_vals(Clause *cl, Value **args, Value **vals) {
  int k = 0;
  for (int i = 0; i < cl->npats; i++) {
    Pat *p = cl->pats[i];
    Value *v = args[i];
    switch (p->kind) {
    case P_VAR:
      vals[k++] = v;
      break;
    case P_CONS:
      if (p->u.cons.head->kind == P_VAR) vals[k++] = v->u.cons.head;
      if (p->u.cons.tail->kind == P_VAR) vals[k++] = v->u.cons.tail;
      break;
    case P_CON:
      for (int j = 0; j < p->u.con.n; j++)
        if (p->u.con.args[j]->kind == P_VAR) vals[k++] = v->u.con.args[j];
      break;
    case P_TUPLE:
      for (int j = 0; j < p->u.tuple.n; j++)
        if (p->u.tuple.items[j]->kind == P_VAR) vals[k++] = v->u.tup.items[j];
      break;
    default:
      break;
    }
  }
}

/* The variables of ps (variables or _) bound to vals, in frame. */
static inline void bind_parts(Env *frame, int n, Pat **ps, Value **vals) {
  for (int i = 0; i < n; i++)
    if (ps[i]->kind == P_VAR) {
      frame->names[frame->n] = ps[i]->u.var;
      frame->vals[frame->n++] = vals[i];
    }
}

/* match() of a simple clause's patterns (clause_simple), in two passes:
   the arguments its patterns look into are forced and checked left to
   right, stopping at the first that does not match, as match() does
   (which forces nothing for a variable or _ inside a pattern); only a
   clause that matches gets a frame, sized for its variables and where
   bindings, filled in match()'s order. Returns the frame or NULL. */
static Env *match_simple(Interp *I, Clause *cl, int simple, Env *env,
                         Value **args) {
  for (int i = 0; i < cl->npats; i++) {
    Pat *p = cl->pats[i];
    Value *v;
    switch (p->kind) {
    case P_NIL:
      if (force(I, args[i])->kind != V_NIL) return NULL;
      break;
    case P_CONS:
      if (force(I, args[i])->kind != V_CONS) return NULL;
      break;
    case P_NUM:
      v = force(I, args[i]);
      if (v->kind != V_NUM || v->u.num != p->u.num) return NULL;
      break;
    case P_BOOL:
      v = force(I, args[i]);
      if (v->kind != V_BOOL || v->u.b != p->u.b) return NULL;
      break;
    case P_CON:
      if (p->u.con.con->con_arity != p->u.con.n) { /* match's error */
        Env none = {NULL, 0, 0, NULL, NULL};
        match(I, p, args[i], &none);
      }
      v = force(I, args[i]);
      if (v->kind != V_CON || v->u.con.con != p->u.con.con) return NULL;
      break;
    case P_TUPLE:
      v = force(I, args[i]);
      if (v->kind != V_TUPLE || v->u.tup.n != p->u.tuple.n) return NULL;
      break;
    default:
      break;
    }
  }
  if (cl->frame_names) {
    /* no where bindings: the frame is never added to, so its names can
       be the clause's own, and its values follow it in one block */
    int n = simple - 1;
    Env *frame = val_small(sizeof(Env) + sizeof(Value *) * (size_t)n);
    frame->up = env;
    frame->n = frame->cap = n;
    frame->names = cl->frame_names;
    frame->vals = (Value **)(frame + 1);
    simple_vals(cl, args, frame->vals);
    return frame;
  }
  Env *frame = env_new(env, simple + cl->nwhere);
  for (int i = 0; i < cl->npats; i++) {
    Pat *p = cl->pats[i];
    Value *v = args[i]; /* forced above, in place, if looked into */
    switch (p->kind) {
    case P_VAR:
      frame->names[frame->n] = p->u.var;
      frame->vals[frame->n++] = v;
      break;
    case P_CONS:
      bind_parts(frame, 1, &p->u.cons.head, &v->u.cons.head);
      bind_parts(frame, 1, &p->u.cons.tail, &v->u.cons.tail);
      break;
    case P_CON:
      bind_parts(frame, p->u.con.n, p->u.con.args, v->u.con.args);
      break;
    case P_TUPLE:
      bind_parts(frame, p->u.tuple.n, p->u.tuple.items, v->u.tup.items);
      break;
    default:
      break;
    }
  }
  return frame;
}

/* Bindings a clause's patterns make before its frame exists: match()
   binds into this many slots on the C stack (more go to the heap, as
   env_bind grows a frame), and only a clause that matches gets a frame,
   of the size it needs. */
#define MATCH_SCRATCH 16

/* A clause's patterns matched in general (match_simple handles the
   common ones): its frame, or NULL when it does not match. A function of
   its own, so that its scratch arrays are not holes in select_clause's
   frame (see COLD); the values' array starts zeroed for the same reason. */
static __attribute__((noinline)) Env *match_general(Interp *I, Clause *cl,
                                                    Env *env, Value **args) {
  Sym *snames[MATCH_SCRATCH];
  Value *svals[MATCH_SCRATCH] = {0};
  Env *frame;
  Env scratch = {env, 0, MATCH_SCRATCH, snames, svals};
  int ok = 1;
  for (int i = 0; i < cl->npats && ok; i++)
    ok = match(I, cl->pats[i], args[i], &scratch);
  if (!ok) return NULL;
  int n = scratch.n;
  if (cl->nwhere == 0 && n > 0) {
    /* as match_simple's: a match that succeeds binds the same names
       in the same order every time, kept once in the clause */
    if (!cl->frame_names) {
      Sym **names = GC_MALLOC(sizeof(Sym *) * (size_t)n);
      memcpy(names, scratch.names, sizeof(Sym *) * (size_t)n);
      cl->frame_names = names;
    }
    frame = val_small(sizeof(Env) + sizeof(Value *) * (size_t)n);
    frame->up = env;
    frame->n = frame->cap = n;
    frame->names = cl->frame_names;
    frame->vals = (Value **)(frame + 1);
    for (int i = 0; i < n; i++) frame->vals[i] = scratch.vals[i];
  } else {
    frame = env_new(env, n + cl->nwhere);
    for (int i = 0; i < n; i++) {
      frame->names[i] = scratch.names[i];
      frame->vals[i] = scratch.vals[i];
    }
    frame->n = n;
  }
  return frame;
}

static _Noreturn COLD void no_clause_error(Interp *I, Def *d, Value **args,
                                           Pos pos);

/* Choose the clause of d that matches args and the body whose guard holds;
   returns the body and its environment for the caller to evaluate. */
static Expr *select_clause(Interp *I, Def *d, Env *env, Value **args,
                           Pos pos, Env **out_env) {
  for (int c = 0; c < d->nclauses; c++) {
    Clause *cl = d->clauses[c];
    Env *frame;
    int simple = args ? clause_simple(cl) : -1;
    /* Its first pattern that can fail is a constructor's, after variables:
       the argument is forced here as matching would force it next, and
       another constructor (or none) rules the clause out before anything
       is bound, and with it every clause after it whose first such
       pattern looks there for another constructor still (Shift's fifteen
       clauses on its second argument). A pattern of the wrong arity is
       left to matching and its error. */
    if (cl->quick_col &&
        cl->quick_con->con_arity == cl->pats[cl->quick_col - 1]->u.con.n) {
      int col = cl->quick_col;
      Value *v = force(I, args[col - 1]);
      Sym *con = v->kind == V_CON ? v->u.con.con : NULL;
      if (con != cl->quick_con) {
        while (c + 1 < d->nclauses) {
          Clause *next = d->clauses[c + 1];
          clause_simple(next);
          if (next->quick_col != col || next->quick_con == con ||
              next->quick_con->con_arity != next->pats[col - 1]->u.con.n)
            break;
          c++;
        }
        continue;
      }
    }
    if (simple > 0) {
      frame = match_simple(I, cl, simple, env, args);
      if (!frame) continue;
    } else {
      frame = match_general(I, cl, env, args);
      if (!frame) continue;
    }
    if (cl->nwhere) bind_defs(I, cl->nwhere, cl->where, frame);
    for (int b = 0; b < cl->nbodies; b++) {
      Expr *g = cl->guards[b];
      int kb;
      if (!g || (known_bool(I, g, frame, &kb)
                     ? kb
                     : force_bool(I, eval(I, g, frame), g->pos, "a guard"))) {
        *out_env = frame;
        return cl->bodies[b];
      }
    }
  }
  no_clause_error(I, d, args, pos);
}

static _Noreturn COLD void no_clause_error(Interp *I, Def *d, Value **args,
                                           Pos pos) {
  char buf[400];
  brief_args(I, d->arity, args, buf, sizeof buf);
  if (d->name && !strcmp(d->name->name, "case"))
    qcs_error(pos, "no alternative of this case matches %s", buf);
  if (d->name)
    qcs_error(pos, "no clause of %s matches the argument%s %s", d->name->name,
              d->arity == 1 ? "" : "s", buf);
  if (d->arity == 0)
    qcs_error(pos, "no guard holds in this definition");
  qcs_error(pos, "no clause of this lambda matches %s", buf);
}

/* ---- application ---- */

/* A position in the user's code for something the prelude builds: the
   innermost call from outside the prelude (a Rounded rebuilt by Shift is
   reported where the user wrote Shift). */
Pos eval_user_pos(Interp *I, Pos pos) {
  if (!pos.src || !pos.src->prelude) return pos;
  if (I->origin) return *I->origin;
  int n = I->ntrace < TRACE_MAX ? I->ntrace : TRACE_MAX;
  for (int i = n - 1; i >= 0; i--) {
    const Pos *t = &I->trace[i].pos;
    if (t->src && !t->src->prelude) return *t;
  }
  return pos;
}

/* Is the source at pos right after a '-' (spaces between)? Then
   `Cylinder -1 1` was read as Cylinder - (1 1), as in Haskell. */
static int after_minus(Pos pos) {
  if (!pos.src || !pos.src->text || pos.line < 1 || pos.col < 2) return 0;
  const char *t = pos.src->text;
  for (int line = 1; line < pos.line; line++) {
    t = strchr(t, '\n');
    if (!t) return 0;
    t++;
  }
  for (int c = pos.col - 2; c >= 0; c--) {
    if (t[c] == '-') return 1;
    if (t[c] != ' ' && t[c] != '\t') return 0;
  }
  return 0;
}

static _Noreturn COLD void not_function_error(Value *f, int n, Pos pos,
                                              const char *over_name,
                                              int over_arity) {
  char buf[160];
  val_brief(f, buf, sizeof buf);
  if (over_name)
    qcs_error(pos, "%s takes %d argument%s, but it is given %d (its "
              "result, %s, is not a function: %s)", over_name, over_arity,
              over_arity == 1 ? "" : "s", over_arity + n, val_describe(f),
              buf);
  qcs_error(pos, "%s is not a function, but it is applied to %d "
            "argument%s: %s%s", val_describe(f), n, n == 1 ? "" : "s", buf,
            f->kind == V_NUM && after_minus(pos)
                ? " (a negative argument goes in parentheses: "
                  "f (-1), not f -1)"
                : "");
}

/* Apply f to n arguments. Returns 1 with (*body, *benv) set when the result
   is a function body to evaluate in tail position, or 0 with *result. */
static int call(Interp *I, Value *f, int n, Value **args, Pos pos,
                const Pos *spos, Value **result, Expr **body, Env **benv,
                int depth) {
  /* A function given more arguments than it takes applies its result to
     the rest: if that is no function, the message says so by name. */
  const char *over_name = NULL;
  int over_arity = 0;
  for (;;) {
    f = force(I, f);
    if (f->kind == V_PAP) {
      Value **all = val_array(f->u.pap.n + n);
      memcpy(all, f->u.pap.args, sizeof(Value *) * (size_t)f->u.pap.n);
      memcpy(all + f->u.pap.n, args, sizeof(Value *) * (size_t)n);
      args = all;
      n += f->u.pap.n;
      f = f->u.pap.fn;
      continue;
    }
    if (f->kind != V_FUNC)
      not_function_error(f, n, pos, over_name, over_arity);
    int a = f->u.fn.arity;
    if (n < a) {
      Value *p = val_cell();
      p->kind = V_PAP;
      p->u.pap.fn = f;
      p->u.pap.n = n;
      p->u.pap.args = args;
      *result = p;
      return 0;
    }
    Value *r;
    switch (f->u.fn.kind) {
    case F_CON: {
      Sym *c = f->u.fn.u.con;
      if (n > a)
        qcs_error(pos, "constructor %s takes %d argument%s, but it is given "
                  "%d", c->name, a, a == 1 ? "" : "s", n);
      /* eval's E_APP (spos given) made args for this call alone */
      Value **cargs = args;
      if (!spos) {
        cargs = val_array(a);
        memcpy(cargs, args, sizeof(Value *) * (size_t)a);
      }
      *result = val_con(c, a, cargs);
      if (pos.src) { /* scene errors found later point back here */
        if (spos && !pos.src->prelude) {
          (*result)->u.con.pos = spos;  /* the call's own, in its Expr */
        } else if (pos.src->prelude && I->origin) {
          (*result)->u.con.pos = I->origin; /* eval_user_pos's; never
                                               written after it is set */
        } else {
          Pos *p = val_small(sizeof *p);
          *p = eval_user_pos(I, pos);
          (*result)->u.con.pos = p;
        }
      }
      return 0;
    }
    case F_BUILTIN:
      trace_set(I, depth, f->u.fn.u.bi->name, pos);
      r = f->u.fn.u.bi->fn(I, args, pos);
      break;
    case F_DEF: {
      Def *d = f->u.fn.u.def;
      trace_set(I, depth, d->name ? d->name->name : "a lambda", pos);
      /* the user's code calls the prelude: errors in there are reported
         here (eval() puts the origin back when it returns) */
      if (pos.src && !pos.src->prelude && d->pos.src &&
          d->pos.src->prelude) {
        if (spos) {
          I->origin = spos;
        } else {
          Pos *o = val_small(sizeof *o);
          *o = pos;
          I->origin = o;
        }
      }
      Env *env;
      Expr *b = select_clause(I, d, f->u.fn.env, args, pos, &env);
      if (n == a) {
        *body = b;
        *benv = env;
        return 1;
      }
      r = eval(I, b, env);
      break;
    }
    default:
      qcs_error(pos, "internal error: bad function kind");
    }
    if (n == a) {
      *result = r;
      return 0;
    }
    if (f->u.fn.kind == F_DEF && f->u.fn.u.def->name) {
      over_name = f->u.fn.u.def->name->name;
      over_arity = a;
    } else if (f->u.fn.kind == F_BUILTIN) {
      over_name = f->u.fn.u.bi->name;
      over_arity = a;
    } else {
      over_name = NULL;
    }
    f = r;
    args += a;
    n -= a;
  }
}

Value *apply(Interp *I, Value *f, int n, Value **args, Pos pos) {
  Value *r;
  Expr *body;
  Env *env;
  int depth = I->ntrace;
  if (call(I, f, n, args, pos, NULL, &r, &body, &env, depth)) r = eval(I, body, env);
  I->ntrace = depth;
  return r;
}

/* ---- operators ---- */

static int values_equal(Interp *I, Value *a, Value *b, Pos pos);

static Value *arith(Interp *I, TokKind op, Value *a, Value *b, Pos pos);

/* A tuple of n Reals as one block: the n Reals, the tuple, its item array
   (the items and the tuple's pointer point into the block). One
   allocation instead of n + 2, and one object for the collector to mark.
   A Real needs only its kind and number, so each takes NUM_CELL bytes,
   not a whole Value's: a Real is never overwritten (force writes only
   thunks), and a copy of a whole Value from one (force's *v = *r) reads
   on into the Reals after it and the tuple, inside the block. 112 bytes
   for a 3-tuple instead of 184: soft-cloud holds a million of them. */
typedef struct { unsigned char kind; double num; } NumCell;
#define NUM_CELL sizeof(NumCell)
static Value *vec_block(int n, const double *x) {
  _Static_assert(offsetof(Value, u.num) == offsetof(NumCell, num) &&
                 NUM_CELL <= sizeof(Value),
                 "a Real's cell is a Value's first bytes");
  char *blk = val_small(NUM_CELL * (size_t)n + sizeof(Value) +
                        sizeof(Value *) * (size_t)n);
  Value *t = (Value *)(blk + NUM_CELL * (size_t)n);
  Value **it = (Value **)(t + 1);
  for (int i = 0; i < n; i++) {
    Value *c = (Value *)(blk + NUM_CELL * (size_t)i);
    c->kind = V_NUM;
    c->u.num = x[i];
    it[i] = c;
  }
  t->kind = V_TUPLE;
  t->u.tup.n = n;
  t->u.tup.items = it;
  return t;
}

static double num_op(TokKind op, double x, double y) {
  switch (op) {
  case T_PLUS: return x + y;
  case T_MINUS: return x - y;
  case T_STAR: return x * y;
  case T_SLASH: return x / y;
  default: return pow(x, y); /* T_CARET */
  }
}

static Value *vec_map2(Interp *I, TokKind op, Value *a, Value *b, Pos pos) {
  if (a->u.tup.n != b->u.tup.n)
    qcs_error(pos, "'%s' on tuples of different sizes (%d and %d)",
              op_text(op), a->u.tup.n, b->u.tup.n);
  int n = a->u.tup.n;
  if (n <= VEC_BLOCK_MAX) { /* Reals on both sides: no cell per item */
    double x[VEC_BLOCK_MAX];
    int i = 0;
    for (; i < n; i++) {
      Value *p = force(I, a->u.tup.items[i]), *q = force(I, b->u.tup.items[i]);
      if (p->kind != V_NUM || q->kind != V_NUM) break;
      x[i] = num_op(op, p->u.num, q->u.num);
    }
    if (i == n) return vec_block(n, x);
  }
  Value **it = val_array(n);
  for (int i = 0; i < n; i++)
    it[i] = arith(I, op, force(I, a->u.tup.items[i]),
                  force(I, b->u.tup.items[i]), pos);
  return val_tuple(n, it);
}

static Value *vec_scale(Interp *I, TokKind op, Value *t, Value *s, int s_first,
                        Pos pos) {
  int n = t->u.tup.n;
  if (n <= VEC_BLOCK_MAX && s->kind == V_NUM) {
    double x[VEC_BLOCK_MAX];
    int i = 0;
    for (; i < n; i++) {
      Value *p = force(I, t->u.tup.items[i]);
      if (p->kind != V_NUM) break;
      x[i] = s_first ? num_op(op, s->u.num, p->u.num)
                     : num_op(op, p->u.num, s->u.num);
    }
    if (i == n) return vec_block(n, x);
  }
  Value **it = val_array(n);
  for (int i = 0; i < n; i++) {
    Value *x = force(I, t->u.tup.items[i]);
    it[i] = s_first ? arith(I, op, s, x, pos) : arith(I, op, x, s, pos);
  }
  return val_tuple(n, it);
}

/* + - * / ^ on Reals, and elementwise on tuples (vectors): t+t, t-t,
   s*t, t*s, t/s. */
static Value *arith(Interp *I, TokKind op, Value *a, Value *b, Pos pos) {
  if (a->kind == V_NUM && b->kind == V_NUM) {
    double x = a->u.num, y = b->u.num;
    switch (op) {
    case T_PLUS: return val_num(x + y);
    case T_MINUS: return val_num(x - y);
    case T_STAR: return val_num(x * y);
    case T_SLASH: return val_num(x / y);
    case T_CARET: return val_num(pow(x, y));
    default: break;
    }
  }
  if (a->kind == V_TUPLE && b->kind == V_TUPLE &&
      (op == T_PLUS || op == T_MINUS))
    return vec_map2(I, op, a, b, pos);
  if (a->kind == V_NUM && b->kind == V_TUPLE && op == T_STAR)
    return vec_scale(I, op, b, a, 1, pos);
  if (a->kind == V_TUPLE && b->kind == V_NUM && (op == T_STAR || op == T_SLASH))
    return vec_scale(I, op, a, b, 0, pos);
  char ba[120], bb[120];
  val_brief(a, ba, sizeof ba);
  val_brief(b, bb, sizeof bb);
  qcs_error(pos, "'%s' cannot combine %s (%s) and %s (%s)", op_text(op),
            val_describe(a), ba, val_describe(b), bb);
}

static int values_equal(Interp *I, Value *a, Value *b, Pos pos) {
  eval_check(I, pos);
  a = force(I, a);
  b = force(I, b);
  if (a->kind == V_NIL || a->kind == V_CONS) {
    unsigned long long n = 0;
    while (a->kind == V_CONS && b->kind == V_CONS) {
      eval_check(I, pos);
      eval_list_count(I, pos, ++n);
      if (!values_equal(I, a->u.cons.head, b->u.cons.head, pos)) return 0;
      a = force(I, a->u.cons.tail);
      b = force(I, b->u.cons.tail);
    }
    return a->kind == V_NIL && b->kind == V_NIL;
  }
  if (a->kind != b->kind) return 0;
  switch (a->kind) {
  case V_NUM: return a->u.num == b->u.num;
  case V_BOOL: return a->u.b == b->u.b;
  case V_STR:
    return a->u.str.len == b->u.str.len &&
           !memcmp(eval_str_chars(I, a, pos), eval_str_chars(I, b, pos),
                   a->u.str.len);
  case V_TUPLE:
    if (a->u.tup.n != b->u.tup.n) return 0;
    for (int i = 0; i < a->u.tup.n; i++)
      if (!values_equal(I, a->u.tup.items[i], b->u.tup.items[i], pos)) return 0;
    return 1;
  case V_CON:
    if (a->u.con.con != b->u.con.con) return 0;
    for (int i = 0; i < a->u.con.n; i++)
      if (!values_equal(I, a->u.con.args[i], b->u.con.args[i], pos)) return 0;
    return 1;
  case V_FOREIGN: return a->u.foreign.ptr == b->u.foreign.ptr;
  default:
    qcs_error(pos, "functions cannot be compared");
  }
}

/* fmt names v's kind (%s), then shows it briefly (%s) */
static _Noreturn COLD void brief_error(Value *v, Pos pos, const char *fmt) {
  char b[120];
  val_brief(v, b, sizeof b);
  qcs_error(pos, fmt, val_describe(v), b);
}

static _Noreturn COLD void compare_error(Value *a, Value *b, Pos pos,
                                         TokKind op) {
  char ba[120], bb[120];
  val_brief(a, ba, sizeof ba);
  val_brief(b, bb, sizeof bb);
  qcs_error(pos, "'%s' compares two Reals or two Strings, not %s (%s) and %s "
            "(%s)", op_text(op), val_describe(a), ba, val_describe(b), bb);
}

static int compare(Interp *I, Value *a, Value *b, Pos pos, TokKind op) {
  a = force(I, a);
  b = force(I, b);
  if (a->kind == V_NUM && b->kind == V_NUM)
    return a->u.num < b->u.num ? -1 : a->u.num > b->u.num ? 1 : 0;
  if (a->kind == V_STR && b->kind == V_STR)
    return strcmp(eval_str_chars(I, a, pos), eval_str_chars(I, b, pos));
  compare_error(a, b, pos, op);
}

static Value *append(Interp *I, Value *a, Value *b, Pos pos);

static Value *bi_append_k(Interp *I, Value **args, Pos pos) {
  return append(I, args[0], args[1], pos);
}
static const Builtin append_builtin = {"++", 2, bi_append_k, NULL};
static Value *append_fn;

/* xs ++ ys, lazily: the tail is a delayed append. */
static Value *append(Interp *I, Value *a, Value *b, Pos pos) {
  a = force(I, a);
  if (a->kind == V_STR) {
    /* A rope node, not a copy: building a String by ++ on either side is
       linear. max-memory is checked as it was for a copy, with both sides
       and the joined String flat (as they are when the result is
       flattened while its parts are still in use), so no String can
       outgrow the limit. */
    Value *r = force(I, b);
    if (r->kind != V_STR)
      type_error(I, r, pos, "a String", "the right side of ++ on strings");
    size_t la = a->u.str.len, lb = r->u.str.len;
    if (lb >= SIZE_MAX / 4 - la)
      qcs_error(pos, "out of memory for a string of %zu + %zu bytes", la, lb);
    eval_alloc_check(I, pos, la + (r == a ? 0 : lb) + la + lb + 1);
    if (lb == 0) return a;
    if (la == 0) return r;
    return val_str_concat(a, r);
  }
  if (a->kind == V_NIL) {
    Value *r = force(I, b);
    if (r->kind != V_NIL && r->kind != V_CONS)
      qcs_error(pos, "'++' joins two lists or two Strings, not a list and %s",
                val_describe(r));
    return r;
  }
  if (a->kind != V_CONS)
    qcs_error(pos, "'++' joins two lists or two Strings, not %s",
              val_describe(a));
  Value **args = val_array(2);
  args[0] = a->u.cons.tail;
  args[1] = b;
  if (!append_fn) append_fn = eval_builtin_value(&append_builtin);
  return val_cons(a->u.cons.head, delay_apply(append_fn, 2, args));
}

static Value *index_list(Interp *I, Value *xs, Value *nv, Pos pos) {
  double n = force_num(I, nv, pos, "the index of !!");
  if (n < 0 || n != floor(n))
    qcs_error(pos, "'!!' needs a whole index >= 0, not %.17g", n);
  Value *v = force(I, xs);
  if (v->kind != V_CONS && v->kind != V_NIL)
    brief_error(v, pos, "'!!' indexes a list, not %s: %s");
  for (double i = 0; i < n; i++) {
    if (v->kind != V_CONS) break;
    eval_check(I, pos);
    eval_list_count(I, pos, (unsigned long long)i + 1);
    v = force(I, v->u.cons.tail);
  }
  if (v->kind != V_CONS)
    qcs_error(pos, "index %.17g is past the end of the list", n);
  return force(I, v->u.cons.head);
}

static Value *binop(Interp *I, Expr *e, Env *env) {
  TokKind op = e->u.bin.op;
  Pos pos = e->pos;
  switch (op) {
  case T_AND: case T_KAND:
    if (!force_bool(I, eval(I, e->u.bin.a, env), e->u.bin.a->pos,
                    "the left side of &&"))
      return I->v_false;
    return val_bool(I, force_bool(I, eval(I, e->u.bin.b, env), e->u.bin.b->pos,
                                  "the right side of &&"));
  case T_OR: case T_KOR:
    if (force_bool(I, eval(I, e->u.bin.a, env), e->u.bin.a->pos,
                   "the left side of ||"))
      return I->v_true;
    return val_bool(I, force_bool(I, eval(I, e->u.bin.b, env), e->u.bin.b->pos,
                                  "the right side of ||"));
  case T_COLON:
    return val_cons(delay(I, e->u.bin.a, env), delay(I, e->u.bin.b, env));
  case T_APPEND:
    return append(I, delay(I, e->u.bin.a, env), delay(I, e->u.bin.b, env), pos);
  case T_INDEX:
    return index_list(I, delay(I, e->u.bin.a, env), delay(I, e->u.bin.b, env),
                      pos);
  case T_EQ:
    return val_bool(I, values_equal(I, eval(I, e->u.bin.a, env),
                                    eval(I, e->u.bin.b, env), pos));
  case T_NE:
    return val_bool(I, !values_equal(I, eval(I, e->u.bin.a, env),
                                     eval(I, e->u.bin.b, env), pos));
  case T_LT: case T_LE: case T_GT: case T_GE: {
    Value *a = force(I, eval(I, e->u.bin.a, env));
    Value *b = force(I, eval(I, e->u.bin.b, env));
    if (a->kind == V_NUM && b->kind == V_NUM) { /* IEEE: NaN is unordered */
      double x = a->u.num, y = b->u.num;
      return val_bool(I, op == T_LT ? x < y : op == T_LE ? x <= y
                         : op == T_GT ? x > y : x >= y);
    }
    int c = compare(I, a, b, pos, op);
    int r = op == T_LT ? c < 0 : op == T_LE ? c <= 0 : op == T_GT ? c > 0 : c >= 0;
    return val_bool(I, r);
  }
  default: {
    Value *a = eval(I, e->u.bin.a, env);
    Value *b = eval(I, e->u.bin.b, env);
    return arith(I, op, a, b, pos);
  }
  }
}

/* ---- ranges ---- */

/* [from, from+step .. to]: element k is from + k*step (no drift); a Real
   range stops past to + step/2, as Haskell's does. */
/* args: from, step, to (NULL: no end), k, and the range's position (a
   foreign Pos, for max-list errors found when a later element is
   forced). Elements are pure arithmetic that cannot fail, so they are
   made RANGE_CHUNK at a time, evaluated, with one delayed application for
   the rest: a list consumed as it is made then costs two cells per
   element (its Real and its cons) instead of six. A chunk stops short of
   the element past max-list, so the limit's error comes when that element
   is forced, as before. */
#define RANGE_CHUNK 64
static Value *bi_range_k(Interp *I, Value **args, Pos pos) {
  double from = args[0]->u.num, step = args[1]->u.num;
  double k = args[3]->u.num;
  const Pos *rpos = args[4]->u.foreign.ptr;
  Value *first = NULL, **link = &first;
  for (int i = 0; i < RANGE_CHUNK; i++, k++) {
    double x = from + k * step;
    if (args[2]) {
      double to = args[2]->u.num;
      /* Every range, whole numbers too, runs while not past to + step/2,
         as Haskell's ranges of Doubles do ([1, 3 .. 8] ends at 9). */
      double limit = to + step / 2;
      if (step > 0 ? x > limit : x < limit) {
        *link = I->v_nil;
        return first;
      }
    }
    if (I->max_list && k + 1 > (double)I->max_list && i > 0) break;
    eval_list_count(I, *rpos, (unsigned long long)k + 1);
    Value *c = val_cons(val_num(x), NULL);
    *link = c;
    link = &c->u.cons.tail;
  }
  Value **next = val_array(5);
  next[0] = args[0];
  next[1] = args[1];
  next[2] = args[2];
  next[3] = val_num(k);
  next[4] = args[4];
  static const Builtin range_builtin = {"enumFromThenTo", 5, bi_range_k, NULL};
  static Value *range_fn;
  if (!range_fn) range_fn = eval_builtin_value(&range_builtin);
  (void)pos;
  *link = delay_apply(range_fn, 5, next);
  return first;
}

static Value *range(Interp *I, Expr *e, Env *env) {
  Pos pos = e->pos;
  double from = force_num(I, eval(I, e->u.range.from, env), pos,
                          "the start of a range");
  double step = 1;
  if (e->u.range.then)
    step = force_num(I, eval(I, e->u.range.then, env), pos,
                     "the second element of a range") - from;
  Value **args = val_array(5);
  args[0] = val_num(from);
  args[1] = val_num(step);
  if (e->u.range.to) {
    args[2] = val_num(force_num(I, eval(I, e->u.range.to, env), pos,
                                "the end of a range"));
    if (step == 0) qcs_error(pos, "a range with step 0 never ends");
  }
  if (!isfinite(from) || !isfinite(step))
    qcs_error(pos, "a range needs finite bounds");
  args[3] = val_num(0);
  Pos *rpos = GC_MALLOC(sizeof *rpos);
  *rpos = pos;
  args[4] = val_foreign(rpos, "position");
  return bi_range_k(I, args, pos);
}

/* ---- the evaluator ---- */

/* eval of e, an E_APP of a constructor (a global, resolved so) to all its
   arguments (the prelude's Union (Shift v a) (Shift v b)): what call()
   makes of it, with the value and its arguments in one block as known_con
   makes them, and no look-up or call() round. Out of line, to keep eval's
   own frame as it was for the other cases. */
static __attribute__((noinline)) Value *eval_con(Interp *I, Expr *e,
                                                 Env *env) {
  Expr *fe = e->u.app.fn;
  int n = e->u.app.n;
  Value *v = val_small(sizeof(Value) + sizeof(Value *) * (size_t)n);
  Value **cargs = (Value **)(v + 1);
  v->kind = V_CON;
  v->u.con.con = fe->u.var;
  v->u.con.n = n;
  v->u.con.args = cargs;
  v->u.con.pos = NULL;
  for (int i = 0; i < n; i++) cargs[i] = delay(I, e->u.app.args[i], env);
  if (e->pos.src) { /* as call() sets it */
    if (!e->pos.src->prelude) {
      v->u.con.pos = &e->pos;
    } else if (I->origin) {
      v->u.con.pos = I->origin;
    } else {
      Pos *p = val_small(sizeof *p);
      *p = eval_user_pos(I, e->pos);
      v->u.con.pos = p;
    }
  }
  return v;
}

/* eval of e, an E_TUPLE: a block of Reals if they are known, else the
   tuple and its items' array in one block (one allocation, one object for
   the collector), the items delayed. */
static __attribute__((noinline)) Value *eval_tuple(Interp *I, Expr *e,
                                                   Env *env) {
  double t[VEC_BLOCK_MAX];
  int n = known_vec(I, e, env, t);
  if (n > 0) return vec_block(n, t);
  n = e->u.tuple.n;
  Value *v = val_small(sizeof(Value) + sizeof(Value *) * (size_t)n);
  Value **items = (Value **)(v + 1);
  v->kind = V_TUPLE;
  v->u.tup.n = n;
  v->u.tup.items = items;
  for (int i = 0; i < n; i++) items[i] = delay(I, e->u.tuple.items[i], env);
  return v;
}

Value *eval(Interp *I, Expr *e, Env *env) {
  int depth = I->ntrace;
  const Pos *origin = I->origin;
  /* Trace slots: the first call made here, then the latest tail call. */
  int tslot = depth;
  Value *result;
  for (;;) {
    eval_check(I, e->pos);
    switch (e->kind) {
    case E_NUM:
      result = lit_num(e);
      goto done;
    case E_STR:
      result = lit_str(e);
      goto done;
    case E_BOOL:
      result = val_bool(I, e->u.b);
      goto done;
    case E_VAR:
      result = force(I, lookup(I, e, env));
      goto done;
    case E_WILD:
      qcs_error(e->pos, "'_' stands only in patterns");
    case E_APP: {
      Expr *fe = e->u.app.fn;
      int n = e->u.app.n;
      if (fe->kind == E_VAR && fe->u.vslot == RES_GLOBAL && n > 0 &&
          fe->u.var->con_arity == n) {
        result = eval_con(I, e, env);
        goto done;
      }
      /* a named function (the common case) without a nested eval: what
         eval's E_VAR does, less its step check, made here for the call */
      Value *f = e->u.app.fn->kind == E_VAR
                     ? force(I, lookup(I, e->u.app.fn, env))
                     : eval(I, e->u.app.fn, env);
      Value **args = val_small(sizeof(Value *) * (size_t)n);
      for (int i = 0; i < n; i++) args[i] = delay(I, e->u.app.args[i], env);
      /* A built-in that walks a list (sum, length, foldl) runs long in
         frames laid over the stack that eval, delay and lookup have just
         used: slots of those frames that it never writes keep what they
         held, often env, and the collector, which scans the stack
         conservatively, then keeps env's frame and, through it, a list
         bound there and being consumed (`let xs = [1 .. 10^6] in sum xs`
         held 131 MB for its 10^6 cells, 23 MB now). The same goes for the
         registers it saves. Only for those built-ins: for mod or sqrt the
         scrub would cost more than the call. */
      if (f->kind == V_FUNC && f->u.fn.kind == F_BUILTIN &&
          builtin_walks_list(f->u.fn.u.bi)) {
        scrub_near();
        CLEAR_CALLEE_SAVED();
      }
      Expr *body;
      Env *benv = NULL; /* its slot would still hold the last tail call's */
      if (call(I, f, n, args, e->pos, &e->pos, &result, &body, &benv,
               tslot)) {
        tslot = depth + 1;
        e = body;
        env = benv;
        continue;
      }
      goto done;
    }
    case E_LAMBDA:
      result = mk_fn(e->u.lambda, env);
      goto done;
    case E_LET: {
      Env *frame = env_new(env, e->u.let.n + 1);
      bind_defs(I, e->u.let.n, e->u.let.defs, frame);
      env = frame;
      e = e->u.let.body;
      continue;
    }
    case E_DEFBODY: {
      Env *benv;
      Expr *body = select_clause(I, e->u.def, env, NULL, e->pos, &benv);
      env = benv;
      e = body;
      continue;
    }
    case E_IF: {
      int kb;
      if (!known_bool(I, e->u.cond.c, env, &kb))
        kb = force_bool(I, eval(I, e->u.cond.c, env), e->u.cond.c->pos,
                        "the condition of if");
      e = kb ? e->u.cond.t : e->u.cond.f;
      continue;
    }
    case E_TUPLE:
      result = eval_tuple(I, e, env);
      goto done;
    case E_LIST: {
      result = I->v_nil;
      for (int i = e->u.tuple.n - 1; i >= 0; i--)
        result = val_cons(delay(I, e->u.tuple.items[i], env), result);
      goto done;
    }
    case E_RANGE:
      result = range(I, e, env);
      goto done;
    case E_BINOP:
      result = binop(I, e, env);
      goto done;
    case E_NEG: {
      Value *x = eval(I, e->u.neg, env);
      if (x->kind == V_NUM) {
        result = val_num(-x->u.num);
      } else if (x->kind == V_TUPLE) {
        result = vec_scale(I, T_STAR, x, val_num(-1), 1, e->pos);
      } else {
        brief_error(x, e->pos, "unary '-' needs a Real or a tuple, not %s (%s)");
      }
      goto done;
    }
    }
    qcs_error(e->pos, "internal error: unknown expression kind %d", e->kind);
  }
done:
  I->ntrace = depth;
  I->origin = origin;
  return result;
}

/* ---- brief descriptions ---- */

void val_brief(Value *v, char *buf, size_t size) {
  FILE *f = fmemopen(buf, size, "w");
  if (!f) {
    snprintf(buf, size, "?");
    return;
  }
  print_brief(f, v, 3);
  fclose(f);
  buf[size - 1] = 0;
}
