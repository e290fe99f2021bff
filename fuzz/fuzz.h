/* fuzz.h: what the libFuzzer targets of qcs share (see fuzz/README.md).
 *
 * Each target is one translation unit defining LLVMFuzzerTestOneInput; it
 * is linked with every library object of qcs (all of src/ but main.c),
 * built with clang -fsanitize=fuzzer,address,undefined by `make fuzz`.
 *
 * The interpreter's limits are set low so that a hostile input meets a
 * limit and an error, not a timeout: evaluation steps, memory for values,
 * and the stack budget (libFuzzer runs inputs on the main thread, 8 MB). */
#ifndef QCS_FUZZ_H
#define QCS_FUZZ_H

#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "bind/bind.h"
#include "lang/interp.h"
#include "render/render.h"
#include "bind/render_lang.h"
#include "lang/value.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define FUZZ_MAX_STEPS   200000ULL
#define FUZZ_MAX_MEMORY  (256u << 20)
#define FUZZ_STACK_LIMIT (3u << 20)

/* The input as a NUL-terminated string (an embedded NUL ends it, as it
   ends the text the interpreter is given). The caller frees it. */
static inline char *fuzz_text(const uint8_t *data, size_t size) {
  char *s = malloc(size + 1);
  if (!s) abort();
  memcpy(s, data, size);
  s[size] = 0;
  return s;
}

/* Point the interpreter's stack budget at the caller's frame. */
#define FUZZ_STACK(I) do {                                       \
    char probe_;                                                 \
    interp_set_stack((I), &probe_, FUZZ_STACK_LIMIT);            \
  } while (0)

static inline void fuzz_limits(Interp *I) {
  interp_set_max_steps(I, FUZZ_MAX_STEPS);
  interp_set_max_memory(I, FUZZ_MAX_MEMORY);
}
/* A render capture hook (render_lang.h) for the targets: renders the
   compiled scene at 12 x 8, one sample, one thread, and throws the image
   away, so that nothing is written. */
static inline int fuzz_tiny_render(void *ctx, const struct Scene *s,
                                   const struct RenderSettings *rs,
                                   const char *path, char *err,
                                   size_t errlen) {
  (void)ctx; (void)path;
  RenderSettings small = *rs;
  small.width = 12;
  small.height = 8;
  small.spp = 1;
  small.threads = 1;
  small.progress = NULL;
  RenderReport rep;
  Image *im = render_scene(s, &small, &rep, NULL, err, errlen);
  if (!im) return -1;
  img_free(im);
  return 0;
}
#endif
