#!/usr/bin/env bash
# Prepares, on a machine with the network, what scripts/gpu-bench.sh needs on a bare Linux x86-64
# machine with a GPU and no network (docs/results.md, "On a GPU"). Everything goes into .gpu/,
# in the checkout's root, which git ignores; carry that one folder to the GPU machine with it.
#
#   .gpu/wheels/   the abi3 wheel of oit (dist/'s when no source is newer, else built here with
#                  maturin; OIT_WHEEL=path takes that one), and for CPython PY_VERSIONS (default
#                  3.9 to 3.12) on manylinux x86-64: trimesh (5.2.0, or the newest for 3.9), and
#                  pygfx 0.17.0 with its dependencies pinned (wgpu 0.32.0, rendercanvas, pylinalg,
#                  freetype-py, uharfbuzz, hsluv, jinja2, markupsafe, cffi, pycparser), all or
#                  none for each Python: they exist for 3.11 and later, and on older ones the
#                  bench skips its pygfx part; numpy only for NUMPY_FOR (default 3.12; 15 MiB a
#                  version: the GPU machine's Python is expected to bring numpy)
#   .gpu/vulkan/   the Vulkan loader and its friends, Debian .deb files unpacked (libvulkan1,
#                  glvnd's libGL/libEGL/libGLX/libOpenGL/libGLESv2, libX11 and what it needs): the
#                  bench puts on LD_LIBRARY_PATH only those the GPU machine lacks; the NVIDIA
#                  driver brings its own ICD
#   .gpu/data/     dragon-100k.obj when shared/data has it, for the dragons scene (else a stand-in)
#   .gpu/SOURCE.txt, MANIFEST.txt  the commit the wheel was built from; every file and its size
#
# Size: 41 MiB with the defaults (oit 9.3, numpy 15.0, the other wheels 9.8, the loader 3.7,
# the dragon 3.1); it must stay under 60 MiB, so that it travels with the checkout's 14 MiB
# (64 MiB in all). Time: about 10 seconds here when the wheel is fresh (downloads), plus the
# wheel's build when a source is newer than dist/'s (seconds to 20 minutes on 2 cores, as cargo
# finds its cache).
#
# Usage: bash scripts/gpu-prepare.sh            (then: bash scripts/gpu-bench.sh OUT_DIR there)
#        PY_VERSIONS="3.12" NUMPY_FOR="" bash scripts/gpu-prepare.sh   (smaller: one Python, no numpy)
set -euo pipefail
cd "$(dirname "$0")/.."
VENV=${VENV:-.venv}
PY_VERSIONS=${PY_VERSIONS:-3.9 3.10 3.11 3.12}
NUMPY_FOR=${NUMPY_FOR-3.12}
DEST=.gpu
LIMIT_MIB=60
# Runtime dependencies, pinned to what the tests run here (pyproject.toml pins pygfx and wgpu).
CORE_WHEELS=(trimesh==5.2.0)
PYGFX_WHEELS=(pygfx==0.17.0 wgpu==0.32.0 rendercanvas==2.7.2 pylinalg==0.6.8 freetype-py==2.5.1 uharfbuzz==0.57.0
              hsluv==5.0.5 jinja2==3.1.6 markupsafe==3.0.4 cffi==2.1.1 pycparser==3.12)
DEBS=(libvulkan1 libglvnd0 libgl1 libglx0 libegl1 libgles2 libopengl0 libx11-6 libxext6 libxcb1 libxau6 libxdmcp6 libbsd0 libmd0)
export CARGO_TARGET_DIR=${CARGO_TARGET_DIR:-$HOME/.cache/oit/target}

PY="$VENV/bin/python"
[ -x "$PY" ] || { echo "gpu-prepare: no $PY: run 'make setup' (scripts/setup.sh) first" >&2; exit 1; }
rm -rf "$DEST.new"
mkdir -p "$DEST.new/wheels" "$DEST.new/vulkan" "$DEST.new/debs"

# 1. oit's abi3 wheel: OIT_WHEEL when set, else dist/'s when nothing it is built from changed
# since, else a fresh build.
wheel=${OIT_WHEEL:-$(find dist -maxdepth 1 -name 'oit-*.whl' 2>/dev/null | head -n 1)}
if [ -n "${OIT_WHEEL:-}" ] || { [ -n "$wheel" ] && [ -z "$(find crates shaders python pyproject.toml Cargo.toml Cargo.lock \
      -type f -newer "$wheel" -not -path '*/__pycache__/*' -not -name '*.so' -print -quit)" ]; }; then
  echo "gpu-prepare: oit wheel: $wheel"
  case $(basename "$wheel") in oit-*-abi3-*.whl) ;; *) echo "gpu-prepare: $wheel is not named as an abi3 wheel" >&2; exit 1 ;; esac
  cp "$wheel" "$DEST.new/wheels/"
else
  echo "gpu-prepare: building the oit wheel (dist/ has none, or the sources are newer)"
  "$VENV/bin/maturin" build --release --out "$DEST.new/wheels" -q
fi

# 2. Runtime dependencies for each Python version, wheels only, for manylinux x86-64.
download() {  # download PYTHON_VERSION SPEC...
  local v=$1
  shift
  "$PY" -m pip download -q --no-deps --only-binary=:all: --implementation cp --python-version "$v" \
    --platform manylinux2014_x86_64 --platform manylinux_2_17_x86_64 --platform manylinux_2_28_x86_64 \
    --platform manylinux_2_34_x86_64 --platform manylinux_2_35_x86_64 --platform manylinux1_x86_64 \
    --platform linux_x86_64 -d "${DEST_WHEELS:-$DEST.new/wheels}" "$@"
}
# trimesh pinned where that Python has it, else the newest for it; pygfx's set exactly as pinned
# (its baseline holds ratios to that version: docs/results.md), all or none for each Python.
for v in $PY_VERSIONS; do
  echo "gpu-prepare: wheels for Python $v"
  download "$v" "${CORE_WHEELS[@]}" 2>/dev/null || download "$v" "trimesh>=4" ||
    { echo "gpu-prepare: no trimesh wheel for Python $v" >&2; exit 1; }
  rm -rf "$DEST.new/pygfx" && mkdir "$DEST.new/pygfx"
  if (DEST_WHEELS="$DEST.new/pygfx" download "$v" "${PYGFX_WHEELS[@]}") 2>/dev/null; then
    mv -n "$DEST.new"/pygfx/*.whl "$DEST.new/wheels/"
  else
    echo "gpu-prepare: no wheels of ${PYGFX_WHEELS[*]} for Python $v: the pygfx rows are skipped there"
  fi
done
rm -rf "$DEST.new/pygfx"
for v in $NUMPY_FOR; do
  echo "gpu-prepare: numpy for Python $v"
  download "$v" "numpy>=1.24"
done

# 3. The Vulkan loader and friends as Debian packages, unpacked (never into /).
if ! command -v apt-get >/dev/null || ! command -v dpkg >/dev/null; then
  echo "gpu-prepare: apt-get and dpkg are needed to fetch the Vulkan loader (${DEBS[*]})" >&2
  exit 1
fi
apt_opts=(-o APT::Architecture=amd64 -o APT::Architectures=amd64)
if ! (cd "$DEST.new/debs" && apt-get "${apt_opts[@]}" download "${DEBS[@]}" >/dev/null 2>&1); then
  echo "gpu-prepare: apt-get update (the package lists are missing or stale)"
  if [ "$(id -u)" = 0 ]; then apt-get "${apt_opts[@]}" update -qq; else sudo apt-get "${apt_opts[@]}" update -qq; fi
  (cd "$DEST.new/debs" && apt-get "${apt_opts[@]}" download "${DEBS[@]}" >/dev/null)
fi
for deb in "$DEST.new"/debs/*.deb; do
  dpkg -x "$deb" "$DEST.new/vulkan"
  basename "$deb" >>"$DEST.new/vulkan/PACKAGES.txt"
done
rm -rf "$DEST.new/debs" "$DEST.new/vulkan/usr/share"

# 4. The dragon mesh of the dragons scene, when there is one (else the scene uses its stand-in),
# and which sources the wheel was built from.
for d in ${OIT_DATA:-} shared/data ../shared/data; do
  if [ -f "$d/dragon-100k.obj" ]; then
    mkdir -p "$DEST.new/data" && cp "$d/dragon-100k.obj" "$DEST.new/data/"
    break
  fi
done
echo "$(git describe --always --dirty 2>/dev/null || echo unknown) prepared $(date -u '+%Y-%m-%d %H:%M UTC')" >"$DEST.new/SOURCE.txt"

# 5. The manifest, the size check, then the swap.
total=$(du -sb "$DEST.new" | cut -f1)
(cd "$DEST.new" && find . -type f -printf '%10s  %P\n' | sort -k2) >"$DEST.new/manifest.tmp"
mv "$DEST.new/manifest.tmp" "$DEST.new/MANIFEST.txt"
printf '%10s  total (%s MiB)\n' "$total" "$((total / 1048576))" >>"$DEST.new/MANIFEST.txt"
if [ "$total" -gt $((LIMIT_MIB * 1048576)) ]; then
  echo "gpu-prepare: $DEST.new is $((total / 1048576)) MiB, past $LIMIT_MIB MiB: set fewer PY_VERSIONS or NUMPY_FOR" >&2
  exit 1
fi
rm -rf "$DEST"
mv "$DEST.new" "$DEST"
echo "gpu-prepare: $DEST is $((total / 1048576)) MiB ($(find "$DEST/wheels" -name '*.whl' | wc -l) wheels, $(wc -l <"$DEST/vulkan/PACKAGES.txt") packages);" \
     "carry $DEST with the checkout; on the GPU machine: bash scripts/gpu-bench.sh OUT_DIR"
