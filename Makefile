# The two commands of the README: `make demo` and `make test`. Each installs what is missing
# (scripts/install-deps), configures with a CMake preset, builds and runs.
PRESET ?= release
JOBS ?= $(shell nproc)
BUILD_DIR = build/$(PRESET)
PIEZOSHIFT = $(BUILD_DIR)/apps/piezoshift/piezoshift
DEMO_OUT ?= out/demo

.PHONY: all deps configure build test demo sanitize bench format format-check clean

all: build

deps:
	@scripts/install-deps

configure: deps
	@cmake --preset $(PRESET) >/dev/null

build: configure
	@cmake --build --preset $(PRESET) -j $(JOBS)

test: build
	@ctest --preset $(PRESET) -j $(JOBS)

demo: build
	@$(PIEZOSHIFT) reproduce --out $(DEMO_OUT)

sanitize:
	@$(MAKE) --no-print-directory test PRESET=sanitize

bench: build
	@$(BUILD_DIR)/bench/piezoshift_bench

format:
	@git ls-files '*.cpp' '*.hpp' | xargs clang-format -i

format-check:
	@git ls-files '*.cpp' '*.hpp' | xargs clang-format --dry-run -Werror

clean:
	@rm -rf build out
