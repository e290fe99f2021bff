/* limits.h: the errors of the resource limits, and the stack check.
 *
 * Owns nothing: the limits themselves are fields of the Interp (see
 * interp.h for their names, defaults and how they are set). This is the
 * part of them the parser needs as well as the evaluator, so that the
 * parser depends on the interpreter's state only through these reads:
 * the stack base and limit, and the top-level item's position for an error
 * found where no position is at hand.
 *
 * Failure modes: every function here raises the error (qcs_error, see
 * error.h), never returns it. The message says which limit was hit and
 * how to raise it, the same for every limit.
 *
 * Threads: as the Interp: one thread at a time. The stack check compares
 * the address of a local with I->stack_base, so it is only meaningful on
 * the thread the Interp's stack base was taken from. */
#ifndef QCS_LIMITS_H
#define QCS_LIMITS_H

#include "lang/value.h"

/* An error for a resource limit hit (see interp.h): the message, then
   "(limit NAME; raise it with :set NAME N or --NAME N)". Without a
   position at hand, the top-level item's is used. */
_Noreturn void eval_limit_error(Interp *I, Pos pos, const char *limit,
                                const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
/* "WHAT more than SIZE of stackAFTER" as a max-stack error. */
_Noreturn void eval_stack_error(Interp *I, Pos pos, const char *what,
                                const char *after);
/* The stack check alone (the parser and the static checker use it). */
static inline void eval_stack_check(Interp *I, Pos pos, const char *what) {
  char probe;
  if ((size_t)(I->stack_base - &probe) > I->stack_limit)
    eval_stack_error(I, pos, what, "");
}
#endif
