#!/usr/bin/env bash
# The car seat (scenes/examples/car-seat) upholstered three ways and written side by side, with
# enlarged crops below (the paper's Fig. 10 layout): left to right
#   1. measured: the MERL red fabric as a neural BRDF (measured_nbrdf merl-red-fabric),
#   2. computed: the fabric table summed (the paper's formula) from the red-cotton fiber table,
#      on a light-grey foam backing (backing_reflectance, WEFT_BACKING, default 0.6; "none" for
#      the bare sheet, whose transmitted light is lost inside the seat: docs/car-seat.md),
#   3. classic: Lambert + Cook-Torrance fibers, diffuse colour = the computed table's reflectance
#      at normal incidence (same brightness, classic angular behaviour).
# Outputs in ${WEFT_OUT:-out/seat}/: seat.glb, the three renders (.exr linear, .png preview),
# the crops (crop-*.exr/png), side-by-side.exr and side-by-side.png (top row: whole seat; bottom
# row: the crop of the cushion's front edge, piping and bolster, 4x, nearest),
# timings.json. The fiber and fabric tables are cached in that folder (delete them to re-bake).
# WEFT_SPP overrides the scene's samples per pixel, WEFT_THREADS the thread count (0 = all),
# WEFT_BACKING the computed fabric's backing reflectance.
set -euo pipefail
cd "$(dirname "$0")/.."
weft=$(pwd)/${WEFT_BUILD_DIR:-build}/tools/weft
[ -x "$weft" ] || { echo "seat.sh: $weft not found; run scripts/build.sh first" >&2; exit 1; }
command -v oiiotool > /dev/null || { echo "seat.sh: oiiotool (OpenImageIO) is needed" >&2; exit 1; }
out=${WEFT_OUT:-out/seat}
mkdir -p "$out"
out=$(cd "$out" && pwd)
scene_dir=$(pwd)/scenes/examples/car-seat
threads=${WEFT_THREADS:-0}
spp_args=()
[ -n "${WEFT_SPP:-}" ] && spp_args=(--spp "$WEFT_SPP")

echo "== 1. the seat"
"$weft" scene car-seat -o "$out/seat.glb"

echo "== 2. the computed fabric table (red-cotton fiber, paper's summation; cached)"
if [ ! -f "$out/red-cotton-fabric.exr" ] || [ ! -f "$out/fabric.json" ]; then
  (cd "$out" && "$weft" bake fabric --fiber red-cotton --method summation --quiet --json \
    -o red-cotton-fabric.tmp.exr > fabric.tmp.json &&
    mv red-cotton-fabric.tmp.exr red-cotton-fabric.exr && mv fabric.tmp.json fabric.json)
fi

echo "== 3. three descriptions"
/usr/bin/python3 - "$scene_dir" "$out" "${WEFT_BACKING:-0.6}" <<'PY'
import json, sys
scene_dir, out, backing = sys.argv[1], sys.argv[2], sys.argv[3]
base = json.load(open(f"{scene_dir}/car-seat.json"))
base["gltf"] = f"{out}/seat.glb"
rho = [min(1.0, max(0.0, v)) for v in json.load(open(f"{out}/fabric.json"))["reflectance_normal_incidence"]]
variants = {
    "measured": None,  # the bundled binding
    # Upholstery cloth lies on foam: the light the table transmits comes back through it.
    "computed": {"type": "fabric_table", "params": {"file": f"{out}/red-cotton-fabric.exr",
                 **({} if backing == "none" else {"backing_reflectance": float(backing)})}},
    "classic": {"type": "classic_fiber", "params": {"reflectance": rho, "distribution": "beckmann",
                                                    "alpha": 0.35, "ior": 1.557}},
}
for name, mat in variants.items():
    scene = json.loads(json.dumps(base))
    if mat:
        for key in ("centre", "bolster", "piping", "headrest"):
            scene["materials"][key] = mat
    json.dump(scene, open(f"{out}/seat-{name}.json", "w"), indent=2)
print(f"classic diffuse colour = computed table's reflectance at normal incidence: {rho}")
print(f"computed fabric's backing reflectance: {backing}")
PY

echo "== 4. render"
for v in measured computed classic; do
  "$weft" render "$out/seat-$v.json" -o "$out/seat-$v.exr" --preview "$out/seat-$v.png" \
    --threads "$threads" "${spp_args[@]}" --quiet --json > "$out/render-$v.json"
  /usr/bin/python3 -c "
import json; j = json.load(open('$out/render-$v.json'))
print(f\"$v: {j['width']}x{j['height']}, {j['spp']} spp, {j['seconds']:.1f} s, {j['rays']} rays, \"
      f\"{j['rays_per_s']/1e6:.2f} M rays/s, {j['nonfinite_samples']} non-finite samples\")"
done

echo "== 5. side by side, crops enlarged 4x below"
crop=120x90+140+195
for ext in exr png; do
  args=()
  for v in measured computed classic; do args+=("$out/seat-$v.$ext"); done
  for v in measured computed classic; do
    oiiotool "$out/seat-$v.$ext" --cut "$crop" --resample 480x360 -o "$out/crop-$v.$ext"
    args+=("$out/crop-$v.$ext")
  done
  oiiotool "${args[@]}" --mosaic:pad=4 3x2 -o "$out/side-by-side.$ext"
done
/usr/bin/python3 - "$out" <<'PY'
import json, sys
out = sys.argv[1]
runs = {v: json.load(open(f"{out}/render-{v}.json")) for v in ("measured", "computed", "classic")}
total = sum(r["seconds"] for r in runs.values())
json.dump({"renders": runs, "total_seconds": total}, open(f"{out}/timings.json", "w"), indent=2)
print(f"total render time {total:.1f} s; written {out}/side-by-side.exr and .png")
PY
