# skybake: the two commands.
#   make demo   install what is missing, build, run the demo on generated data
#   make test   install what is missing, build, run the whole test suite
# Other targets: build, test-fast (labels unit and io), test-gpu (label gpu: on a
# machine with a CUDA device), test-sanitize, fuzz, bench, install, format, clean.

BUILD      ?= build
BUILD_ASAN ?= build-asan
BUILD_TYPE ?= Release
JOBS       ?= $(shell nproc)
PREFIX     ?= /usr/local
CMAKE_FLAGS ?=
GENERATOR  := $(shell command -v ninja >/dev/null 2>&1 && echo "-G Ninja")

.PHONY: all deps configure build test test-fast test-gpu test-sanitize demo bench fuzz install format clean

all: build

deps:
	@./scripts/install-deps.sh

$(BUILD)/CMakeCache.txt:
	cmake -S . -B $(BUILD) $(GENERATOR) -DCMAKE_BUILD_TYPE=$(BUILD_TYPE) $(CMAKE_FLAGS)

configure: deps $(BUILD)/CMakeCache.txt

build: configure
	cmake --build $(BUILD) -j $(JOBS)

test: build
	ctest --test-dir $(BUILD) --output-on-failure -j $(JOBS)
	$(MAKE) --no-print-directory test-sanitize

test-fast: build
	ctest --test-dir $(BUILD) --output-on-failure -j $(JOBS) -L 'unit|io'

# The GPU tests alone, verbosely, on a machine with a CUDA device: with
# SKYBAKE_REQUIRE_GPU=1 a missing or broken device fails them instead of skipping.
test-gpu: build
	SKYBAKE_REQUIRE_GPU=1 ctest --test-dir $(BUILD) --output-on-failure -L gpu -V

# ASan + UBSan build of the I/O tests (label "io"): hostile files must not crash.
# Leaks inside third-party libraries (tools/fuzz/lsan.supp) are suppressed; skybake's are not.
test-sanitize: deps
	cmake -S . -B $(BUILD_ASAN) $(GENERATOR) -DCMAKE_BUILD_TYPE=Debug -DSKYBAKE_SANITIZE=ON \
	  -DSKYBAKE_WITH_CUDA=OFF -DSKYBAKE_WITH_MPI=OFF -DSKYBAKE_BUILD_BENCH=OFF $(CMAKE_FLAGS)
	cmake --build $(BUILD_ASAN) -j $(JOBS) --target skybake_io_test_targets
	ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 LSAN_OPTIONS=suppressions=$(CURDIR)/tools/fuzz/lsan.supp \
	  ctest --test-dir $(BUILD_ASAN) --output-on-failure -j $(JOBS) -L io

demo: build
	./scripts/demo.sh $(BUILD)

bench: build
	./scripts/bench.sh $(BUILD)

# Every parser's libFuzzer target for FUZZ_SECONDS (default 120) each; new
# coverage is merged into tools/fuzz/corpus/, which CI replays (fuzz.replay.*).
fuzz: deps
	FUZZ_SECONDS=$${FUZZ_SECONDS:-120} ./tools/fuzz/run.sh

install: build
	cmake --install $(BUILD) --prefix $(PREFIX)

format:
	find include src apps tests bench tools -name '*.h' -o -name '*.cpp' -o -name '*.cu' | xargs clang-format -i

clean:
	rm -rf $(BUILD) $(BUILD_ASAN)
