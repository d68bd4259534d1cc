#!/usr/bin/env bash
# Prepares a fresh machine: a Vulkan driver (lavapipe through apt when none is present),
# the Python virtual environment, and the abi3 wheel of the extension, built once.
set -euo pipefail
cd "$(dirname "$0")/.."
VENV=${VENV:-.venv}
PYTHON=${PYTHON:-python3}
# One cargo target directory outside the clone, reused by later clones on this machine.
export CARGO_TARGET_DIR=${CARGO_TARGET_DIR:-$HOME/.cache/oit/target}

have_vulkan_driver() {
  ls /usr/share/vulkan/icd.d/*.json /etc/vulkan/icd.d/*.json 2>/dev/null | grep -q .
}
if ! have_vulkan_driver || ! ldconfig -p 2>/dev/null | grep -q libvulkan.so.1; then
  if command -v apt-get >/dev/null && [ "$(id -u)" = 0 ]; then
    echo "setup: installing the Vulkan loader and lavapipe (mesa-vulkan-drivers)"
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq mesa-vulkan-drivers libvulkan1 >/dev/null
  elif command -v apt-get >/dev/null && command -v sudo >/dev/null; then
    sudo apt-get update -qq && sudo DEBIAN_FRONTEND=noninteractive apt-get install -y -qq mesa-vulkan-drivers libvulkan1 >/dev/null
  else
    echo "setup: no Vulkan driver found and apt-get is not usable here; install a Vulkan driver" \
         "(on Debian/Ubuntu: mesa-vulkan-drivers) and run again" >&2
    exit 1
  fi
fi

if [ ! -x "$VENV/bin/python" ]; then
  "$PYTHON" -m venv "$VENV"
fi
"$VENV/bin/python" -m pip install -q --upgrade pip >/dev/null
"$VENV/bin/python" -m pip install -q "maturin>=1.16,<2" numpy trimesh pytest hypothesis

rm -rf dist
"$VENV/bin/maturin" build --release --out dist -q 2>&1 | grep -v "^🔗\|^📦\|^🍹\|^⚠️" || true
wheel=$(ls dist/oit-*.whl)
"$VENV/bin/python" -m pip install -q --force-reinstall --no-deps "$wheel"
echo "setup: installed $(basename "$wheel")"
