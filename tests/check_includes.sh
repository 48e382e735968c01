#!/bin/sh
# Include-circle check: no module of the library includes, directly or around a circle, a header
# of a module that includes one of its own. A module is a file stem of src/LAYER/ (NAME.c with
# NAME.h); an internal header, NAME_internal.h or NAME_ctx.h (what the files of module NAME
# share), counts with module NAME; a public header src/include/conifit/NAME.h with the module of
# src/LAYER/NAME.c. An edge A -> B is a file of A including a header of B. Exits 1 listing every
# circle found, each step with the file and the include that makes it.
# Usage: tests/check_includes.sh (from anywhere; reads src/).
cd "$(dirname "$0")/.." || exit 70

# One line per file ("F FILE"), then one per include ("I FILE HEADER"); awk maps each to modules.
files=$(find src -name '*.[ch]' | sort)
{
  for f in $files; do echo "F $f"; done
  grep -H '^[[:space:]]*#[[:space:]]*include[[:space:]]*"' $files |
    sed -n 's/^\([^:]*\):[[:space:]]*#[[:space:]]*include[[:space:]]*"\([^"]*\)".*/I \1 \2/p'
} | awk '
  $1 == "F" { exists[$2] = 1; if ($2 ~ /\.c$/) { b = $2; sub(/^.*\//, "", b); csrc[b] = $2 } next }
  {
    f = $2; inc = $3
    if (inc ~ /^conifit\//) t = "src/include/" inc
    else if (inc ~ /\//) t = "src/" inc
    else { t = f; sub(/[^\/]*$/, "", t); t = t inc }
    if (!(t in exists)) next # check_layers.sh reports it
    from = module(f); to = module(t)
    if (from == to) next
    if (!((from, to) in edge)) { edge[from, to] = f " includes \"" inc "\""; adj[from] = adj[from] " " to; v[from]; v[to] }
  }
  function module(p,    n) {
    if (p ~ /^src\/include\/conifit\//) {
      n = p; sub(/^.*\//, "", n); sub(/\.h$/, ".c", n)
      if (n in csrc) p = csrc[n]
    }
    sub(/^src\//, "", p); sub(/\.[ch]$/, "", p); sub(/_(internal|ctx)$/, "", p)
    return p
  }

  END {
    bad = 0
    n = 0
    for (x in v) order[++n] = x
    for (i = 2; i <= n; i++) { x = order[i]; for (j = i - 1; j >= 1 && order[j] > x; j--) order[j + 1] = order[j]; order[j + 1] = x }
    for (i = 1; i <= n; i++) if (state[order[i]] == 0) visit(order[i], 0)
    if (!bad) print "check_includes: no include circle between modules (" n " modules)"
    exit bad
  }
  function visit(x, depth,    m, a, k, w, j, msg) {
    state[x] = 1; stack[depth] = x
    m = split(adj[x], a, " ")
    for (k = 1; k <= m; k++) {
      w = a[k]
      if (state[w] == 1) {
        for (j = depth; j >= 0 && stack[j] != w; j--) ;
        msg = ""
        for (; j <= depth; j++) msg = msg "\n  " stack[j] " -> " (j < depth ? stack[j + 1] : w) ": " edge[stack[j], (j < depth ? stack[j + 1] : w)]
        print "check_includes: include circle:" msg > "/dev/stderr"; bad = 1
      } else if (state[w] == 0) visit(w, depth + 1)
    }
    state[x] = 2
  }'
