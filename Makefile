# Quick start: `make demo` (set up everything and run the bundled example), `make test`.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.deps-stamp
OUT    ?= out

.PHONY: all setup build test test-rust test-python demo bench docs clean

all: build

DEVELOP := VIRTUAL_ENV=$(abspath $(VENV)) PATH="$(abspath $(BIN)):$$PATH" $(BIN)/maturin develop --release -q

# The dependencies are pyproject.toml's, once: the core's, every extra (`all`) and `dev`, installed
# by maturin with the package (editable install of python/regrasp).
$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install -q --upgrade pip
	$(BIN)/pip install -q "maturin>=1.5,<2"
	$(DEVELOP) -E all,dev
	touch $@

setup: $(STAMP)

# Build the Rust extension into the virtual environment (the dependencies are there already).
build: $(STAMP)
	$(DEVELOP)

test: test-rust test-python

test-rust:
	PROPTEST_RNG_SEED=$${PROPTEST_RNG_SEED:-20261123} cargo test --release -p regrasp-core

test-python: build
	$(BIN)/pytest -q

demo: build
	$(BIN)/regrasp demo --out $(OUT)/demo

# The docs site (mkdocs.yml: docs/ and the API pages from the docstrings) into site/.
docs: build
	$(BIN)/mkdocs build --strict

bench: build
	cargo bench -p regrasp-core --bench cones --bench mncp --bench mpc
	$(BIN)/regrasp bench --json

clean:
	rm -rf target $(VENV) $(OUT) python/regrasp/*.so
