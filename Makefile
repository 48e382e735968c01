# conifit: plain Makefile. Targets:
#   make            build build/conifit and the library build/libconifit.a, build/libconifit.so
#                   (optimised, with debug info)
#   make install    install the binary, libraries, headers, conifit.pc and conifit-static.pc (a
#                   static link of libconifit), man pages and the Python module under
#                   DESTDIR$(PREFIX) (PREFIX=/usr/local); make uninstall removes them
#   make test-install  install into a scratch DESTDIR and build, link and run a C program and the
#                   Python module against the staged tree (part of make test)
#   make deps       install the Debian packages conifit needs (as root; otherwise prints the command)
#   make example    set up, then fit and validate a shipped table into build/example/ (the README's
#                   first command; as root it installs missing packages, otherwise it prints the
#                   one apt-get line and stops)
#   make fits       re-fit every table in data/ into fits/ (JSON and PNG), validated in the lattice
#   make test       build and run the cmocka suite (the README's second command). The programs
#                   marked `/* conifit: vector-level ... */` (those that call the vector code: the
#                   law's and the family's lanes, the lattice's explicit step) run once for each
#                   copy of it the processor can run (AVX-512, AVX2, SSE2: the environment
#                   variable CONIFIT_SIMD selects it), every other program once, at the first
#                   (widest) level: 79 programs, 8 of them marked, make 95 runs on an AVX-512
#                   processor instead of 237; SIMD="sse2" runs at the levels named only
#   make sanitize   the same suite under AddressSanitizer + UndefinedBehaviorSanitizer, every program
#                   once with the SSE2 copies of the vector code (SIMD= names others; make test
#                   runs the vector-level programs at every level)
#   make fuzz       libFuzzer (clang, ASan + UBSan) on each parser for FUZZ_SECONDS (default 60) s
#   make bench      the benchmark report into build/bench/report/ (optimised build, separate from
#                   the tests); make bench-update copies it over the committed tests/bench/
#   make figures    regenerate fits/figures/*.png (validation, hysteresis, creep, the probed liver)
#                   from data/scenes
#   make clean
# WERROR=1 turns warnings into errors (CI sets it).

CC      ?= cc
PKGS    := nlopt gsl jansson
TESTPKGS := cmocka libxml-2.0
DEBS    := build-essential pkg-config libnlopt-dev libgsl-dev libcmocka-dev libjansson-dev \
           libsuitesparse-dev libmumps-seq-dev libopenblas0-serial libxml2-dev gnuplot-nox calculix-ccx clang \
           libclang-rt-dev libgmsh-dev python3-vtk9
BUILD   ?= build
SIMD    ?=

# -Wno-missing-field-initializers: a spring written {D1, D2, n, d, G, H} is a plain conical spring,
# its tail fields zero by the language's rule (conifit/spring.h).
WARN    := -Wall -Wextra -Wpedantic -Wshadow -Wmissing-prototypes -Wstrict-prototypes \
           -Wno-overlength-strings -Wno-missing-field-initializers
ifeq ($(WERROR),1)
WARN    += -Werror
endif
# -fno-trapping-math: no code tests floating-point exception flags, and it lets the vectoriser
# compute both sides of a selection (the law's lanes, model/law_simd.h); results are unchanged.
OPT     ?= -O2 -g -fno-math-errno -fno-trapping-math
CPPFLAGS += -D_DEFAULT_SOURCE -Isrc/include -Isrc
# SuiteSparse CHOLMOD (sparse Cholesky of the lattice tangent): newer releases ship CHOLMOD.pc;
# Debian 12's libsuitesparse-dev has none and keeps its headers in include/suitesparse.
SPARSE_CFLAGS := $(shell pkg-config --cflags CHOLMOD 2>/dev/null || echo -I/usr/include/suitesparse)
# MUMPS (sequential build: L D L^T of indefinite tangents) likewise has no pkg-config file.
SPARSE_CFLAGS += -I/usr/include/mumps_seq
# CHOLMOD and MUMPS (with the BLAS, LAPACK and Fortran runtime they need) and Gmsh (volume meshes
# of tissue bodies) are opened with dlopen at their first use (src/model/sparse_dl.c,
# src/io/mesh.c), not linked: a command that does not use them does not load them. Only their
# headers are needed to build; the run-time names of the solvers are the SONAMEs of the libraries
# the linker would take for -lcholmod and -ldmumps_seq.
soname = $(shell f=$$($(CC) -print-file-name=lib$(1).so) && objdump -p "$$f" 2>/dev/null | sed -n 's/^ *SONAME *//p')
CHOLMOD_SONAME := $(call soname,cholmod)
MUMPS_SONAME   := $(call soname,dmumps_seq)
SPARSE_CFLAGS += $(if $(CHOLMOD_SONAME),-DCF_CHOLMOD_SONAME='"$(CHOLMOD_SONAME)"') \
                 $(if $(MUMPS_SONAME),-DCF_MUMPS_SONAME='"$(MUMPS_SONAME)"')
SPARSE_LIBS   := -ldl
CFLAGS  += -std=c17 $(OPT) -fopenmp $(WARN) $(shell pkg-config --cflags $(PKGS) 2>/dev/null) $(SPARSE_CFLAGS)
LDLIBS  += $(shell pkg-config --libs $(PKGS) 2>/dev/null) $(SPARSE_LIBS) -fopenmp -lm -lpthread

ifeq ($(SANITIZE),1)
BUILD   := build/asan
CFLAGS  += -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all
LDFLAGS += -fsanitize=address,undefined
OPT     := -O1 -g
endif

# Sources by layer (src/notes/architecture.md): src/LAYER/*.c. The library is every layer but cli/;
# the public headers (what a program calls, at most 10: tests/check_public.sh) live in
# src/include/conifit/ and are installed, every other header beside its sources in src/LAYER/.
CLI_SRC := $(wildcard src/cli/*.c)
LIB_SRC := $(filter-out $(CLI_SRC),$(wildcard src/*/*.c))
LIB_OBJ := $(LIB_SRC:src/%.c=$(BUILD)/obj/%.o)
CLI_OBJ := $(CLI_SRC:src/%.c=$(BUILD)/obj/%.o)
# The library: build/libconifit.a (these objects) and build/libconifit.so (the same sources built
# again position-independent). Its version is CF_VERSION in src/include/conifit/version.h and
# nowhere else; the SONAME carries its major number. The shared library exports exactly the cf_*
# functions declared in the public headers (a version script made from the headers and the
# objects), every other symbol is local to it. The conifit binary and the tests link the static
# library (they also call internal helpers), so build/conifit runs from a fresh clone and from an
# install without any library path; libconifit.so is for other programs and for Python.
VERSION := $(shell sed -n 's/^\#define CF_VERSION "\(.*\)"/\1/p' src/include/conifit/version.h)
MAJOR   := $(firstword $(subst ., ,$(VERSION)))
LIB_A   := $(BUILD)/libconifit.a
LIB_SO  := $(BUILD)/libconifit.so
SONAME  := libconifit.so.$(MAJOR)
PIC_OBJ := $(LIB_SRC:src/%.c=$(BUILD)/pic/%.o)
PUBLIC_H := $(wildcard src/include/conifit/*.h)
# Tests by what they test: unit/ one module each, cli/ the command's behaviour, props/ properties
# across modules (fuzz/ and bench/ have their own targets).
TESTS   := $(patsubst tests/%.c,$(BUILD)/tests/%,$(wildcard tests/*/test_*.c))
# The test programs that exercise the vector code directly (a line `/* conifit: vector-level */`
# in their source): make test runs them at every level, the others once. The copies differ by a
# few units in the last place (measured against the scalar law by test_law and test_family), far
# below what the other programs' fits and runs are checked to.
VECTOR_TESTS := $(patsubst tests/%.c,$(BUILD)/tests/%,\
                  $(shell grep -l '^/\* conifit: vector-level' tests/*/test_*.c))
ONCE_TESTS   := $(filter-out $(VECTOR_TESTS),$(TESTS))

.PHONY: all lib install install-paths uninstall test-install deps example test sanitize fuzz bench bench-update clean check-deps figures fits

all: check-deps $(BUILD)/conifit $(LIB_A) $(LIB_SO)

# Fails with the exact install command when a package is missing.
check-deps:
	@missing=""; for p in $(PKGS) $(TESTPKGS); do pkg-config --exists $$p 2>/dev/null || missing="$$missing $$p"; done; \
	printf '#include <cholmod.h>\n' | $(CC) $(SPARSE_CFLAGS) -E - >/dev/null 2>&1 || missing="$$missing cholmod"; \
	printf '#include <dmumps_c.h>\n' | $(CC) $(SPARSE_CFLAGS) -E - >/dev/null 2>&1 || missing="$$missing mumps"; \
	printf '#include <gmshc.h>\n' | $(CC) -E - >/dev/null 2>&1 || missing="$$missing gmsh"; \
	if [ -n "$$missing" ]; then \
	  echo "conifit: missing libraries:$$missing. Install them with:" >&2; \
	  echo "  apt-get update && apt-get install -y $(DEBS)   (or: make deps, as root)" >&2; exit 1; fi

deps:
	@missing=""; for d in $(DEBS); do dpkg -s $$d >/dev/null 2>&1 || missing="$$missing $$d"; done; \
	if [ -z "$$missing" ]; then echo "conifit: all packages present"; \
	elif [ "$$(id -u)" = 0 ]; then \
	  echo "conifit: installing$$missing"; \
	  export DEBIAN_FRONTEND=noninteractive; \
	  apt-get update -qq && apt-get install -y -qq --no-install-recommends $$missing >/dev/null && \
	  echo "conifit: installed$$missing"; \
	else echo "conifit: missing packages. Run as root:" >&2; \
	  echo "  apt-get update && apt-get install -y$$missing" >&2; exit 1; fi

example: deps
	@$(MAKE) --no-print-directory all
	@mkdir -p $(BUILD)/example
	$(BUILD)/conifit fit data/telescoping_noise1pct.csv --validate -o $(BUILD)/example/telescoping_noise1pct.json --plot $(BUILD)/example/telescoping_noise1pct.png

fits: check-deps $(BUILD)/conifit
	$(BUILD)/conifit fit data/*.csv --validate -o fits/ --plot fits/ -j 4
	@mkdir -p fits/series
	$(BUILD)/conifit fit data/series/*.csv --branches 2 -o fits/series/ --plot fits/series/ -j 2
	@if [ -d ../shared/datasets ]; then \
	  $(BUILD)/conifit fit ../shared/datasets/muscle_compression_relaxation_*.csv -o fits/series/ --plot fits/series/ -j 2; \
	else echo "conifit: ../shared/datasets absent: the muscle relaxation fits are not refreshed"; fi

$(BUILD)/obj/%.o: src/%.c
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS) $(CFLAGS) -MMD -MP -c $< -o $@

$(LIB_A): $(LIB_OBJ)
	@rm -f $@
	$(AR) rcs $@ $^

$(BUILD)/pic/%.o: src/%.c
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS) $(CFLAGS) -fPIC -MMD -MP -c $< -o $@

# The exported set: every cf_NAME( declared in a public header that the objects define.
$(BUILD)/libconifit.map: $(PUBLIC_H) $(PIC_OBJ) tests/exports.sh
	sh tests/exports.sh list $(PIC_OBJ) > $@.names
	{ echo '{ global:'; sed 's/$$/;/' $@.names; echo 'local: *; };'; } > $@

$(LIB_SO).$(VERSION): $(PIC_OBJ) $(BUILD)/libconifit.map
	$(CC) -shared $(LDFLAGS) -Wl,-soname,$(SONAME) -Wl,--version-script,$(BUILD)/libconifit.map \
	  -Wl,--no-undefined $(PIC_OBJ) -o $@ $(LDLIBS)

$(LIB_SO): $(LIB_SO).$(VERSION)
	ln -sf $(notdir $<) $(BUILD)/$(SONAME)
	ln -sf $(SONAME) $@

lib: $(LIB_A) $(LIB_SO)

$(BUILD)/conifit: $(CLI_OBJ) $(LIB_A)
	$(CC) $(LDFLAGS) $(CLI_OBJ) $(LIB_A) -o $@ $(LDLIBS)

# Each test links the library (and may see internals through -Isrc); the CLI tests run the binary.
$(BUILD)/tests/%: tests/%.c $(LIB_A)
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS) -Itests $(CFLAGS) -MMD -MP -MF $@.d $(shell pkg-config --cflags $(TESTPKGS) 2>/dev/null) $< $(LIB_A) -o $@ \
	  $(LDFLAGS) $(LDLIBS) $(shell pkg-config --libs $(TESTPKGS) 2>/dev/null)

# test_mech_systems sees every call of the Newton driver's two entries: the linker wraps them.
$(BUILD)/tests/unit/test_mech_systems: LDFLAGS += -Wl,--wrap=cf_mech_newton -Wl,--wrap=cf_mech_inertia

# Header dependencies, as the compiler found them (-MMD -MP): a header edit rebuilds its dependants.
-include $(wildcard $(BUILD)/obj/*/*.d $(BUILD)/pic/*/*.d $(BUILD)/tests/*/*.d build/fuzz/obj/*/*.d \
                    build/bench/obj/*/*.d)

test: check-deps $(BUILD)/conifit $(LIB_SO) $(TESTS) $(REPLAYS)
	@sh tests/check_layers.sh
	@CC='$(CC)' sh tests/check_public.sh
	@sh tests/check_cycles.sh $(LIB_OBJ)
	@sh tests/check_includes.sh
	@sh tests/check_size.sh
	@sh tests/exports.sh check $(LIB_SO)
	@sh tests/check_gsl_guard.sh $(BUILD)
	@CONIFIT=$(BUILD)/conifit sh tests/man/check_options.sh
	@$(if $(filter 1,$(SANITIZE)),,sh tests/install/run.sh)
	@$(foreach f,$(FUZZERS),CONIFIT_FUZZ_QUIET=1 $(BUILD)/fuzz-replay/$(f) $(FUZZ_SEEDS_$(f)) \
	  tests/fuzz/regressions/$(f) || { echo "conifit: fuzz replay $(f) FAILED" >&2; exit 1; };)
	@levels="$(SIMD)"; if [ -z "$$levels" ]; then \
	  case $$(CONIFIT_SIMD= $(BUILD)/conifit --version) in \
	    *"processor: avx512"*) levels="avx512 avx2 sse2" ;; \
	    *"processor: avx2"*) levels="avx2 sse2" ;; \
	    *) levels=sse2 ;; esac; fi; \
	fail=0; first=$${levels%% *}; \
	echo "conifit: test programs that do not depend on the vector level, with its $$first copies"; \
	for t in $(ONCE_TESTS); do CONIFIT_SIMD=$$first CONIFIT=$(BUILD)/conifit $$t || fail=1; done; \
	for l in $$levels; do \
	  echo "conifit: test programs of the vector code with its $$l copies"; \
	  for t in $(VECTOR_TESTS); do CONIFIT_SIMD=$$l CONIFIT=$(BUILD)/conifit $$t || fail=1; done; done; \
	if [ $$fail = 0 ]; then echo "conifit: all test programs passed ($$levels)"; else echo "conifit: TEST FAILURES" >&2; exit 1; fi

# Installation (GNU conventions): PREFIX (default /usr/local) and DESTDIR (a staging root).
PREFIX     ?= /usr/local
BINDIR     ?= $(PREFIX)/bin
LIBDIR     ?= $(PREFIX)/lib
INCLUDEDIR ?= $(PREFIX)/include
MANDIR     ?= $(PREFIX)/share/man
PYTHONDIR  ?= $(PREFIX)/lib/python3/dist-packages
PKGCONFIGDIR ?= $(LIBDIR)/pkgconfig
MANPAGES   := $(wildcard src/man/*.[13])
INSTALL    ?= install

# conifit.pc and the Python module are written for this PREFIX as they are installed (the module
# looks for the library in LIBDIR first).
PC_SED := -e 's|@PREFIX@|$(PREFIX)|' -e 's|@LIBDIR@|$(LIBDIR)|' -e 's|@INCLUDEDIR@|$(INCLUDEDIR)|' \
  -e 's|@VERSION@|$(VERSION)|' -e 's|@PKGS@|$(PKGS)|' \
  -e 's|@LIBS_PRIVATE@|$(strip $(SPARSE_LIBS)) -lgomp -lm -lpthread|'

# Every installed path is quoted in the recipes, and a DESTDIR or directory holding a blank,
# tab or quote is refused before anything is written or removed: make splits words at blanks, so
# "DIR/notes.txt stage" would otherwise name two paths (one of them the user's file) and a
# trailing blank would leave DESTDIR out of the path (the real installation under PREFIX).
INSTALL_VARS := DESTDIR PREFIX BINDIR LIBDIR INCLUDEDIR MANDIR PYTHONDIR PKGCONFIGDIR
install-paths:
	@$(foreach v,$(INSTALL_VARS),$(if $(or $(filter-out 1,$(words x$($(v))x)),$(findstring ',$($(v))),$(findstring ",$($(v)))),\
	  printf '%s\n' 'conifit: $(v)='\''$(subst ','\'',$($(v)))'\'' holds a blank or a quote: install and uninstall refuse it (name a folder without one)' >&2; exit 2;))true

D := $(DESTDIR)
install: install-paths all
	$(INSTALL) -d '$(D)$(BINDIR)' '$(D)$(LIBDIR)' '$(D)$(INCLUDEDIR)/conifit' \
	  '$(D)$(PKGCONFIGDIR)' '$(D)$(MANDIR)/man1' '$(D)$(MANDIR)/man3' '$(D)$(PYTHONDIR)'
	$(INSTALL) -m 755 $(BUILD)/conifit '$(D)$(BINDIR)/conifit'
	$(INSTALL) -m 644 $(LIB_A) '$(D)$(LIBDIR)/libconifit.a'
	$(INSTALL) -m 755 $(LIB_SO).$(VERSION) '$(D)$(LIBDIR)/libconifit.so.$(VERSION)'
	ln -sf libconifit.so.$(VERSION) '$(D)$(LIBDIR)/$(SONAME)'
	ln -sf $(SONAME) '$(D)$(LIBDIR)/libconifit.so'
	$(INSTALL) -m 644 $(PUBLIC_H) '$(D)$(INCLUDEDIR)/conifit/'
	sed $(PC_SED) src/pkgconfig/conifit.pc.in > '$(D)$(PKGCONFIGDIR)/conifit.pc'
	sed $(PC_SED) src/pkgconfig/conifit-static.pc.in > '$(D)$(PKGCONFIGDIR)/conifit-static.pc'
	$(INSTALL) -m 644 $(filter %.1,$(MANPAGES)) '$(D)$(MANDIR)/man1/'
	$(INSTALL) -m 644 $(filter %.3,$(MANPAGES)) '$(D)$(MANDIR)/man3/'
	sed 's|^_INSTALLED_LIBDIR = .*|_INSTALLED_LIBDIR = "$(LIBDIR)"|' src/python/conifit.py \
	  > '$(D)$(PYTHONDIR)/conifit.py'

# Also the bytecode Python wrote beside the module when it was imported
# (__pycache__/conifit.*.pyc), and that folder when nothing else is left in it.
uninstall: install-paths
	rm -f '$(D)$(BINDIR)/conifit' '$(D)$(LIBDIR)/libconifit.a' \
	  '$(D)$(LIBDIR)/libconifit.so.$(VERSION)' '$(D)$(LIBDIR)/$(SONAME)' \
	  '$(D)$(LIBDIR)/libconifit.so' '$(D)$(PKGCONFIGDIR)/conifit.pc' \
	  '$(D)$(PKGCONFIGDIR)/conifit-static.pc' \
	  $(foreach m,$(notdir $(filter %.1,$(MANPAGES))),'$(D)$(MANDIR)/man1/$(m)') \
	  $(foreach m,$(notdir $(filter %.3,$(MANPAGES))),'$(D)$(MANDIR)/man3/$(m)') \
	  '$(D)$(PYTHONDIR)/conifit.py' '$(D)$(PYTHONDIR)/__pycache__'/conifit.*.pyc
	rmdir '$(D)$(PYTHONDIR)/__pycache__' 2>/dev/null || true
	rm -rf '$(D)$(INCLUDEDIR)/conifit'

# Installs into a scratch DESTDIR with PREFIX=/usr and uses the staged tree as a user would.
test-install: all
	@sh tests/install/run.sh

# Debian's python3-vtk9 serves Debian's interpreter (another python3 first on PATH lacks VTK).
FIGURE_PYTHON ?= /usr/bin/python3

figures: check-deps $(BUILD)/conifit
	@mkdir -p fits/figures
	$(BUILD)/conifit simulate data/scenes/uniaxial.json -o $(BUILD)/uniaxial.csv --plot fits/figures/validation.png
	$(BUILD)/conifit simulate data/scenes/hysteresis.json -o $(BUILD)/hysteresis.csv --plot fits/figures/hysteresis.png
	$(BUILD)/conifit simulate data/scenes/creep.json -o $(BUILD)/creep.csv --plot fits/figures/creep.png
	@if [ -f ../shared/meshes/liver2.msh ]; then \
	  $(BUILD)/conifit simulate data/scenes/liver_probe.json -o $(BUILD)/liver_probe.csv --vtu $(BUILD)/liver_probe && \
	  $(FIGURE_PYTHON) fits/figures/liver_probe.py $(BUILD)/liver_probe fits/figures/liver_probe.png; \
	else echo "conifit: ../shared/meshes absent: fits/figures/liver_probe.png is not refreshed"; fi
	gnuplot fits/figures/type_regions.gp
	$(BUILD)/conifit curve --D1 10 --D2 30 --n 4 --d 1 --G 80000 --H 50 --n_tail 1 --H_tail 20 --points 2001 -o $(BUILD)/three_regions_tail.csv
	$(BUILD)/conifit curve --D1 10 --D2 30 --n 4 --d 1 --G 80000 --H 30 --points 2001 -o $(BUILD)/three_regions_cone.csv
	gnuplot fits/figures/three_regions.gp

# Leaks inside third-party libraries (Gmsh's surface classification) are suppressed by
# tests/lsan.supp; every test program and every conifit it runs inherits the setting.
sanitize:
	@LSAN_OPTIONS=suppressions=$(CURDIR)/tests/lsan.supp $(MAKE) --no-print-directory test SANITIZE=1 \
	  SIMD="$(or $(SIMD),sse2)"

# Fuzzing (tests/fuzz/README.md): one libFuzzer harness per parser, the library built again with
# clang and ASan + UBSan; seed corpora from data/ and fits/. `make test` replays the seeds and the
# saved crash inputs (tests/fuzz/regressions/NAME/) through the same harnesses, built with $(CC).
FUZZERS      := table fitfile scene args merge unitsrow
FUZZ_SECONDS ?= 60
FUZZ_CC      ?= clang
FUZZ_CFLAGS  := -std=c17 -g -O1 -fno-omit-frame-pointer -fsanitize=address,undefined \
                -fno-sanitize-recover=all $(shell pkg-config --cflags $(PKGS) 2>/dev/null) \
                $(SPARSE_CFLAGS)
FUZZ_LIBS    := $(shell pkg-config --libs $(PKGS) 2>/dev/null) $(SPARSE_LIBS) -lm -lpthread
FUZZ_OBJ     := $(LIB_SRC:src/%.c=build/fuzz/obj/%.o) build/fuzz/obj/cli/cli.o \
                build/fuzz/obj/cli/cli_summary.o
REPLAYS      := $(FUZZERS:%=$(BUILD)/fuzz-replay/%)
# (named here, after the test rule read its prerequisites: make expands them on reading)
test: $(REPLAYS)
FUZZ_SEEDS_table   = data/*.csv
FUZZ_SEEDS_fitfile = fits/*.json
FUZZ_SEEDS_scene   = data/scenes/*.json
FUZZ_SEEDS_args    = tests/fuzz/args
FUZZ_SEEDS_merge   = tests/fuzz/merge
FUZZ_SEEDS_unitsrow = tests/fuzz/unitsrow

$(BUILD)/fuzz-replay/%: tests/fuzz/replay.c tests/fuzz/fuzz_%.c tests/fuzz/fuzz.h $(LIB_A) \
                        $(BUILD)/obj/cli/cli.o $(BUILD)/obj/cli/cli_summary.o
	@mkdir -p $(dir $@)
	$(CC) $(CPPFLAGS) $(CFLAGS) tests/fuzz/replay.c tests/fuzz/fuzz_$*.c \
	  $(BUILD)/obj/cli/cli.o $(BUILD)/obj/cli/cli_summary.o $(LIB_A) -o $@ $(LDFLAGS) $(LDLIBS)

.SECONDARY: $(FUZZ_OBJ)
build/fuzz/obj/%.o: src/%.c
	@mkdir -p $(dir $@)
	$(FUZZ_CC) $(CPPFLAGS) $(FUZZ_CFLAGS) -MMD -MP -fsanitize=fuzzer-no-link -c $< -o $@

build/fuzz/fuzz_%: tests/fuzz/fuzz_%.c tests/fuzz/fuzz.h $(FUZZ_OBJ)
	$(FUZZ_CC) $(CPPFLAGS) $(FUZZ_CFLAGS) -fsanitize=fuzzer $< $(FUZZ_OBJ) -o $@ $(FUZZ_LIBS)

# Each fuzzer runs FUZZ_SECONDS on a working corpus in build/fuzz/corpus/NAME seeded from the
# repository; a crash stops the run with its input in build/fuzz/crash-NAME-*: add it to
# tests/fuzz/regressions/NAME/ once fixed.
fuzz: check-deps $(FUZZERS:%=build/fuzz/fuzz_%)
	@mkdir -p $(FUZZERS:%=build/fuzz/corpus/%)
	@cp $(FUZZ_SEEDS_table) build/fuzz/corpus/table/
	@cp $(FUZZ_SEEDS_fitfile) build/fuzz/corpus/fitfile/
	@cp $(FUZZ_SEEDS_scene) build/fuzz/corpus/scene/
	@cp $(FUZZ_SEEDS_args)/* build/fuzz/corpus/args/
	@cp $(FUZZ_SEEDS_merge)/* build/fuzz/corpus/merge/
	@cp $(FUZZ_SEEDS_unitsrow)/* build/fuzz/corpus/unitsrow/
	@for f in $(FUZZERS); do \
	  echo "conifit: fuzzing $$f for $(FUZZ_SECONDS) s"; \
	  build/fuzz/fuzz_$$f -max_total_time=$(FUZZ_SECONDS) -timeout=20 -rss_limit_mb=2048 -close_fd_mask=3 \
	    -print_final_stats=1 -artifact_prefix=build/fuzz/crash-$$f- build/fuzz/corpus/$$f \
	    $$(ls -d tests/fuzz/regressions/$$f 2>/dev/null) 2>build/fuzz/$$f.log \
	    || { tail -n 40 build/fuzz/$$f.log >&2; echo "conifit: fuzzer $$f found a crash" >&2; exit 1; }; \
	  grep -E "stat::number_of_executed_units|stat::peak_rss_mb" build/fuzz/$$f.log; \
	done

clean:
	rm -rf build

# The benchmark program: optimised build of the library plus tests/bench/*.c; writes
# build/bench/report/REPORT.md and its plots (progress on a terminal). BENCH_ARGS=--quick for a
# short smoke run. The committed report in tests/bench/ changes only through make bench-update.
BENCH_OBJ := $(LIB_SRC:src/%.c=build/bench/obj/%.o)
build/bench/obj/%.o: src/%.c
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS) $(CFLAGS) -MMD -MP -c $< -o $@
build/bench/conifit-bench: $(wildcard tests/bench/*.c) tests/bench/bench.h $(BENCH_OBJ)
	$(CC) $(CPPFLAGS) -Itests/bench $(CFLAGS) $(wildcard tests/bench/*.c) $(BENCH_OBJ) -o $@ $(LDFLAGS) $(LDLIBS)
BENCH_OUT := build/bench/report
bench: check-deps build/bench/conifit-bench $(BUILD)/conifit
	@mkdir -p $(BENCH_OUT)
	build/bench/conifit-bench $(BENCH_ARGS) $(BENCH_OUT)
	@echo "conifit: the report is $(BENCH_OUT)/REPORT.md; 'make bench-update' copies it (and its plots) over tests/bench/"
bench-update:
	@test -f $(BENCH_OUT)/REPORT.md || { echo "conifit: no report in $(BENCH_OUT): run make bench first" >&2; exit 1; }
	cp $(BENCH_OUT)/REPORT.md $(BENCH_OUT)/*.png $(BENCH_OUT)/*.dat tests/bench/
