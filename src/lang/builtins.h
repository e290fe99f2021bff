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
 * the limits reach them. Same thread rules as the evaluator.
 *
 * The args array belongs to the call: the evaluator makes a fresh one per
 * application (eval.c's E_APP, a partial application's, apply()'s callers
 * here) and does not read it after the call, so a built-in that consumes a
 * long list takes it out of the array (builtins.c's take_arg) and the
 * consumed prefix can be collected. The exception is a delayed
 * application (delay_apply), whose array is the thunk's and is kept to
 * restore it after an error: the built-ins delayed that way (ranges, ++,
 * concatMap) leave their arrays alone. */
#ifndef QCS_BUILTINS_H
#define QCS_BUILTINS_H

#include <stddef.h>

#include "lang/value.h"

#define BUILTINS(X)                                                          \
  X("sqrt", 1, bi_sqrt, "sqrt x: square root; e.g. sqrt 16")                 \
  X("sin", 1, bi_sin, "sin x: sine of x radians; e.g. sin (pi / 2)")         \
  X("cos", 1, bi_cos, "cos x: cosine of x radians; e.g. cos pi")             \
  X("tan", 1, bi_tan, "tan x: tangent of x radians; e.g. tan (pi / 4)")      \
  X("asin", 1, bi_asin, "asin x: arcsine, in radians; e.g. asin 1")          \
  X("acos", 1, bi_acos, "acos x: arccosine, in radians; e.g. acos 0")        \
  X("atan", 1, bi_atan, "atan x: arctangent, in radians; e.g. atan 1")       \
  X("atan2", 2, bi_atan2,                                                    \
    "atan2 y x: angle of (x, y) in radians; e.g. atan2 1 0")                 \
  X("exp", 1, bi_exp, "exp x: e to the power x; e.g. exp 1")                 \
  X("log", 1, bi_log, "log x: natural logarithm; e.g. log (exp 2)")          \
  X("fract", 1, bi_fract, "fract x: x less its floor, in [0, 1); e.g. fract 2.25") \
  X("floor", 1, bi_floor, "floor x: the whole number at or below x; e.g. floor (-1.5)") \
  X("ceiling", 1, bi_ceiling, "ceiling x: the whole number at or above x; e.g. ceiling 1.2") \
  X("round", 1, bi_round, "round x: halves away from zero; e.g. round 2.5")  \
  X("truncate", 1, bi_truncate,                                              \
    "truncate x: towards zero; e.g. truncate (-1.7)")                        \
  X("abs", 1, bi_abs, "abs x: x without its sign; e.g. abs (-3)")            \
  X("min", 2, bi_min, "min a b: the smaller; e.g. min 2 3")                  \
  X("max", 2, bi_max, "max a b: the larger; e.g. max 2 3")                   \
  X("mod", 2, bi_mod,                                                        \
    "mod x y: remainder with the sign of y; e.g. mod (-1) 3")                \
  X("pi", 0, bi_pi, "pi: 3.141592653589793; e.g. pi / 2")                    \
  X("isNaN", 1, bi_isNaN, "isNaN x: is x not a number?; e.g. isNaN (0 / 0)") \
  X("isInfinite", 1, bi_isInfinite, "isInfinite x: is x +-infinity?; e.g. isInfinite (1 / 0)") \
  X("not", 1, bi_not, "not b: True for False, False for True; e.g. not True") \
  X("show", 1, bi_show, "show v: v printed as a String; e.g. show (1, \"a\")") \
  X("showReal", 2, bi_showReal,                                              \
    "showReal digits x: x to that many significant digits (0: shortest); e.g. showReal 3 pi") \
  X("error", 1, bi_error,                                                    \
    "error msg: stop with an error; e.g. if 2 < 0 then error \"negative\" else 2") \
  X("seq", 2, bi_seq, "seq a b: evaluate a, then give b; e.g. seq (1 + 1) 3") \
  X("dot", 2, bi_dot,                                                        \
    "dot u v: scalar product of 3-vectors; e.g. dot (1, 2, 3) (4, 5, 6)")    \
  X("cross", 2, bi_cross,                                                    \
    "cross u v: vector product of 3-vectors; e.g. cross (1, 0, 0) (0, 1, 0)") \
  X("norm", 1, bi_norm, "norm v: length of a 3-vector; e.g. norm (3, 4, 0)") \
  X("length", 1, bi_length, "length xs: the number of elements; e.g. length [1, 2, 3]") \
  X("sum", 1, bi_sum,                                                        \
    "sum xs: of Reals or of vectors; e.g. sum [(1, 0, 0), (0, 2, 0)]")       \
  X("product", 1, bi_product, "product xs: of Reals; e.g. product [1 .. 5]") \
  X("foldl", 3, bi_foldl,                                                    \
    "foldl f z xs: strict left fold; e.g. foldl (\\acc x -> acc * 10 + x) 0 [1, 2, 3]") \
  X("concatMap", 2, bi_concatMap,                                            \
    "concatMap f xs: f on each element, the results joined, lazily; e.g. concatMap (\\x -> [x, x]) [1, 2]") \
  X("%concatMap", 2, bi_concatMap, NULL)

void builtins_install(Interp *I);

/* If b is a Real function of n Reals defined everywhere (sqrt, floor,
   min, ...: no error, no loop for any Real), sets *out to its value at x
   and returns 1; else returns 0. */
int builtin_num(const Builtin *b, int n, const double *x, double *out);
/* Likewise for a Real function of two tuples of Reals, of na and nb items
   (dot of two 3-tuples): its value in *out and 1, or 0 if b is not such a
   function or the sizes are not the ones it takes. */
int builtin_vec_num(const Builtin *b, const double *x, int na, const double *y,
                    int nb, double *out);
/* Is b such a function (builtin_vec_num can succeed for it)? */
int builtin_is_vec_num(const Builtin *b);
/* Is b one of the built-ins that walk a whole list in one call (length,
   sum, product, foldl)? eval.c clears the stack and registers it runs
   over, so that a list it consumes is not kept by a stale pointer. */
int builtin_walks_list(const Builtin *b);
/* Install one built-in as a global (the layers above use it for theirs).
   Its doc reads "NAME ARGS: what it does; e.g. EXAMPLE": :doc and :info
   show both parts, and the suite runs the example. */
void builtin_define(Interp *I, const Builtin *b);
const Builtin *builtins_table(size_t *n);
#endif
