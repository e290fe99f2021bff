# qcs: a scene language for rounded polyhedra and soft objects.
#
#   make            build ./qcs
#   make demo       install what is missing, build, run the bundled example
#   make test       install what is missing, build, run every test suite
#   make sanitize   the test suite under ASan + UBSan (clang)
#   make tsan       the threaded tests under ThreadSanitizer (clang)
#   make fuzz       the libFuzzer targets, FUZZ_TIME seconds each
#   make difftest   N random programs (default 5000) through qcs and Hugs 98, SEED=
#   make install    PREFIX=/usr/local DESTDIR=
#
# System packages are installed through apt-get when make runs as root and
# something is missing; otherwise the missing packages are named.

CC      ?= cc
PREFIX  ?= /usr/local
DESTDIR ?=
BUILD   ?= build
OPT     ?= -O2

# Debian packages the build and the tests need.
DEB_PKGS := pkg-config libreadline-dev libgc-dev libpng-dev libopenexr-dev \
            libmpfr-dev libgmp-dev tmux clang hugs libchafa-dev libglib2.0-dev \
            libmicrohttpd-dev parallel openexr python3-yaml libzip-dev \
            zlib1g-dev
PC_PKGS  := readline bdw-gc libpng OpenEXR libzip zlib gmp

WARN   := -Wall -Wextra -Werror -Wshadow -Wstrict-prototypes \
          -Wmissing-prototypes -Wno-unused-parameter
PKG_CFLAGS = $(shell pkg-config --cflags $(PC_PKGS) 2>/dev/null)
PKG_LIBS   = $(shell pkg-config --libs $(PC_PKGS) 2>/dev/null)
# The front end alone draws pictures in the terminal (libchafa).
APP_PC     := chafa libmicrohttpd
APP_CFLAGS = $(shell pkg-config --cflags $(APP_PC) 2>/dev/null)
# Their libraries are loaded when first used (src/app/dynlib.h), not linked:
# a script does not pay for them at start-up.
APP_LIBS   = -ldl
CFLAGS  ?= $(OPT) -g
ALL_CFLAGS = -std=c11 -D_DEFAULT_SOURCE -D_POSIX_C_SOURCE=200809L -DGC_THREADS \
             $(WARN) $(CFLAGS) $(PKG_CFLAGS) -MMD -MP -Isrc -I$(BUILD)
LIBS    = $(PKG_LIBS) -lm -lpthread

# (The layer libraries' prerequisites are computed per target.)
.SECONDEXPANSION:

# The layers, each a folder of src/ and a static library, from the ground
# up (see README.md, "Layout"); tools/check-layers.sh fails the build on an
# include that crosses a layer the wrong way.
LAYERS  := core scene render lang bind study
LIB_ORDER := study bind lang render scene core
SRCS    := $(sort $(wildcard $(LAYERS:%=src/%/*.c) src/app/*.c))
OBJS    := $(SRCS:src/%.c=$(BUILD)/%.o)
APP_OBJS := $(filter $(BUILD)/app/%,$(OBJS))
layer_objs = $(filter $(BUILD)/$(1)/%,$(OBJS))
LAYER_LIBS := $(LIB_ORDER:%=$(BUILD)/libqcs%.a)
CORE_LIB := $(BUILD)/libqcscore.a
UNIT_SRCS := $(sort $(wildcard tests/unit/test_*.c))
UNIT_BINS := $(UNIT_SRCS:tests/unit/%.c=$(BUILD)/tests/%)
# Kernel tests: they link the geometry core alone (no interpreter, no GC).
KERNEL_TESTS := test_bounds test_density test_poly test_roots test_soft
KERNEL_BINS := $(KERNEL_TESTS:%=$(BUILD)/tests/%)
# The numerical stability suite (issue 6): same harness, MPFR references.
STAB_SRCS := $(sort $(wildcard tests/stability/test_*.c))
UNIT_BINS += $(STAB_SRCS:tests/stability/%.c=$(BUILD)/tests/%)
# The fuzz targets of fuzz/ as plain programs that replay fuzz/corpus/.
REPLAY_BINS := $(patsubst %,$(BUILD)/fuzz/replay_%,parse eval probes image render)

.PHONY: all units deps demo test check sanitize tsan install uninstall clean bench update-references gallery lesson-pictures layers difftest

BIN ?= qcs

all: $(BIN)

# qcs itself is linked without libzip and readline: src/app/zipload.c
# loads libzip when a 3MF file is first written, src/app/repl.c readline
# when the prompt first runs on a terminal (the tests, without app/, link
# both as the layers' users would).
$(BIN): $(APP_OBJS) $(LAYER_LIBS) $(BUILD)/layers.ok
	$(CC) $(ALL_CFLAGS) -o $@ $(APP_OBJS) $(LAYER_LIBS) $(filter-out -lzip -lreadline,$(LIBS)) $(APP_LIBS)

$(APP_OBJS): ALL_CFLAGS += $(APP_CFLAGS)

# One static library per layer.
$(BUILD)/libqcs%.a: $$(call layer_objs,%)
	@rm -f $@
	$(AR) rcs $@ $^

# The layering rule, checked on every build.
$(BUILD)/layers.ok: tools/check-layers.sh $(wildcard src/*/*.c src/*/*.h)
	@mkdir -p $(BUILD)
	@sh tools/check-layers.sh src
	@touch $@

layers: $(BUILD)/layers.ok

units: $(UNIT_BINS) $(REPLAY_BINS)

# The layers' own code is also clean under -Wconversion (gcc and clang);
# tests and fuzz targets are not held to it.
$(OBJS): ALL_CFLAGS += -Wconversion

# The tracer's kernels at -O3 (unless OPT is given on the command line, as
# the sanitizer builds do): about 5% fewer instructions on the rounded
# scenes, the same pictures bit for bit (no fast-math, no contraction).
HOT_OBJS := $(filter $(BUILD)/core/%,$(OBJS)) $(BUILD)/scene/ray.o \
            $(BUILD)/render/render.o $(BUILD)/render/camera.o
$(HOT_OBJS): OPT = -O3

$(BUILD)/%.o: src/%.c | $(BUILD)/prelude.inc $(BUILD)/kit.inc
	@mkdir -p $(dir $@)
	$(CC) $(ALL_CFLAGS) -c -o $@ $<

# The viewer's page (HTML, CSS, JavaScript), embedded as the prelude is.
$(BUILD)/view_page.inc: src/app/view_page.html tools/embed.sh
	@mkdir -p $(BUILD)
	sh tools/embed.sh qcs_view_page src/app/view_page.html < $< > $@.tmp && mv $@.tmp $@

$(BUILD)/app/view.o: $(BUILD)/view_page.inc

# The prelude is qcs source, embedded in the binary as a C string.
$(BUILD)/prelude.inc: stdlib/prelude.qcs tools/embed.sh
	@mkdir -p $(BUILD)
	sh tools/embed.sh qcs_prelude_source < $< > $@.tmp && mv $@.tmp $@

# The modeller's kit (solids, transforms, patterns), loaded after it.
$(BUILD)/kit.inc: stdlib/kit.qcs tools/embed.sh
	@mkdir -p $(BUILD)
	sh tools/embed.sh qcs_kit_source stdlib/kit.qcs < $< > $@.tmp && mv $@.tmp $@

$(KERNEL_BINS): $(BUILD)/tests/%: tests/unit/%.c $(CORE_LIB) tests/unit/check.h
	@mkdir -p $(BUILD)/tests
	$(CC) $(ALL_CFLAGS) -Itests/unit -o $@ $< $(CORE_LIB) -lm -lmpfr -lgmp

$(BUILD)/tests/%: tests/unit/%.c $(LAYER_LIBS) tests/unit/check.h
	@mkdir -p $(BUILD)/tests
	$(CC) $(ALL_CFLAGS) -Itests/unit -o $@ $< $(LAYER_LIBS) $(LIBS) -lmpfr -lgmp

$(BUILD)/tests/%: tests/stability/%.c $(LAYER_LIBS) tests/unit/check.h
	@mkdir -p $(BUILD)/tests
	$(CC) $(ALL_CFLAGS) -Itests/unit -Itests/stability -o $@ $< $(LAYER_LIBS) $(LIBS) -lmpfr -lgmp

# deps: install (as root) or name the missing Debian packages.
deps:
	@missing=""; for p in $(DEB_PKGS); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q 'ok installed' || missing="$$missing $$p"; \
	done; \
	if [ -n "$$missing" ]; then \
	  if [ "$$(id -u)" = 0 ]; then \
	    echo "installing:$$missing"; \
	    (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $$missing) >/dev/null || \
	      { echo "error: apt-get could not install:$$missing" >&2; exit 1; }; \
	  else \
	    echo "error: missing Debian packages:$$missing" >&2; \
	    echo "       run 'sudo apt-get install$$missing' or run make as root" >&2; exit 1; \
	  fi; \
	fi

demo: deps
	@$(MAKE) -s qcs
	./qcs examples/demo.qcs
	@mkdir -p gallery
	./qcs -o gallery/figure12.png examples/figure12.qcs
	./qcs -o gallery/figure12.exr examples/figure12.qcs
	@echo "pictures: gallery/figure12.png and gallery/figure12.exr"


# The viewer's tests drive a real browser (tests/suite-view.sh).
TEST_DEB_PKGS := chromium
.PHONY: test-deps
test-deps:
	@dpkg-query -W -f='$${Status}' $(TEST_DEB_PKGS) 2>/dev/null | grep -q 'ok installed' || \
	  if [ "$$(id -u)" = 0 ]; then \
	    echo "installing: $(TEST_DEB_PKGS)"; \
	    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $(TEST_DEB_PKGS) >/dev/null || \
	      echo "note: apt-get could not install $(TEST_DEB_PKGS): the browser tests are skipped"; \
	  else \
	    echo "note: $(TEST_DEB_PKGS) is not installed: the browser tests are skipped"; \
	  fi

# suite-mesh.sh reads meshes back with admesh and OpenSCAD (under xvfb-run;
# openscad is 40 packages, 88.5 MB installed, about 35 s to install; xvfb
# 16 MB), each skipped without it.
MESH_TEST_PKGS := admesh openscad xvfb xauth
.PHONY: test-deps-mesh
test-deps-mesh:
	@for p in $(MESH_TEST_PKGS); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q 'ok installed' || \
	  { [ "$$(id -u)" = 0 ] && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $$p >/dev/null 2>&1; } || \
	  echo "note: $$p is not installed: its mesh read-back tests are skipped"; \
	done

# suite-editors.sh loads the highlighting in Vim and Emacs (skipped without them).
.PHONY: test-deps-editors
test-deps-editors:
	@for p in vim emacs-nox; do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q 'ok installed' || \
	  { [ "$$(id -u)" = 0 ] && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $$p >/dev/null 2>&1; } || \
	  echo "note: $$p is not installed: its editor test is skipped"; \
	done

test: deps test-deps test-deps-mesh test-deps-editors
	@$(MAKE) -s $(BIN) units
	@sh tests/run-all.sh

check: test

# difftest: N random programs of the subset qcs shares with Haskell 98,
# run through qcs and Hugs (runhugs) and compared value by value (issue
# 20); every disagreement prints both programs. make test runs 300.
N    ?= 5000
SEED ?= 1
difftest: deps
	@$(MAKE) -s $(BIN)
	@python3 tests/difftest/difftest.py -n $(N) --seed $(SEED) --qcs ./$(BIN)

# Every rendering example to gallery/NAME.png and gallery/NAME.exr.
gallery: deps
	@$(MAKE) -s qcs
	@mkdir -p gallery
	@for f in examples/*.qcs; do \
	  grep -q -E '^[^/]*render(With)? ' $$f || continue; \
	  n=$$(basename $$f .qcs); \
	  ./qcs -o gallery/$$n.png $$f > /dev/null 2> gallery/$$n.log && \
	  ./qcs -o gallery/$$n.exr $$f > /dev/null 2>> gallery/$$n.log && \
	  echo "gallery/$$n.png gallery/$$n.exr: $$(grep -m1 " sample" gallery/$$n.log | sed 's/^[^:]*: //')" || \
	  { echo "error: $$f:"; cat gallery/$$n.log; exit 1; }; \
	done

# The lessons' pictures for the README (doc/images/lessons/): needs
# chromium and ImageMagick.
lesson-pictures:
	@$(MAKE) -s qcs
	@sh tools/lesson-pictures.sh

# bench: qcs timed side by side with POV-Ray 3.7 (issue 7); see bench/README.md.
# POV-Ray (Debian package povray) is installed as root if missing; without it
# bench/run.sh times qcs alone and says so. BENCH_ARGS go to bench/run.sh (default -c: callgrind counts too).
BENCH_ARGS ?= -c
.PHONY: bench-callgrind
bench: deps
	@$(MAKE) -s $(BIN)
	@dpkg-query -W -f='$${Status}' povray 2>/dev/null | grep -q 'ok installed' || \
	  if [ "$$(id -u)" = 0 ]; then \
	    echo "installing: povray"; \
	    (DEBIAN_FRONTEND=noninteractive apt-get install -y -qq povray || \
	     (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq povray)) >/dev/null 2>&1 || \
	      echo "note: apt-get could not install povray: the POV-Ray half of the bench is skipped"; \
	  else \
	    echo "note: povray is not installed (run 'sudo apt-get install povray' or make bench as root): the POV-Ray half is skipped"; \
	  fi
	@QCS=./$(BIN) bash bench/run.sh $(BENCH_ARGS)
	@python3 bench/view_bench.py ./$(BIN) examples/figure12.qcs

# Instruction counts per scene under callgrind (150x95, one thread): bench/callgrind.csv.
bench-callgrind: deps
	@$(MAKE) -s $(BIN)
	@dpkg-query -W -f='$${Status}' valgrind 2>/dev/null | grep -q 'ok installed' || \
	  { [ "$$(id -u)" = 0 ] && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq valgrind >/dev/null 2>&1; } || \
	  echo "note: valgrind is not installed"
	@QCS=./$(BIN) bash bench/callgrind.sh

# After a deliberate change to the pictures: look at them, then refresh.
update-references: qcs units
	@mkdir -p tests/images
	QCS_UPDATE_REFERENCES=1 build/tests/test_render

# Leak checks are off for the test set as a whole (detect_leaks=0), but
# the viewer's processes turn them on for themselves (tests/view/viewtest.py:
# a leak fails view-stop). Checked 2026-11-25 with detect_leaks=1: the
# language suite (268 scripts), the 13 examples and the REPL report none.
SAN_FLAGS := -g -fsanitize=address,undefined -fno-sanitize-recover=all
sanitize: deps
	@$(MAKE) -s BUILD=build-san BIN=build-san/qcs CC=clang \
	  OPT="-O1 -fno-omit-frame-pointer" CFLAGS="$(SAN_FLAGS)" build-san/qcs units
	@QCS=build-san/qcs QCS_UNIT_DIR=build-san/tests \
	  ASAN_OPTIONS=detect_leaks=0 UBSAN_OPTIONS=print_stacktrace=1 sh tests/run-all.sh

# tsan: the multi-threaded parts under ThreadSanitizer (clang): the render,
# fast-path and image (the PNG writer's threads) unit tests, every
# rendering example on 4 threads and the REPL suite (tests/tsan.sh); any
# report fails it (halt_on_error=1).
TSAN_FLAGS := -g -fsanitize=thread
.PHONY: tsan
tsan: deps
	@$(MAKE) -s BUILD=build-tsan BIN=build-tsan/qcs CC=clang \
	  OPT="-O1 -fno-omit-frame-pointer" CFLAGS="$(TSAN_FLAGS)" \
	  build-tsan/qcs build-tsan/tests/test_render build-tsan/tests/test_fastpaths \
	  build-tsan/tests/test_image
	@QCS=build-tsan/qcs QCS_UNIT_DIR=build-tsan/tests sh tests/tsan.sh

# fuzz: the libFuzzer targets of fuzz/ (clang, ASan + UBSan), each run for
# FUZZ_TIME seconds; see fuzz/README.md. FUZZ_TARGETS picks some of them.
FUZZ_TARGETS ?= parse eval probes image render
FUZZ_TIME    ?= 60
FUZZ_FLAGS   := -g -fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=all
.PHONY: fuzz fuzz-build fuzz-bins
fuzz: fuzz-build
	@FUZZ_TIME=$(FUZZ_TIME) sh fuzz/run.sh $(FUZZ_TARGETS)

fuzz-build: deps
	@$(MAKE) -s BUILD=build-fuzz CC=clang OPT="-O1 -fno-omit-frame-pointer" \
	  CFLAGS="$(FUZZ_FLAGS)" fuzz-bins

fuzz-bins: $(FUZZ_TARGETS:%=$(BUILD)/fuzz/fuzz_%)

# The same targets without libFuzzer, to replay fuzz/corpus/ in make test.
$(BUILD)/fuzz/replay_%: fuzz/fuzz_%.c fuzz/replay.c fuzz/fuzz.h $(LAYER_LIBS)
	@mkdir -p $(BUILD)/fuzz
	$(CC) $(ALL_CFLAGS) -Ifuzz -o $@ $< fuzz/replay.c $(LAYER_LIBS) $(LIBS)

$(BUILD)/fuzz/fuzz_%: fuzz/fuzz_%.c fuzz/fuzz.h $(LAYER_LIBS)
	@mkdir -p $(BUILD)/fuzz
	$(CC) $(ALL_CFLAGS) -fsanitize=fuzzer -Ifuzz -o $@ $< $(LAYER_LIBS) $(LIBS)

# import "NAME" looks in $(PREFIX)/share/qcs last (after QCS_PATH).
$(BUILD)/lang/interp.o: ALL_CFLAGS += -DQCS_LIBDIR='"$(PREFIX)/share/qcs"'

install: qcs
	install -d $(DESTDIR)$(PREFIX)/bin $(DESTDIR)$(PREFIX)/share/qcs \
	  $(DESTDIR)$(PREFIX)/share/man/man1
	install -m 755 qcs $(DESTDIR)$(PREFIX)/bin/qcs
	install -m 644 stdlib/prelude.qcs $(DESTDIR)$(PREFIX)/share/qcs/prelude.qcs
	install -m 644 stdlib/kit.qcs $(DESTDIR)$(PREFIX)/share/qcs/kit.qcs
	install -m 644 examples/parts/*.qcs $(DESTDIR)$(PREFIX)/share/qcs/
	install -m 644 doc/qcs.1 $(DESTDIR)$(PREFIX)/share/man/man1/qcs.1
	@# Editor support (editors/README.md): where Vim and Emacs look, and a
	@# copy of every file in share/qcs/editors for the rest.
	install -d $(DESTDIR)$(PREFIX)/share/vim/vimfiles/syntax \
	  $(DESTDIR)$(PREFIX)/share/vim/vimfiles/ftdetect \
	  $(DESTDIR)$(PREFIX)/share/emacs/site-lisp \
	  $(DESTDIR)$(PREFIX)/share/qcs/editors/vim/syntax \
	  $(DESTDIR)$(PREFIX)/share/qcs/editors/vim/ftdetect \
	  $(DESTDIR)$(PREFIX)/share/qcs/editors/textmate $(DESTDIR)$(PREFIX)/share/qcs/editors/emacs
	install -m 644 editors/vim/syntax/qcs.vim $(DESTDIR)$(PREFIX)/share/vim/vimfiles/syntax/qcs.vim
	install -m 644 editors/vim/ftdetect/qcs.vim $(DESTDIR)$(PREFIX)/share/vim/vimfiles/ftdetect/qcs.vim
	install -m 644 editors/emacs/qcs-mode.el $(DESTDIR)$(PREFIX)/share/emacs/site-lisp/qcs-mode.el
	install -m 644 editors/README.md $(DESTDIR)$(PREFIX)/share/qcs/editors/README.md
	install -m 644 editors/vim/syntax/qcs.vim $(DESTDIR)$(PREFIX)/share/qcs/editors/vim/syntax/qcs.vim
	install -m 644 editors/vim/ftdetect/qcs.vim $(DESTDIR)$(PREFIX)/share/qcs/editors/vim/ftdetect/qcs.vim
	install -m 644 editors/textmate/*.json $(DESTDIR)$(PREFIX)/share/qcs/editors/textmate/
	install -m 644 editors/emacs/qcs-mode.el $(DESTDIR)$(PREFIX)/share/qcs/editors/emacs/qcs-mode.el
	@echo "editors: Vim syntax in $(PREFIX)/share/vim/vimfiles$(if $(filter /usr,$(PREFIX)),, (add it to Vim's runtimepath: set rtp+=$(PREFIX)/share/vim/vimfiles))"
	@echo "editors: Emacs qcs-mode.el in $(PREFIX)/share/emacs/site-lisp ((require 'qcs-mode))"
	@echo "editors: VS Code: cp -r $(PREFIX)/share/qcs/editors/textmate ~/.vscode/extensions/qcs"

uninstall:
	rm -f $(DESTDIR)$(PREFIX)/bin/qcs $(DESTDIR)$(PREFIX)/share/man/man1/qcs.1
	rm -f $(DESTDIR)$(PREFIX)/share/vim/vimfiles/syntax/qcs.vim \
	  $(DESTDIR)$(PREFIX)/share/vim/vimfiles/ftdetect/qcs.vim \
	  $(DESTDIR)$(PREFIX)/share/emacs/site-lisp/qcs-mode.el
	rm -rf $(DESTDIR)$(PREFIX)/share/qcs

clean:
	rm -rf $(BUILD) build-san build-tsan build-fuzz qcs

-include $(OBJS:.o=.d)
# The test binaries and fuzz replays are built straight from their .c with
# -MMD: their .d files make a change to a header they include rebuild them.
-include $(UNIT_BINS:=.d) $(REPLAY_BINS:=.d)
