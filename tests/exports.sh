#!/bin/sh
# The public interface of libconifit is the set of cf_* functions declared in the headers of
# src/include/conifit/ (the installed ones; every other header is internal, beside its sources in
# src/LAYER/, and its functions stay local to the shared library; a name in a comment is not a
# declaration). Two uses:
#   exports.sh list OBJECT...   those of them the objects define (the shared library's version
#                               script is made from this list)
#   exports.sh check LIB.so     exit 1 naming every dynamic symbol the library defines that is
#                               not such a function, and every such function it does not export
cd "$(dirname "$0")/.." || exit 70
declared() {
  cat src/include/conifit/*.h | tr -s ' \n\t' '   ' | sed -E 's#/\*([^*]|\*+[^*/])*\*+/##g' | grep -oE '\bcf_[A-Za-z0-9_]+ ?\(' |
    tr -d ' (' | sort -u
}
case $1 in
  list)
    shift
    nm -g --defined-only "$@" | awk 'NF == 3 && $2 ~ /^[TDBRV]$/ { print $3 }' | sort -u > "${TMPDIR:-/tmp}/cf-exports.$$"
    declared | comm -12 - "${TMPDIR:-/tmp}/cf-exports.$$"
    rm -f "${TMPDIR:-/tmp}/cf-exports.$$" ;;
  check)
    got=$(nm -D --defined-only "$2" | awk 'NF == 3 { print $3 }' | sort -u)
    want=$(sh "$0" list "$(dirname "$2")"/pic/*/*.o)
    [ -n "$got" ] || { echo "exports: $2 defines no dynamic symbol" >&2; exit 1; }
    extra=$(printf '%s\n' "$got" | comm -23 - "$(printf '%s\n' "$want" > "${TMPDIR:-/tmp}/cf-want.$$"; echo "${TMPDIR:-/tmp}/cf-want.$$")")
    missing=$(printf '%s\n' "$got" | comm -13 - "${TMPDIR:-/tmp}/cf-want.$$")
    rm -f "${TMPDIR:-/tmp}/cf-want.$$"
    [ -z "$extra" ] && [ -z "$missing" ] && { echo "exports: $(printf '%s\n' "$got" | wc -l) public cf_* functions, nothing else"; exit 0; }
    [ -n "$extra" ] && echo "exports: $2 exports symbols outside the public headers:" $extra >&2
    [ -n "$missing" ] && echo "exports: $2 does not export:" $missing >&2
    exit 1 ;;
  *) echo "usage: exports.sh list OBJECT... | check LIB.so" >&2; exit 2 ;;
esac
