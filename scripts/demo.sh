#!/usr/bin/env bash
# README's main command: install dependencies, build, and run the main job on bundled defaults.
# Outputs go to ${WEFT_OUT:-out}/.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh
out=${WEFT_OUT:-out}
mkdir -p "$out"
weft=build/tools/weft
echo "== colour of a red reflectance spectrum under D65"
"$weft" spectrum $(for b in $(seq 0 32); do if [ $b -gt 21 ]; then echo 0.6; else echo 0.03; fi; done)
