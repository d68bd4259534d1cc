# The two commands of the README: `make demo` and `make test`. Both set up what they need.
VENV ?= .venv
PY := $(VENV)/bin/python
export CARGO_TARGET_DIR ?= $(HOME)/.cache/oit/target

.PHONY: setup demo test test-rust test-python bench viewer

setup:
	bash scripts/setup.sh

demo: setup
	$(PY) -m oit demo -o out/demo.png

test: setup test-rust test-python

test-rust:
	cargo test --release -p oit-core

test-python:
	$(PY) -m pytest -q

bench: setup
	$(PY) -m oit bench --out out/bench

# The interactive viewer (crates/oit-viewer, docs/viewer.md); `python -m oit view` finds it here.
viewer:
	cargo build --release -p oit-viewer
