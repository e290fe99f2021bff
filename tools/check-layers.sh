#!/bin/sh
# check-layers.sh: fail if a source file includes across a layer the wrong
# way. Each folder of src/ is a layer; a file may include headers of the
# layers listed for its own (quoted includes are written "layer/name.h").
# The geometry core uses libc and libm only: no stdio streams, no GC; the
# scene and the renderer use no GC and write nothing to stdout or stderr.
#
#   sh tools/check-layers.sh [SRC]    (default: src)
src=${1:-src}
status=0
# The C library's and libm's headers (C11 and POSIX) that core/ may use.
CORE_SYSTEM="assert.h complex.h ctype.h errno.h fenv.h float.h inttypes.h \
limits.h math.h setjmp.h stdalign.h stdatomic.h stdbool.h stddef.h stdint.h \
stdlib.h string.h strings.h time.h"
allowed() {
  case $1 in
  core)   echo "core" ;;
  scene)  echo "core scene" ;;
  render) echo "core scene render" ;;
  lang)   echo "lang" ;;
  bind)   echo "core scene render lang bind" ;;
  study)  echo "core scene render lang bind study" ;;
  app)    echo "core scene render lang bind study app" ;;
  *)      echo "" ;;
  esac
}
for dir in "$src"/*/; do
  layer=$(basename "$dir")
  ok=$(allowed "$layer")
  if [ -z "$ok" ]; then
    echo "$dir: not a known layer (core scene render lang bind study app)" >&2
    status=1
    continue
  fi
  for f in "$dir"*.c "$dir"*.h; do
    [ -f "$f" ] || continue
    # quoted includes: every one names its layer
    grep -n '^[[:space:]]*#[[:space:]]*include[[:space:]]*"' "$f" |
    while IFS= read -r line; do
      n=${line%%:*}
      inc=$(printf '%s\n' "$line" | sed 's/.*include[[:space:]]*"\([^"]*\)".*/\1/')
      case $inc in
      */*) target=${inc%%/*} ;;
      *) case $inc in *.inc) continue ;; esac
         echo "$f:$n: #include \"$inc\" does not name its layer (write \"LAYER/$inc\")"
         continue ;;
      esac
      case " $ok " in
      *" $target "*) ;;
      *) echo "$f:$n: layer '$layer' may not include \"$inc\" (it may use: $ok)" ;;
      esac
    done
    # angle-bracket includes of the project's own headers obey the same rule
    grep -n '^[[:space:]]*#[[:space:]]*include[[:space:]]*<\(core\|scene\|render\|lang\|bind\|study\|app\)/' "$f" |
    while IFS= read -r line; do
      n=${line%%:*}
      inc=$(printf '%s\n' "$line" | sed 's/.*include[[:space:]]*<\([^>]*\)>.*/\1/')
      target=${inc%%/*}
      case " $ok " in
      *" $target "*) ;;
      *) echo "$f:$n: layer '$layer' may not include <$inc> (it may use: $ok)" ;;
      esac
    done
    case $layer in
    core|scene|render)
      grep -n '^[[:space:]]*#[[:space:]]*include[[:space:]]*<\(gc\.h\|gc/[^>]*\)>' "$f" |
        sed "s|^\([0-9]*\):.*|$f:\1: layer '$layer' may not use the garbage collector|"
      grep -n '\<\(stderr\|stdout\)\>' "$f" |
        sed "s|^\([0-9]*\):.*|$f:\1: layer '$layer' prints nothing (return a code and a message)|" ;;
    esac
    case $layer in
    core)
      grep -n '^[[:space:]]*#[[:space:]]*include[[:space:]]*<stdio\.h>' "$f" |
        sed "s|^\([0-9]*\):.*|$f:\1: layer 'core' uses libc and libm only, no stdio|"
      # and no other library: its system headers are the C library's
      grep -n '^[[:space:]]*#[[:space:]]*include[[:space:]]*<' "$f" |
      while IFS= read -r line; do
        n=${line%%:*}
        inc=$(printf '%s\n' "$line" | sed 's/.*include[[:space:]]*<\([^>]*\)>.*/\1/')
        case " $CORE_SYSTEM " in
        *" $inc "*) ;;
        *) echo "$f:$n: layer 'core' uses libc and libm only: <$inc> is not one of their headers" ;;
        esac
      done ;;
    esac
  done
done > "${TMPDIR:-/tmp}/qcs-layers.$$"
if [ -s "${TMPDIR:-/tmp}/qcs-layers.$$" ]; then
  cat "${TMPDIR:-/tmp}/qcs-layers.$$" >&2
  echo "error: include(s) across layers the wrong way (see tools/check-layers.sh)" >&2
  status=1
fi
rm -f "${TMPDIR:-/tmp}/qcs-layers.$$"
exit $status
