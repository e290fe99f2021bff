/* core.h: the geometry core, libqcscore.a, as a whole.
 *
 * What it owns. The mathematics of the two papers as flat C structures
 * and kernels, with no knowledge of the language above it:
 *   vec.h       3-vectors (static inline)
 *   interval.h  the interval rules of the density ops
 *   tape.h      the shape and Sethi-Ullman order of a postfix tape
 *   density.h   density trees as tapes: eq. (2), Figure 4, the gradient,
 *               pruning to a ray segment (Lobb, Section 2)
 *   csg.h       sharp CSG tapes: point classification, span lists (Roth)
 *   bounds.h    outer and inner bounds of a density tape (Figure 8)
 *   conv.h      the true convolution the density approximates (Figure 5)
 *   lg.h        LG bounds and the guaranteed root search (Section 3.4)
 *   poly.h      real polynomials up to degree 6 and their real roots
 *   soft.h      soft objects: field, keys' BVH, every crossing of a ray
 *               (Wyvill and Trotman)
 *   bvh.h       one bounding-volume hierarchy of boxes
 *   heap.h      one binary min-heap
 *
 * Dependencies. libc and libm only: no garbage collector, no language
 * values, no stdio streams (tools/check-layers.sh enforces the includes).
 *
 * Errors, the one style of this layer. A function that can fail returns a
 * code (0 is success; each module's codes are an enum beside it, with a
 * *_strerror for the message) or -1, or NULL with the code in an int *err
 * the caller passes. Nothing here prints, exits, longjmps or keeps a
 * global error state; running out of memory is an error like any other.
 *
 * Memory. Builders (dt_builder, csg_builder, soft_build) malloc what they
 * return; the caller frees it with the module's *_free. A finished tape or
 * soft object is immutable.
 *
 * Threads. No global mutable state: finished tapes and soft objects may be
 * read by any number of threads at once; per-ray scratch (span arrays, the
 * soft object's scratch) belongs to one thread.
 *
 * Units. Positions and distances are scene units; a ray is o + t d with d
 * of any non-zero length, and t (and every tolerance along a ray) is in
 * units of d. Densities are in [0, 1] for well-formed trees (a Sum may
 * exceed 1: the paper's Figure 15b, flagged by the bounds). */
#ifndef QCS_CORE_H
#define QCS_CORE_H

/* Success, for every module's error codes. */
#define CORE_OK 0

#endif
