#!/bin/sh
# Layer check: no source or header of conifit includes one from a higher layer.
# Order, lowest first (src/notes/architecture.md):
#   base < model < io < fit < check < report < export < pipeline < cli
# A file's layer is its folder src/LAYER/. A public header src/include/conifit/NAME.h belongs to
# the layer of src/LAYER/NAME.c; a public header with no such source names its layer in a comment
# "conifit-layer: LAYER". Exit 1 with every upward include listed.
cd "$(dirname "$0")/.." || exit 70
order="base model io fit check report export pipeline cli"

rank() {
  i=0
  for l in $order; do
    [ "$l" = "$1" ] && { echo $i; return; }
    i=$((i + 1))
  done
  echo -1
}

# layer_of FILE -> the layer name, or nothing when it cannot be told
layer_of() {
  case $1 in
    src/include/conifit/*.h)
      n=$(basename "$1" .h)
      for c in src/*/"$n".c; do
        [ -f "$c" ] && { basename "$(dirname "$c")"; return; }
      done
      sed -n 's/.*conifit-layer: *\([a-z]*\).*/\1/p' "$1" | head -n 1 ;;
    src/*/*)
      d=${1#src/}; echo "${d%%/*}" ;;
  esac
}

bad=0
for f in $(find src -name '*.[ch]' | sort); do
  from=$(layer_of "$f")
  rf=$(rank "$from")
  if [ "$rf" -lt 0 ]; then
    echo "check_layers: $f: cannot tell its layer (folder not one of: $order)" >&2; bad=1; continue
  fi
  for inc in $(sed -n 's/^[[:space:]]*#[[:space:]]*include[[:space:]]*"\([^"]*\)".*/\1/p' "$f"); do
    case $inc in
      conifit/*) target=src/include/$inc ;;
      */*) target=src/$inc ;;
      *) target=$(dirname "$f")/$inc ;;
    esac
    if [ ! -f "$target" ]; then
      echo "check_layers: $f includes \"$inc\", which is not in src/" >&2; bad=1; continue
    fi
    to=$(layer_of "$target")
    rt=$(rank "$to")
    if [ "$rt" -lt 0 ]; then
      echo "check_layers: $target: cannot tell its layer" >&2; bad=1
    elif [ "$rt" -gt "$rf" ]; then
      echo "check_layers: $f ($from) includes \"$inc\" ($to): upward include" >&2; bad=1
    fi
  done
done
[ $bad = 0 ] && echo "check_layers: no upward include ($order)"
exit $bad
