#!/usr/bin/env bash
# Installs the Khronos glTF validator (npm package gltf-validator, the version pinned in
# tests/exchange/node/package-lock.json) into tests/exchange/node/node_modules, for the glTF
# export test (weft_tests_exchange, GltfMaterial.ExportPassesTheKhronosValidator), which skips
# with a message when node or the package is missing. Needs node and npm (Debian: nodejs, npm;
# scripts/install-deps.sh --tests installs them). Does nothing when the package is present.
set -euo pipefail
exec "$(dirname "$0")/npm-pinned.sh" install-gltf-validator tests/exchange/node gltf-validator
