/* builtins.h: the table of functions written in C (see builtins.c).
 * Adding one is one line here and its function in builtins.c.
 *
 * Each is installed as a global Sym holding a V_FUNC of kind F_BUILTIN,
 * before the prelude loads (so the prelude may use and wrap them). A
 * built-in gets its arguments unforced (thunks) and forces what it needs
 * with the checked helpers of eval.h, which name the argument in their
 * errors; it raises errors with qcs_error and returns a Value in weak-head
 * normal form or a delayed application. Built-ins that loop over a list
 * call eval_check and eval_list_count per element, so the interrupt and
 * the limits reach them. Same thread rules as the evaluator. */
#ifndef QCS_BUILTINS_H
#define QCS_BUILTINS_H

#include <stddef.h>

#include "lang/value.h"

#define BUILTINS(X)                                                          \
  X("sqrt", 1, bi_sqrt, "sqrt x: square root")                               \
  X("sin", 1, bi_sin, "sin x: sine of x radians")                            \
  X("cos", 1, bi_cos, "cos x: cosine of x radians")                          \
  X("tan", 1, bi_tan, "tan x: tangent of x radians")                         \
  X("asin", 1, bi_asin, "asin x: in radians")                                \
  X("acos", 1, bi_acos, "acos x: in radians")                                \
  X("atan", 1, bi_atan, "atan x: in radians")                                \
  X("atan2", 2, bi_atan2, "atan2 y x: angle of (x, y) in radians")           \
  X("exp", 1, bi_exp, "exp x")                                               \
  X("log", 1, bi_log, "log x: natural logarithm")                            \
  X("floor", 1, bi_floor, "floor x")                                         \
  X("ceiling", 1, bi_ceiling, "ceiling x")                                   \
  X("round", 1, bi_round, "round x: halves away from zero")                  \
  X("truncate", 1, bi_truncate, "truncate x: towards zero")                  \
  X("abs", 1, bi_abs, "abs x")                                               \
  X("min", 2, bi_min, "min a b")                                             \
  X("max", 2, bi_max, "max a b")                                             \
  X("mod", 2, bi_mod, "mod x y: remainder with the sign of y")               \
  X("pi", 0, bi_pi, "pi: 3.141592653589793")                                 \
  X("isNaN", 1, bi_isNaN, "isNaN x")                                         \
  X("isInfinite", 1, bi_isInfinite, "isInfinite x")                          \
  X("not", 1, bi_not, "not b")                                               \
  X("show", 1, bi_show, "show v: v printed as a String")                     \
  X("showReal", 2, bi_showReal,                                              \
    "showReal digits x: x to that many significant digits (0: shortest)")     \
  X("error", 1, bi_error, "error msg: stop with an error")                   \
  X("seq", 2, bi_seq, "seq a b: evaluate a, then give b")                    \
  X("dot", 2, bi_dot, "dot u v: scalar product of 3-vectors")                \
  X("cross", 2, bi_cross, "cross u v: vector product of 3-vectors")          \
  X("norm", 1, bi_norm, "norm v: length of a 3-vector")                      \
  X("length", 1, bi_length, "length xs")                                     \
  X("sum", 1, bi_sum, "sum xs: of Reals or of vectors")                      \
  X("product", 1, bi_product, "product xs")                                  \
  X("foldl", 3, bi_foldl, "foldl f z xs: strict left fold")                  \
  X("concatMap", 2, bi_concatMap, "concatMap f xs: lazy")                    \
  X("%concatMap", 2, bi_concatMap, NULL)

void builtins_install(Interp *I);
const Builtin *builtins_table(size_t *n);
#endif
