#!/bin/sh
# make test-install: installs conifit into a scratch DESTDIR with PREFIX=/usr, then uses the staged
# tree as a user would: builds tests/install/law_example.c and fit_example.c with `pkg-config
# --cflags --libs conifit` against the shared library and with `pkg-config --static --libs
# conifit-static` against the static one (which must not need libconifit.so), runs them and
# compares the forces with the installed binary's `conifit force`, and the fit file fit_example.c
# writes through the table-fit handle (conifit/tablefit.h) and the output handle with `conifit fit
# data/telescoping.csv -o` (the identifiable quantities of each type, to 1e-9 relative); compiles
# every installed header alone against the staged include folder; runs the installed Python module; checks the man
# pages are in place; finally `make uninstall` must leave no file behind (nor the bytecode Python
# wrote beside the module). Install and uninstall refuse a DESTDIR or PREFIX holding a blank or a
# quote without touching anything (a trailing blank, or "DIR/notes.txt stage", once named the
# real installation or the user's file).
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
         usr/lib/pkgconfig/conifit.pc usr/lib/pkgconfig/conifit-static.pc usr/share/man/man1/conifit.1 usr/share/man/man3/libconifit.3 \
         usr/lib/python3/dist-packages/conifit.py; do
  [ -e "$root/$f" ] || fail "make install did not install /$f"
done
# every installed header alone, with only the staged include folder on the path
for h in "$root"/usr/include/conifit/*.h; do
  printf '#include <conifit/%s>\n' "$(basename "$h")" |
    ${CC:-cc} -std=c17 -fsyntax-only -I"$root/usr/include" -x c - ||
    fail "the installed header $(basename "$h") does not compile alone"
done
soname=$(readelf -d "$root/usr/lib/libconifit.so" | sed -n 's/.*SONAME.*\[\(.*\)\]/\1/p')
[ -e "$root/usr/lib/$soname" ] || fail "no /usr/lib/$soname (the SONAME $soname)"

export PKG_CONFIG_SYSROOT_DIR="$root" PKG_CONFIG_PATH="$root/usr/lib/pkgconfig"
cflags=$(pkg-config --cflags conifit) || fail "pkg-config --cflags conifit"
libs=$(pkg-config --libs conifit) || fail "pkg-config --libs conifit"
# the static library while the system's own libraries stay shared, exactly as pkg-config says
static=$(pkg-config --static --libs conifit-static) || fail "pkg-config --static --libs conifit-static"
# build NAME: tests/install/NAME_example.c as $stage/NAME-shared and $stage/NAME-static
build() {
  ${CC:-cc} -std=c17 "tests/install/$1_example.c" $cflags -o "$stage/$1-shared" $libs ||
    fail "building $1_example.c against the shared library with: $cflags $libs"
  ${CC:-cc} -std=c17 "tests/install/$1_example.c" $cflags -o "$stage/$1-static" $static ||
    fail "building $1_example.c against the static library with: $cflags $static"
  LD_LIBRARY_PATH="$root/usr/lib" ldd "$stage/$1-shared" | grep -q "$soname => $root/usr/lib/" ||
    fail "the shared $1 example does not load $root/usr/lib/$soname"
  ! ldd "$stage/$1-static" | grep -q libconifit || fail "the static $1 example loads libconifit.so"
  ! readelf -d "$stage/$1-static" | grep NEEDED | grep -q libconifit ||
    fail "the static $1 example needs libconifit.so (linked with: $static)"
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

# the bytecode an import writes beside the module (whether or not the example's import wrote it)
if command -v python3 >/dev/null 2>&1; then
  python3 -c 'import py_compile, sys; py_compile.compile(sys.argv[1], doraise=True)' \
    "$root/usr/lib/python3/dist-packages/conifit.py" || fail "compiling the installed module"
  [ -d "$root/usr/lib/python3/dist-packages/__pycache__" ] || fail "no __pycache__ after compiling"
fi

# A DESTDIR or PREFIX holding a blank is refused and touches nothing: a trailing blank once let
# uninstall remove the real installation under PREFIX, and "DIR/notes.txt stage" the user's file.
echo "the user's notes" > "$stage/notes.txt"
# (PREFIX: the staged installation, standing for the real one)
for bad in "$stage/notes.txt stage" "$stage/x " "$stage/it's"; do
  code=0
  ${MAKE:-make} --no-print-directory -s uninstall BUILD="$BUILD" DESTDIR="$bad" PREFIX="$root/usr" \
    >"$stage/bad.log" 2>&1 || code=$?
  [ $code -ne 0 ] || fail "make uninstall DESTDIR='$bad' was not refused"
  grep -q "DESTDIR=.* holds a blank or a quote" "$stage/bad.log" ||
    { cat "$stage/bad.log" >&2; fail "make uninstall DESTDIR='$bad': no clear message"; }
done
code=0
${MAKE:-make} --no-print-directory -s install BUILD="$BUILD" DESTDIR="$stage/new" PREFIX="/usr/my prefix" \
  >"$stage/bad.log" 2>&1 || code=$?
[ $code -ne 0 ] && grep -q "PREFIX=.* holds a blank" "$stage/bad.log" || fail "PREFIX with a blank not refused"
[ ! -e "$stage/new" ] || fail "a refused install wrote $stage/new"
[ "$(cat "$stage/notes.txt")" = "the user's notes" ] || fail "a refused uninstall touched notes.txt"
[ -x "$root/usr/bin/conifit" ] && [ -e "$root/usr/lib/libconifit.so" ] ||
  fail "a refused uninstall removed the staged installation"
rm -f "$stage/notes.txt"

${MAKE:-make} --no-print-directory -s uninstall BUILD="$BUILD" DESTDIR="$root" PREFIX=/usr \
  >"$stage/uninstall.log" 2>&1 || { cat "$stage/uninstall.log" >&2; fail "make uninstall"; }
left=$(find "$root" -type f -o -type l)
[ -z "$left" ] || fail "make uninstall left: $left"
[ ! -e "$root/usr/lib/python3/dist-packages/__pycache__" ] || fail "make uninstall left __pycache__"
echo "test-install: staged install (PREFIX=/usr) built and ran shared and static against pkg-config; forces match conifit force; fit files written through the table-fit and output handles match conifit fit; installed headers compile alone; conifit-static needs no libconifit.so; blanks in DESTDIR/PREFIX refused; uninstall clean"
