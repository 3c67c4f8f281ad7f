#!/usr/bin/env bash
# README's main command: install what is missing, build, and run `weft verify` on the bundled
# defaults (red-cotton fiber, bundled poplin at fiber detail, MERL red fabric): the computed
# fabric (fiber-level ray trace and the paper's summation) and the classic Lambert + Cook-Torrance
# baseline against the measurement at every measured incidence, with plots, metrics, the colour
# table and an offline page, ${WEFT_OUT:-out}/verify/index.html (docs/verify.md).
# WEFT_QUALITY (draft | default | publication) trades time for noise; WEFT_THREADS (0 = all
# cores) does not change the results.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh  # the build and run set; the test set (Slurm among it) only for test.sh
# The program alone: its tests, benchmarks and Python module need packages the demo does not
# install.
scripts/build.sh -DWEFT_BUILD_TESTS=OFF -DWEFT_BUILD_BENCH=OFF -DWEFT_BUILD_PYTHON=OFF
out=${WEFT_OUT:-out}
mkdir -p "$out"
weft=${WEFT_BUILD_DIR:-build}/tools/weft
"$weft" verify --quality "${WEFT_QUALITY:-default}" --threads "${WEFT_THREADS:-0}" \
  -o "$out/verify"
echo "done: open $out/verify/index.html"
