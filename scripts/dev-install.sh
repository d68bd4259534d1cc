#!/usr/bin/env bash
# Rebuilds the wheel and reinstalls it into the existing virtual environment (no apt, no pip
# dependency step): the inner loop while developing. scripts/setup.sh does everything.
set -euo pipefail
cd "$(dirname "$0")/.."
VENV=${VENV:-.venv}
export CARGO_TARGET_DIR=${CARGO_TARGET_DIR:-$HOME/.cache/oit/target}
rm -rf dist
"$VENV/bin/maturin" build --release --out dist -q 2>&1 | grep -E "^error|^warning: unused" -A5 || true
"$VENV/bin/python" -m pip install -q --force-reinstall --no-deps dist/oit-*.whl
