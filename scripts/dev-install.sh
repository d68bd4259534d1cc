#!/usr/bin/env bash
# The inner loop while developing: builds the extension and installs the package into the
# existing virtual environment in editable mode (python/oit is used in place, so Python edits
# need no rebuild). scripts/setup.sh does the full set-up and installs the abi3 wheel.
set -euo pipefail
cd "$(dirname "$0")/.."
VENV=${VENV:-.venv}
export CARGO_TARGET_DIR=${CARGO_TARGET_DIR:-$HOME/.cache/oit/target}
VIRTUAL_ENV="$PWD/$VENV" "$VENV/bin/maturin" develop --release -q 2>&1 | grep -E "^error|^warning: unused" -A5 || true
