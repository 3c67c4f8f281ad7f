#!/usr/bin/env bash
# Installs Weft's dependencies from Debian 12 packages (the platform of README.md's quick start).
# By default the build and run set (what scripts/demo.sh needs: the libraries, the compiler and
# the plots' matplotlib); with --tests also what only the test suite needs (scripts/test.sh
# passes it): Google Test and Google Benchmark, pybind11 and pytest for the Python module
# (python/) and its tests, slurm-wlm and munge for the single-node Slurm of
# tests/tools/slurm_test.sh, and nodejs and npm for the glTF validator of the export tests
# (scripts/install-gltf-validator.sh; only when no npm is on the PATH, which may come from another
# source than Debian's), and chromium for the screenshot test of the HTML preview. Installs only
# the packages that are missing; skips apt entirely when none is. --list prints the chosen set,
# one package a line, and installs nothing.
# Usage: install-deps.sh [--tests] [--list]
set -euo pipefail
build_run=(build-essential cmake ninja-build pkg-config
  libembree-dev libopenimageio-dev openimageio-tools libopenexr-dev libimath-dev
  libtinygltf-dev nlohmann-json3-dev libtbb-dev libcli11-dev
  python3-matplotlib python3-numpy)
tests_only=(libgtest-dev libbenchmark-dev slurm-wlm munge
  pybind11-dev python3-dev python3-pytest  # the Python module (python/) and its tests
  chromium)  # headless, the screenshot test of weft export's HTML preview

packages=("${build_run[@]}")
list=0
for a in "$@"; do
  case "$a" in
    --tests)
      packages+=("${tests_only[@]}")
      command -v npm >/dev/null || packages+=(nodejs npm)
      ;;
    --list) list=1 ;;
    *)
      echo "install-deps: unknown option '$a' (usage: install-deps.sh [--tests] [--list])" >&2
      exit 2
      ;;
  esac
done
if [ "$list" -eq 1 ]; then
  printf '%s\n' "${packages[@]}"
  exit 0
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all packages present"
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
