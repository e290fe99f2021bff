#!/bin/sh
# suite-lang.sh: the language tests (tests/lang/**/*.qcs) and every example
# of the manual (```qcs blocks in lang/*.md), checked against their
# expectation comments:
#   // expect: TEXT          the next line of stdout is TEXT
#   // expect error: TEXT    stderr contains TEXT and the exit status is 1
#   // expect status: N      the exit status is N
# A file with no "expect error" must exit 0 and print exactly the expected
# lines. Prints "ok NAME" or "FAIL NAME: why" per test.
QCS=${QCS:-./qcs}
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT

check() { # check NAME FILE
  name=$1 file=$2
  sed -n 's|.*// expect: \(.*\)$|\1|p' "$file" > "$tmp/want"
  sed -n 's|.*// expect error: \(.*\)$|\1|p' "$file" > "$tmp/want_err"
  want_status=$(sed -n 's|.*// expect status: \([0-9]*\).*|\1|p' "$file" | tail -n 1)
  if [ -s "$tmp/want_err" ]; then want_status=${want_status:-1}; fi
  want_status=${want_status:-0}
  (cd "$(dirname "$file")" && timeout 60 "$OLDPWD/$QCS" "$(basename "$file")" \
      > "$tmp/out" 2> "$tmp/err" < /dev/null)
  status=$?
  if [ "$status" -ne "$want_status" ]; then
    echo "FAIL $name: exit status $status, expected $want_status: $(head -c 300 "$tmp/err" | tr '\n' ' ')"
    return
  fi
  if ! cmp -s "$tmp/out" "$tmp/want"; then
    echo "FAIL $name: stdout differs: $(diff "$tmp/want" "$tmp/out" | head -6 | tr '\n' ' ')"
    return
  fi
  while IFS= read -r line; do
    if ! grep -qF -- "$line" "$tmp/err"; then
      echo "FAIL $name: stderr lacks '$line': $(head -c 300 "$tmp/err" | tr '\n' ' ')"
      return
    fi
  done < "$tmp/want_err"
  if grep -q -E 'AddressSanitizer|runtime error:|LeakSanitizer' "$tmp/err"; then
    echo "FAIL $name: sanitizer report: $(grep -m1 -E 'Sanitizer|runtime error' "$tmp/err")"
    return
  fi
  echo "ok $name"
}

for f in $(find tests/lang -name '*.qcs' | sort); do
  check "lang/${f#tests/lang/}" "$f"
done

# Examples of the manual: each ```qcs block is a test of its own.
for md in lang/*.md; do
  [ -f "$md" ] || continue
  awk -v dir="$tmp" -v base="$(basename "$md" .md)" '
    /^```qcs[ \t]*$/ { n++; f = sprintf("%s/%s-%03d.qcs", dir, base, n); inb = 1; next }
    /^```/ { if (inb) { close(f); inb = 0 }; next }
    inb { print > f }' "$md"
  for f in "$tmp/$(basename "$md" .md)"-*.qcs; do
    [ -f "$f" ] || continue
    check "manual/$(basename "$f")" "$f"
  done
done
