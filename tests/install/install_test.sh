#!/bin/bash
# The installed program runs from its prefix alone: `cmake --install` into a fresh prefix, then
# weft runs from another fresh folder with the source tree (and the build tree in it) hidden where
# the system allows it (a private mount namespace with an empty tmpfs over the source tree).
#   install_test.sh CMAKE BUILD_DIR SOURCE_DIR
set -euo pipefail
cmake=$1
build=$2
src=$3
tmp=$(mktemp -d "${TMPDIR:-/tmp}/weft-install-test.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
prefix=$tmp/prefix
"$cmake" --install "$build" --prefix "$prefix" >"$tmp/install.log"
mkdir "$tmp/run"

# The commands, run in $tmp/run by the installed weft; each output checked after.
cat >"$tmp/commands.sh" <<SCRIPT
set -eu
cd '$tmp/run'
'$prefix/bin/weft' medium red-cotton >medium.txt
'$prefix/bin/weft' medium '$prefix/share/weft/fiber/templates/full.json' >template.txt 2>/dev/null
'$prefix/bin/weft' medium '$prefix/share/weft/fiber/presets/silk.json' >preset.txt 2>/dev/null
'$prefix/bin/weft' weave -o weave.gltf >/dev/null
'$prefix/bin/weft' verify --quality draft --quiet -o out >verify.txt
SCRIPT

if unshare -rm sh -c "mount -t tmpfs none '$src'" 2>/dev/null; then
  echo "source tree hidden: $src"
  unshare -rm bash -c "mount -t tmpfs none '$src' && bash '$tmp/commands.sh'"
else
  echo "no private mount namespace here: the source tree stays visible"
  bash "$tmp/commands.sh"
fi

fail=0
for f in medium.txt template.txt preset.txt weave.gltf verify.txt out/metrics.json \
  out/inplane.csv out/index.html out/inplane-00.0deg.png out/render-reflection-computed.exr; do
  if [ ! -s "$tmp/run/$f" ]; then
    echo "missing or empty: $f"
    fail=1
  fi
done
# The measurement the report compared against is the bundled one (metrics.json names it).
grep -q "merl-red-fabric" "$tmp/run/out/metrics.json" || { echo "metrics.json: no merl-red-fabric"; fail=1; }
exit $fail
