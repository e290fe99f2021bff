/* error.c: positioned errors, the handler chain, and error display. */
#include "lang/error.h"

#include <gc.h>
#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define QCS_ASAN 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__) && !defined(QCS_ASAN)
#define QCS_ASAN 1
#endif
#ifdef QCS_ASAN
#include <sanitizer/asan_interface.h>
#endif
#include <pthread.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

const Pos pos_none = {NULL, 0, 0};

static _Thread_local ErrFrame *err_top;
static _Thread_local ErrCleanup *err_cleanups;
static _Thread_local ErrInfo err_current;

ErrInfo *err_info(void) { return &err_current; }

void err_push(ErrFrame *f) {
  f->prev = err_top;
  f->cleanups = err_cleanups;
  err_top = f;
}

void err_pop(ErrFrame *f) {
  if (err_top == f) err_top = f->prev;
}

void err_defer(ErrCleanup *c, void (*fn)(void *arg), void *arg) {
  c->fn = fn;
  c->arg = arg;
  c->prev = err_cleanups;
  err_cleanups = c;
}

void err_release(ErrCleanup *c) {
  /* Innermost first; a cleanup already run by an unwinding error is gone. */
  if (err_cleanups == c) err_cleanups = c->prev;
}

/* Run the cleanups registered since the frame was set, innermost first,
   while their owners' stack frames still exist. */
static void run_cleanups(ErrCleanup *stop) {
  while (err_cleanups && err_cleanups != stop) {
    ErrCleanup *c = err_cleanups;
    err_cleanups = c->prev;
    c->fn(c->arg);
  }
}

static _Noreturn void err_throw(void) {
  ErrFrame *f = err_top;
  if (!f) {
    run_cleanups(NULL);
    err_report(stderr, "error", err_current.pos, err_current.msg);
    exit(1);
  }
  run_cleanups(f->cleanups);
  err_top = f->prev;
#ifdef QCS_ASAN
  /* The frames between here and the handler's die with the jump. ASan
     clears their redzones itself only for stacks below a size it trusts;
     the interpreter's is 256M, so after a deep recursion ends in an error
     ("recursion too deep") stale redzones would make later, shallower
     calls look like overflows. Clear them here: the handler's ErrFrame
     lies in its frame, above every frame the jump discards. */
  char here;
  if ((char *)f > &here)
    __asan_unpoison_memory_region(&here, (size_t)((char *)f - &here));
#endif
  longjmp(f->jb, 1);
}

/* ---- source tags ---- */

/* The table of interned positions, in the collected heap so that the
   sources it names stay alive (the static pointer is a root). Looked up
   through an open-addressed hash of tag numbers. */
static pthread_mutex_t tag_lock = PTHREAD_MUTEX_INITIALIZER;
static Pos *tag_table;      /* tag_table[0] is pos_none */
static int tag_n = 1, tag_cap;
static int *tag_hash;       /* tag numbers, 0 = empty; size tag_hcap */
static int tag_hcap;

static unsigned pos_hash(Pos p) {
  uintptr_t h = (uintptr_t)p.src * 2654435761u;
  h ^= (uintptr_t)p.line * 40503u + (uintptr_t)p.col * 9973u;
  return (unsigned)(h ^ (h >> 16));
}

static int pos_same(Pos a, Pos b) {
  return a.src == b.src && a.line == b.line && a.col == b.col;
}

static int tag_grow(void) {
  if (tag_n >= tag_cap) {
    int cap = tag_cap ? tag_cap * 2 : 256;
    Pos *t = GC_MALLOC(sizeof(Pos) * (size_t)cap);
    if (!t) return -1;
    if (tag_table) memcpy(t, tag_table, sizeof(Pos) * (size_t)tag_n);
    else t[0] = pos_none;
    tag_table = t;
    tag_cap = cap;
  }
  if (2 * (tag_n + 1) > tag_hcap) {
    int hcap = tag_hcap ? tag_hcap * 2 : 512;
    int *h = calloc((size_t)hcap, sizeof *h);
    if (!h) return -1;
    for (int i = 1; i < tag_n; i++) {
      unsigned k = pos_hash(tag_table[i]) & (unsigned)(hcap - 1);
      while (h[k]) k = (k + 1) & (unsigned)(hcap - 1);
      h[k] = i;
    }
    free(tag_hash);
    tag_hash = h;
    tag_hcap = hcap;
  }
  return 0;
}

int pos_tag(Pos pos) {
  if (!pos.src && pos.line == 0) return 0;
  pthread_mutex_lock(&tag_lock);
  int tag = -1;
  if (tag_grow() == 0) {
    unsigned k = pos_hash(pos) & (unsigned)(tag_hcap - 1);
    while (tag_hash[k] && !pos_same(tag_table[tag_hash[k]], pos))
      k = (k + 1) & (unsigned)(tag_hcap - 1);
    if (!tag_hash[k]) {
      tag_table[tag_n] = pos;
      tag_hash[k] = tag_n++;
    }
    tag = tag_hash[k];
  }
  pthread_mutex_unlock(&tag_lock);
  return tag;
}

Pos tag_pos(int tag) {
  pthread_mutex_lock(&tag_lock);
  Pos p = tag > 0 && tag < tag_n ? tag_table[tag] : pos_none;
  pthread_mutex_unlock(&tag_lock);
  return p;
}

_Noreturn void err_rethrow(void) { err_throw(); }

static int word_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
         (c >= '0' && c <= '9') || c == '_' || c == '.' || c == '\'' || c == '"';
}

/* "nan", "-nan", "inf", "-inf" standing alone (as printf's %g writes
   them) become NaN, NaN, Infinity, -Infinity, so that messages of the C
   code agree with what the language prints, whatever the platform's sign
   of a NaN. */
static void qcs_nonfinite(char *msg, size_t size) {
  static const struct { const char *c, *qcs; } words[] = {
    {"-nan", "NaN"}, {"nan", "NaN"}, {"-inf", "-Infinity"}, {"inf", "Infinity"}};
  char out[sizeof err_current.msg];
  size_t o = 0;
  for (const char *p = msg; *p && o + 1 < sizeof out;) {
    int done = 0;
    if (p == msg || !word_char(p[-1]))
      for (size_t w = 0; w < sizeof words / sizeof words[0] && !done; w++) {
        size_t n = strlen(words[w].c);
        if (!strncmp(p, words[w].c, n) && !word_char(p[n])) {
          size_t m = strlen(words[w].qcs);
          if (o + m >= sizeof out) break;
          memcpy(out + o, words[w].qcs, m);
          o += m;
          p += n;
          done = 1;
        }
      }
    if (!done) out[o++] = *p++;
  }
  out[o] = 0;
  snprintf(msg, size, "%s", out);
}

_Noreturn void qcs_verror(Pos pos, const char *fmt, va_list ap) {
  err_current.pos = pos;
  err_current.incomplete = 0;
  err_current.trace[0] = 0;
  vsnprintf(err_current.msg, sizeof err_current.msg, fmt, ap);
  if (strstr(err_current.msg, "nan") || strstr(err_current.msg, "inf"))
    qcs_nonfinite(err_current.msg, sizeof err_current.msg);
  err_throw();
}

_Noreturn void qcs_error_verbatim(Pos pos, const char *msg) {
  err_current.pos = pos;
  err_current.incomplete = 0;
  err_current.trace[0] = 0;
  snprintf(err_current.msg, sizeof err_current.msg, "%s", msg);
  err_throw();
}

_Noreturn void qcs_error(Pos pos, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  qcs_verror(pos, fmt, ap);
}

_Noreturn void qcs_error_incomplete(Pos pos, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  err_current.pos = pos;
  err_current.trace[0] = 0;
  vsnprintf(err_current.msg, sizeof err_current.msg, fmt, ap);
  va_end(ap);
  err_current.incomplete = 1;
  err_throw();
}

/* The text of line `line` of src, without its newline. */
static const char *line_start(const Src *src, int line, int *len) {
  const char *p = src->text;
  for (int l = 1; l < line && *p; p++)
    if (*p == '\n') l++;
  const char *e = p;
  while (*e && *e != '\n') e++;
  *len = (int)(e - p);
  return p;
}

void err_report(FILE *out, const char *kind, Pos pos, const char *msg) {
  if (pos.src && pos.line > 0) {
    fprintf(out, "%s:%d:%d: %s: %s\n", pos.src->name, pos.line, pos.col, kind,
            msg);
    if (pos.src->text) {
      int len;
      const char *l = line_start(pos.src, pos.line, &len);
      /* b: the byte of the column (columns count UTF-8 sequences and tabs
         to the next multiple of 8, as the lexer does). */
      int b = 0, col = 1;
      while (b < len && col < pos.col) {
        if (l[b] == '\t') col = ((col - 1) / 8 + 1) * 8 + 1;
        else if (((unsigned char)l[b] & 0xC0) != 0x80) col++;
        b++;
      }
      while (b < len && ((unsigned char)l[b] & 0xC0) == 0x80) b++;
      /* A long line is shown as a window of 200 bytes around the column. */
      int start = 0;
      if (b > 150) {
        start = b - 60;
        while (start < b && ((unsigned char)l[start] & 0xC0) == 0x80) start++;
      }
      int end = len - start > 200 ? start + 200 : len;
      while (end > start && end < len &&
             ((unsigned char)l[end] & 0xC0) == 0x80)
        end--;
      fprintf(out, "  %s%.*s%s\n  %s", start ? "..." : "", end - start,
              l + start, end < len ? "..." : "", start ? "   " : "");
      /* The caret under the column, keeping the line's own tabs. */
      for (int i = start; i < b && i < end; i++) {
        if (l[i] == '\t') fputc('\t', out);
        else if (((unsigned char)l[i] & 0xC0) != 0x80) fputc(' ', out);
      }
      fputs("^\n", out);
    }
  } else {
    fprintf(out, "qcs: %s: %s\n", kind, msg);
  }
}

void qcs_warning(Pos pos, const char *fmt, ...) {
  char buf[1024];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(buf, sizeof buf, fmt, ap);
  va_end(ap);
  err_report(stderr, "warning", pos, buf);
}

int edit_distance(const char *a, const char *b) {
  size_t la = strlen(a), lb = strlen(b);
  if (la > 64 || lb > 64) return 99;
  int d[65][65];
  for (size_t i = 0; i <= la; i++) d[i][0] = (int)i;
  for (size_t j = 0; j <= lb; j++) d[0][j] = (int)j;
  for (size_t i = 1; i <= la; i++)
    for (size_t j = 1; j <= lb; j++) {
      int c = d[i - 1][j - 1] + (a[i - 1] != b[j - 1]);
      if (d[i - 1][j] + 1 < c) c = d[i - 1][j] + 1;
      if (d[i][j - 1] + 1 < c) c = d[i][j - 1] + 1;
      d[i][j] = c;
    }
  return d[la][lb];
}
