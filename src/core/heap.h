/* heap.h: one binary min-heap, for any entry type with a double key.
 *
 * HEAP_DEFINE(name, type, key) defines static inline
 *   void name_push(type *h, int *n, type e)   insert e (h holds *n entries
 *                                             and has room for one more)
 *   type name_pop(type *h, int *n)            remove and return the entry
 *                                             with the least key (*n > 0)
 * over an array the caller owns and sizes; key names the entry's double
 * member.  The sift code is written once here and expanded per entry type,
 * so each heap keeps its entries unboxed and its speed (soft.c's front-to-
 * back BVH walk and its key events use it per ray).  Ties and NaN keys:
 * a NaN never moves up or down, so keep keys non-NaN.  No allocation, no
 * state: each heap is its caller's array. */
#ifndef QCS_HEAP_H
#define QCS_HEAP_H

#define HEAP_DEFINE(name, type, key)                                      \
  static inline void name##_push(type *h, int *n, type e) {               \
    int j = (*n)++;                                                       \
    while (j > 0 && h[(j - 1) / 2].key > e.key) {                         \
      h[j] = h[(j - 1) / 2];                                              \
      j = (j - 1) / 2;                                                    \
    }                                                                     \
    h[j] = e;                                                             \
  }                                                                       \
  static inline type name##_pop(type *h, int *n) {                        \
    type top = h[0], last = h[--*n];                                      \
    int j = 0;                                                            \
    for (;;) {                                                            \
      int c = 2 * j + 1;                                                  \
      if (c >= *n) break;                                                 \
      if (c + 1 < *n && h[c + 1].key < h[c].key) c++;                     \
      if (h[c].key >= last.key) break;                                    \
      h[j] = h[c];                                                        \
      j = c;                                                              \
    }                                                                     \
    h[j] = last;                                                          \
    return top;                                                           \
  }

#endif
