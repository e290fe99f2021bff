/* mix.h: a 64-bit key mixed so that every bit reaches the low bits, for
 * hash tables indexed by the low bits (murmur3's finalizer). */
#ifndef QCS_CORE_MIX_H
#define QCS_CORE_MIX_H

#include <stdint.h>

static inline uint64_t mix64(uint64_t x) {
  x ^= x >> 33;
  x *= 0xff51afd7ed558ccdull;
  x ^= x >> 33;
  x *= 0xc4ceb9fe1a85ec53ull;
  x ^= x >> 33;
  return x;
}

#endif
