# The two commands of the README: `make demo` and `make test`. Both set up what they need.
VENV ?= .venv
PY := $(VENV)/bin/python
export CARGO_TARGET_DIR ?= $(HOME)/.cache/oit/target

.PHONY: setup demo test test-rust test-python bench viewer test-viewer

setup:
	bash scripts/setup.sh

demo: setup
	$(PY) -m oit demo -o out/demo.png

test: setup test-rust test-viewer test-python

test-rust:
	cargo test --release -p oit-core

# The viewer's Rust tests (they also build the binary that tests/test_viewer.py runs under
# Xvfb in test-python); xvfb-run comes from Debian's xvfb.
test-viewer:
	cargo test --release -p oit-viewer
	@command -v xvfb-run >/dev/null || { [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null && \
	  apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq xvfb xauth >/dev/null; } || \
	  echo "make: no xvfb-run (apt-get install xvfb): the viewer's screenshot tests will be skipped"

test-python:
	$(PY) -m pytest -q

bench: setup
	$(PY) -m oit bench --out out/bench

# The interactive viewer (crates/oit-viewer, docs/viewer.md); `python -m oit view` finds it here.
viewer:
	cargo build --release -p oit-viewer
