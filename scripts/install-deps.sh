#!/usr/bin/env bash
# Installs Weft's build and run dependencies from Debian 12 packages (the platform of README.md's
# quick start). Skips apt entirely when everything is already present.
set -euo pipefail
packages=(build-essential cmake ninja-build pkg-config
  libembree-dev libopenimageio-dev openimageio-tools libopenexr-dev libimath-dev
  libtinygltf-dev nlohmann-json3-dev libtbb-dev libcli11-dev
  libgtest-dev libbenchmark-dev python3-matplotlib python3-numpy
  pybind11-dev python3-dev python3-pytest  # the Python module (python/) and its tests
  slurm-wlm munge)  # slurm-wlm, munge: the single-node Slurm of tests/tools/slurm_test.sh
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
