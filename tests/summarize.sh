#!/bin/sh
# Sums the RESULT lines given (build/<configuration>/<program>.result, one per pair that
# `make test` builds and runs) and
# prints one line "N passed, N failed". A program that did not build, crashed before its
# RESULT line, or exited non-zero after it (a sanitizer report at exit, say) counts as one
# failed case. Shows the failing lines of each failing log. Exit status 1 if any failed.
results=$1
passed=0
failed=0
for r in $results; do
  # r is build/<configuration>/<program>.result
  c=$(basename "$(dirname "$r")")
  t=$(basename "$r" .result)
  if [ ! -f "$r" ]; then
    echo "[$c] $t: did not build"
    failed=$((failed + 1))
    continue
  fi
  set -- $(cat "$r")
  p=$2; f=$3
  status=$(cat "build/$c/$t.status" 2>/dev/null || echo 1)
  if [ "$f" -eq 0 ] && [ "$status" -ne 0 ]; then
    f=1
    echo "[$c] $t: exit status $status after its cases"
  fi
  passed=$((passed + p))
  failed=$((failed + f))
  if [ "$f" -ne 0 ]; then
    echo "[$c] $t: $f failed; from build/$c/$t.log:"
    grep -v '^PASS ' "build/$c/$t.log" | head -n 40 | sed 's/^/    /'
  fi
done
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
