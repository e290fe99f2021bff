/* error.c: positioned errors, the handler chain, and error display. */
#include "error.h"

#include <stdlib.h>
#include <string.h>

const Pos pos_none = {NULL, 0, 0};

static _Thread_local ErrFrame *err_top;
static _Thread_local ErrInfo err_current;

ErrInfo *err_info(void) { return &err_current; }

void err_push(ErrFrame *f) {
  f->prev = err_top;
  err_top = f;
}

void err_pop(ErrFrame *f) {
  if (err_top == f) err_top = f->prev;
}

static _Noreturn void err_throw(void) {
  ErrFrame *f = err_top;
  if (!f) {
    err_report(stderr, "error", err_current.pos, err_current.msg);
    exit(1);
  }
  err_top = f->prev;
  longjmp(f->jb, 1);
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
