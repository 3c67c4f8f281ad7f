#!/usr/bin/env bash
# Configures and builds Weft into ${WEFT_BUILD_DIR:-build} (Release unless BUILD_TYPE is set).
# Extra CMake arguments are passed through, e.g. scripts/build.sh -DWEFT_SANITIZE=ON.
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${WEFT_BUILD_DIR:-build}
cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE="${BUILD_TYPE:-Release}" "$@"
cmake --build "$build_dir" -j "${WEFT_JOBS:-2}"
