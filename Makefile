# Quick start: `make demo` (set up everything and run the bundled example), `make test`.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.deps-stamp
OUT    ?= out

.PHONY: all setup build test test-rust test-python demo bench clean

all: build

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install -q --upgrade pip
	$(BIN)/pip install -q "maturin>=1.5,<2" "numpy>=1.24" "scipy>=1.10" "matplotlib>=3.7" "casadi>=3.6" "mujoco>=3.1" "tqdm>=4.60" "ray>=2.9" "pytest>=7" "hypothesis>=6.80"
	touch $@

setup: $(STAMP)

# Build the Rust extension into the virtual environment (editable install of python/regrasp).
build: $(STAMP)
	VIRTUAL_ENV=$(abspath $(VENV)) PATH="$(abspath $(BIN)):$$PATH" $(BIN)/maturin develop --release -q

test: test-rust test-python

test-rust:
	PROPTEST_RNG_SEED=$${PROPTEST_RNG_SEED:-20261123} cargo test --release -p regrasp-core

test-python: build
	$(BIN)/pytest -q

demo: build
	$(BIN)/regrasp demo --out $(OUT)/demo

bench: build
	cargo bench -p regrasp-core --bench cones --bench mncp --bench mpc
	$(BIN)/regrasp bench --json

clean:
	rm -rf target $(VENV) $(OUT) python/regrasp/*.so
