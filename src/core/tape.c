/* tape.c: tree shape and Sethi-Ullman order of postfix tapes (tape.h). */
#include "core/tape.h"

#include <stdlib.h>
#include <string.h>

void tape_shape(const unsigned char *leaf, int n, int *left, int *right,
                int *stk) {
  int sp = 0;
  for (int i = 0; i < n; i++) {
    if (leaf[i]) {
      left[i] = right[i] = -1;
    } else {
      right[i] = stk[--sp];
      left[i] = stk[--sp];
    }
    stk[sp++] = i;
  }
}

int tape_order(const unsigned char *leaf, int n, int *order, int *depth) {
  /* The DFS stack needs up to 2 entries per tree level plus one. */
  int *left = malloc(((size_t)n * 5 + 2) * sizeof(int));
  if (!left) return TAPE_ENOMEM;
  int *right = left + n, *need = left + 2 * n, *stk = left + 3 * n;
  tape_shape(leaf, n, left, right, stk);
  for (int i = 0; i < n; i++) {
    if (left[i] < 0) {
      need[i] = 1;
    } else {
      int nl = need[left[i]], nr = need[right[i]];
      need[i] = nl == nr ? nl + 1 : (nl > nr ? nl : nr);
    }
  }
  *depth = need[n - 1];
  /* Explicit DFS: stk holds nodes, ~i marks "both children emitted". */
  int no = 0, sp = 0;
  stk[sp++] = n - 1;
  while (sp) {
    int e = stk[--sp];
    if (e < 0) {
      int i = ~e;
      order[no++] = need[right[i]] > need[left[i]] ? ~i : i;
      continue;
    }
    if (left[e] < 0) { order[no++] = e; continue; }
    int first = left[e], second = right[e];
    if (need[second] > need[first]) { first = right[e]; second = left[e]; }
    stk[sp++] = ~e;
    stk[sp++] = second;
    stk[sp++] = first;
  }
  free(left);
  return TAPE_OK;
}

int tape_reorder(const void *in, void *out, size_t size, int n,
                 int (*operand)(int op), int diff, int rdiff, int *depth) {
  const char *src = in;
  char *dst = out;
  unsigned char *leaf = calloc((size_t)n, 1);
  int *order = malloc((size_t)n * sizeof(int));
  int e = leaf && order ? TAPE_OK : TAPE_ENOMEM;
  for (int i = 0; !e && i < n; i++) {
    int op;
    memcpy(&op, src + (size_t)i * size, sizeof op);
    leaf[i] = operand(op) != 0;
  }
  if (!e) e = tape_order(leaf, n, order, depth);
  for (int k = 0; !e && k < n; k++) {
    int i = order[k] < 0 ? ~order[k] : order[k];
    char *o = dst + (size_t)k * size;
    memcpy(o, src + (size_t)i * size, size);
    if (order[k] < 0) {
      int op;
      memcpy(&op, o, sizeof op);
      op = op == diff ? rdiff : op == rdiff ? diff : op;
      memcpy(o, &op, sizeof op);
    }
  }
  free(leaf);
  free(order);
  return e;
}
