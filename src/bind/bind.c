/* bind.c: the whole language. See bind.h. */
#include "bind/bind.h"

#include "bind/mesh_lang.h"
#include "bind/plot.h"
#include "bind/probes.h"
#include "bind/render_lang.h"

void bind_install(Interp *I) {
  probes_install(I);
  plot_install(I);
  render_install(I);
  mesh_lang_install(I);
}

Interp *bind_interp_new(void) { return interp_new(bind_install); }
