#!/usr/bin/env bash
# README's test command: install dependencies, build, run the whole test suite.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh
ctest --test-dir "${WEFT_BUILD_DIR:-build}" --output-on-failure -j 2
