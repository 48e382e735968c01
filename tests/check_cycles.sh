#!/bin/sh
# Call-circle check: no two source files of the library call each other, directly or through
# others (a file's functions may call those of files "below" it only, so that each file can be
# read, tested and replaced from the bottom up). Reads the objects given (nm: what each defines
# and what it needs) and exits 1 listing every circle found, with the symbols that close it.
# Usage: tests/check_cycles.sh OBJ...
[ $# -gt 0 ] || { echo "usage: $0 OBJ..." >&2; exit 2; }
for o in "$@"; do
  nm "$o" | awk -v o="$o" '$2 ~ /^[TDBR]$/ && NF == 3 { print "D", o, $3 } $1 == "U" && NF == 2 { print "U", o, $2 }'
done | awk '
  $1 == "D" { def[$3] = $2; next }
  { need[++nn] = $2 SUBSEP $3 }
  END {
    for (i = 1; i <= nn; i++) {
      split(need[i], p, SUBSEP); o = p[1]; s = p[2]
      if (!(s in def) || def[s] == o) continue
      t = def[s]
      if (!((o, t) in edge)) { edge[o, t] = s; adj[o] = adj[o] " " t }
    }
    bad = 0
    for (v in adj) state[v] = 0
    for (v in adj) if (state[v] == 0) visit(v, 0)
    if (!bad) print "check_cycles: no call circle between the library'"'"'s files"
    exit bad
  }
  function visit(v, depth,    n, a, k, w, j, msg) {
    state[v] = 1; stack[depth] = v
    n = split(adj[v], a, " ")
    for (k = 1; k <= n; k++) {
      w = a[k]
      if (state[w] == 1) {
        msg = ""
        for (j = depth; j >= 0 && stack[j] != w; j--) ;
        for (; j <= depth; j++) msg = msg stack[j] " -(" edge[stack[j], (j < depth ? stack[j + 1] : w)] ")-> "
        print "check_cycles: call circle: " msg w > "/dev/stderr"; bad = 1
      } else if (state[w] == 0) visit(w, depth + 1)
    }
    state[v] = 2
  }'
