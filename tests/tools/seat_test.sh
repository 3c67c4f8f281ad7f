#!/usr/bin/env bash
# scripts/seat.sh at a tiny size (32 x 24 pixels, 1 spp, a 20 mm seat grid, a coarse fiber table,
# 20 ray-trace particles per incident bin) in a scratch folder: every output it names is written,
# every panel has the size asked for, the mosaic holds them (two rows, 4-pixel gaps), the labels
# are drawn where oiiotool can draw text, the close-up is its own camera (12 cm from its look-at
# point, a repeat of at least 16 pixels at the scene's 360-pixel height), and timings.json has
# every render.
# Usage: seat_test.sh WEFT SOURCE_DIR
set -uo pipefail
weft=$(readlink -f "$1")
src=$(readlink -f "$2")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail=0
bad() {
  echo "seat_test: $*"
  fail=1
}
# A coarse fiber table (1 s) instead of the preset's (minutes on a loaded machine); spectral, as
# the default run's fabric tables are (a matched colour's table is), so that the classic variant's
# colour is read from a spectrum as there (its 33 bands were once bound as the RGB colour).
"$weft" bake fiber red-cotton --photons 2000 --resolution 4 --bands spectral --quiet \
  -o "$work/fiber.exr" > /dev/null || { echo "seat_test: the fiber bake failed"; exit 1; }
WEFT_BIN=$weft WEFT_OUT=$work/out WEFT_WIDTH=32 WEFT_HEIGHT=24 WEFT_SPP=1 WEFT_THREADS=2 \
  WEFT_PARTICLES=20 WEFT_SEAT_CELL_MM=20 WEFT_FIBER=$work/fiber.exr \
  bash "$src/scripts/seat.sh" > "$work/log" 2>&1 ||
  { cat "$work/log"; echo "seat_test: seat.sh failed"; exit 1; }
out=$work/out
size() { oiiotool --info "$1" | sed -E 's/.*: +([0-9]+) x +([0-9]+),.*/\1x\2/'; }
variants=(measured computed classic summation)
for v in "${variants[@]}"; do
  for f in seat-$v closeup-$v crop-$v; do
    for ext in exr png; do [ -f "$out/$f.$ext" ] || bad "$f.$ext not written"; done
  done
  for f in render-$v render-closeup-$v; do [ -f "$out/$f.json" ] || bad "$f.json not written"; done
  for f in seat-$v closeup-$v; do
    [ -f "$out/$f.json" ] || bad "$f.json not written"
    for ext in exr png; do
      [ "$(size "$out/$f.$ext")" = 32x24 ] || bad "$f.$ext is $(size "$out/$f.$ext"), not 32x24"
    done
  done
  [ "$(size "$out/crop-$v.exr")" = 32x24 ] || bad "crop-$v.exr is $(size "$out/crop-$v.exr")"
done
for f in seat.glb closeup-computed-table.exr closeup-computed-table.png side-by-side.exr \
  side-by-side.png timings.json closeup-camera.json fabric.json red-cotton-fabric.exr \
  summation.json red-cotton-summation.exr; do
  [ -f "$out/$f" ] || bad "$f not written"
done
# Four panels of 32 with three 4-pixel gaps; two rows of 24 with one gap.
for ext in exr png; do
  [ "$(size "$out/side-by-side.$ext")" = 140x52 ] ||
    bad "side-by-side.$ext is $(size "$out/side-by-side.$ext"), not 140x52"
done
# The label: the mosaic's first panel is the labelled whole render, so it differs from it.
if oiiotool --create 8x8 3 --text:font=DejaVuSans:size=8 x -o "$work/font.exr" > /dev/null 2>&1
then
  oiiotool "$out/side-by-side.exr" --cut 32x24+0+0 --origin +0+0 -o "$work/panel.exr"
  oiiotool --diff "$work/panel.exr" "$out/seat-measured.exr" > /dev/null 2>&1 &&
    bad "the first panel carries no label"
fi
python3 - "$out" "${variants[@]}" <<'PY' || fail=1
import json, math, sys
out, variants = sys.argv[1], sys.argv[2:]
bad = False
def fail(msg):
    global bad
    print(f"seat_test: {msg}")
    bad = True
whole = json.load(open(f"{out}/seat-measured.json"))["camera"]
close = json.load(open(f"{out}/closeup-measured.json"))["camera"]
if close == whole:
    fail("the close-up has the whole view's camera")
d = math.dist(close["position"], close["look_at"])
if abs(d - 0.12) > 1e-9:
    fail(f"the close-up camera is {d} m from its look-at point, not 0.12")
cam = json.load(open(f"{out}/closeup-camera.json"))
short = min(cam["repeat_px"].values()) * 360 / cam["height_px"]  # at the scene's height
if short < 16:
    fail(f"a repeat spans {short:.1f} pixels at 360 pixels high, fewer than 16")
t = json.load(open(f"{out}/timings.json"))
for name in [f"{k}-{v}" for k in ("seat", "closeup") for v in variants]:
    r = t["renders"].get(name)
    if not r or r["rays"] <= 0 or r["seconds"] <= 0:
        fail(f"timings.json: no rays or time for {name}")
    elif name.startswith("closeup") and "repeat_px" not in r:
        fail(f"timings.json: no repeat_px for {name}")
if "closeup-computed-table" not in t["renders"]:
    fail("timings.json: no closeup-computed-table")
if len(t["bake"]["relative_noise_per_channel"]) != 33:  # the spectral fiber: 33 bands
    fail("timings.json: the bake's noise per band is missing")
sys.exit(1 if bad else 0)
PY
[ $fail = 0 ] || cat "$work/log"
exit $fail
