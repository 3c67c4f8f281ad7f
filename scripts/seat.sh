#!/usr/bin/env bash
# The car seat (scenes/examples/car-seat) upholstered several ways, whole and up close, written
# side by side (the paper's Fig. 10 layout; docs/car-seat.md): left to right
#   1. measured: the MERL red fabric as a neural BRDF (measured_nbrdf merl-red-fabric),
#   2. computed: the fabric table ray-traced through the fiber-level red-cotton poplin (`weft bake
#      fabric --method raytrace --detail fiber`), on a light-grey foam backing
#      (backing_reflectance, WEFT_BACKING, default 0.6; "none" for the bare sheet), with its weave
#      table (--weave-out) at level auto: the close-up shows the weave, the whole seat the table
#      (a repeat there is far below a pixel); WEFT_WEAVE=0 leaves the weave out,
#   3. classic: Lambert + Cook-Torrance fibers, diffuse colour = the computed table's reflectance
#      at normal incidence (same brightness, classic angular behaviour),
#   4. summation (WEFT_SUMMATION=1, the default; 0 leaves it out): the paper's summed table from
#      the same fiber table, on the same foam.
# The computed and summation tables take the measured fabric's colour: the fiber's dyes are
# scaled until each table's d/8 reading (its reflectance for light near the normal) meets the
# measured one's (`weft bake fabric --colour measured:merl-red-fabric`, docs/colour.md); the
# matched tables are spectral. WEFT_COLOUR sets another colour (any --colour form), "none" keeps
# the fiber's recipe as written (as does a WEFT_FIBER that is a baked table, whose colour is fixed).
# Top row: the whole seat; bottom row: a close-up camera 12 cm from the cushion's front piping
# (a rendered close-up, not a crop), where one weave repeat spans about 18 pixels at 480 x 360.
# Outputs in ${WEFT_OUT:-out/seat}/: seat.glb; per variant V the descriptions seat-V.json and
# closeup-V.json, the renders seat-V.exr/.png and closeup-V.exr/.png and their summaries
# render-V.json and render-closeup-V.json; closeup-computed-table.exr/.png (the computed
# close-up at the fabric table level: the same render as closeup-computed with WEFT_WEAVE=0); closeup-camera.json (the close-up's geometry, the repeat in pixels); the crops of
# the whole renders (crop-V.exr/.png, the cushion's front edge enlarged 4x); side-by-side.exr and
# .png (labelled); closeup-levels.exr/.png (weave against table level, when there is a weave);
# timings.json. The fiber and fabric tables are cached in that folder (red-cotton-fabric.exr with
# fabric.json, red-cotton-weave.exr, red-cotton-summation.exr with summation.json; delete them to
# re-bake; a different WEFT_FIBER or WEFT_PARTICLES re-bakes).
# Environment: WEFT_OUT; WEFT_WIDTH, WEFT_HEIGHT, WEFT_SPP (every render; default the scene's
# 480 x 360, 16 spp); WEFT_THREADS (0 = all); WEFT_BACKING; WEFT_PARTICLES (ray-trace particles
# per incident bin, default 200000); WEFT_FIBER (the fiber table, spec or preset both fabric
# tables are made from, default red-cotton); WEFT_COLOUR (default measured:merl-red-fabric);
# WEFT_SUMMATION; WEFT_WEAVE; WEFT_SEAT_CELL_MM (the seat's grid,
# default 5); WEFT_BIN (the weft program, default ${WEFT_BUILD_DIR:-build}/tools/weft).
set -euo pipefail
cd "$(dirname "$0")/.."
weft=${WEFT_BIN:-$(pwd)/${WEFT_BUILD_DIR:-build}/tools/weft}
[ -x "$weft" ] || { echo "seat.sh: $weft not found; run scripts/build.sh first" >&2; exit 1; }
weft=$(realpath "$weft")
command -v oiiotool > /dev/null || { echo "seat.sh: oiiotool (OpenImageIO) is needed" >&2; exit 1; }
out=${WEFT_OUT:-out/seat}
mkdir -p "$out"
out=$(cd "$out" && pwd)
scene_dir=$(pwd)/scenes/examples/car-seat
threads=${WEFT_THREADS:-0}
particles=${WEFT_PARTICLES:-200000}
fiber=${WEFT_FIBER:-red-cotton}
backing=${WEFT_BACKING:-0.6}
colour=${WEFT_COLOUR:-measured:merl-red-fabric}
[[ "$fiber" == *.exr ]] && [ -z "${WEFT_COLOUR:-}" ] && colour=none
colour_args=()
[ "$colour" != none ] && colour_args=(--colour "$colour")
variants=(measured computed classic)
[ "${WEFT_SUMMATION:-1}" != 0 ] && variants+=(summation)
size_args=()
[ -n "${WEFT_WIDTH:-}" ] && size_args+=(--width "$WEFT_WIDTH")
[ -n "${WEFT_HEIGHT:-}" ] && size_args+=(--height "$WEFT_HEIGHT")
[ -n "${WEFT_SPP:-}" ] && size_args+=(--spp "$WEFT_SPP")
# The fabric table's weave level (docs/car-seat.md): the close-up shows the weave; WEFT_WEAVE=0
# renders every view at the table level.
weave=${WEFT_WEAVE:-1}
no_weave="(WEFT_WEAVE=0)"

echo "== 1. the seat"
"$weft" scene car-seat -o "$out/seat.glb" --cell-mm "${WEFT_SEAT_CELL_MM:-5}"

echo "== 2. the computed fabric table (fiber-level ray trace) and the summed one; cached"
# bake NAME JSON KEY ARGS...: NAME.exr and its summary JSON.json in the output folder unless they
# are there from a bake of the same KEY (the fiber, method and sizes); the wall time includes the
# fiber table's bake into .weft-cache the first time.
bake() {
  local name=$1 json=$2 key=$3 start end
  shift 3
  if /usr/bin/python3 -c "
import json, os, sys
try: ok = json.load(open('$out/$json.json'))['seat_key'] == sys.argv[1]
except (OSError, KeyError, ValueError): ok = False
sys.exit(0 if ok and os.path.exists('$out/$name.exr') else 1)" "$key"; then
    return
  fi
  start=$(date +%s.%N)
  (cd "$out" && "$weft" bake fabric --fiber "$fiber" --threads "$threads" "$@" --quiet --json \
    -o "$name.tmp.exr" > "$json.tmp.json" && mv "$name.tmp.exr" "$name.exr")
  end=$(date +%s.%N)
  /usr/bin/python3 - "$out" "$name" "$json" "$key" "$start" "$end" <<'PY'
import json, os, sys
out, name, js, key, start, end = *sys.argv[1:5], *map(float, sys.argv[5:])
j = json.load(open(f"{out}/{js}.tmp.json"))
j.update({"output": f"{name}.exr", "seat_key": key, "wall_seconds": end - start})
if "weave" in j:
    j["weave"]["file"] = os.path.join(out, os.path.basename(j["weave"]["file"]))
json.dump(j, open(f"{out}/{js}.json", "w"), indent=2)
os.remove(f"{out}/{js}.tmp.json")
PY
}
weave_args=()
[ "$weave" = 1 ] && weave_args=(--weave-out red-cotton-weave.exr)
bake red-cotton-fabric fabric "$fiber raytrace fiber $particles weave=$weave colour=$colour" \
  --method raytrace --detail fiber --samples "$particles" "${weave_args[@]}" "${colour_args[@]}"
[ "${WEFT_SUMMATION:-1}" != 0 ] &&
  bake red-cotton-summation summation "$fiber summation colour=$colour" --method summation \
    "${colour_args[@]}"
/usr/bin/python3 -c "
import json; j = json.load(open('$out/fabric.json'))
n = ' / '.join(f'{100 * x:.2f}' for x in j['relative_noise_per_channel'])
per = 'channel (R / G / B)' if len(j['relative_noise_per_channel']) == 3 else 'band'
print(f\"ray trace: {j['particles']} particles ({$particles} per incident bin), \"
      f\"{j['cpu_seconds']:.1f} CPU-s, {j['wall_seconds']:.0f} s wall, \"
      f\"relative noise per {per} {n} %\")
if j.get('weave'):
    w = j['weave']
    print(f\"weave table: {w.get('positions')} positions, resolution {w.get('resolution')}, \"
          f\"relative noise {w.get('relative_noise')}\")"

echo "== 3. the descriptions, whole and close up"
repeat_dir=$(mktemp -d)
trap 'rm -rf "$repeat_dir"' EXIT
"$weft" weave -o "$repeat_dir/poplin.glb" --json > "$repeat_dir/poplin.json"
describe() {  # the descriptions, with the weave level where $weave is 1
  /usr/bin/python3 - "$weft" "$scene_dir" "$out" "$backing" "$weave" "$repeat_dir/poplin.json" \
    "${WEFT_HEIGHT:-}" "${variants[@]}" <<'PY'
import json, math, subprocess, sys
weft, scene_dir, out, backing, weave, poplin, height = sys.argv[1:8]
variants = sys.argv[8:]
base = json.load(open(f"{scene_dir}/car-seat.json"))
base["gltf"] = f"{out}/seat.glb"
height = int(height) if height else base["render"]["height"]
rho = json.load(open(f"{out}/fabric.json"))["reflectance_normal_incidence"]
if len(rho) != 3:  # a spectral table (a matched colour is one): its linear sRGB under D65
    rho = json.loads(subprocess.run([weft, "spectrum", *map(str, rho)], check=True,
                                    capture_output=True, text=True).stdout)["linear_srgb"]
# The classic material's colour is a reflectance in [0, 1]; a saturated red's linear sRGB can
# leave it (a negative green or blue), which the classic model cannot hold: said, not hidden.
inside = [min(1.0, max(0.0, v)) for v in rho]
if inside != rho:
    print(f"classic diffuse colour: linear sRGB {rho} lies outside [0, 1]; taken as {inside}")
rho = inside
# Upholstery cloth lies on foam: the light the table transmits comes back through it.
foam = {} if backing == "none" else {"backing_reflectance": float(backing)}
computed = {"file": f"{out}/red-cotton-fabric.exr", **foam}
if weave == "1":
    computed.update({"weave": f"{out}/red-cotton-weave.exr", "level": "auto"})
bindings = {
    "measured": None,  # the bundled binding
    "computed": {"type": "fabric_table", "params": computed},
    "classic": {"type": "classic_fiber", "params": {"reflectance": rho, "distribution": "beckmann",
                                                    "alpha": 0.35, "ior": 1.557}},
    "summation": {"type": "fabric_table",
                  "params": {"file": f"{out}/red-cotton-summation.exr", **foam}},
}
if weave == "1":
    bindings["computed-table"] = {"type": "fabric_table", "params": {**computed, "level": "table"}}
# The close-up: 12 cm from the crease between the cushion's front piping and its centre panel,
# 10 cm right of the middle, seen from the side of the whole view's camera, 4 degrees high.
look_at, towards, distance_m, yfov_deg = [0.10, 0.3785, 0.249], [0.553, 0.4, 0.794], 0.12, 4.0
norm = math.sqrt(sum(x * x for x in towards))
closeup = {"type": "perspective", "look_at": look_at, "up": [0, 1, 0], "yfov_deg": yfov_deg,
           "position": [p + distance_m * t / norm for p, t in zip(look_at, towards)]}
# A pixel's footprint on cloth facing the camera at the look-at point, and the poplin's repeat.
pixel_m = 2 * distance_m * math.tan(math.radians(yfov_deg) / 2) / height
repeat_mm = json.load(open(poplin))["repeat_mm"]
px = {k: v * 1e-3 / pixel_m for k, v in repeat_mm.items()}
json.dump({"distance_m": distance_m, "yfov_deg": yfov_deg, "height_px": height,
           "pixel_um": pixel_m * 1e6, "repeat_mm": repeat_mm, "repeat_px": px},
          open(f"{out}/closeup-camera.json", "w"), indent=2)
print(f"close-up: {distance_m * 100:.0f} cm, yfov {yfov_deg} deg, {height} px high: a pixel is "
      f"{pixel_m * 1e6:.1f} um; the poplin's repeat ({repeat_mm['x']} x {repeat_mm['z']} mm) "
      f"spans {px['x']:.1f} x {px['z']:.1f} pixels on cloth facing the camera")
for name in variants + (["computed-table"] if weave == "1" else []):
    mat = bindings[name]
    scene = json.loads(json.dumps(base))
    if mat:
        for key in ("centre", "bolster", "piping", "headrest"):
            scene["materials"][key] = mat
    if name != "computed-table":
        json.dump(scene, open(f"{out}/seat-{name}.json", "w"), indent=2)
    scene["camera"] = closeup
    json.dump(scene, open(f"{out}/closeup-{name}.json", "w"), indent=2)
print(f"classic diffuse colour = computed table's reflectance at normal incidence: {rho}")
print(f"computed fabric's backing reflectance: {backing}")
PY
}
describe

echo "== 4. render"
render() {  # NAME: NAME.json rendered to NAME.exr/.png, its summary render-NAME.json (whole
  # views: render-V.json); wall time = loading the scene + rendering
  local start end js=$out/render-${1#seat-}.json
  start=$(date +%s.%N)
  "$weft" render "$out/$1.json" -o "$out/$1.exr" --preview "$out/$1.png" \
    --threads "$threads" "${size_args[@]}" --quiet --json > "$js"
  end=$(date +%s.%N)
  /usr/bin/python3 -c "
import json; j = json.load(open('$js'))
j['wall_seconds'] = $end - $start
json.dump(j, open('$js', 'w'), indent=2)
print(f\"$1: {j['width']}x{j['height']}, {j['spp']} spp, {j['seconds']:.1f} s \"
      f\"({j['wall_seconds']:.1f} s wall with loading), {j['rays']} rays, \"
      f\"{j['rays_per_s']/1e6:.2f} M rays/s, {j['nonfinite_samples']} non-finite samples\")
for k, v in j.items():  # what the weave level reports (level chosen, repeat in pixels)
    if 'weave' in k or 'level' in k: print(f'  {k}: {json.dumps(v)}')"
}
for v in "${variants[@]}"; do
  render "seat-$v"
  render "closeup-$v"
done
if [ "$weave" = 1 ]; then
  render closeup-computed-table
else
  echo "closeup-computed is at the fabric table level: this weft has no weave level" \
    "$no_weave; closeup-computed-table is the same render"
  for ext in exr png; do cp "$out/closeup-computed.$ext" "$out/closeup-computed-table.$ext"; done
  cp "$out/render-closeup-computed.json" "$out/render-closeup-computed-table.json"
fi

echo "== 5. side by side: whole seats on top, close-ups below, labelled"
read -r width height < <(/usr/bin/python3 -c "
import json; j = json.load(open('$out/render-measured.json')); print(j['width'], j['height'])")
# Labels need a font; oiiotool names DejaVu Sans where fontconfig has it.
font=DejaVuSans
label_ok=1
oiiotool --create 8x8 3 --text:font=$font:size=8 x -o "$repeat_dir/font.exr" > /dev/null 2>&1 ||
  { label_ok=0; echo "seat.sh: oiiotool cannot draw text with $font: panels unlabelled" >&2; }
size=$(( height / 24 > 8 ? height / 24 : 8 ))
# labelled IMAGE TEXT: oiiotool arguments that read IMAGE and write TEXT into it at the top left,
# white with a dark shadow, into the array 'ops' (one oiiotool call for all panels: each call
# costs seconds of start-up on a loaded machine).
labelled() {
  ops=("$1")
  [ "$label_ok" = 1 ] || return 0
  local x=$((size / 2)) y=$((size + size / 2))
  ops+=("--text:x=$((x + 1)):y=$((y + 1)):size=$size:color=0,0,0:font=$font" "$2"
    "--text:x=$x:y=$y:size=$size:color=1,1,1:font=$font" "$2")
}
level=table
[ "$weave" = 1 ] && level="weave (auto)"
repeat_px=$(/usr/bin/python3 -c "
import json; p = json.load(open('$out/closeup-camera.json'))['repeat_px']
print(f\"{p['z']:.0f}x{p['x']:.0f}\")")
dyed=""
[ "$colour" != none ] && dyed=", dyed to $colour d/8"
declare -A names=([measured]="measured (MERL red fabric)"
  [computed]="computed: ray trace, foam $backing$dyed" [classic]="classic (Lambert + Cook-Torrance)"
  [summation]="summation (paper), foam $backing$dyed")
crop_w=$(( width * 120 / 480 > 1 ? width * 120 / 480 : 1 ))
crop_h=$(( height * 90 / 360 > 1 ? height * 90 / 360 : 1 ))
crop="${crop_w}x${crop_h}+$(( width * 140 / 480 ))+$(( height * 195 / 360 ))"
for ext in exr png; do
  args=()  # the crops, each written and popped; then the panels, labelled, and their mosaic
  for v in "${variants[@]}"; do
    args+=("$out/seat-$v.$ext" --cut "$crop" --resample $((4 * crop_w))x$((4 * crop_h))
      -o "$out/crop-$v.$ext" --pop)
  done
  for v in "${variants[@]}"; do
    labelled "$out/seat-$v.$ext" "${names[$v]}"
    args+=("${ops[@]}")
  done
  for v in "${variants[@]}"; do
    text="close-up"
    [ "$v" = computed ] && text="close-up, $level"
    labelled "$out/closeup-$v.$ext" "$text; repeat ${repeat_px} px"
    args+=("${ops[@]}")
  done
  oiiotool "${args[@]}" --mosaic:pad=4 ${#variants[@]}x2 -o "$out/side-by-side.$ext"
  if [ "$weave" = 1 ]; then
    labelled "$out/closeup-computed.$ext" "close-up, $level; repeat ${repeat_px} px"
    args=("${ops[@]}")
    labelled "$out/closeup-computed-table.$ext" "close-up, fabric table level"
    oiiotool "${args[@]}" "${ops[@]}" --mosaic:pad=4 2x1 -o "$out/closeup-levels.$ext"
  fi
done
/usr/bin/python3 - "$out" "$weave" "${variants[@]}" <<'PY'
import json, sys
out, weave, variants = sys.argv[1], sys.argv[2] == "1", sys.argv[3:]
cam = json.load(open(f"{out}/closeup-camera.json"))
renders = {}
for name in [f"seat-{v}" for v in variants] + [f"closeup-{v}" for v in variants] + \
        ["closeup-computed-table"]:
    j = json.load(open(f"{out}/render-{name[5:] if name.startswith('seat-') else name}.json"))
    r = {"seconds": j["seconds"], "wall_seconds": j["wall_seconds"], "rays": j["rays"],
         "width": j["width"], "height": j["height"], "spp": j["spp"]}
    if name.startswith("closeup"):
        r["repeat_px"] = cam["repeat_px"]  # per side, on cloth facing the camera
        r.update({k: v for k, v in j.items() if "weave" in k or "level" in k})
    renders[name] = r
if not weave:  # copied, not rendered
    renders["closeup-computed-table"] = {"same_render_as": "closeup-computed"}
bake = json.load(open(f"{out}/fabric.json"))
total = sum(r.get("seconds", 0) for r in renders.values())
wall = sum(r.get("wall_seconds", 0) for r in renders.values())
json.dump({"renders": renders, "render_seconds": total, "render_wall_seconds": wall,
           "closeup_camera": cam,
           "bake": {k: bake.get(k) for k in ("particles", "cpu_seconds", "seconds",
                                             "wall_seconds",
                                             "relative_noise_per_channel", "weave")}},
          open(f"{out}/timings.json", "w"), indent=2)
print(f"total render time {total:.1f} s ({wall:.1f} s wall with loading); "
      f"written {out}/side-by-side.exr and .png")
PY
