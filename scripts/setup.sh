#!/usr/bin/env bash
# Installs every Debian and PyPI dependency Flurry uses. Idempotent: when all is
# present it only checks (a few seconds) and installs nothing.
# `--gallery` also installs what only scripts/gallery.sh needs (ffmpeg, for the animated
# previews), which CI and building do not; `--profile` what only scripts/instance_lines.py
# needs (valgrind).
set -euo pipefail
GALLERY=0
PROFILE=0
for arg in "$@"; do
  case "$arg" in
    --gallery) GALLERY=1 ;;
    --profile) PROFILE=1 ;;
    *) echo "setup: unknown option $arg (known: --gallery, --profile)" >&2; exit 2 ;;
  esac
done

DEB_PACKAGES=(
  build-essential cmake ninja-build pkg-config git clang-format
  libglm-dev nlohmann-json3-dev libcli11-dev libstb-dev libpng-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  # OpenCL through PoCL
  pocl-opencl-icd ocl-icd-opencl-dev opencl-clhpp-headers opencl-c-headers clinfo
  # OpenVDB export (and an independent reader for the tests)
  libopenvdb-dev libtbb-dev libblosc-dev libboost-iostreams-dev libopenvdb-tools python3-openvdb
  # Rendering: GLFW + OpenGL, headless under Xvfb with Mesa's software GL
  libglfw3-dev libgl-dev libgl1-mesa-dri libegl-mesa0 xvfb xauth
  # Emulated CPUs without AVX / AVX-512 for the instruction-set tests
  qemu-user
)
if [ "$GALLERY" = 1 ]; then DEB_PACKAGES+=(ffmpeg); fi
if [ "$PROFILE" = 1 ]; then DEB_PACKAGES+=(valgrind); fi
PY_PACKAGES=(numpy matplotlib pytest nanobind scikit-build-core)

SUDO=""
if [ "$(id -u)" != 0 ]; then SUDO="sudo"; fi

missing=()
for p in "${DEB_PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing Debian packages: ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -q
  $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

PY=${PYTHON:-python3}
pymissing=()
for p in "${PY_PACKAGES[@]}"; do
  mod=${p//-/_}
  "$PY" -c "import ${mod}" 2>/dev/null || pymissing+=("$p")
done
if [ ${#pymissing[@]} -gt 0 ]; then
  echo "setup: installing PyPI packages: ${pymissing[*]}"
  "$PY" -m pip install -q "${pymissing[@]}" || "$PY" -m pip install -q --break-system-packages "${pymissing[@]}"
fi
echo "setup: all dependencies present"
