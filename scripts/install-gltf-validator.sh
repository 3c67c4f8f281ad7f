#!/usr/bin/env bash
# Installs the Khronos glTF validator (npm package gltf-validator, the version pinned in
# tests/exchange/node/package-lock.json) into tests/exchange/node/node_modules, for the glTF
# export test (weft_tests_exchange, GltfMaterial.ExportPassesTheKhronosValidator), which skips
# with a message when node or the package is missing. Needs node and npm (Debian: nodejs, npm;
# scripts/install-deps.sh --tests installs them). Does nothing when the package is present.
set -euo pipefail
cd "$(dirname "$0")/../tests/exchange/node"
if [ -f node_modules/gltf-validator/package.json ]; then
  echo "install-gltf-validator: present"
  exit 0
fi
command -v npm >/dev/null || {
  echo "install-gltf-validator: npm not found (install nodejs and npm)" >&2
  exit 1
}
npm ci --no-audit --no-fund
