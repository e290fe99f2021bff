/* bvh.h: one bounding-volume hierarchy of axis-aligned boxes, for the
 * tracer's primitives (render.c) and the keys of a soft object (soft.c).
 *
 * Owns: a tree of boxes over n caller items, built by median split on the
 * axis where the items' centres spread widest, children of a node adjacent
 * (left = first, right = first + 1), and idx, the items in leaf order (a
 * leaf holds idx[first .. first + count)).  The caller keeps its items and
 * reorders them by idx if it likes (soft.c moves its keys into leaf order).
 *
 * Invariants: a leaf's box is the union of its items' boxes and an inner
 * node's the union of its children's (empty item boxes, lo > hi, are
 * allowed); a leaf holds 1 .. leaf_max items; n = 0 gives no nodes.  The
 * median split makes depth <= ceil(log2 n) + 1 levels, so a depth-first
 * traversal that pops one node and pushes its two children never holds more
 * than depth + 1 <= BVH_STACK entries: bvh_build fails (BVH_EDEPTH) rather
 * than build a tree a BVH_STACK array could not walk, so traversals need no
 * overflow check and never drop a node.
 *
 * The split: BVH_SELECT orders each node's items by quickselect (O(n) per
 * level; the order within each half is unspecified but deterministic);
 * BVH_SORT sorts them stably by centre (ties keep the input order, so equal
 * items are met in the caller's order; O(n log n) per level).  Each user
 * keeps the split it had before the merge, so no picture changes.
 *
 * Memory: bvh_build mallocs nodes and idx, released by bvh_free; the tree
 * is read-only afterwards and may be shared by threads.  Units: whatever
 * the caller's coordinates are. */
#ifndef QCS_BVH_H
#define QCS_BVH_H

#include <stddef.h>

/* Depth-first traversal stacks of this many entries are always enough. */
#define BVH_STACK 64

enum { BVH_SELECT = 0, BVH_SORT = 1 };
enum { BVH_OK = 0, BVH_ENOMEM, BVH_EDEPTH };

typedef struct bvh_node {
  double lo[3], hi[3];
  int first;   /* inner node: its left child (right = first + 1);
                  leaf: its first item in idx */
  int count;   /* items of a leaf; 0 for an inner node */
} bvh_node;

typedef struct bvh {
  bvh_node *nodes;  /* nodes[0] is the root (none when n = 0) */
  int nnodes;
  int *idx;         /* the items in leaf order */
  int n;
  int depth;        /* levels (1: the root is a leaf) */
} bvh;

/* One item: its box and the centre the split orders it by. */
typedef struct bvh_item {
  double lo[3], hi[3], c[3];
} bvh_item;

/* Build over items[0 .. n) with leaves of at most leaf_max >= 1 items and
 * the given split; on failure *b holds no memory. */
int bvh_build(bvh *b, const bvh_item *items, int n, int leaf_max, int split);

/* The same over items kept in the caller's own records: item j's box is
 * lo[0..3) and hi[0..3), its centre c[0..3), each at j * stride bytes past
 * the pointer given (soft.c's keys, without a copy as bvh_items). */
typedef struct bvh_items {
  const double *lo, *hi, *c;
  size_t stride;  /* bytes from one item's record to the next's */
} bvh_items;
int bvh_build_view(bvh *b, bvh_items items, int n, int leaf_max, int split);
void bvh_free(bvh *b);

/* Whether p lies in the node's box (closed). */
static inline int bvh_node_has(const bvh_node *nd, const double p[3]) {
  return !(p[0] < nd->lo[0] || p[0] > nd->hi[0] || p[1] < nd->lo[1] ||
           p[1] > nd->hi[1] || p[2] < nd->lo[2] || p[2] > nd->hi[2]);
}

#endif
