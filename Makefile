# Quick start: `make demo` (set up everything and run the bundled example), `make test`.
# Each stage prints one line with its time (scripts/stage); its whole output is in out/logs/.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
OUT    ?= out
LOGS   := $(OUT)/logs
STAGE  := scripts/stage
# the dependencies, in two steps: what the demo needs (the core's and `plot`), then the rest
# (every extra, `all`, and `dev`) for the tests and the docs
DEMO_DEPS := $(VENV)/.deps-demo
ALL_DEPS  := $(VENV)/.deps-all
EXT       := python/regrasp/_core.abi3.so
RUST_SRC  := Cargo.toml Cargo.lock $(shell find crates -name '*.rs' -o -name Cargo.toml)
# `make`'s Rust profile (Cargo.toml): the extension and `cargo test` share its compiled dependencies
PROFILE   ?= release-fast

# the core's unit and property tests, with a fixed proptest seed
CARGO_TEST := env PROPTEST_RNG_SEED=$${PROPTEST_RNG_SEED:-20261123} cargo test --profile $(PROFILE) -p regrasp-core -q

.PHONY: all setup build test test-rust test-python demo bench docs clean

all: build

MATURIN := env VIRTUAL_ENV=$(abspath $(VENV)) PATH="$(abspath $(BIN)):$$PATH" $(BIN)/maturin develop
DEVELOP := $(MATURIN) --profile $(PROFILE)
# pyproject.toml's requirements: the core's and those of the extras named
deps = $(shell $(PYTHON) -c "import tomllib; p = tomllib.load(open('pyproject.toml', 'rb'))['project']; \
	print(' '.join(repr(d) for d in p['dependencies'] + [d for e in '$(1)'.split() for d in p['optional-dependencies'][e]]))")
PIP := $(BIN)/pip install --progress-bar off --disable-pip-version-check

# The virtual environment, the demo's dependencies, the extension built once and installed in
# editable mode (python/regrasp).
$(DEMO_DEPS): pyproject.toml
	@$(STAGE) "python environment" $(LOGS)/venv.log $(PYTHON) -m venv $(VENV)
	@$(STAGE) "dependencies (core, plot)" $(LOGS)/pip-demo.log $(PIP) "maturin>=1.5,<2" $(call deps,plot)
	@$(STAGE) "Rust extension ($(PROFILE), installed editable)" $(LOGS)/build.log $(DEVELOP)
	@touch $@

$(ALL_DEPS): $(DEMO_DEPS)
	@$(STAGE) "dependencies (every extra, dev)" $(LOGS)/pip-all.log $(PIP) $(call deps,all dev)
	@touch $@

setup: $(ALL_DEPS)

# The extension again only when a Rust source changed since it was built (checked again here: a
# first setup has just built it).
$(EXT): $(RUST_SRC) | $(DEMO_DEPS)
	@if [ ! -e $@ ] || [ -n "$$(find $(RUST_SRC) -newer $@)" ]; then \
		$(STAGE) "Rust extension ($(PROFILE))" $(LOGS)/build.log $(DEVELOP) --skip-install && touch $@; fi

build: $(EXT)

# pytest's workers (pytest-xdist): one per core, at most 4 (each holds MuJoCo models and an arm)
PYTEST_WORKERS ?= $(shell n=$$(nproc 2>/dev/null || echo 2); [ $$n -gt 4 ] && n=4; echo $$n)
# a test file's tests stay on one worker (its module fixtures are computed once)
PYTEST := $(BIN)/pytest -q -n $(PYTEST_WORKERS) --dist loadfile

# The Rust tests in the background (niced: pytest's workers keep the cores), pytest in front; the
# Rust tests' summary and, on failure, their log's end after pytest's.
test: build $(ALL_DEPS)
	@mkdir -p $(LOGS); STAGE_PLAIN=1 nice -n 10 $(STAGE) "cargo test ($(PROFILE))" $(LOGS)/cargo-test.log $(CARGO_TEST) \
		2>$(LOGS)/cargo-test.stage & rust=$$!; \
	start=$$(date +%s); $(PYTEST) --durations=10; py=$$?; echo "pytest: exit $$py in $$(( $$(date +%s) - start )) s" >&2; \
	wait $$rust; rs=$$?; cat $(LOGS)/cargo-test.stage >&2; [ $$py -eq 0 ] && [ $$rs -eq 0 ]

test-rust:
	$(CARGO_TEST)

test-python: build $(ALL_DEPS)
	$(PYTEST)

demo: build
	@$(BIN)/regrasp demo --out $(OUT)/demo

# The docs site (mkdocs.yml: docs/ and the API pages from the docstrings) into site/.
docs: build $(ALL_DEPS)
	$(BIN)/mkdocs build --strict

# The benchmarks run on the release profile (link-time optimisation), as the wheel is built.
bench: $(ALL_DEPS)
	cargo bench -p regrasp-bench --bench cones --bench mncp --bench mpc
	@$(STAGE) "Rust extension (release)" $(LOGS)/build.log $(MATURIN) --release --skip-install
	$(BIN)/regrasp bench --json

clean:
	rm -rf target $(VENV) $(OUT) python/regrasp/*.so
