#!/bin/sh
# The man page against the command: for each subcommand, the set of options (-x, --name) that
# `conifit SUBCOMMAND --help` mentions must be the set that its subsection of src/man/conifit.1
# ("conifit SUBCOMMAND") mentions, and every subcommand of `conifit --help` must have one.
# Exit 1 naming each difference. CONIFIT names the binary (default build/conifit).
cd "$(dirname "$0")/../.." || exit 70
bin=${CONIFIT:-build/conifit}
man=src/man/conifit.1
tmp=$(mktemp -d "${TMPDIR:-/tmp}/conifit-man.XXXXXX") || exit 70
trap 'rm -rf "$tmp"' EXIT
options() { grep -oE '(^|[^A-Za-z0-9_-])--?[A-Za-z][A-Za-z0-9-]*' | sed 's/^[^-]*//' | sort -u; }
cmds=$("$bin" --help | sed -n 's/^  \([a-z][a-z]*\)  .*/\1/p')
[ -n "$cmds" ] || { echo "check_options: no subcommand in '$bin --help'" >&2; exit 1; }
bad=0
for c in $cmds; do
  "$bin" "$c" --help | options > "$tmp/help"
  # the subsection, roff escapes undone
  awk -v want=".SS \"conifit $c\"" '$0 == want { on = 1; next } /^\.S[SH] / { on = 0 } on' "$man" |
    sed -e 's/\\-/-/g' -e 's/\\f[BIRP]//g' > "$tmp/page"
  if [ ! -s "$tmp/page" ]; then
    echo "check_options: $man has no subsection .SS \"conifit $c\"" >&2; bad=1; continue
  fi
  options < "$tmp/page" > "$tmp/man"
  only_help=$(comm -23 "$tmp/help" "$tmp/man" | tr '\n' ' ')
  only_man=$(comm -13 "$tmp/help" "$tmp/man" | tr '\n' ' ')
  [ -z "$only_help" ] || { echo "check_options: conifit $c --help has, $man lacks: $only_help" >&2; bad=1; }
  [ -z "$only_man" ] || { echo "check_options: $man has, conifit $c --help lacks: $only_man" >&2; bad=1; }
done
[ $bad = 0 ] && echo "check_options: conifit.1 and --help agree on the options of: $(echo $cmds)"
exit $bad
