/* builtins.c: functions of the language written in C.
 *
 * The one place where the language reaches C code: each entry of the
 * BUILTINS table is (name, arity, C function, one-line doc). Arguments
 * arrive unevaluated; a builtin forces what it needs. Probes of the
 * geometry core register themselves through the same table (see
 * probes.c). */
#include "lang/builtins.h"

#include <gc.h>
#include <math.h>
#include <string.h>

#include "lang/eval.h"
#include "lang/print.h"

#define ARGNUM(i, what) force_num(I, args[i], pos, what)

/* ---- numbers ---- */

#define MATH1(cname, expr, doc)                                  \
  static double num_##cname(double x) { return expr; }           \
  static Value *bi_##cname(Interp *I, Value **args, Pos pos) {   \
    double x = ARGNUM(0, "the argument of " #cname);             \
    return val_num(num_##cname(x));                              \
  }
MATH1(sqrt, sqrt(x), "")
MATH1(sin, sin(x), "")
MATH1(cos, cos(x), "")
MATH1(tan, tan(x), "")
MATH1(asin, asin(x), "")
MATH1(acos, acos(x), "")
MATH1(atan, atan(x), "")
MATH1(exp, exp(x), "")
MATH1(log, log(x), "")
MATH1(floor, floor(x), "")
MATH1(ceiling, ceil(x), "")
MATH1(round, round(x), "")
MATH1(truncate, trunc(x), "")
MATH1(abs, fabs(x), "")
MATH1(fract, x - floor(x), "")

static double num_atan2(double y, double x);
static double num_min(double a, double b);
static double num_max(double a, double b);
static Value *bi_atan2(Interp *I, Value **args, Pos pos) {
  double y = ARGNUM(0, "y of atan2");
  return val_num(num_atan2(y, ARGNUM(1, "x of atan2")));
}
static Value *bi_min(Interp *I, Value **args, Pos pos) {
  double a = ARGNUM(0, "the first argument of min");
  double b = ARGNUM(1, "the second argument of min");
  return val_num(num_min(a, b));
}
static Value *bi_max(Interp *I, Value **args, Pos pos) {
  double a = ARGNUM(0, "the first argument of max");
  double b = ARGNUM(1, "the second argument of max");
  return val_num(num_max(a, b));
}
static double num_atan2(double y, double x) { return atan2(y, x); }
static double num_min(double a, double b) { return b < a ? b : a; }
static double num_max(double a, double b) { return b > a ? b : a; }

/* The functions above: defined for every Real (NaN and infinities give a
   Real), so the evaluator may apply them to known Reals at once. */
static const struct { BuiltinFn bi; double (*f1)(double); } num1[] = {
    {bi_sqrt, num_sqrt},   {bi_sin, num_sin},     {bi_cos, num_cos},
    {bi_tan, num_tan},     {bi_asin, num_asin},   {bi_acos, num_acos},
    {bi_atan, num_atan},   {bi_exp, num_exp},     {bi_log, num_log},
    {bi_floor, num_floor}, {bi_ceiling, num_ceiling}, {bi_round, num_round},
    {bi_truncate, num_truncate}, {bi_abs, num_abs}, {bi_fract, num_fract}};
static const struct { BuiltinFn bi; double (*f2)(double, double); } num2[] = {
    {bi_atan2, num_atan2}, {bi_min, num_min}, {bi_max, num_max}};

static const Builtin builtins[];
static const size_t nbuiltins;
/* Per entry of builtins[]: its Real function, or NULL (builtin_install). */
static double (*num1_of[128])(double);
static double (*num2_of[128])(double, double);

static void num_index(void) {
  for (size_t j = 0; j < nbuiltins && j < 128; j++) {
    for (size_t i = 0; i < sizeof num1 / sizeof *num1; i++)
      if (num1[i].bi == builtins[j].fn) num1_of[j] = num1[i].f1;
    for (size_t i = 0; i < sizeof num2 / sizeof *num2; i++)
      if (num2[i].bi == builtins[j].fn) num2_of[j] = num2[i].f2;
  }
}

int builtin_num(const Builtin *b, int n, const double *x, double *out) {
  if (b < builtins || b >= builtins + nbuiltins) return 0; /* not the table's */
  size_t j = (size_t)(b - builtins);
  if (j >= 128) return 0;
  if (n == 1 && num1_of[j]) {
    *out = num1_of[j](x[0]);
    return 1;
  }
  if (n == 2 && num2_of[j]) {
    *out = num2_of[j](x[0], x[1]);
    return 1;
  }
  return 0;
}

/* mod x y has the sign of y, like Haskell's mod. */
static Value *bi_mod(Interp *I, Value **args, Pos pos) {
  double x = ARGNUM(0, "the first argument of mod");
  double y = ARGNUM(1, "the second argument of mod");
  if (y == 0) qcs_error(pos, "mod by zero");
  double r = fmod(x, y);
  if (r != 0 && (r < 0) != (y < 0)) r += y;
  return val_num(r);
}
static Value *bi_pi(Interp *I, Value **args, Pos pos) { return val_num(M_PI); }
static Value *bi_isNaN(Interp *I, Value **args, Pos pos) {
  return val_bool(I, isnan(ARGNUM(0, "the argument of isNaN")));
}
static Value *bi_isInfinite(Interp *I, Value **args, Pos pos) {
  return val_bool(I, isinf(ARGNUM(0, "the argument of isInfinite")));
}

/* ---- booleans, strings, errors ---- */

static Value *bi_not(Interp *I, Value **args, Pos pos) {
  return val_bool(I, !force_bool(I, args[0], pos, "the argument of not"));
}
/* show v is v as it prints: a String comes back quoted, as in Haskell, so
   that show (1, "a") and show "a" agree. */
static Value *bi_show(Interp *I, Value **args, Pos pos) {
  Value *v = force(I, args[0]);
  if (v->kind == V_NUM) { /* as print_value writes it, without its stream */
    char buf[32];
    format_real_digits(buf, v->u.num, I->digits);
    return val_str(GC_STRDUP(buf));
  }
  return val_str(show_value(I, v));
}
/* showReal digits x: x rounded to digits significant digits (1..17), as
   :set digits prints it; digits 0 is the shortest form that reads back. */
static Value *bi_showReal(Interp *I, Value **args, Pos pos) {
  double n = ARGNUM(0, "the digits of showReal");
  double x = ARGNUM(1, "the number of showReal");
  if (!(n >= 0 && n <= 17) || n != floor(n))
    qcs_error(pos, "showReal needs a whole number of digits from 0 to 17, "
              "not %g", n);
  char buf[40];
  format_real_digits(buf, x, (int)n);
  return val_str(GC_STRDUP(buf));
}
/* error msg: said where the user's code called it, even when that was
   through the prelude (Scale's "factors > 0"); the text is the user's
   own, shown as it is. */
static Value *bi_error(Interp *I, Value **args, Pos pos) {
  const char *msg = force_str(I, args[0], pos, "the message of error");
  qcs_error_verbatim(eval_user_pos(I, pos), msg);
}
static Value *bi_seq(Interp *I, Value **args, Pos pos) {
  force(I, args[0]);
  return force(I, args[1]);
}

/* ---- vectors ---- */

static double dot3(const double *a, const double *b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
static Value *bi_dot(Interp *I, Value **args, Pos pos) {
  double a[3], b[3];
  force_vec3(I, args[0], pos, "the first argument of dot", a);
  force_vec3(I, args[1], pos, "the second argument of dot", b);
  return val_num(dot3(a, b));
}

int builtin_is_vec_num(const Builtin *b) { return b->fn == bi_dot; }

int builtin_vec_num(const Builtin *b, const double *x, int na, const double *y,
                    int nb, double *out) {
  if (b->fn != bi_dot || na != 3 || nb != 3) return 0;
  *out = dot3(x, y);
  return 1;
}
static Value *bi_cross(Interp *I, Value **args, Pos pos) {
  double a[3], b[3];
  force_vec3(I, args[0], pos, "the first argument of cross", a);
  force_vec3(I, args[1], pos, "the second argument of cross", b);
  return val_tuple3(a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                    a[0] * b[1] - a[1] * b[0]);
}
static Value *bi_norm(Interp *I, Value **args, Pos pos) {
  double a[3];
  force_vec3(I, args[0], pos, "the argument of norm", a);
  return val_num(hypot(hypot(a[0], a[1]), a[2]));
}

/* ---- lists: the strict loops (lazy ones are in the prelude) ---- */

static Value *list_next(Interp *I, Value *v, Pos pos, const char *what) {
  v = force(I, v);
  if (v->kind != V_CONS && v->kind != V_NIL)
    qcs_error(pos, "%s must be a list, not %s", what, val_describe(v));
  return v;
}

/* The list argument args[i], taken out of the array: a loop that walks a
   list must not leave its head reachable from there, or the whole list,
   produced lazily as the loop goes, stays alive until the loop ends
   (`length [1 .. 10000000]` would hold 10^7 cells). The array is this
   call's own (see builtins.h), the caller does not read it again. */
static Value *take_arg(Value **args, int i) {
  Value *v = args[i];
  args[i] = NULL;
  return v;
}

static Value *bi_length(Interp *I, Value **args, Pos pos) {
  unsigned long long n = 0;
  for (Value *v = list_next(I, take_arg(args, 0), pos, "the argument of length");
       v->kind == V_CONS; v = list_next(I, v->u.cons.tail, pos, "a list tail")) {
    eval_check(I, pos);
    eval_list_count(I, pos, ++n);
  }
  return val_num((double)n);
}
static Value *bi_sum(Interp *I, Value **args, Pos pos) {
  Value *acc = NULL;
  unsigned long long n = 0;
  for (Value *v = list_next(I, take_arg(args, 0), pos, "the argument of sum");
       v->kind == V_CONS; v = list_next(I, v->u.cons.tail, pos, "a list tail")) {
    eval_check(I, pos);
    eval_list_count(I, pos, ++n);
    Value *x = force(I, v->u.cons.head);
    if (!acc) {
      acc = x;
    } else if (acc->kind == V_NUM && x->kind == V_NUM) {
      acc = val_num(acc->u.num + x->u.num);
    } else if (acc->kind == V_TUPLE && x->kind == V_TUPLE &&
               acc->u.tup.n == x->u.tup.n) {
      Value **it = val_array(acc->u.tup.n);
      for (int i = 0; i < acc->u.tup.n; i++)
        it[i] = val_num(force_num(I, acc->u.tup.items[i], pos, "a sum element") +
                        force_num(I, x->u.tup.items[i], pos, "a sum element"));
      acc = val_tuple(acc->u.tup.n, it);
    } else {
      qcs_error(pos, "sum adds Reals or vectors of one size, not %s",
                val_describe(x));
    }
  }
  return acc ? acc : val_num(0);
}
static Value *bi_product(Interp *I, Value **args, Pos pos) {
  double p = 1;
  unsigned long long n = 0;
  for (Value *v = list_next(I, take_arg(args, 0), pos, "the argument of product");
       v->kind == V_CONS; v = list_next(I, v->u.cons.tail, pos, "a list tail")) {
    eval_check(I, pos);
    eval_list_count(I, pos, ++n);
    p *= force_num(I, v->u.cons.head, pos, "an element of product");
  }
  return val_num(p);
}
/* foldl f z xs, strict in the accumulator (so long lists need no stack). */
static Value *bi_foldl(Interp *I, Value **args, Pos pos) {
  Value *acc = args[1];
  unsigned long long n = 0;
  for (Value *v = list_next(I, take_arg(args, 2), pos, "the list of foldl");
       v->kind == V_CONS; v = list_next(I, v->u.cons.tail, pos, "a list tail")) {
    eval_list_count(I, pos, ++n);
    Value **a = val_array(2);
    a[0] = acc;
    a[1] = v->u.cons.head;
    acc = apply(I, args[0], 2, a, pos);
  }
  return force(I, acc);
}

int builtin_walks_list(const Builtin *b) {
  return b->fn == bi_length || b->fn == bi_sum || b->fn == bi_product ||
         b->fn == bi_foldl;
}

static Value *bi_concatMap(Interp *I, Value **args, Pos pos);
static const Builtin concatmap_builtin = {"concatMap", 2, bi_concatMap, NULL};
static Value *bi_append(Interp *I, Value **args, Pos pos);
static const Builtin append_builtin = {"++", 2, bi_append, NULL};

/* ys ++ rest where rest is lazy. */
static Value *bi_append(Interp *I, Value **args, Pos pos) {
  Value *a = list_next(I, args[0], pos, "the result of concatMap's function");
  if (a->kind == V_NIL) return force(I, args[1]);
  Value **next = val_array(2);
  next[0] = a->u.cons.tail;
  next[1] = args[1];
  static Value *append_fn;
  if (!append_fn) append_fn = eval_builtin_value(&append_builtin);
  return val_cons(a->u.cons.head, delay_apply(append_fn, 2, next));
}

/* concatMap f xs, lazily: list comprehensions are built on it. */
static Value *bi_concatMap(Interp *I, Value **args, Pos pos) {
  unsigned long long skipped = 0;
  for (Value *v = list_next(I, args[1], pos, "the list of a generator");;) {
    if (v->kind == V_NIL) return v;
    Value **a = val_array(1);
    a[0] = v->u.cons.head;
    Value *ys = list_next(I, apply(I, args[0], 1, a, pos), pos,
                          "the result of concatMap's function");
    if (ys->kind == V_NIL) { /* skip empty results without recursion */
      eval_check(I, pos);
      eval_list_count(I, pos, ++skipped);
      v = list_next(I, v->u.cons.tail, pos, "a list tail");
      continue;
    }
    Value **rest = val_array(2);
    rest[0] = args[0];
    rest[1] = v->u.cons.tail;
    static Value *concatmap_fn;
    if (!concatmap_fn) concatmap_fn = eval_builtin_value(&concatmap_builtin);
    Value *more = delay_apply(concatmap_fn, 2, rest);
    /* [y] ++ more is y : more: a comprehension's element (its result is
       one cons onto an evaluated []) costs no delayed append */
    if (ys->u.cons.tail->kind == V_NIL) return val_cons(ys->u.cons.head, more);
    Value **app = val_array(2);
    app[0] = ys;
    app[1] = more;
    return bi_append(I, app, pos);
  }
}

static const Builtin builtins[] = {
#define X(name, arity, fn, doc) {name, arity, fn, doc},
    BUILTINS(X)
#undef X
};
static const size_t nbuiltins = sizeof builtins / sizeof *builtins;

/* A table's doc is "WHAT; e.g. EXAMPLE": split at the last "; e.g. ". */
void builtin_define(Interp *I, const Builtin *b) {
  Sym *s = sym_intern(I, b->name, (int)strlen(b->name));
  s->global = b->arity == 0 ? b->fn(I, NULL, pos_none) : val_builtin(b);
  s->builtin = 1;
  s->doc = b->doc;
  s->example = NULL;
  if (!b->doc) return;
  const char *eg = NULL;
  for (const char *p = b->doc; (p = strstr(p, "; e.g. ")) != NULL; p++) eg = p;
  if (!eg) return;
  size_t n = (size_t)(eg - b->doc);
  char *doc = GC_MALLOC_ATOMIC(n + 1);
  memcpy(doc, b->doc, n);
  doc[n] = 0;
  s->doc = doc;
  s->example = eg + strlen("; e.g. ");
}

void builtins_install(Interp *I) {
  static int indexed;
  if (!indexed) num_index(), indexed = 1;
  for (size_t i = 0; i < sizeof builtins / sizeof *builtins; i++)
    builtin_define(I, &builtins[i]);
}

const Builtin *builtins_table(size_t *n) {
  *n = sizeof builtins / sizeof *builtins;
  return builtins;
}
