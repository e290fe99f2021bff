/* value.c: value constructors, symbols and environments. */
#include "lang/value.h"

#include <gc.h>
#include <stdlib.h>
#include <string.h>

atomic_int qcs_interrupted;

static size_t hash(const char *s, int len) {
  size_t h = 1469598103934665603u;
  for (int i = 0; i < len; i++) h = (h ^ (unsigned char)s[i]) * 1099511628211u;
  return h;
}

Sym *sym_intern(Interp *I, const char *name, int len) {
  if (I->nsyms * 2 >= I->symcap) {
    size_t cap = I->symcap ? I->symcap * 2 : 1024;
    Sym **tab = GC_MALLOC(sizeof(Sym *) * cap);
    for (size_t i = 0; i < I->symcap; i++)
      for (Sym *s = I->symtab[i], *nx; s; s = nx) {
        nx = s->next;
        size_t h = hash(s->name, (int)strlen(s->name)) & (cap - 1);
        s->next = tab[h];
        tab[h] = s;
      }
    I->symtab = tab;
    I->symcap = cap;
  }
  size_t h = hash(name, len) & (I->symcap - 1);
  for (Sym *s = I->symtab[h]; s; s = s->next)
    if ((int)strlen(s->name) == len && !memcmp(s->name, name, (size_t)len))
      return s;
  Sym *s = GC_MALLOC(sizeof *s);
  char *n = GC_MALLOC_ATOMIC((size_t)len + 1);
  memcpy(n, name, (size_t)len);
  n[len] = 0;
  s->name = n;
  s->con_arity = -1;
  s->next = I->symtab[h];
  I->symtab[h] = s;
  I->nsyms++;
  return s;
}

static void *cell_batch;  /* GC_malloc_many's list, linked by GC_NEXT */

Value *val_cell(void) {
  if (!cell_batch) {
    cell_batch = GC_malloc_many(sizeof(Value));
    if (!cell_batch) return GC_MALLOC(sizeof(Value));  /* out of memory: */
  }                                                    /* GC's own handler */
  Value *v = cell_batch;
  cell_batch = GC_NEXT(cell_batch);
  GC_NEXT(v) = NULL;
  return v;
}

/* Small blocks (arrays, frames, positions) the same way, one batch list
   per size in 16-byte steps: GC_MALLOC costs several times more per call
   (a thread-local lookup, its own locking), and the evaluator makes two or
   three such blocks per call it evaluates. */
#define SMALL_STEP 16
#define SMALL_MAX 256
static void *small_batch[SMALL_MAX / SMALL_STEP + 1];

void *val_small(size_t bytes) {
  if (bytes > SMALL_MAX) return GC_MALLOC(bytes);
  size_t c = (bytes + SMALL_STEP - 1) / SMALL_STEP;
  if (c == 0) c = 1;
  void *b = small_batch[c];
  if (!b) {
    b = GC_malloc_many(c * SMALL_STEP);
    if (!b) return GC_MALLOC(bytes);
  }
  small_batch[c] = GC_NEXT(b);
  GC_NEXT(b) = NULL;
  return b;
}

static Value *alloc(VKind k) {
  Value *v = val_cell();
  v->kind = (unsigned char)k;
  return v;
}

Value *val_num(double x) {
  Value *v = alloc(V_NUM);
  v->u.num = x;
  return v;
}

Value *val_bool(Interp *I, int b) { return b ? I->v_true : I->v_false; }

Value *val_str(const char *s) {
  Value *v = alloc(V_STR);
  v->u.str.s = s;
  v->u.str.len = strlen(s);
  return v;
}

/* Sides this short and flat are copied rather than linked: the copy is
   bounded, so ++ stays O(1), and a rope gets fewer, longer pieces. */
#define STR_COPY_MAX 32

Value *val_str_concat(Value *a, Value *b) {
  size_t la = a->u.str.len, lb = b->u.str.len;
  Value *v = alloc(V_STR);
  v->u.str.len = la + lb;
  if (la + lb <= STR_COPY_MAX && a->u.str.s && b->u.str.s) {
    char *s = GC_MALLOC_ATOMIC(la + lb + 1);
    if (s) {
      memcpy(s, a->u.str.s, la);
      memcpy(s + la, b->u.str.s, lb + 1);
      v->u.str.s = s;
      return v;
    }
  }
  v->u.str.left = a;
  v->u.str.right = b;
  return v;
}

/* Left to right through the tree, with the right sides still to copy on
   a stack of our own (a rope built by s ++ piece is as deep as it has
   pieces). Every piece has a byte, so the walk is O(len) even when parts
   are shared (s ++ s). */
const char *val_str_chars(Value *v) {
  if (v->u.str.s) return v->u.str.s;
  size_t len = v->u.str.len;
  char *buf = GC_MALLOC_ATOMIC(len + 1);
  if (!buf) return NULL;
  Value *local[64], **stack = local;
  size_t n = 0, cap = sizeof local / sizeof *local, at = 0;
  for (Value *x = v;;) {
    while (!x->u.str.s) {
      if (n == cap) {
        Value **grown = malloc(2 * cap * sizeof *grown);
        if (!grown) {
          if (stack != local) free(stack);
          return NULL;
        }
        memcpy(grown, stack, n * sizeof *grown);
        if (stack != local) free(stack);
        stack = grown;
        cap *= 2;
      }
      stack[n++] = x->u.str.right;
      x = x->u.str.left;
    }
    memcpy(buf + at, x->u.str.s, x->u.str.len);
    at += x->u.str.len;
    if (n == 0) break;
    x = stack[--n];
  }
  if (stack != local) free(stack);
  buf[len] = 0;
  v->u.str.s = buf;
  v->u.str.left = v->u.str.right = NULL;
  return buf;
}

Value **val_array(int n) {  /* batched, as val_small: a call's arguments */
  return val_small(sizeof(Value *) * (size_t)(n > 0 ? n : 1));
}

Value *val_tuple(int n, Value **items) {
  Value *v = alloc(V_TUPLE);
  v->u.tup.n = n;
  v->u.tup.items = items;
  return v;
}

Value *val_tuple3(double x, double y, double z) {
  Value **it = val_array(3);
  it[0] = val_num(x);
  it[1] = val_num(y);
  it[2] = val_num(z);
  return val_tuple(3, it);
}

Value *val_cons(Value *head, Value *tail) {
  Value *v = alloc(V_CONS);
  v->u.cons.head = head;
  v->u.cons.tail = tail;
  return v;
}

Value *val_nil(Interp *I) { return I->v_nil; }

Value *val_con(Sym *con, int n, Value **args) {
  Value *v = alloc(V_CON);
  v->u.con.con = con;
  v->u.con.n = n;
  v->u.con.args = args;
  return v;
}

Value *val_builtin(const Builtin *b) {
  Value *v = alloc(V_FUNC);
  v->u.fn.kind = F_BUILTIN;
  v->u.fn.arity = b->arity;
  v->u.fn.u.bi = b;
  return v;
}

Value *val_foreign(void *ptr, const char *tag) {
  Value *v = alloc(V_FOREIGN);
  v->u.foreign.ptr = ptr;
  v->u.foreign.tag = tag;
  return v;
}

/* The frame and its first arrays are one block (most frames never grow). */
Env *env_new(Env *up, int cap) {
  if (cap < 1) cap = 1;
  Env *e = val_small(sizeof *e + (sizeof(Sym *) + sizeof(Value *)) * (size_t)cap);
  e->up = up;
  e->cap = cap;
  e->names = (Sym **)(e + 1);
  e->vals = (Value **)(e->names + cap);
  return e;
}

void env_bind(Env *env, Sym *name, Value *v) {
  if (env->n == env->cap) {
    int cap = env->cap * 2;
    Sym **names = GC_MALLOC(sizeof(Sym *) * (size_t)cap);
    Value **vals = GC_MALLOC(sizeof(Value *) * (size_t)cap);
    memcpy(names, env->names, sizeof(Sym *) * (size_t)env->n);
    memcpy(vals, env->vals, sizeof(Value *) * (size_t)env->n);
    env->names = names;
    env->vals = vals;
    env->cap = cap;
  }
  env->names[env->n] = name;
  env->vals[env->n] = v;
  env->n++;
}

const char *val_describe(Value *v) {
  switch (v->kind) {
  case V_NUM: return "a Real";
  case V_BOOL: return "a Bool";
  case V_STR: return "a String";
  case V_TUPLE: return v->u.tup.n == 3 ? "a 3-tuple" : "a tuple";
  case V_NIL: case V_CONS: return "a list";
  case V_CON: return "a constructor value";
  case V_FUNC: case V_PAP: return "a function";
  case V_FOREIGN: return v->u.foreign.tag;
  default: return "an unevaluated value";
  }
}
