#!/usr/bin/env bash
# README's main command: install what is missing, build, and run the main job end to end on the
# bundled defaults:
#   1. bake the red-cotton fiber (Mie -> photon transport in the fiber -> fiber BSDF table),
#   2. render the bundled woven patch with that table on its yarns,
#   3. sweep a virtual gonioreflectometer in the plane of incidence (light at 30 deg) for the
#      computed fabric and for the classic Lambert + Cook-Torrance baseline,
#   4. plot both against the measured red fabric (MERL, NBRDF fit) and compare colours (HSV).
# Outputs go to ${WEFT_OUT:-out}/. WEFT_PHOTONS and WEFT_SPP trade time for noise.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh
out=${WEFT_OUT:-out}
mkdir -p "$out"
out=$(cd "$out" && pwd)
weft=${WEFT_BUILD_DIR:-build}/tools/weft
photons=${WEFT_PHOTONS:-100000}
spp=${WEFT_SPP:-16}
examples=$(pwd)/scenes/examples

echo "== 1. bake the red-cotton fiber BSDF table ($photons photons per band)"
"$weft" bake fiber red-cotton --bands rgb --resolution 8 --photons "$photons" --json \
  -o "$out/red-cotton-fiber.exr" > "$out/bake.json"
/usr/bin/python3 - "$out/bake.json" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
print(f"baked {j['spec']} ({j['spec_hash']}): {j['photons']} photons, {j['scattering_events']} "
      f"scattering events in {j['seconds']:.1f} s ({j['events_per_s']:.3g} events/s)")
print("  nm   albedo  surface  absorbed  energy balance")
for b in j["per_band"][::4]:
    print(f"  {b['wavelength_nm']:.0f}  {b['albedo']:.4f}  {b['surface_reflected']:.4f}   "
          f"{b['absorbed']:.4f}    {b['energy_balance']:.6f}")
PY

echo "== 2. scenes: the woven patch with the baked table, and with the classic baseline"
# The classic model's diffuse colour is the fiber's own volume albedo (albedo - surface part), so
# the two differ only in how light is distributed, not in how much comes back.
albedo=$(/usr/bin/python3 -c "
import json,sys; j=json.load(open('$out/bake.json'))
print(' '.join(str(max(0.0, b['albedo'] - b['surface_reflected'])) for b in j['per_band']))")
rgb=$("$weft" spectrum $albedo | /usr/bin/python3 -c "
import json,sys; c=json.load(sys.stdin)['linear_srgb']; print(','.join(f'{min(1.0, max(0.0, v)):.4f}' for v in c))")
/usr/bin/python3 - "$examples" "$out" "$rgb" <<'PY'
import json, sys
examples, out, rgb = sys.argv[1], sys.argv[2], [float(v) for v in sys.argv[3].split(",")]
base = json.load(open(f"{examples}/woven-patch.json"))
base["gltf"] = f"{examples}/woven-patch.gltf"
fiber = {"type": "fiber_table", "params": {"file": f"{out}/red-cotton-fiber.exr"}}
classic = {"type": "classic_fiber", "params": {"reflectance": rgb, "distribution": "beckmann",
                                               "alpha": 0.35, "ior": 1.557}}
for name, mat in (("woven-red-cotton", fiber), ("woven-classic", classic)):
    scene = dict(base)
    scene["materials"] = {"warp": mat, "weft": mat}
    json.dump(scene, open(f"{out}/{name}.json", "w"), indent=2)
print(f"classic baseline diffuse colour (linear sRGB): {rgb}")
PY

echo "== 3. render the woven patch"
"$weft" render "$out/woven-red-cotton.json" --spp "$spp" -o "$out/woven-red-cotton.exr" \
  --preview "$out/woven-red-cotton.png"

echo "== 4. virtual gonioreflectometer, light at 30 deg, views -70..70 deg"
for name in woven-red-cotton woven-classic; do
  "$weft" sweep "$out/$name.json" --light-zenith-deg 30 --view-zenith-deg -70:70:10 \
    --spp "$spp" --resolution 48 -o "$out/sweep-$name.csv"
done

echo "== 5. computed vs measured vs classic, in the plane of incidence"
/usr/bin/python3 tools/plot_inplane.py --theta-i 30 \
  --computed "$out/sweep-woven-red-cotton.csv" --baseline "$out/sweep-woven-classic.csv" \
  --measured materials/data/measured/merl-red-fabric/inplane.csv \
  -o "$out/inplane-30deg.png" --summary "$out/inplane-30deg.json"
echo "done: outputs in $out"
