#!/usr/bin/env bash
# Installs three.js (npm package three, the version pinned in exchange/viewer/package-lock.json)
# into exchange/viewer/node_modules, which `weft export TABLE.exr -o preview.html` inlines into
# the page (exchange/src/preview_html.cpp; the export says so and names this script when it is
# missing). Needs node and npm once (Debian: nodejs, npm; scripts/install-deps.sh --tests installs
# them); the export itself needs no network. Does nothing when the package is present.
set -euo pipefail
exec "$(dirname "$0")/npm-pinned.sh" install-viewer exchange/viewer three
