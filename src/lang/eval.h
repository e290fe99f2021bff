/* eval.h: the lazy evaluator.
 *
 * eval() reduces an expression to weak-head normal form; force() does the
 * same for a value that may be a thunk, updating the thunk in place (call
 * by need). Arguments and bindings are delayed, never evaluated before they
 * are needed. Tail calls (function bodies, if, let, guards) reuse the C
 * frame, so loops written as recursion run in constant C stack; deep
 * non-tail recursion is stopped with "recursion too deep" before the C
 * stack runs out. Errors are raised with qcs_error (see error.h).
 *
 * Variables: a local is read from the frame and slot resolve.c recorded
 * in the E_VAR (its name there is checked; one it never resolved is found
 * by scanning the Env chain); a global from its Sym at the time of the
 * lookup: the prelude's own code sees Sym.prelude_value, everything else
 * Sym.global, so REPL redefinitions and --set overrides take effect.
 *
 * Invariants: a thunk being forced is a V_BLACKHOLE and has an entry in
 * I->forcing (its contents before, for eval_restore); forcing a blackhole
 * is a cycle, reported as "this value depends on itself" at the first
 * thunk of the cycle with a position in the user's code. After any error,
 * the handler must call eval_restore (interp.c's do), or thunks the error
 * interrupted stay blackholes and later report false cycles. I->ntrace is
 * the call depth, restored by every return.
 *
 * Threads: one evaluation at a time per Interp, on the thread whose stack
 * base it was given (the stack check measures that thread's stack); values
 * are allocated by that thread only (val_cell). Render workers never call
 * in here. */
#ifndef QCS_EVAL_H
#define QCS_EVAL_H

#include "lang/interp.h"
#include "lang/limits.h"
#include "lang/value.h"

Value *eval(Interp *I, Expr *e, Env *env);
Value *force(Interp *I, Value *v);
/* A value for e in env without evaluating it (a thunk unless trivial). */
Value *delay(Interp *I, Expr *e, Env *env);
/* f applied to n arguments, reduced to weak-head normal form. */
Value *apply(Interp *I, Value *f, int n, Value **args, Pos pos);
/* The built-in b as a function value made once, for C code that delays
   calls to it per element (an uncollectable cell: keep it in a static). */
Value *eval_builtin_value(const Builtin *b);
/* A lazy application: a thunk that computes f args when forced. */
Value *delay_apply(Value *f, int n, Value **args);

/* Forcing helpers that check the kind, with an error at pos naming what
   was expected (`what` is e.g. "the radius of Rounded"). */
double force_num(Interp *I, Value *v, Pos pos, const char *what);
int force_bool(Interp *I, Value *v, Pos pos, const char *what);
const char *force_str(Interp *I, Value *v, Pos pos, const char *what);
/* The bytes of the String v (already forced), NUL-terminated: a rope made
   by ++ is flattened here, once, within max-memory (its error at pos). */
const char *eval_str_chars(Interp *I, Value *v, Pos pos);
/* A 3-tuple of Reals. */
void force_vec3(Interp *I, Value *v, Pos pos, const char *what, double out[3]);

/* A global's value as installed from its definition. */
Value *eval_global_value(Interp *I, Def *d);
/* The constructor `s` as a value (a function of its arity, or itself). */
Value *eval_con_value(Interp *I, Sym *s);

/* After an error: put back every thunk that was being forced (above
   nforcing entries), so a later evaluation retries it instead of seeing a
   false "depends on itself". */
void eval_restore(Interp *I, int nforcing);

/* Recursion-depth, step and interrupt checks (also used by builtins that
   loop). The common case (nothing to report, not the 4096th step) is
   inline; eval_check_slow does the rest. */
void eval_check_slow(Interp *I, Pos pos);
static inline void eval_check(Interp *I, Pos pos) {
  char probe;
  ++I->steps;
  if (atomic_load_explicit(&qcs_interrupted, memory_order_relaxed) ||
      (size_t)(I->stack_base - &probe) > I->stack_limit ||
      (I->steps > I->max_steps && I->max_steps) || ++I->memcheck >= 4096)
    eval_check_slow(I, pos);
}

/* Before one large allocation (a String): bytes more would pass
   max-memory -> the limit's error. */
void eval_alloc_check(Interp *I, Pos pos, size_t bytes);
/* Counts element n (1-based) of a list against max-list. */
_Noreturn void eval_list_limit(Interp *I, Pos pos, unsigned long long n);
static inline void eval_list_count(Interp *I, Pos pos, unsigned long long n) {
  if (n > I->max_list && I->max_list) eval_list_limit(I, pos, n);
}

/* For a position inside the prelude, the innermost call from the user's
   code in the call trace (an error raised by the prelude is reported
   where the user called it); other positions are returned as they are. */
Pos eval_user_pos(Interp *I, Pos pos);

/* The brief, non-forcing description of a value for error messages:
   thunks show as "...", long lists and deep trees are cut. */
void val_brief(Value *v, char *buf, size_t size);
#endif
