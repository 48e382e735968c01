#!/bin/sh
# Public-surface check: the headers `make install` installs (src/include/conifit/*.h) are what a
# program calls, and nothing else. Fails (exit 1, naming each offence) when
#   - there are more than 10 of them;
#   - one includes, in quotes or angle brackets, a conifit header that is not itself public (its
#     quoted includes must all be "conifit/NAME.h" of this folder: no private header such as
#     "fit/fit.h" leaks into an installation, where it would not exist);
#   - one does not compile alone, twice (its guard), with only the public folder on the include
#     path and no definition from the build (no -D_DEFAULT_SOURCE, -Isrc): a type or call it names
#     must come from the public set;
#   - a public type cf_X_options has no cf_X_default_options() beside it (the one pattern of
#     options on the public surface).
# Every other header lives beside its sources in src/LAYER/ (tests/check_layers.sh).
#   check_public.sh   (CC: the compiler, default cc)
cd "$(dirname "$0")/.." || exit 70
cc=${CC:-cc}
max=10
bad=0
headers=$(ls src/include/conifit/*.h 2>/dev/null)
[ -n "$headers" ] || { echo "check_public: no header in src/include/conifit" >&2; exit 1; }
n=$(printf '%s\n' $headers | wc -l)
if [ "$n" -gt $max ]; then
  echo "check_public: $n public headers (at most $max):" $(printf '%s\n' $headers | xargs -n1 basename) >&2
  bad=1
fi
tmp=$(mktemp -d "${TMPDIR:-/tmp}/cf-public.XXXXXX") || exit 70
trap 'rm -rf "$tmp"' EXIT
all=$(cat $headers)
for h in $headers; do
  name=$(basename "$h")
  for inc in $(sed -n 's/^[[:space:]]*#[[:space:]]*include[[:space:]]*"\([^"]*\)".*/\1/p' "$h"); do
    case $inc in
      conifit/*) [ -f "src/include/$inc" ] ||
        { echo "check_public: $h includes \"$inc\", which is not a public header" >&2; bad=1; } ;;
      *) echo "check_public: $h includes \"$inc\", a header outside src/include/conifit/" >&2; bad=1 ;;
    esac
  done
  for inc in $(sed -n 's/^[[:space:]]*#[[:space:]]*include[[:space:]]*<\(conifit\/[^>]*\)>.*/\1/p' "$h"); do
    [ -f "src/include/$inc" ] ||
      { echo "check_public: $h includes <$inc>, which is not a public header" >&2; bad=1; }
  done
  printf '#include <conifit/%s>\n#include <conifit/%s>\nint cf_check_public_unit;\n' "$name" "$name" > "$tmp/unit.c"
  if ! "$cc" -std=c17 -Wall -Wextra -Wpedantic -Werror -fsyntax-only -Isrc/include "$tmp/unit.c" \
       > "$tmp/cc.log" 2>&1; then
    echo "check_public: $h does not compile alone with -Isrc/include only:" >&2
    sed 's/^/  /' "$tmp/cc.log" >&2; bad=1
  fi
done
for t in $(printf '%s\n' "$all" | sed -n 's/.*} *\(cf_[a-z0-9_]*_options\) *;.*/\1/p' | sort -u); do
  x=${t#cf_}; x=${x%_options}
  printf '%s\n' "$all" | grep -q "\bcf_${x}_default_options *(" ||
    { echo "check_public: $t has no cf_${x}_default_options()" >&2; bad=1; }
done
[ $bad = 0 ] && echo "check_public: $n public headers, each closed and compiling alone:" \
  $(printf '%s\n' $headers | xargs -n1 basename)
exit $bad
