#!/bin/sh
# make test-install: installs conifit into a scratch DESTDIR with PREFIX=/usr, then uses the staged
# tree as a user would: builds tests/install/law_example.c and fit_example.c with `pkg-config
# --cflags --libs conifit` against the shared library and with `--static` against the static one,
# runs them and compares the forces with the installed binary's `conifit force`, and the fit file
# written through the output handle with `conifit fit data/telescoping.csv -o` (the identifiable
# quantities of each type, to 1e-9 relative); runs the installed Python module; checks the man
# pages are in place; finally `make uninstall` must leave no file behind.
# Exit 1 naming the first failing step.
set -eu
cd "$(dirname "$0")/../.."
BUILD=${BUILD:-build}
stage=$(mktemp -d "${TMPDIR:-/tmp}/conifit-install.XXXXXX")
trap 'rm -rf "$stage"' EXIT
fail() { echo "test-install: FAILED: $*" >&2; exit 1; }

${MAKE:-make} --no-print-directory -s install BUILD="$BUILD" DESTDIR="$stage/root" PREFIX=/usr \
  >"$stage/install.log" 2>&1 || { cat "$stage/install.log" >&2; fail "make install"; }
root=$stage/root
for f in usr/bin/conifit usr/lib/libconifit.a usr/lib/libconifit.so usr/include/conifit/law.h \
         usr/lib/pkgconfig/conifit.pc usr/share/man/man1/conifit.1 usr/share/man/man3/libconifit.3 \
         usr/lib/python3/dist-packages/conifit.py; do
  [ -e "$root/$f" ] || fail "make install did not install /$f"
done
soname=$(readelf -d "$root/usr/lib/libconifit.so" | sed -n 's/.*SONAME.*\[\(.*\)\]/\1/p')
[ -e "$root/usr/lib/$soname" ] || fail "no /usr/lib/$soname (the SONAME $soname)"

export PKG_CONFIG_SYSROOT_DIR="$root" PKG_CONFIG_PATH="$root/usr/lib/pkgconfig"
cflags=$(pkg-config --cflags conifit) || fail "pkg-config --cflags conifit"
libs=$(pkg-config --libs conifit) || fail "pkg-config --libs conifit"
static=$(pkg-config --static --libs conifit) || fail "pkg-config --static --libs conifit"
# -l:libconifit.a: the static library while the system's own libraries stay shared
static=$(printf '%s\n' "$static" | sed 's/-lconifit\b/-l:libconifit.a/')
# build NAME: tests/install/NAME_example.c as $stage/NAME-shared and $stage/NAME-static
build() {
  ${CC:-cc} -std=c17 "tests/install/$1_example.c" $cflags -o "$stage/$1-shared" $libs ||
    fail "building $1_example.c against the shared library with: $cflags $libs"
  ${CC:-cc} -std=c17 "tests/install/$1_example.c" $cflags -o "$stage/$1-static" $static ||
    fail "building $1_example.c against the static library with: $cflags $static"
  LD_LIBRARY_PATH="$root/usr/lib" ldd "$stage/$1-shared" | grep -q "$soname => $root/usr/lib/" ||
    fail "the shared $1 example does not load $root/usr/lib/$soname"
  ! ldd "$stage/$1-static" | grep -q libconifit || fail "the static $1 example loads libconifit.so"
}
build law
build fit

us="-3 -0.5 0 0.4 1.5 4 7.25 9.1 12"
LD_LIBRARY_PATH="$root/usr/lib" "$stage/law-shared" $us > "$stage/shared.out" ||
  fail "running the shared law example"
"$stage/law-static" $us > "$stage/static.out" || fail "running the static law example"
for u in $us; do
  "$root/usr/bin/conifit" force --D1 4 --D2 12 --n 5 --d 0.8 --G 80000 --H 10 --u "$u" |
    sed "s/^/$u /" || fail "conifit force --u $u"
done > "$stage/binary.out"
version=$("$root/usr/bin/conifit" --version | sed -n 's/^conifit //p')
for out in shared static; do
  grep -q "^version $version\$" "$stage/$out.out" || fail "$out example: version is not $version"
  # every force, one at a time and in the batch, within 1e-12 of |F| of the binary's
  awk -v name="$out" 'NR == FNR { want[$1] = $2; n++; next }
    $1 == "version" { next }
    { u = ($1 == "many") ? $2 : $1; got = ($1 == "many") ? $3 : $2
      if (!(u in want)) { print name ": no binary force at u = " u; bad = 1; next }
      d = got - want[u]; if (d < 0) d = -d; s = want[u] < 0 ? -want[u] : want[u]
      if (d > 1e-12 * (s > 1 ? s : 1)) { print name ": F(" u ") = " got ", conifit force says " want[u]; bad = 1 }
      seen++ }
    END { if (seen != 2 * n) { print name ": " seen " forces for " n " displacements"; bad = 1 } exit bad }' \
    "$stage/binary.out" "$stage/$out.out" >&2 || fail "$out example against conifit force"
done

# "TYPE QUANTITY VALUE" for each identifiable quantity of each fit of a fit file
identifiable() {
  awk '/^      "type": "/ { split($0, q, "\""); type = q[4] }
    inside { if ($0 ~ /"[A-Za-z_]+": \{/) { split($0, q, "\""); key = q[2] }
             if ($1 == "\"value\":") { v = $2; sub(/,$/, "", v); print type, key, v }
             depth += gsub(/\{/, "{") - gsub(/\}/, "}"); if (depth <= 0) inside = 0; next }
    /"identifiable": \{/ { inside = 1; depth = 1 }' "$1"
}
"$root/usr/bin/conifit" fit data/telescoping.csv -o "$stage/binary.json" >/dev/null 2>&1 ||
  fail "conifit fit data/telescoping.csv -o"
identifiable "$stage/binary.json" > "$stage/binary.ident"
[ "$(wc -l < "$stage/binary.ident")" -eq 6 ] || fail "conifit fit: not 3 identifiable quantities of 2 types"
for out in shared static; do
  LD_LIBRARY_PATH="$root/usr/lib" "$stage/fit-$out" data/telescoping.csv "$stage/$out.json" \
    > "$stage/fit-$out.out" || fail "running the $out fit example"
  identifiable "$stage/$out.json" > "$stage/$out.ident"
  awk -v name="$out" 'NR == FNR { want[$1 " " $2] = $3; n++; next }
    { k = $1 " " $2
      if (!(k in want)) { print name ": " k " is not in the binary'"'"'s fit file"; bad = 1; next }
      d = $3 - want[k]; if (d < 0) d = -d; s = want[k] < 0 ? -want[k] : want[k]
      if (d > 1e-9 * s) { print name ": " k " = " $3 ", conifit fit says " want[k]; bad = 1 }
      seen++ }
    END { if (seen != n) { print name ": " seen " identifiable quantities for " n; bad = 1 } exit bad }' \
    "$stage/binary.ident" "$stage/$out.ident" >&2 || fail "$out fit example against conifit fit"
done

if command -v python3 >/dev/null 2>&1; then
  CONIFIT_LIBRARY="$root/usr/lib/$soname" PYTHONPATH="$root/usr/lib/python3/dist-packages" \
    python3 tests/install/example.py "$root/usr/bin/conifit" > "$stage/python.out" 2>&1 ||
    { cat "$stage/python.out" >&2; fail "the installed Python module"; }
else
  echo "test-install: python3 absent: the installed Python module is not tried"
fi

${MAKE:-make} --no-print-directory -s uninstall BUILD="$BUILD" DESTDIR="$root" PREFIX=/usr \
  >"$stage/uninstall.log" 2>&1 || { cat "$stage/uninstall.log" >&2; fail "make uninstall"; }
left=$(find "$root" -type f -o -type l)
[ -z "$left" ] || fail "make uninstall left: $left"
echo "test-install: staged install (PREFIX=/usr) built and ran shared and static against pkg-config; forces match conifit force; fit files written through the output handle match conifit fit; uninstall clean"
