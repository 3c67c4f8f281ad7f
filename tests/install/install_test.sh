#!/bin/bash
# The installed program runs from its prefix alone: `cmake --install` into a fresh prefix, then
# weft runs from another fresh folder with the source tree (and the build tree in it) hidden where
# the system allows it (a private mount namespace with an empty tmpfs over the source tree).
# With PYTHON and PYTHON_DIR (a build with the Python module, python/): `import weft` from
# <prefix>/PYTHON_DIR bakes a fiber, and finds the bundled measurement in <prefix>/share/weft.
#   install_test.sh CMAKE BUILD_DIR SOURCE_DIR [PYTHON PYTHON_DIR]
set -euo pipefail
cmake=$1
build=$2
src=$3
python=${4:-}
python_dir=${5:-}
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
if [ -n "$python" ]; then
  # A folder verify refuses (not empty, not a report), reached only once the plan has read the
  # bundled measurement.
  cat >>"$tmp/commands.sh" <<SCRIPT
export PYTHONPATH='$prefix/$python_dir' PYTHONDONTWRITEBYTECODE=1
'$python' -c "import weft; t = weft.bake_fiber('red-cotton', photons=2000, resolution=4); print(t.values.shape)" >python.txt
mkdir -p not-a-report && echo x >not-a-report/x
'$python' -c "
import weft
print(weft.__file__)
try:
    weft.verify('draft', output='not-a-report')
except weft.Error as e:
    print(e)
" >python-verify.txt
SCRIPT
fi

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
if [ -n "$python" ]; then
  grep -qx "(32, 32, 33)" "$tmp/run/python.txt" || { echo "python.txt: $(cat "$tmp/run/python.txt")"; fail=1; }
  # The installed module, and the refusal of the folder (not a missing measurement).
  grep -q "^$prefix/$python_dir/weft" "$tmp/run/python-verify.txt" &&
    grep -q "not-a-report" "$tmp/run/python-verify.txt" ||
    { echo "python-verify.txt: $(cat "$tmp/run/python-verify.txt")"; fail=1; }
fi
exit $fail
