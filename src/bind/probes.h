/* probes.h: the geometry core seen from the language.
 *
 * Probes are ordinary functions of qcs (Density, Gradient, PointInObject,
 * Displacement, OuterBounds, InnerBounds, LG, Roots, Field, Trace, ...),
 * listed in one table in probes.c like the builtins. Each compiles the
 * scene value it is given (see scene.h) and calls the same kernels the
 * renderer uses, so what a student asks at the prompt is what the renderer
 * sees. */
#ifndef QCS_PROBES_H
#define QCS_PROBES_H

#include "lang/value.h"

void probes_install(Interp *I);
#endif
