#!/bin/sh
# suite-examples.sh: every example runs without error; those that render
# do so at a small size into a temporary folder. Prints "ok NAME" or
# "FAIL NAME: why" per example.
QCS=${QCS:-./qcs}
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
for f in examples/*.qcs; do
  name=$(basename "$f" .qcs)
  if grep -q -E '^[^/]*render(With)? ' "$f"; then
    timeout 120 "$QCS" -o "$tmp/$name.png" --size 60x38 "$f" > "$tmp/out" 2> "$tmp/err" < /dev/null
    st=$?
    [ $st -eq 0 ] && [ ! -s "$tmp/$name.png" ] && st=99
  else
    (cd "$tmp" && timeout 120 "$OLDPWD/$QCS" "$OLDPWD/$f" > out 2> err < /dev/null)
    st=$?
  fi
  if [ $st -ne 0 ] || grep -q 'error:' "$tmp/err"; then
    echo "FAIL example $name: status $st: $(grep -m2 -E 'error' "$tmp/err" | tr '\n' ' ')"
  else
    echo "ok example $name"
  fi
done
