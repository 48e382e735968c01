#!/bin/sh
# Size check: no source file of conifit over 800 lines, and no function over 100 lines unless the
# comment above it says why ("Long only because ...", "Kept as one function because ...").
# A function is counted from its first line (a declaration at column 0) to its closing brace at
# column 0. Exit 1 listing each offender.
cd "$(dirname "$0")/.." || exit 70
bad=0
for f in src/*/*.c src/*/*.h src/include/conifit/*.h; do
  n=$(wc -l < "$f")
  if [ "$n" -gt 800 ]; then
    echo "check_size: $f: $n lines (at most 800)" >&2; bad=1
  fi
done
for f in src/*/*.c; do
  awk -v file="$f" '
    /^\/\*/ { cstart = NR; comment = "" }
    { if (cstart) comment = comment " " $0 }
    /\*\/[ \t]*$/ { cend = NR; why = comment; cstart = 0 }
    /^[A-Za-z_][A-Za-z0-9_ \t\*]*[ \t\*]+\**[A-Za-z_][A-Za-z0-9_]*\(/ && !infn && $0 !~ /;[ \t]*$/ {
      sig = NR; name = $0; sub(/\(.*/, "", name); n = split(name, w, /[ \t\*]+/); name = w[n]
      reason = (cend == sig - 1 && why ~ /[Ll]ong only because|[Kk]ept as one function/)
    }
    /^\{/ && sig { infn = 1 }
    /^\}/ && infn {
      len = NR - sig + 1
      if (len > 100 && !reason) { printf "check_size: %s:%d: %s is %d lines (at most 100 without a reason written above it)\n", file, sig, name, len > "/dev/stderr"; bad = 1 }
      infn = 0; sig = 0
    }
    END { exit bad }' "$f" || bad=1
done
[ $bad = 0 ] && echo "check_size: no file over 800 lines, no function over 100 lines without its reason"
exit $bad
