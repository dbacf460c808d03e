# Chimera's front door. On a fresh Debian 12 machine:
#   make demo    install what is missing, build, run the Figure 4 demo
#   make test    install what is missing, build and test: plain, ASAN+UBSAN, TSAN trees, a fuzz pass
# `make help` lists the other targets. CI runs .ci/run (= make test) with CI=true, which
# turns compiler warnings into errors.

SHELL := /bin/bash
.SHELLFLAGS := -euo pipefail -c
.DEFAULT_GOAL := build
# The targets share build trees and apt; run them in the order given, never in parallel.
.NOTPARALLEL:

JOBS ?= 2
BUILD_DIR ?= build
ASAN_DIR ?= build-asan
TSAN_DIR ?= build-tsan
FUZZ_DIR ?= build-fuzz
FUZZ_SECONDS ?= 60
BENCH_DIR ?= build-bench
BUILD_TYPE ?= RelWithDebInfo
export JOBS BUILD_DIR ASAN_DIR TSAN_DIR FUZZ_DIR

# The main job. It may change as the demo grows; everything else refers to this variable.
DEMO_CMD ?= scripts/demo.sh $(BUILD_DIR) 5

# What `make format` and `make tidy` look at.
FORMAT_DIRS := include src modules sim apps tests bench
TIDY_DIRS ?= src modules sim apps

.PHONY: help setup setup-lint setup-bench build build-bench test check fuzz demo bench bench-quick soak format format-check tidy clean

help:
	@echo "make demo          install missing packages, build, run the demo (DEMO_CMD)"
	@echo "make test          build and test $(BUILD_DIR)/, then ASAN+UBSAN ($(ASAN_DIR)/), TSAN ($(TSAN_DIR)/), a short fuzz pass ($(FUZZ_DIR)/)"
	@echo "make build         configure and build $(BUILD_DIR)/ ($(BUILD_TYPE), Ninja, ccache if present)"
	@echo "make check         only the sanitizer trees of make test"
	@echo "make fuzz          build the libFuzzer targets ($(FUZZ_DIR)/, clang), fuzz each FUZZ_SECONDS=$(FUZZ_SECONDS) s; fails on any finding"
	@echo "make bench         Release build in $(BENCH_DIR)/, run every benchmark (~5 min), write bench/results/latest.{json,md}"
	@echo "make bench-quick   the same, short (under a minute once built); report in $(BENCH_DIR)/bench-results/quick/"
	@echo "make soak          Figure 4 with its logger and the flight recorder for an hour (SOAK_SECONDS) on the real clock: memory, lost rows, misses; into the bench report"
	@echo "make format        clang-format the sources in place; format-check only reports"
	@echo "make tidy          clang-tidy over $(TIDY_DIRS)/ (fails on any finding)"
	@echo "make setup         install the missing Debian packages (scripts/packages.txt)"
	@echo "make clean         remove the build trees"
	@echo "Variables: JOBS=$(JOBS)  CI=true (warnings are errors)  TEST_TIMEOUT=seconds per test"

# Quiet and a few milliseconds when nothing is missing, so it simply runs every time.
setup:
	@bash scripts/setup.sh
	@bash scripts/setup-browser.sh

setup-lint:
	@bash scripts/setup.sh lint

# The benchmarks' peers (iceoryx, Cyclone DDS): an optional group, so that `make test` never installs them.
setup-bench:
	@bash scripts/setup.sh bench

build: setup
	@bash scripts/build.sh $(BUILD_DIR) -DCMAKE_BUILD_TYPE=$(BUILD_TYPE)

test: setup
	@bash scripts/test.sh main asan tsan fuzz

check: setup
	@bash scripts/test.sh asan tsan

# Findings (crash-*, leak-*, timeout-*) land in $(FUZZ_DIR)/fuzz-work/NAME/; docs/fuzzing.md says
# how one becomes a regression input.
fuzz: setup
	@FUZZ_SECONDS=$(FUZZ_SECONDS) bash scripts/test.sh fuzz

demo: build
	$(DEMO_CMD)

build-bench: setup-bench
	@bash scripts/build.sh $(BENCH_DIR) -DCMAKE_BUILD_TYPE=Release -DCHIMERA_BUILD_BENCH=ON -DCHIMERA_BUILD_TESTS=OFF

# Not run by CI. The committed bench/results/ are the latest full run.
bench: build-bench
	@bench/run.sh $(BENCH_DIR)

bench-quick: build-bench
	@bench/run.sh $(BENCH_DIR) --quick

# Not run by CI (its short pass on the virtual clock is a test: tests/integration/soak). The result
# goes into bench/results/soak.json and the benchmark report's "Soak" section.
SOAK_SECONDS ?= 3600
soak: build-bench
	@/usr/bin/python3 bench/soak.py $(BENCH_DIR)/apps/chimera/chimera --seconds $(SOAK_SECONDS) --json bench/results/soak.json; \
	  rc=$$?; /usr/bin/python3 bench/report.py bench/results/latest.json >/dev/null; exit $$rc

# Sources to format: found on disk (not from git), so new files are included before they are committed.
format_files = $(shell find $(FORMAT_DIRS) -type f \( -name '*.hpp' -o -name '*.cpp' -o -name '*.inl' -o -name '*.h' -o -name '*.cc' \) 2>/dev/null | sort)

format: setup-lint
	@clang-format -i $(format_files)

format-check: setup-lint
	@n=0; for f in $(format_files); do \
	  clang-format --dry-run --Werror "$$f" >/dev/null 2>&1 || { echo "needs formatting: $$f"; n=$$((n + 1)); }; \
	done; \
	if ((n)); then echo "format-check: $$n file(s) differ from .clang-format (make format fixes them)" >&2; exit 1; fi; \
	echo "format-check: clean"

# clang-tidy needs only the compile commands, not a build: configure the tree if it has none.
tidy: setup-lint
	@[[ -f $(BUILD_DIR)/compile_commands.json ]] || CONFIGURE_ONLY=1 bash scripts/build.sh $(BUILD_DIR) -DCMAKE_BUILD_TYPE=$(BUILD_TYPE)
	@bash scripts/tidy.sh $(BUILD_DIR) $(TIDY_DIRS)

clean:
	rm -rf $(BUILD_DIR) $(ASAN_DIR) $(TSAN_DIR) $(FUZZ_DIR) $(BENCH_DIR)
