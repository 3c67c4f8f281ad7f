#!/usr/bin/env bash
# README's test command: install dependencies (the test set too: Google Test and Benchmark,
# pybind11 and pytest, slurm-wlm and munge, node and the Khronos glTF validator, chromium and
# three.js for the HTML preview's tests), build with the
# tests, benchmarks and Python module (also in a build folder that scripts/demo.sh configured
# without them), run the whole test suite.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh --tests
# Without the registry the validator's test skips and says why; the rest runs as before.
scripts/install-gltf-validator.sh || echo "test.sh: no glTF validator, its test will skip"
# The HTML preview's three.js (exchange/viewer): without it its tests skip and say why.
scripts/install-viewer.sh || echo "test.sh: no three.js for the HTML preview, its tests will skip"
scripts/build.sh -DWEFT_BUILD_TESTS=ON -DWEFT_BUILD_BENCH=ON -DWEFT_BUILD_PYTHON=ON
ctest --test-dir "${WEFT_BUILD_DIR:-build}" --output-on-failure -j 2
