# quadray: build, run and test on a machine without a GPU (Mesa lavapipe).
#
#   make run                         install what is missing, render the default scene
#   make run SCENE=scenes/x.toml OUT=x ARGS="--spp 64"
#   make test                        install what is missing, run the tests
#   make bench                       the perturbation benchmark (release build)
#   make lint                        rustfmt check and clippy with warnings as errors
#
# Every target is idempotent; `setup` installs only what is missing and is
# quiet (one line) when everything is there.

SHELL := /bin/bash
CARGO ?= cargo
# Scene file for `make run`; empty renders the built-in default scene.
SCENE ?=
# Output name for `make run`: writes $(OUT).png and $(OUT).exr.
OUT ?= render
# Extra `quadray render` flags for `make run`, e.g. ARGS="--spp 64 --half".
ARGS ?=

.PHONY: all setup run test bench lint fmt

all: test

setup:
	@bash scripts/setup-debian.sh
	@bash scripts/setup-oidn.sh
	@bash scripts/setup-vulkan-runtime.sh
	@$(CARGO) fmt --version >/dev/null 2>&1 || rustup component add rustfmt
	@$(CARGO) clippy --version >/dev/null 2>&1 || rustup component add clippy

run: setup
	$(CARGO) run --release -- render $(SCENE) -o $(OUT) $(ARGS)

# The test profile builds at opt-level 2 (Cargo.toml), so no release build is
# needed; the tests turn the Vulkan validation layer on.
test: setup
	$(CARGO) test -- --show-output

bench: setup
	$(CARGO) bench --bench perturbations

fmt:
	$(CARGO) fmt

lint: setup
	$(CARGO) fmt --check
	$(CARGO) clippy --all-targets -- -D warnings
