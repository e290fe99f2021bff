/* bvh.c: building the BVH of bvh.h. */
#include "core/bvh.h"

#include <math.h>
#include <stdlib.h>

typedef struct {
  bvh *b;
  const bvh_item *it;
  int leaf_max, split;
  const double *cen[3];  /* the items' centres, one array per axis */
  int *tmp;   /* BVH_SORT: merge buffer of n ints */
} builder;

/* Quickselect: order idx[0..n) so that idx[mid] has the median centre. */
static void select_median(int *idx, const double *c, int n, int mid) {
  int lo = 0, hi = n - 1;
  while (lo < hi) {
    double pv = c[idx[(lo + hi) / 2]];
    int i = lo, j = hi;
    while (i <= j) {
      while (c[idx[i]] < pv) i++;
      while (c[idx[j]] > pv) j--;
      if (i <= j) { int t = idx[i]; idx[i] = idx[j]; idx[j] = t; i++; j--; }
    }
    if (mid <= j) hi = j;
    else if (mid >= i) lo = i;
    else break;
  }
}

/* Stable merge sort of idx[0..n) by centre (equal centres keep their
 * order), bottom-up through tmp. */
static void sort_stable(int *idx, int *tmp, const double *c, int n) {
  for (int w = 1; w < n; w *= 2) {
    for (int s = 0; s < n; s += 2 * w) {
      int m = s + w < n ? s + w : n, e = s + 2 * w < n ? s + 2 * w : n;
      int i = s, j = m, k = s;
      while (i < m && j < e)
        tmp[k++] = c[idx[i]] <= c[idx[j]] ? idx[i++] : idx[j++];
      while (i < m) tmp[k++] = idx[i++];
      while (j < e) tmp[k++] = idx[j++];
    }
    for (int k = 0; k < n; k++) idx[k] = tmp[k];
  }
}

/* Node ni over idx[first .. first + n), at level lvl (1: the root). */
static void build_node(builder *B, int ni, int first, int n, int lvl) {
  bvh *b = B->b;
  const bvh_item *it = B->it;
  int *idx = b->idx + first;
  if (lvl > b->depth) b->depth = lvl;
  if (n <= B->leaf_max) {
    bvh_node *nd = &b->nodes[ni];
    for (int i = 0; i < 3; i++) { nd->lo[i] = INFINITY; nd->hi[i] = -INFINITY; }
    for (int j = 0; j < n; j++) {
      const bvh_item *k = &it[idx[j]];
      for (int i = 0; i < 3; i++) {
        if (k->lo[i] < nd->lo[i]) nd->lo[i] = k->lo[i];
        if (k->hi[i] > nd->hi[i]) nd->hi[i] = k->hi[i];
      }
    }
    nd->first = first;
    nd->count = n;
    return;
  }
  int axis = 0;
  double ext[3];
  for (int i = 0; i < 3; i++) {
    const double *c = B->cen[i];
    double clo = INFINITY, chi = -INFINITY;
    for (int j = 0; j < n; j++) {
      double x = c[idx[j]];
      if (x < clo) clo = x;
      if (x > chi) chi = x;
    }
    ext[i] = chi - clo;
    if (ext[i] > ext[axis]) axis = i;
  }
  int half = n / 2;
  if (B->split == BVH_SORT) sort_stable(idx, B->tmp, B->cen[axis], n);
  else select_median(idx, B->cen[axis], n, half);
  int left = b->nnodes;
  b->nnodes += 2;
  build_node(B, left, first, half, lvl + 1);
  build_node(B, left + 1, first + half, n - half, lvl + 1);
  bvh_node *nd = &b->nodes[ni], *l = &b->nodes[left], *r = &b->nodes[left + 1];
  for (int i = 0; i < 3; i++) {
    nd->lo[i] = fmin(l->lo[i], r->lo[i]);
    nd->hi[i] = fmax(l->hi[i], r->hi[i]);
  }
  nd->first = left;
  nd->count = 0;
}

int bvh_build(bvh *b, const bvh_item *items, int n, int leaf_max, int split) {
  b->nodes = NULL;
  b->idx = NULL;
  b->nnodes = b->n = b->depth = 0;
  if (n <= 0) return BVH_OK;
  if (leaf_max < 1) leaf_max = 1;
  b->nodes = malloc((2 * (size_t)n + 1) * sizeof *b->nodes);
  b->idx = malloc((size_t)n * sizeof *b->idx);
  double *cen = malloc(3 * (size_t)n * sizeof *cen);
  builder B = {b, items, leaf_max, split, {cen, cen + n, cen + 2 * (size_t)n},
               NULL};
  if (split == BVH_SORT) B.tmp = malloc((size_t)n * sizeof *B.tmp);
  if (!b->nodes || !b->idx || !cen || (split == BVH_SORT && !B.tmp)) {
    free(B.tmp);
    free(cen);
    bvh_free(b);
    return BVH_ENOMEM;
  }
  for (int j = 0; j < n; j++) {
    b->idx[j] = j;
    for (int i = 0; i < 3; i++) cen[(size_t)i * (size_t)n + (size_t)j] = items[j].c[i];
  }
  b->n = n;
  b->nnodes = 1;
  build_node(&B, 0, 0, n, 1);
  free(B.tmp);
  free(cen);
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
