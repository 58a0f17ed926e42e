# The two commands of the README: `make demo` and `make test`. Each installs what is missing
# (scripts/install-deps), configures with a CMake preset, builds and runs. Compiles go through
# ccache (cmake/Ccache.cmake), so a rebuild in another folder or preset reuses the objects.
PRESET ?= release
JOBS ?= $(shell nproc)
BUILD_DIR = build/$(PRESET)
PIEZOSHIFT = $(BUILD_DIR)/apps/piezoshift/piezoshift
DEMO_OUT ?= out/demo

.PHONY: all deps configure build test test-fast demo figures mcu python python-install sanitize fuzz bench format format-check clean

all: build

deps:
	@scripts/install-deps

configure: deps
	@cmake --preset $(PRESET) >/dev/null

build: configure
	@cmake --build --preset $(PRESET) -j $(JOBS)

# Every tier (unit, integration, acceptance; docs/testing.md). TEST_LABELS narrows it to a
# regular expression of tiers, as `test-fast` and `sanitize` do.
TEST_LABELS ?=
test: build
	@scripts/run-tests $(BUILD_DIR) $(PRESET) $(JOBS) '$(TEST_LABELS)'

# The unit tier only: the edit-compile loop.
test-fast:
	@$(MAKE) --no-print-directory test TEST_LABELS=unit

# Builds only what the demo runs: the program (and the dashboard page it carries).
demo: configure
	@cmake --build --preset $(PRESET) -j $(JOBS) --target piezoshift_cli
	@$(PIEZOSHIFT) reproduce --out $(DEMO_OUT)

# Every figure the project draws, as SVG in docs/figures/ (the gallery docs/figures.md).
figures: configure
	@cmake --build --preset $(PRESET) -j $(JOBS) --target piezoshift_cli
	@scripts/figures $(PIEZOSHIFT)

# The controller in float on a Cortex-M4F under QEMU (docs/mcu.md): cross-builds the firmware,
# runs it and prints its sizes, the equivalence with the host controller and the cost per tick.
mcu: configure
	@cmake --build --preset $(PRESET) -j $(JOBS) --target piezoshift_firmware test_mcu
	@arm-none-eabi-size $(BUILD_DIR)/firmware/piezoshift_firmware.elf
	@grep -E 'controller_tick|g_controller|g_test_vector_begin' \
	  $(BUILD_DIR)/firmware/piezoshift_firmware.symbols
	@$(BUILD_DIR)/tests/mcu/test_mcu

# The Python package (docs/python.md): built into $(BUILD_DIR)/python/piezoshift.
python: configure
	@cmake --build --preset $(PRESET) -j $(JOBS) --target _piezoshift
	@echo "python: PYTHONPATH=$(CURDIR)/$(BUILD_DIR)/python /usr/bin/python3 -c 'import piezoshift'"

# Installs it into the user's site-packages (~/.local), importable without PYTHONPATH.
python-install: python
	@cmake --install $(BUILD_DIR) --component python --prefix $(HOME)/.local

# The unit and integration tiers under ASan + UBSan; acceptance runs once, in release (`make test`).
sanitize:
	@$(MAKE) --no-print-directory test PRESET=sanitize TEST_LABELS='unit|integration'

# libFuzzer targets under ASan + UBSan (the `sanitize` build, clang; docs/fuzzing.md), FUZZ_SECONDS
# each, JOBS at a time.
FUZZ_SECONDS ?= 60
fuzz: deps
	@FUZZ_SECONDS=$(FUZZ_SECONDS) JOBS=$(JOBS) scripts/fuzz

bench: build
	@$(BUILD_DIR)/bench/piezoshift_bench

format:
	@git ls-files '*.cpp' '*.hpp' | xargs clang-format -i

format-check:
	@git ls-files '*.cpp' '*.hpp' | xargs clang-format --dry-run -Werror

clean:
	@rm -rf build out
