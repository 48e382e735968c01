#!/bin/sh
# GSL guard check (base/gslguard.h): every public cf_* function of libconifit that can reach a
# GSL call must do so through a function that enters the guard (one that calls cf_gsl_enter,
# CF_GSL_GUARD's first act), so that GSL's handler never aborts a program that calls the library.
# The call graph is read from the position-independent objects (objdump's calls and relocations:
# direct calls, and functions whose address is taken, such as callbacks handed to GSL or NLopt);
# static functions are told apart by their object. Exit 1 naming each public function with an
# unguarded path, and the path.
#   check_gsl_guard.sh BUILD   (the folder holding pic/*/*.o)
cd "$(dirname "$0")/.." || exit 70
build=${1:-build}
objs=$(ls "$build"/pic/*/*.o 2>/dev/null)
[ -n "$objs" ] || { echo "check_gsl_guard: no objects in $build/pic" >&2; exit 70; }
command -v objdump >/dev/null 2>&1 || { echo "check_gsl_guard: objdump absent: not checked"; exit 0; }
tmp=$(mktemp -d "${TMPDIR:-/tmp}/cf-gslguard.XXXXXX") || exit 70
trap 'rm -rf "$tmp"' EXIT
sh tests/exports.sh list $objs > "$tmp/public"
for o in $objs; do
  # the object's static functions, then its disassembly with relocations
  { nm "$o" | awk '$2 == "t" { print "L", $3 }'; objdump -dr --no-show-raw-insn "$o"; } |
    awk -v obj="$o" '
      function key(s) { sub(/\..*/, "", s); return (s in loc) ? obj ":" s : s }
      $1 == "L" && NF == 2 { s = $2; sub(/\..*/, "", s); loc[s] = 1; next }
      /^[0-9a-f]+ <[^>]+>:$/ { f = $2; gsub(/[<>:]/, "", f); cur = key(f); next }
      cur == "" { next }
      /R_X86_64_/ { t = $NF; sub(/[-+]0x[0-9a-f]+$/, "", t); if (t !~ /^\./) print cur, key(t); next }
      /\t(call|jmp|j[a-z]+) +[0-9a-f]+ <[^>]+>/ {
        t = $0; sub(/.*</, "", t); sub(/>.*/, "", t); sub(/\+0x[0-9a-f]+$/, "", t)
        t = key(t); if (t != cur) print cur, t }'
done | sort -u > "$tmp/edges"
awk -v pub="$tmp/public" '
  BEGIN { while ((getline l < pub) > 0) public[l] = 1 }
  { out[$1] = out[$1] " " $2; if ($2 == "cf_gsl_enter") guarded[$1] = 1 }
  # the first GSL call reachable from f without passing a guarded function, as a path
  function reach(f,    n, i, c, p) {
    if (f in guarded) return ""
    if (f in seen) return ""
    seen[f] = 1
    n = split(out[f], c, " ")
    for (i = 1; i <= n; i++) {
      if (c[i] ~ /^gsl_/) return f " -> " c[i]
      p = reach(c[i]); if (p != "") return f " -> " p
    }
    return ""
  }
  END {
    bad = 0
    for (f in public) {
      delete seen; p = reach(f)
      if (p != "") { print "check_gsl_guard: " f " reaches GSL unguarded: " p > "/dev/stderr"; bad = 1 }
      checked++
    }
    if (!bad) print "check_gsl_guard: every path from the " checked " public functions to GSL passes a guard"
    exit bad }' "$tmp/edges"
