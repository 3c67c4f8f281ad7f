#!/usr/bin/env bash
# Installs the npm packages pinned in FOLDER/package-lock.json into FOLDER/node_modules, offline
# from then on; does nothing when PACKAGE is present there. Needs node and npm once (Debian:
# nodejs, npm; scripts/install-deps.sh --tests installs them). The one body of
# install-gltf-validator.sh and install-viewer.sh, which name it as NAME in their messages.
# Usage: npm-pinned.sh NAME FOLDER PACKAGE   (FOLDER relative to the repository root)
set -euo pipefail
name=$1 folder=$2 package=$3
cd "$(dirname "$0")/../$folder"
if [ -f "node_modules/$package/package.json" ]; then
  echo "$name: present"
  exit 0
fi
command -v npm >/dev/null || {
  echo "$name: npm not found (install nodejs and npm)" >&2
  exit 1
}
npm ci --no-audit --no-fund
