# vsgl-indirect build. `make help` lists the targets.
#
# Python: the C library is tested from Debian's /usr/bin/python3 (the one
# Debian's Blender 3.4 embeds, with python3-numpy/python3-pytest). The
# newest Blender-as-a-module (`bpy` from PyPI) is tested from $(BPY_PYTHON),
# the pyenv python3 on PATH, into which tools/ installs bpy with pip.
SHELL := /bin/bash
.DEFAULT_GOAL := all

CC      ?= cc
PYTHON  ?= /usr/bin/python3
BPY_PYTHON ?= python3
BUILD   := build
# `=`, not `:=`: OpenEXR's include path is asked for when a recipe runs, after the
# `deps` prerequisite has installed libopenexr-dev on a fresh machine (asked at
# parse time it was empty there, and the first `make` failed on io/exr.c)
INCLUDES = -Icsrc/include -Icsrc/src $(shell pkg-config --cflags-only-I OpenEXR 2>/dev/null)
WARN    := -Wall -Wextra -Wpedantic -Wshadow -Wstrict-prototypes -Wmissing-prototypes
CFLAGS_COMMON = -std=c11 -D_POSIX_C_SOURCE=200809L -DVSGL_BUILDING -fPIC -fvisibility=hidden $(WARN) $(INCLUDES)
OPT     ?= -O2 -g
LDLIBS  := -lembree3 -lOpenEXRCore-3_1 -ldeflate -lpthread -lm

LIB_SRC  := $(sort $(wildcard csrc/src/*/*.c))
TEST_SRC := $(sort $(wildcard tests/c/*.c))
CLI_SRC  := $(sort $(wildcard csrc/cli/*.c))
HEADERS  := $(sort $(wildcard csrc/include/*.h csrc/include/vsgl/*.h))

LIB_OBJ  := $(LIB_SRC:%.c=$(BUILD)/obj/%.o)
TEST_OBJ := $(TEST_SRC:%.c=$(BUILD)/obj/%.o)
ASAN_LIB_OBJ  := $(LIB_SRC:%.c=$(BUILD)/asan/%.o)
ASAN_TEST_OBJ := $(TEST_SRC:%.c=$(BUILD)/asan/%.o)

.PHONY: all help deps test test-c test-python test-blender asan demo bench lint abi clean headers-cxx check-exports

all: $(BUILD)/libvsgl.so check-exports headers-cxx $(if $(CLI_SRC),$(BUILD)/vsgl)

help:
	@echo "make            build build/libvsgl.so (and the CLI build/vsgl)"
	@echo "make demo       the main job on the bundled demo scene (writes out/demo/)"
	@echo "make test       every test suite; ends with 'N passed, N failed'"
	@echo "make asan       C tests under AddressSanitizer + UBSan (clang)"
	@echo "make bench      speed/memory benchmarks, reported as ratios"
	@echo "make screenshots  the add-on's panels in Blender's UI under Xvfb -> docs/img/"
	@echo "make lint       flake8 (setup.cfg), cppcheck over the sources, the kernel's loops vectorised"
	@echo "make broad-lobe-table  regenerate csrc/src/math/broad_lobe_table.c (rough receivers' lobes)"
	@echo "make abi        regenerate the binding's ABI mirror (addon/vsgl_indirect/_libvsgl_abi.py) from the headers"

deps:
	@tools/deps.sh build

$(BUILD)/obj/%.o: %.c $(HEADERS) | deps
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_COMMON) $(OPT) -MMD -MP -c $< -o $@

# RPATH (not RUNPATH: it also applies to the dependencies' own dependencies,
# e.g. embree -> tbb) $ORIGIN: the add-on zip ships libembree3, libOpenEXRCore
# and libtbb beside libvsgl.so (tools/build_addon.sh); a build/ without them
# falls back to the system's.
$(BUILD)/libvsgl.so: $(LIB_OBJ)
	$(CC) -shared -o $@ $^ $(LDLIBS) -Wl,-rpath,'$$ORIGIN' -Wl,--disable-new-dtags

$(BUILD)/vsgl: $(CLI_SRC) $(BUILD)/libvsgl.so
	$(CC) $(CFLAGS_COMMON) $(OPT) -o $@ $(CLI_SRC) -L$(BUILD) -lvsgl -Wl,-rpath,'$$ORIGIN' -lm

# Only vsgl_-prefixed symbols may leave the library.
check-exports: $(BUILD)/libvsgl.so
	@bad=$$(nm -D --defined-only $< | awk '{print $$3}' | grep -v '^vsgl_' | grep -v '^_' || true); \
	if [ -n "$$bad" ]; then echo "exported symbols without the vsgl_ prefix: $$bad"; exit 1; fi

# Every public header compiles on its own as C and as C++.
headers-cxx: $(HEADERS)
	@mkdir -p $(BUILD)
	@for h in $(HEADERS); do \
	  echo "#include \"$$(realpath $$h)\"" > $(BUILD)/hdr.c; \
	  $(CC) -std=c11 $(WARN) -Icsrc/include -fsyntax-only $(BUILD)/hdr.c || exit 1; \
	  cp $(BUILD)/hdr.c $(BUILD)/hdr.cpp; \
	  c++ -std=c++11 -Wall -Wextra -Wpedantic -Icsrc/include -fsyntax-only $(BUILD)/hdr.cpp || exit 1; \
	done; touch $@ 2>/dev/null; true

$(BUILD)/tests/vsgl_tests: $(TEST_OBJ) $(LIB_OBJ)
	@mkdir -p $(dir $@)
	$(CC) -o $@ $^ $(LDLIBS)

test:
	@tools/deps.sh test
	@$(MAKE) --no-print-directory all $(BUILD)/tests/vsgl_tests >/dev/null
	@PYTHON=$(PYTHON) BPY_PYTHON=$(BPY_PYTHON) tools/run_tests.sh

test-c: $(BUILD)/tests/vsgl_tests
	$(BUILD)/tests/vsgl_tests $(T)

test-python: $(BUILD)/libvsgl.so
	$(PYTHON) -m pytest -q tests/python $(T)

# AddressSanitizer + UndefinedBehaviorSanitizer build of the C tests.
ASAN_FLAGS := -O1 -g -fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=undefined
$(BUILD)/asan/%.o: %.c $(HEADERS)
	@mkdir -p $(dir $@)
	clang $(CFLAGS_COMMON) $(ASAN_FLAGS) -MMD -MP -c $< -o $@

$(BUILD)/asan/vsgl_tests: $(ASAN_TEST_OBJ) $(ASAN_LIB_OBJ)
	clang $(ASAN_FLAGS) -o $@ $^ $(LDLIBS)

asan:
	@tools/deps.sh asan
	@$(MAKE) --no-print-directory $(BUILD)/asan/vsgl_tests
	ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
	  VSGL_TEST_QUICK=1 $(BUILD)/asan/vsgl_tests $(T)

demo:
	@tools/deps.sh demo
	@tools/demo.sh

bench:
	@tools/deps.sh bench
	@$(MAKE) --no-print-directory all
	@tools/bench.sh

# Debian's flake8 and cppcheck (tools/deps.sh lint); both must report nothing.
lint:
	@tools/deps.sh lint
	/usr/bin/python3 -m flake8 addon tests tools
	cppcheck --quiet --error-exitcode=1 --std=c11 --enable=warning,portability,performance --inline-suppr \
	  -D__GNUC__ -I csrc/include -I csrc/src csrc/src csrc/cli
	$(PYTHON) tools/check_vectorised.py --cc $(CC)

# The broad-lobe tables (csrc/src/math/broad_lobe_table.c, docs/math.md
# §5.4.4) from the library's own lobe and BRDF: about 2.5 min.
.PHONY: broad-lobe-table
$(BUILD)/gen_broad_lobe: tools/gen_broad_lobe.c $(LIB_OBJ)
	$(CC) $(CFLAGS_COMMON) -Itests/c $(OPT) -o $@ $^ $(LDLIBS)
broad-lobe-table: $(BUILD)/gen_broad_lobe
	$(BUILD)/gen_broad_lobe --write

# The binding's ABI mirror (enums, constants, structs, prototypes) from the
# public headers; tests/python/test_layout.py fails when it is not current.
abi:
	$(PYTHON) tools/gen_abi.py

clean:
	rm -rf $(BUILD)

-include $(LIB_OBJ:.o=.d) $(TEST_OBJ:.o=.d) $(ASAN_LIB_OBJ:.o=.d) $(ASAN_TEST_OBJ:.o=.d)

# The shading kernel: vectorised with ISA clones (kernel.c) and a scalar
# build of the same source (kernel_scalar.c) for the benchmark baseline.
# Unsafe maths is scoped to this one file: it lets GCC use reciprocal and
# reciprocal-square-root estimates plus a Newton step (-mrecip) instead of
# divisions, which cost ~10x more here; the kernel has no NaN/Inf logic
# (its inputs are validated and clamped) and tests bound its error.
KERNEL_MATH := -fno-math-errno -fno-trapping-math -funsafe-math-optimizations -ffinite-math-only -mrecip
$(BUILD)/obj/csrc/src/shade/kernel.o: OPT += -O3 $(KERNEL_MATH)
$(BUILD)/obj/csrc/src/shade/kernel_scalar.o: OPT += -fno-math-errno -fno-trapping-math
# Visibility against a few occluders (scene/occlude_few.c): vectorised over a batch's segments.
$(BUILD)/obj/csrc/src/scene/occlude_few.o: OPT += -O3 -fno-math-errno -fno-trapping-math
# Receivers' glossy lobes (math/warp_lanes.c): vectorised over a block's receivers, the same flags.
$(BUILD)/obj/csrc/src/math/warp_lanes.o: OPT += -O3 -fno-math-errno -fno-trapping-math
# The tests' per-ISA copies of the kernel (tests/c/kernel_isa*.c) take the
# library kernel's flags, so that they check the arithmetic that ships.
$(BUILD)/obj/tests/c/kernel_isa%.o: OPT += -O3 $(KERNEL_MATH)

# libFuzzer + ASan + UBSan on the scene-bundle reader (tests/fuzz/), for
# FUZZ_SECONDS seconds each target from a seed corpus the library writes (CRC checks
# are skipped in this build so mutations reach the structural checks). Findings are
# saved as $(BUILD)/fuzz/crash-* and make the target fail.
.PHONY: fuzz
FUZZ_SECONDS ?= 60
FUZZ_LIB_SRC := csrc/src/io/bundle.c csrc/src/io/atomic.c csrc/src/core/context.c csrc/src/core/result.c \
  csrc/src/core/versioned.c
FUZZ_FLAGS := -O1 -g -fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=undefined
$(BUILD)/fuzz/fuzz_bundle: tests/fuzz/fuzz_bundle.c $(FUZZ_LIB_SRC) $(HEADERS)
	@mkdir -p $(dir $@)
	clang $(CFLAGS_COMMON) $(FUZZ_FLAGS) -fsanitize=fuzzer -DFUZZING_BUILD_MODE_UNSAFE_FOR_PRODUCTION -o $@ tests/fuzz/fuzz_bundle.c $(FUZZ_LIB_SRC) -lm
$(BUILD)/fuzz/make_corpus: tests/fuzz/make_corpus.c $(FUZZ_LIB_SRC) $(HEADERS)
	@mkdir -p $(dir $@)
	clang $(CFLAGS_COMMON) $(FUZZ_FLAGS) -o $@ tests/fuzz/make_corpus.c $(FUZZ_LIB_SRC) -lm
# Issue 10: also scene validation + the render on whatever the reader accepts
# (fuzz_scene: the whole library) and the CLI's option parser (fuzz_cli).
$(BUILD)/fuzz/fuzz_scene: tests/fuzz/fuzz_scene.c $(LIB_SRC) $(HEADERS)
	@mkdir -p $(dir $@)
	clang $(CFLAGS_COMMON) $(FUZZ_FLAGS) -fsanitize=fuzzer -DFUZZING_BUILD_MODE_UNSAFE_FOR_PRODUCTION -o $@ tests/fuzz/fuzz_scene.c $(LIB_SRC) $(LDLIBS)
FUZZ_CLI_SRC := csrc/cli/options.c csrc/src/render/settings.c csrc/src/core/context.c csrc/src/core/result.c \
  csrc/src/core/versioned.c
$(BUILD)/fuzz/fuzz_cli: tests/fuzz/fuzz_cli.c $(FUZZ_CLI_SRC) $(HEADERS) csrc/cli/options.h
	@mkdir -p $(dir $@)
	clang $(CFLAGS_COMMON) -Icsrc/cli $(FUZZ_FLAGS) -fsanitize=fuzzer -o $@ tests/fuzz/fuzz_cli.c $(FUZZ_CLI_SRC) -lm
FUZZ_RUN := UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 ASAN_OPTIONS=detect_leaks=1
fuzz:
	@tools/deps.sh asan
	@$(MAKE) --no-print-directory $(BUILD)/fuzz/fuzz_bundle $(BUILD)/fuzz/make_corpus $(BUILD)/fuzz/fuzz_scene $(BUILD)/fuzz/fuzz_cli
	@mkdir -p $(BUILD)/fuzz/corpus $(BUILD)/fuzz/corpus_scene $(BUILD)/fuzz/corpus_cli
	$(BUILD)/fuzz/make_corpus $(BUILD)/fuzz/corpus
	cp -n $(BUILD)/fuzz/corpus/* $(BUILD)/fuzz/corpus_scene/
	tools/fuzz_cli_seeds.sh $(BUILD)/fuzz/corpus_cli
	$(BUILD)/fuzz/fuzz_bundle tests/fuzz/regressions/*
	$(BUILD)/fuzz/fuzz_scene tests/fuzz/regressions_scene/*
	$(BUILD)/fuzz/fuzz_cli tests/fuzz/regressions_cli/*
	$(FUZZ_RUN) $(BUILD)/fuzz/fuzz_bundle -max_total_time=$(FUZZ_SECONDS) \
	  -dict=tests/fuzz/bundle.dict -artifact_prefix=$(BUILD)/fuzz/ -print_final_stats=1 $(BUILD)/fuzz/corpus
	$(FUZZ_RUN) $(BUILD)/fuzz/fuzz_scene -max_total_time=$(FUZZ_SECONDS) -timeout=30 -rss_limit_mb=4096 \
	  -dict=tests/fuzz/bundle.dict -artifact_prefix=$(BUILD)/fuzz/scene- -print_final_stats=1 $(BUILD)/fuzz/corpus_scene
	$(FUZZ_RUN) $(BUILD)/fuzz/fuzz_cli -max_total_time=$(FUZZ_SECONDS) \
	  -dict=tests/fuzz/cli.dict -artifact_prefix=$(BUILD)/fuzz/cli- -print_final_stats=1 $(BUILD)/fuzz/corpus_cli

# The add-on's panels, compositor setup and preview in Blender's real UI under
# Xvfb (issue 15): docs/img/panel*.png, compositor.png, preview.png.
.PHONY: screenshots
screenshots: $(BUILD)/libvsgl.so
	@tools/panel_screenshots.sh

# Blender add-on zip (issue 5): build/vsgl_indirect.zip with lib/libvsgl.so inside.
.PHONY: addon
addon: $(BUILD)/libvsgl.so
	@tools/build_addon.sh
