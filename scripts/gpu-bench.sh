#!/usr/bin/env bash
# Measures oit on a GPU machine that has no network: `python -m oit bench --gpu` (python/oit/bench/gpu.py)
# from what scripts/gpu-prepare.sh put in .gpu/ beforehand, on a machine with the network.
#
# Prepare (there, in the checkout): bash scripts/gpu-prepare.sh. It fills .gpu/ (git ignores it):
# the abi3 wheel of oit, the wheels of trimesh (Python 3.9 to 3.12), of pygfx 0.17 and its
# dependencies (3.11, 3.12) and of numpy (3.12), the Vulkan loader unpacked from Debian's
# libvulkan1 and its friends, and the dragon mesh when ../shared/data has it: 41 MiB (it must
# stay under 60 MiB, so that it travels with the checkout's 14 MiB), about 10 seconds when
# dist/'s wheel is fresh. Carry .gpu/ with the checkout; on the GPU machine, from its root:
#
#   bash scripts/gpu-bench.sh OUT_DIR           a hardware adapter only; exits 3 if none is found
#   bash scripts/gpu-bench.sh --small OUT_DIR   the same on any adapter (lavapipe) at tiny sizes
#
# Here it installs the wheels into a folder on PYTHONPATH (pip --no-index: never the network; a
# numpy already there is kept), puts the unpacked loader's libraries that the machine lacks on
# LD_LIBRARY_PATH, points the loader at the NVIDIA driver's ICD when it is not where the loader
# looks, prints the adapter and driver, and runs the parts below, each stopped at its time limit,
# printing a line per row; OUT_DIR/gpu.md and gpu.json are rewritten after every part. Without
# .gpu/wheels it uses the oit that PYTHON already imports (PYTHON=.venv/bin/python here).
#
# Time: each part's limit below (345 s in all, plus one row past a limit, and about 10 s to
# install); no GPU has run it yet, so how many rows each part finishes within its limit on a
# data-center GPU is not known. HARD_LIMIT_S (480) stops the whole run from outside.
#   defaults  150 s  every method at its defaults, 5 showcase scenes at 512², 1080p and 4K
#   hair       40 s  hair at 15,000 strands, every method at its defaults, 512² and 1080p
#   sweeps     60 s  k, nodes and layers of every method that has them, that hair at 1080p
#   claims     55 s  docs/claims.md's 15 rows that rest on GPU times, with their verdicts
#   floor      40 s  the floor and the methods over it against pygfx (when its wheels fit Python)
# --small: about 20 s on lavapipe with 2 cores (limits 15, 8, 12, 10, 10 s).
set -euo pipefail
cd "$(dirname "$0")/.."
small=()
out=""
for arg in "$@"; do
  case $arg in
    --small) small=(--small) ;;
    -h | --help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    -*) echo "gpu-bench: unknown option $arg (usage: scripts/gpu-bench.sh [--small] OUT_DIR)" >&2; exit 2 ;;
    *) out=$arg ;;
  esac
done
[ -n "$out" ] || { echo "usage: scripts/gpu-bench.sh [--small] OUT_DIR" >&2; exit 2; }
PYTHON=${PYTHON:-python3}
HARD_LIMIT_S=${HARD_LIMIT_S:-480}
PREP=${OIT_GPU_PREP:-.gpu}  # what scripts/gpu-prepare.sh made (tests point it elsewhere)
mkdir -p "$out"
tmp=${TMPDIR:-/tmp}/oit-gpu-$(id -u)
mkdir -p "$tmp"
say() { echo "gpu-bench: $*"; }

# Python packages: the prepared wheels into $tmp/site, chosen by pip for this Python.
if [ -d "$PREP/wheels" ]; then
  "$PYTHON" -m pip --version >/dev/null 2>&1 || { say "$PYTHON has no pip: it is needed to install $PREP/wheels" >&2; exit 2; }
  names=(oit trimesh)
  "$PYTHON" -c 'import numpy, sys; sys.exit(tuple(map(int, numpy.__version__.split(".")[:2])) < (1, 24))' 2>/dev/null ||
    names+=(numpy)
  if "$PYTHON" -c 'import sys; sys.exit(sys.version_info < (3, 11))'; then
    names+=(pygfx wgpu rendercanvas pylinalg freetype-py uharfbuzz hsluv jinja2 markupsafe cffi pycparser)
  fi
  rm -rf "${tmp:?}/site"
  say "installing ${names[*]} from $PREP/wheels for $("$PYTHON" -V 2>&1)"
  PIP_NO_INDEX=1 "$PYTHON" -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --disable-pip-version-check \
    --find-links "$PREP/wheels" --target "$tmp/site" "${names[@]}" ||
    { say "pip found no wheel above for this Python or machine (oit's needs glibc 2.35 or later):" \
          "rerun scripts/gpu-prepare.sh with PY_VERSIONS or NUMPY_FOR naming $("$PYTHON" -V 2>&1)" >&2; exit 2; }
  export PYTHONPATH="$tmp/site${PYTHONPATH:+:$PYTHONPATH}"
  if [ -f "$PREP/SOURCE.txt" ]; then
    OIT_BUILD_SOURCE=$(cat "$PREP/SOURCE.txt")
    export OIT_BUILD_SOURCE
  fi
elif "$PYTHON" -c 'import oit' 2>/dev/null; then
  say "no $PREP/wheels: using the oit that $PYTHON imports"
else
  say "no $PREP/wheels and $PYTHON cannot import oit: run scripts/gpu-prepare.sh on a machine with the network first" >&2
  exit 2
fi
[ -d "$PREP/data" ] && export OIT_DATA="$PREP/data"

# The Vulkan loader: those of the unpacked libraries this machine lacks, by soname.
if [ -d "$PREP/vulkan" ]; then
  rm -rf "${tmp:?}/lib" && mkdir -p "$tmp/lib"
  have=$(ldconfig -p 2>/dev/null || true)
  for so in "$PREP"/vulkan/usr/lib/x86_64-linux-gnu/*.so.*; do
    soname=$(basename "$so" | sed -E 's/^(.*\.so\.[0-9]+).*$/\1/')
    if [[ $have != *$'\t'"$soname ("* ]]; then  # ldconfig -p: "<TAB>libvulkan.so.1 (libc6,x86-64) => ..."
      ln -sf "$(cd "$(dirname "$so")" && pwd)/$(basename "$so")" "$tmp/lib/$soname"
    fi
  done
  added=$(find "$tmp/lib" -mindepth 1 -printf '%f ')
  [ -n "$added" ] && say "from $PREP/vulkan (this machine lacks them): $added"
  export LD_LIBRARY_PATH="$tmp/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
fi
# The NVIDIA driver's files where a container mounts them, outside the loader's search path.
for d in /usr/local/nvidia/lib64 /usr/local/nvidia/lib; do
  [ -d "$d" ] && export LD_LIBRARY_PATH="$LD_LIBRARY_PATH:$d"
done
if [ -z "${VK_DRIVER_FILES:-}${VK_ICD_FILENAMES:-}" ] && ! compgen -G "/usr/share/vulkan/icd.d/nvidia*.json" >/dev/null &&
   ! compgen -G "/etc/vulkan/icd.d/nvidia*.json" >/dev/null; then
  for icd in /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json /usr/local/nvidia/icd.d/nvidia_icd.json; do
    if [ -f "$icd" ]; then
      say "the NVIDIA ICD: $icd"
      export VK_DRIVER_FILES=$icd VK_ICD_FILENAMES=$icd
      break
    fi
  done
fi
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-$tmp/runtime}
[ -d "$XDG_RUNTIME_DIR" ] || mkdir -m 700 "$XDG_RUNTIME_DIR"
command -v nvidia-smi >/dev/null && say "nvidia-smi: $(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader 2>&1 | head -n 1)"

# The run; `timeout` stops it past the parts' own limits (the files keep what was measured).
run=("$PYTHON" -u -m oit bench --gpu "${small[@]}" --out "$out")
if command -v timeout >/dev/null; then run=(timeout -k 10 "$HARD_LIMIT_S" "${run[@]}"); fi
status=0
"${run[@]}" || status=$?
if [ "$status" = 124 ] || [ "$status" = 137 ]; then
  say "stopped after $HARD_LIMIT_S s; $out/gpu.md holds the parts finished before" >&2
fi
[ -f "$out/gpu.md" ] && say "wrote $out/gpu.md and $out/gpu.json"
exit "$status"
