/* fuzz_eval: parse and run arbitrary scripts with the resource limits of
 * fuzz.h, each in a new interpreter (so that every crash reproduces from
 * its input alone). Renders do not write files: a capture hook renders the
 * compiled scene at 12 x 8, one sample, one thread, and throws the image
 * away. Probes and values print to stdout (make fuzz closes it). */
#include "fuzz.h"

#include "render/render.h"
#include "bind/render_lang.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  static RenderOverrides ov;
  ov.capture = fuzz_tiny_render;
  Interp *I = bind_interp_new();
  render_set_overrides(I, &ov);
  fuzz_limits(I);
  FUZZ_STACK(I);
  char *text = fuzz_text(data, size);
  interp_run_string(I, "<fuzz>", text, MODE_SCRIPT);
  free(text);
  return 0;
}
