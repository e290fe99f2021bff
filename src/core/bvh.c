/* bvh.c: building the BVH of bvh.h. */
#include "core/bvh.h"

#include <math.h>
#include <stdlib.h>

/* An item as the split orders it: its centre and its index. The builder
 * moves these 32-byte records themselves, so each level reads its items
 * in order instead of through idx into three arrays of a million centres
 * (a cache miss an access: build_node was 30% of soft-cloud 10^6's time);
 * the moves and comparisons are those the index arrays had, so the tree
 * is the same. */
typedef struct { double c[3]; int id; } rec;

typedef struct {
  bvh *b;
  bvh_items it;
  int leaf_max, split;
  rec *r;     /* the items, in leaf order once built */
  rec *tmp;   /* BVH_SORT: merge buffer of n records */
  int *leafat;  /* the leaf starting at each position (where one does) */
} builder;

/* Quickselect: order r[0..n) so that r[mid] has the median centre on axis
 * a. */
static void select_median(rec *r, int a, int n, int mid) {
  int lo = 0, hi = n - 1;
  while (lo < hi) {
    double pv = r[(lo + hi) / 2].c[a];
    int i = lo, j = hi;
    while (i <= j) {
      while (r[i].c[a] < pv) i++;
      while (r[j].c[a] > pv) j--;
      if (i <= j) { rec t = r[i]; r[i] = r[j]; r[j] = t; i++; j--; }
    }
    if (mid <= j) hi = j;
    else if (mid >= i) lo = i;
    else break;
  }
}

/* Stable merge sort of r[0..n) by centre on axis a (equal centres keep
 * their order), bottom-up through tmp. */
static void sort_stable(rec *r, rec *tmp, int a, int n) {
  for (int w = 1; w < n; w *= 2) {
    for (int s = 0; s < n; s += 2 * w) {
      int m = s + w < n ? s + w : n, e = s + 2 * w < n ? s + 2 * w : n;
      int i = s, j = m, k = s;
      while (i < m && j < e)
        tmp[k++] = r[i].c[a] <= r[j].c[a] ? r[i++] : r[j++];
      while (i < m) tmp[k++] = r[i++];
      while (j < e) tmp[k++] = r[j++];
    }
    for (int k = 0; k < n; k++) r[k] = tmp[k];
  }
}

/* Node ni over r[first .. first + n), at level lvl (1: the root). */
static void build_node(builder *B, int ni, int first, int n, int lvl) {
  bvh *b = B->b;
  rec *r = B->r + first;
  if (lvl > b->depth) b->depth = lvl;
  if (n <= B->leaf_max) {  /* its box comes later: boxes() */
    bvh_node *nd = &b->nodes[ni];
    nd->first = first;
    nd->count = n;
    B->leafat[first] = ni;
    return;
  }
  int axis = 0;
  double lo0 = INFINITY, lo1 = INFINITY, lo2 = INFINITY;  /* in registers */
  double hi0 = -INFINITY, hi1 = -INFINITY, hi2 = -INFINITY;
  for (int j = 0; j < n; j++) {
    double x = r[j].c[0], y = r[j].c[1], z = r[j].c[2];
    if (x < lo0) lo0 = x;
    if (x > hi0) hi0 = x;
    if (y < lo1) lo1 = y;
    if (y > hi1) hi1 = y;
    if (z < lo2) lo2 = z;
    if (z > hi2) hi2 = z;
  }
  double ext[3] = {hi0 - lo0, hi1 - lo1, hi2 - lo2};
  for (int i = 0; i < 3; i++)
    if (ext[i] > ext[axis]) axis = i;
  int half = n / 2;
  if (B->split == BVH_SORT) sort_stable(r, B->tmp, axis, n);
  else select_median(r, axis, n, half);
  int left = b->nnodes;
  b->nnodes += 2;
  build_node(B, left, first, half, lvl + 1);
  build_node(B, left + 1, first + half, n - half, lvl + 1);
  b->nodes[ni].first = left;
  b->nodes[ni].count = 0;
}

/* The boxes, once the tree is built: each leaf's, the union of its items'
 * boxes, with the leaves taken in leaf order so that the items' boxes,
 * scattered in the caller's order, can be fetched ahead; then each inner
 * node's, the union of its children's, from the last node to the root
 * (children come after their parent). The same unions, in the same order,
 * as when each node's box was made as it was built. */
#define PREFETCH_AHEAD 16
static void boxes(builder *B) {
  bvh *b = B->b;
  const char *lo = (const char *)B->it.lo, *hi = (const char *)B->it.hi;
  size_t st = B->it.stride;
  const rec *r = B->r;
  int n = b->n;
  for (int j = 0; j < n;) {
    bvh_node *nd = &b->nodes[B->leafat[j]];
    for (int i = 0; i < 3; i++) { nd->lo[i] = INFINITY; nd->hi[i] = -INFINITY; }
    for (int e = j + nd->count; j < e; j++) {
#if defined(__GNUC__)
      if (j + PREFETCH_AHEAD < n) {
        __builtin_prefetch(lo + (size_t)r[j + PREFETCH_AHEAD].id * st);
        __builtin_prefetch(hi + (size_t)r[j + PREFETCH_AHEAD].id * st);
      }
#endif
      const double *klo = (const double *)(lo + (size_t)r[j].id * st);
      const double *khi = (const double *)(hi + (size_t)r[j].id * st);
      for (int i = 0; i < 3; i++) {
        if (klo[i] < nd->lo[i]) nd->lo[i] = klo[i];
        if (khi[i] > nd->hi[i]) nd->hi[i] = khi[i];
      }
    }
  }
  for (int ni = b->nnodes - 1; ni >= 0; ni--) {
    bvh_node *nd = &b->nodes[ni];
    if (nd->count) continue;
    const bvh_node *l = &b->nodes[nd->first], *rt = &b->nodes[nd->first + 1];
    for (int i = 0; i < 3; i++) {
      nd->lo[i] = fmin(l->lo[i], rt->lo[i]);
      nd->hi[i] = fmax(l->hi[i], rt->hi[i]);
    }
  }
}

int bvh_build(bvh *b, const bvh_item *items, int n, int leaf_max, int split) {
  bvh_items v = {items ? items->lo : NULL, items ? items->hi : NULL,
                 items ? items->c : NULL, sizeof *items};
  return bvh_build_view(b, v, n, leaf_max, split);
}

int bvh_build_view(bvh *b, bvh_items items, int n, int leaf_max, int split) {
  b->nodes = NULL;
  b->idx = NULL;
  b->nnodes = b->n = b->depth = 0;
  if (n <= 0) return BVH_OK;
  if (leaf_max < 1) leaf_max = 1;
  b->nodes = malloc((2 * (size_t)n + 1) * sizeof *b->nodes);
  b->idx = malloc((size_t)n * sizeof *b->idx);
  rec *r = malloc((size_t)n * sizeof *r);
  builder B = {b, items, leaf_max, split, r, NULL, malloc((size_t)n * sizeof(int))};
  if (split == BVH_SORT) B.tmp = malloc((size_t)n * sizeof *B.tmp);
  if (!b->nodes || !b->idx || !r || !B.leafat || (split == BVH_SORT && !B.tmp)) {
    free(B.leafat);
    free(B.tmp);
    free(r);
    bvh_free(b);
    return BVH_ENOMEM;
  }
  for (int j = 0; j < n; j++) {
    r[j].id = j;
    const double *c = (const double *)((const char *)items.c + (size_t)j * items.stride);
    for (int i = 0; i < 3; i++) r[j].c[i] = c[i];
  }
  b->n = n;
  b->nnodes = 1;
  build_node(&B, 0, 0, n, 1);
  boxes(&B);
  for (int j = 0; j < n; j++) b->idx[j] = r[j].id;
  free(B.leafat);
  free(B.tmp);
  free(r);
  if (b->depth + 1 > BVH_STACK) {  /* not reached: depth <= 33 */
    bvh_free(b);
    return BVH_EDEPTH;
  }
  return BVH_OK;
}

void bvh_free(bvh *b) {
  free(b->nodes);
  free(b->idx);
  b->nodes = NULL;
  b->idx = NULL;
  b->nnodes = b->n = b->depth = 0;
}
