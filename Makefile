# The two commands of the README: `make demo` and `make test`. Both set up what they need.
VENV ?= .venv
PY := $(VENV)/bin/python
export CARGO_TARGET_DIR ?= $(HOME)/.cache/oit/target
# The Vulkan loader's window-system code complains without one (headless machines, CI), as
# python/oit/__init__.py also arranges for Python.
export XDG_RUNTIME_DIR ?= $(shell d=/tmp/oit-runtime-$$(id -u); mkdir -p -m 700 $$d; echo $$d)

.PHONY: setup demo example lint test test-rust test-python test-bench bench viewer test-viewer

setup:
	bash scripts/setup.sh

demo: setup
	$(PY) -m oit demo -o out/demo.png

# The README's Rust example: oit's transparent pass over an engine's own opaque picture.
example:
	cargo run --release -p oit-core --example over_opaque

test: setup lint test-rust test-bench test-python

# Any finding fails: rustfmt (rustfmt.toml), clippy on every target with warnings as errors (in
# release, the profile of the tests, so the two share build scripts and proc-macros), and ruff
# (pyproject.toml's [tool.ruff]) over python/ and tests/. Fix ruff's findings with
# `$(VENV)/bin/ruff check --fix python tests`, rustfmt's with `cargo fmt --all`.
lint:
	cargo fmt --all --check
	cargo clippy --workspace --release --all-targets -- -D warnings
	$(VENV)/bin/ruff check python tests

# The core's and the viewer's Rust tests (these also build the binary that tests/test_viewer.py
# runs under Xvfb in test-python) in one cargo run: cargo resolves features once for both, so
# wgpu, naga and their dependencies compile once. Two runs (-p oit-core, then -p oit-viewer)
# compiled them twice: the viewer's dependencies turn on features of shared crates (bitflags,
# log, smallvec, serde) that change every crate above them. xvfb-run comes from Debian's xvfb.
test-rust:
	cargo test --release -p oit-core -p oit-viewer
	@command -v xvfb-run >/dev/null || { [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null && \
	  apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq xvfb xauth >/dev/null; } || \
	  echo "make: no xvfb-run (apt-get install xvfb): the viewer's screenshot tests will be skipped"

# Kept for the habit: the viewer's tests run in test-rust.
test-viewer: test-rust

# The benchmark's smoke test: every method on every showcase scene, small and thinned (a
# check that the whole bench runs, not a measurement); the tables go to out/bench-quick.
test-bench:
	@mkdir -p out
	$(PY) -m oit bench --quick --no-plots --out out/bench-quick > out/bench-quick.log 2>&1 || \
	  { tail -n 40 out/bench-quick.log; exit 1; }
	@grep -c "^| " out/bench-quick/results.md | xargs -I{} echo "bench --quick: {} table lines in out/bench-quick/results.md"

test-python:
	$(PY) -m pytest -q

bench: setup
	$(PY) -m oit bench --out out/bench

# The interactive viewer (crates/oit-viewer, docs/viewer.md); `python -m oit view` finds it here.
viewer:
	cargo build --release -p oit-viewer
