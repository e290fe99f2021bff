/* print.c: printing values. See print.h. */
#define _GNU_SOURCE /* fopencookie */
#include "lang/print.h"

#include <float.h>
#include <gc.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lang/eval.h"

static void layout_real(char *buf, const char *tmp);

void format_real(char *buf, double x) { format_real_digits(buf, x, 0); }

void format_real_digits(char *buf, double x, int digits) {
  if (isnan(x)) {
    strcpy(buf, "NaN");
    return;
  }
  if (isinf(x)) {
    strcpy(buf, x > 0 ? "Infinity" : "-Infinity");
    return;
  }
  if (x == 0) {
    strcpy(buf, signbit(x) ? "-0" : "0");
    return;
  }
  /* A whole number below 2^53 reads back from its own digits and from no
     fewer (rounded to fewer, it is another whole number, held exactly),
     and prints without an exponent: written out directly, it is what the
     search below would find, without its snprintf and strtod calls. */
  if (digits <= 0 && fabs(x) < 9007199254740992.0 && x == floor(x)) {
    char rev[20];
    int k = 0;
    unsigned long long u = (unsigned long long)fabs(x);
    do {
      rev[k++] = (char)('0' + u % 10);
      u /= 10;
    } while (u);
    if (x < 0) *buf++ = '-';
    while (k) *buf++ = rev[--k];
    *buf = 0;
    return;
  }
  /* The fewest significant digits that read back as x (or, with digits
     set, x rounded to that many: a value within rounding of a round
     number shows as that number) ... */
  char tmp[40];
  if (digits > 0) {
    snprintf(tmp, sizeof tmp, "%.*e", (digits > 17 ? 17 : digits) - 1, x);
  } else {
    int prec;
    for (prec = 1; prec <= 17; prec++) {
      snprintf(tmp, sizeof tmp, "%.*e", prec - 1, x);
      if (strtod(tmp, NULL) == x) break;
    }
  }
  layout_real(buf, tmp);
}

/* tmp ("-d.ddde+NN") laid out as JavaScript does, trailing zeros gone. */
static void layout_real(char *buf, const char *tmp) {
  /* ... laid out as JavaScript does: plain for 1e-6 <= |x| < 1e21,
     otherwise with an exponent ("1e-12", "1.5e300"). */
  char digits[20];
  int nd = 0;
  const char *p = tmp;
  int neg = *p == '-';
  if (neg) p++;
  for (; *p && *p != 'e'; p++)
    if (*p >= '0' && *p <= '9') digits[nd++] = *p;
  int exp10 = atoi(p + 1);
  while (nd > 1 && digits[nd - 1] == '0') nd--;
  digits[nd] = 0;
  char *o = buf;
  if (neg) *o++ = '-';
  if (exp10 >= 21 || exp10 < -6) {
    *o++ = digits[0];
    if (nd > 1) {
      *o++ = '.';
      memcpy(o, digits + 1, (size_t)nd - 1);
      o += nd - 1;
    }
    sprintf(o, "e%d", exp10);
  } else if (exp10 >= 0) {
    for (int i = 0; i <= exp10 || i < nd; i++) {
      if (i == exp10 + 1) *o++ = '.';
      *o++ = i < nd ? digits[i] : '0';
    }
    *o = 0;
  } else {
    *o++ = '0';
    *o++ = '.';
    for (int i = 0; i < -exp10 - 1; i++) *o++ = '0';
    memcpy(o, digits, (size_t)nd);
    o[nd] = 0;
  }
}

static void print_str(FILE *out, const char *s) {
  fputc('"', out);
  for (; *s; s++) {
    switch (*s) {
    case '"': fputs("\\\"", out); break;
    case '\\': fputs("\\\\", out); break;
    case '\n': fputs("\\n", out); break;
    case '\t': fputs("\\t", out); break;
    default: fputc(*s, out);
    }
  }
  fputc('"', out);
}

static int needs_parens(Value *v) {
  return (v->kind == V_CON && v->u.con.n > 0) ||
         (v->kind == V_NUM && (signbit(v->u.num) || isnan(v->u.num)));
}

static void print_fn(FILE *out, Value *v) {
  if (v->kind == V_PAP) {
    fputs("<function ", out);
    Value *f = v->u.pap.fn;
    if (f->kind == V_FUNC && f->u.fn.kind == F_DEF && f->u.fn.u.def->name)
      fprintf(out, "%s", f->u.fn.u.def->name->name);
    else if (f->kind == V_FUNC && f->u.fn.kind == F_BUILTIN)
      fprintf(out, "%s", f->u.fn.u.bi->name);
    else if (f->kind == V_FUNC && f->u.fn.kind == F_CON)
      fprintf(out, "%s", f->u.fn.u.con->name);
    else
      fputs("lambda", out);
    fprintf(out, " applied to %d of %d>", v->u.pap.n,
            f->kind == V_FUNC ? f->u.fn.arity : 0);
    return;
  }
  switch (v->u.fn.kind) {
  case F_DEF:
    fprintf(out, "<function %s/%d>",
            v->u.fn.u.def->name ? v->u.fn.u.def->name->name : "lambda",
            v->u.fn.arity);
    break;
  case F_BUILTIN:
    fprintf(out, "<built-in %s/%d>", v->u.fn.u.bi->name, v->u.fn.arity);
    break;
  case F_CON:
    fprintf(out, "<constructor %s/%d>", v->u.fn.u.con->name, v->u.fn.arity);
    break;
  }
}

/* show's stream writes into a buffer in the values' heap, counted
   against max-memory: an error while showing leaves nothing to free but
   the small FILE. */
typedef struct ShowBuf {
  FILE *f;
  char *buf;
  size_t len, cap, max;
  int over;  /* a write would have passed max */
} ShowBuf;
static _Thread_local ShowBuf *cur_show;

static ssize_t show_write(void *cookie, const char *data, size_t n) {
  ShowBuf *b = cookie;
  if (b->max && b->len + n + 1 > b->max) {
    b->over = 1;
    return 0;
  }
  if (b->len + n + 1 > b->cap) {
    size_t cap = b->cap * 2;
    while (cap < b->len + n + 1) cap *= 2;
    char *nb = GC_MALLOC_ATOMIC(cap);
    if (!nb) {
      b->over = 1;
      return 0;
    }
    memcpy(nb, b->buf, b->len);
    b->buf = nb;
    b->cap = cap;
  }
  memcpy(b->buf + b->len, data, n);
  b->len += n;
  return (ssize_t)n;
}

static _Noreturn void show_too_big(Interp *I) {
  char sz[32];
  interp_format_size(sz, sizeof sz, I->max_memory);
  eval_limit_error(I, pos_none, "max-memory", "show: the text would use more "
                   "than %s of memory", sz);
}

/* With digits set, a number within rounding of 0 beside larger ones of
   the same tuple or list (a gradient's 2e-31 beside 7.5, a plane offset's
   2.3e-16 beside 1) shows as 0: the scale is the largest magnitude of a
   tuple, or of a list of at most ZERO_SCAN numbers, all finite; -1 for
   anything else. print_value has forced the value already. */
#define ZERO_SCAN 4096
static void print_rec(Interp *I, FILE *out, Value *v, int parens);
static double zero_scale(Interp *I, Value *v) {
  if (I->digits <= 0) return -1;
  double scale = 0;
  if (v->kind == V_TUPLE) {
    for (int i = 0; i < v->u.tup.n; i++) {
      Value *x = force(I, v->u.tup.items[i]);
      if (x->kind != V_NUM || !isfinite(x->u.num)) return -1;
      scale = fmax(scale, fabs(x->u.num));
    }
    return scale;
  }
  for (int n = 0; v->kind == V_CONS; n++) {
    Value *x = force(I, v->u.cons.head);
    if (n == ZERO_SCAN || x->kind != V_NUM || !isfinite(x->u.num)) return -1;
    scale = fmax(scale, fabs(x->u.num));
    v = force(I, v->u.cons.tail);
  }
  return v->kind == V_NIL ? scale : -1;
}

static void print_elem(Interp *I, FILE *out, Value *x, double scale) {
  if (scale > 0 && fabs(force(I, x)->u.num) <= 8 * DBL_EPSILON * scale)
    fputs("0", out);
  else
    print_rec(I, out, x, 0);
}

static void print_rec(Interp *I, FILE *out, Value *v, int parens) {
  eval_check(I, pos_none);
  if (cur_show && out == cur_show->f && cur_show->over) show_too_big(I);
  v = force(I, v);
  char buf[32];
  if (parens && needs_parens(v)) {
    fputc('(', out);
    print_rec(I, out, v, 0);
    fputc(')', out);
    return;
  }
  switch (v->kind) {
  case V_NUM:
    format_real_digits(buf, v->u.num, I->digits);
    fputs(buf, out);
    break;
  case V_BOOL:
    fputs(v->u.b ? "True" : "False", out);
    break;
  case V_STR:
    print_str(out, eval_str_chars(I, v, pos_none));
    break;
  case V_TUPLE: {
    double scale = zero_scale(I, v);
    fputc('(', out);
    for (int i = 0; i < v->u.tup.n; i++) {
      if (i) fputs(", ", out);
      print_elem(I, out, v->u.tup.items[i], scale);
    }
    fputc(')', out);
    break;
  }
  case V_NIL:
  case V_CONS: {
    double scale = zero_scale(I, v);
    fputc('[', out);
    unsigned long long n = 0;
    for (int first = 1; v->kind == V_CONS; first = 0) {
      eval_list_count(I, pos_none, ++n);
      if (!first) fputs(", ", out);
      print_elem(I, out, v->u.cons.head, scale);
      v = force(I, v->u.cons.tail);
    }
    if (v->kind != V_NIL) {
      fputs(" : ", out);
      print_rec(I, out, v, 0);
    }
    fputc(']', out);
    break;
  }
  case V_CON:
    fputs(v->u.con.con->name, out);
    for (int i = 0; i < v->u.con.n; i++) {
      fputc(' ', out);
      print_rec(I, out, v->u.con.args[i], 1);
    }
    break;
  case V_FUNC:
  case V_PAP:
    print_fn(out, v);
    break;
  case V_FOREIGN:
    fprintf(out, "<%s>", v->u.foreign.tag);
    break;
  default:
    fputs("<?>", out);
  }
}

/* Forces v completely, visiting at most *budget nodes; returns 0 when the
   budget ran out first (a long or infinite value). */
static int force_deep(Interp *I, Value *v, long *budget) {
  unsigned long long n = 0;
  for (;;) {
    if (--*budget < 0) return 0;
    eval_check(I, pos_none);
    v = force(I, v);
    switch (v->kind) {
    case V_TUPLE:
      for (int i = 0; i < v->u.tup.n; i++)
        if (!force_deep(I, v->u.tup.items[i], budget)) return 0;
      return 1;
    case V_CON:
      for (int i = 0; i < v->u.con.n; i++)
        if (!force_deep(I, v->u.con.args[i], budget)) return 0;
      return 1;
    case V_CONS:
      eval_list_count(I, pos_none, ++n);
      if (!force_deep(I, v->u.cons.head, budget)) return 0;
      v = v->u.cons.tail; /* the spine iteratively */
      continue;
    default:
      return 1;
    }
  }
}

/* A value is forced before any of it is printed, so that an error inside
   it leaves no half-printed line; only a value too long to force first
   (an infinite list, say) is printed as it is computed. */
void print_value(Interp *I, FILE *out, Value *v) {
  long budget = 1L << 20;
  force_deep(I, v, &budget);
  print_rec(I, out, v, 0);
}

const char *show_value(Interp *I, Value *v) {
  ShowBuf *b = GC_MALLOC(sizeof *b);
  b->cap = 64;
  b->buf = GC_MALLOC_ATOMIC(b->cap);
  b->max = I->max_memory;
  cookie_io_functions_t io = {NULL, show_write, NULL, NULL};
  b->f = fopencookie(b, "w", io);
  if (!b->f) qcs_error(pos_none, "show: cannot open a stream");
  ShowBuf *outer = cur_show; /* show inside show */
  cur_show = b;
  print_value(I, b->f, v);
  int bad = fflush(b->f) != 0 || b->over;
  fclose(b->f);
  cur_show = outer;
  if (bad) show_too_big(I);
  b->buf[b->len] = 0;
  return b->buf;
}

void print_brief(FILE *out, Value *v, int depth) {
  char buf[32];
  switch (v->kind) {
  case V_NUM:
    format_real(buf, v->u.num);
    fputs(buf, out);
    break;
  case V_BOOL:
    fputs(v->u.b ? "True" : "False", out);
    break;
  case V_STR: {
    /* nothing to check the memory against here: a rope too big to
       flatten shows as "..." */
    const char *s = val_str_chars(v);
    if (s) print_str(out, s);
    else fputs("\"...\"", out);
    break;
  }
  case V_TUPLE:
    fputc('(', out);
    for (int i = 0; i < v->u.tup.n; i++) {
      if (i) fputs(", ", out);
      if (depth > 0) print_brief(out, v->u.tup.items[i], depth - 1);
      else fputs("...", out);
    }
    fputc(')', out);
    break;
  case V_NIL:
    fputs("[]", out);
    break;
  case V_CONS: {
    fputc('[', out);
    int i = 0;
    for (; v->kind == V_CONS && i < 4; i++) {
      if (i) fputs(", ", out);
      if (depth > 0) print_brief(out, v->u.cons.head, depth - 1);
      else fputs("...", out);
      v = v->u.cons.tail;
    }
    if (v->kind != V_NIL) fputs(i ? ", ..." : "...", out);
    fputc(']', out);
    break;
  }
  case V_CON:
    fputs(v->u.con.con->name, out);
    for (int i = 0; i < v->u.con.n; i++) {
      fputc(' ', out);
      Value *a = v->u.con.args[i];
      if (depth <= 0) {
        fputs("...", out);
        continue;
      }
      int p = needs_parens(a);
      if (p) fputc('(', out);
      print_brief(out, a, depth - 1);
      if (p) fputc(')', out);
    }
    break;
  case V_FUNC:
  case V_PAP:
    print_fn(out, v);
    break;
  case V_FOREIGN:
    fprintf(out, "<%s>", v->u.foreign.tag);
    break;
  default:
    fputs("...", out);
  }
}
