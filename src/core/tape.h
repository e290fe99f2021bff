/* tape.h: the shape of a postfix tape, shared by the density tapes
 * (density.h) and the sharp CSG tapes (csg.h).
 *
 * A tape is a tree written in postfix order: each instruction is either an
 * operand (a leaf or a constant: it pushes one value) or a binary op (it
 * pops two, x below and y on top, and pushes one).  This module knows only
 * that shape, given as one flag per instruction (leaf[i] != 0: operand),
 * so the two tape kinds share one implementation of
 *   - the tree: each op's two children (tape_shape), and
 *   - Sethi-Ullman reordering (tape_order): emit the child that needs more
 *     stack first, so a tree of n leaves needs at most floor(log2 n) + 1
 *     stack slots, however the builder nested it.  Emitting an op's
 *     children in swapped order swaps x and y, which the caller repairs
 *     (a difference becomes a reversed difference; sum, product and the
 *     unions are symmetric).
 * Both are iterative (builder trees may be chains of any length) and
 * expect a well-formed tape (exactly one tree; the builders check that).
 *
 * Memory: the caller's arrays; tape_order allocates O(n) scratch and
 * returns TAPE_ENOMEM if that fails.  No state: any thread. */
#ifndef QCS_TAPE_H
#define QCS_TAPE_H

#include <stddef.h>

enum { TAPE_OK = 0, TAPE_ENOMEM = -1 };

/* left[i], right[i]: the instructions whose values op i pops (x, y), or
 * -1 for an operand.  stk: scratch of n ints. */
void tape_shape(const unsigned char *leaf, int n, int *left, int *right,
                int *stk);

/* Sethi-Ullman order of the tape of n >= 1 instructions: order[k] is the
 * instruction to emit k-th, written ~i (negative) for an op i whose
 * children are emitted in swapped order (its y before its x).  *depth
 * receives the stack slots the reordered tape needs. */
int tape_order(const unsigned char *leaf, int n, int *order, int *depth);

/* The whole reordering of a builder's code for both tape kinds: in and
 * out hold n >= 1 instructions of size bytes whose first member is the
 * int op; operand(op) tells operands from ops; an op emitted with swapped
 * children that is diff becomes rdiff and the reverse.  Returns TAPE_OK
 * or TAPE_ENOMEM. */
int tape_reorder(const void *in, void *out, size_t size, int n,
                 int (*operand)(int op), int diff, int rdiff, int *depth);

#endif
