#!/usr/bin/env bash
# Installs what the project needs from Debian 12 packages (nothing else is downloaded).
# Safe to run again: apt-get skips what is already installed.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  nlohmann-json3-dev libcli11-dev libfmt-dev libomp-dev
  libgtest-dev libgmock-dev libpng-dev
  # Mesh obstacles (Obstacles[].geometryFile: OBJ, STL, PLY) through assimp.
  libassimp-dev
  python3 python3-vtk9 python3-numpy
  # Surfaces (sph surface): OpenVDB's level sets (its CMake module needs Boost.Iostreams), and
  # its Python module, with which the tests read the .vdb files back.
  libopenvdb-dev libboost-iostreams-dev python3-openvdb
  # The Python module (python/: pybind11 and the Python headers), its tests (pytest) and the
  # examples' plots (matplotlib).
  python3-dev python3-pybind11 pybind11-dev python3-pytest python3-matplotlib
  # Readers and players the tests check our output with: meshio (PLY, VTK), ffmpeg/ffprobe
  # (sph render --mp4), headless Chromium driven by Selenium through ChromeDriver (sph view).
  python3-meshio ffmpeg chromium chromium-driver python3-selenium
  # scripts/sanitize.sh: clang, its sanitizer and libFuzzer runtimes, llvm-symbolizer for the
  # reports' stacks, and libomp with Archer (libarcher.so), which makes OpenMP visible to TSan.
  clang-14 libclang-rt-14-dev llvm-14 libomp-14-dev
  # scripts/lint.sh: the format and clang-tidy checks.
  clang-format-14 clang-tidy-14
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all packages already installed"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null; then SUDO=sudo; else
    echo "setup: need root (or sudo) to install: ${missing[*]}" >&2; exit 1
  fi
fi
echo "setup: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
