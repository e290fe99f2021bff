#!/bin/sh
# suite-layers.sh: tools/check-layers.sh passes on src/ and catches each
# kind of wrong include when one is planted in a copy: upward quoted and
# angle-bracket includes, the GC by either spelling in a GC-free layer,
# stdio and a library other than libc/libm in core/, a bare name.
cd "$(dirname "$0")/.." || exit 1
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
if sh tools/check-layers.sh src 2>"$work/e"; then echo "ok layers-src"
else echo "FAIL layers-src: $(head -3 "$work/e" | tr '\n' ' ')"; fi
plant() { # NAME FILE LINE EXPECTED-TEXT
  rm -rf "$work/src"; cp -r src "$work/src"
  printf '%s\n' "$3" >> "$work/src/$2"
  if sh tools/check-layers.sh "$work/src" 2>"$work/e"; then
    echo "FAIL layers-$1: '$3' in $2 was not refused"
  elif ! grep -q "$4" "$work/e"; then
    echo "FAIL layers-$1: message lacks '$4': $(head -2 "$work/e" | tr '\n' ' ')"
  else echo "ok layers-$1"; fi
}
plant core-up-quoted core/tape.c '#include "lang/value.h"' "layer 'core' may not include \"lang/value.h\""
plant core-up-angle core/tape.c '#include <lang/value.h>' "layer 'core' may not include <lang/value.h>"
plant scene-bind scene/scene.c '#include "bind/bind.h"' "layer 'scene' may not include"
plant render-lang render/render.c '#include <lang/eval.h>' "layer 'render' may not include <lang/eval.h>"
plant render-gc render/image.c '#include <gc.h>' "may not use the garbage collector"
plant render-gc-dir render/image.c '#include <gc/gc.h>' "may not use the garbage collector"
plant core-stdio core/poly.c '#include <stdio.h>' "no stdio"
plant core-library core/poly.c '#include <png.h>' "<png.h> is not one of their headers"
plant scene-prints scene/ray.c 'static void f(void) { fputs("x", stderr); }' "prints nothing"
plant bare-name bind/bind.c '#include "value.h"' "does not name its layer"
plant lang-render lang/eval.c '#include "render/render.h"' "layer 'lang' may not include"
