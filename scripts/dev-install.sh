#!/usr/bin/env bash
# The inner loop while developing: builds the extension and installs the package into the
# existing virtual environment in editable mode (python/oit is used in place, so Python edits
# need no rebuild; rerun this after a Rust edit), with the bench, peers and test extras.
# scripts/setup.sh does the full set-up and installs the abi3 wheel over it.
set -euo pipefail
cd "$(dirname "$0")/.."
VENV=${VENV:-.venv}
export CARGO_TARGET_DIR=${CARGO_TARGET_DIR:-$HOME/.cache/oit/target}
log=$(mktemp)
trap 'rm -f "$log"' EXIT
if ! VIRTUAL_ENV="$PWD/$VENV" "$VENV/bin/maturin" develop --release -q --extras bench,peers,test >"$log" 2>&1; then
  cat "$log" >&2
  exit 1
fi
grep -E "^warning: unused" -A5 "$log" || true
echo "dev-install: python/oit is installed in place; rerun after a Rust edit"
