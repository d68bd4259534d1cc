#!/usr/bin/env bash
# Prepares a fresh machine: a Vulkan driver (lavapipe through apt when none is present), an EGL
# driver for VTK's offscreen windows, clippy and rustfmt, the Python virtual environment with
# ruff, and the abi3 wheel of the extension, built once and installed with its bench, peers and
# test extras (matplotlib, FLIP, pygfx, VTK, pytest: all from PyPI).
set -euo pipefail
cd "$(dirname "$0")/.."
VENV=${VENV:-.venv}
PYTHON=${PYTHON:-python3}
# One cargo target directory outside the clone, reused by later clones on this machine.
export CARGO_TARGET_DIR=${CARGO_TARGET_DIR:-$HOME/.cache/oit/target}

# apt_install WHAT PACKAGE...: installs Debian packages as root or through sudo; fails saying
# what is missing where apt-get is not usable.
apt_install() {
  local what=$1
  shift
  if command -v apt-get >/dev/null && [ "$(id -u)" = 0 ]; then
    echo "setup: installing $what ($*)"
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "$@" >/dev/null
  elif command -v apt-get >/dev/null && command -v sudo >/dev/null; then
    echo "setup: installing $what ($*)"
    sudo apt-get update -qq && sudo DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "$@" >/dev/null
  else
    echo "setup: no $what found and apt-get is not usable here; install it" \
         "(on Debian/Ubuntu: $*) and run again" >&2
    exit 1
  fi
}

# No pipes into `grep -q` here: under pipefail, the writer's SIGPIPE would read as "missing".
have_file() {
  compgen -G "$1" >/dev/null
}
have_lib() {
  ldconfig -p 2>/dev/null | grep -c "$1" >/dev/null
}
if ! { have_file "/usr/share/vulkan/icd.d/*.json" || have_file "/etc/vulkan/icd.d/*.json"; } || ! have_lib libvulkan.so.1; then
  apt_install "Vulkan loader and driver" mesa-vulkan-drivers libvulkan1
fi
# VTK (the peers extra) opens its offscreen window through EGL (oit.peers); Mesa's EGL renders
# with llvmpipe where there is no GPU.
if ! have_file "/usr/share/glvnd/egl_vendor.d/*.json" || ! have_lib libEGL.so.1; then
  apt_install "EGL driver" libegl1 libegl-mesa0 libgl1-mesa-dri
fi
# `make lint` runs clippy and rustfmt.
if command -v rustup >/dev/null && ! { cargo clippy --version && cargo fmt --version; } >/dev/null 2>&1; then
  rustup component add clippy rustfmt
fi

if [ ! -x "$VENV/bin/python" ]; then
  "$PYTHON" -m venv "$VENV"
fi
"$VENV/bin/python" -m pip install -q --upgrade pip >/dev/null
"$VENV/bin/python" -m pip install -q "maturin>=1.16,<2" "ruff>=0.17,<0.18"

# with_status WHAT COMMAND...: runs COMMAND with its output in a log, printing one status line
# every SETUP_STATUS_EVERY seconds (20) while it runs, with the crates cargo has compiled so far;
# the log's tail when it fails.
with_status() {
  local what=$1 log start pid rc=0
  shift
  log=$(mktemp)
  start=$SECONDS
  "$@" >"$log" 2>&1 &
  pid=$!
  while ! wait_for "$pid" "${SETUP_STATUS_EVERY:-20}"; do
    echo "setup: $what: $((SECONDS - start)) s, $(grep -c "Compiling " "$log" || true) crates compiled so far"
  done
  wait "$pid" || rc=$?
  if [ "$rc" != 0 ]; then
    tail -n 40 "$log" >&2
    echo "setup: $what failed (exit $rc)" >&2
  fi
  rm -f "$log"
  return "$rc"
}
# wait_for PID SECONDS: whether PID ended within SECONDS.
wait_for() {
  local i
  for ((i = 0; i < $2; i++)); do
    kill -0 "$1" 2>/dev/null || return 0
    sleep 1
  done
  ! kill -0 "$1" 2>/dev/null
}

rm -rf dist
echo "setup: building the extension (cargo, release; the first build compiles wgpu and takes minutes)"
with_status "building the extension" "$VENV/bin/maturin" build --release --out dist
wheel=$(ls dist/oit-*.whl)
"$VENV/bin/python" -m pip install -q --force-reinstall --no-deps "$wheel"
# Then its dependencies and extras (the same version is installed: pip adds only what is missing).
echo "setup: installing the bench, peers and test extras from PyPI (matplotlib, FLIP, pygfx, VTK, pytest)"
with_status "installing the extras" "$VENV/bin/python" -m pip install -q "${wheel}[bench,peers,pygfx,dask,test]"
echo "setup: installed $(basename "$wheel") with the bench, peers and test extras"
