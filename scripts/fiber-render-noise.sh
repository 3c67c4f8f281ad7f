#!/usr/bin/env bash
# Noise and time of the fiber-level renders of `weft verify` (docs/fabric-bsdf.md, "Noise of the
# fiber-level renders"): the bundled poplin at fiber detail, 5 x 5 repeats, every fiber bound to
# a fiber table read by cell, lit by a parallel light of irradiance pi at normal incidence from
# behind (back) and from the viewer's side (front), seen by the orthographic camera 30 deg from
# the normal over whole repeats (222 x 256 pixels, as `weft verify --quality default`), rendered
# spectrally with seeds 1 and 2.
#
#   scripts/fiber-render-noise.sh FIBER_TABLE.exr OUT_DIR [SPP] [SAMPLING]
#
# FIBER_TABLE.exr: e.g. the `fiber-computed.exr` of a `weft verify --quality default` report.
# SPP: samples per pixel (16). SAMPLING: the fiber_table's "sampling", cell (the default with
# cell reads) or bilinear (the density before 2026-12-03), or default: the key left out (the
# material's default; for a weft from before the parameter). Prints per configuration: the CPU
# seconds of each render (user + system, `/usr/bin/time`, loading included), the per-pixel noise
# per channel R, G, B: RMS over the pixels of the two seeds' difference over the image mean (one
# render's own per-pixel noise is that over sqrt 2), and the two images' means. Needs oiiotool.
set -euo pipefail
table=$(realpath "$1")
out=$2
spp=${3:-16}
sampling=${4:-cell}
weft=${WEFT:-build/tools/weft}
mkdir -p "$out"
sampling_key=", \"sampling\": \"$sampling\""
[ "$sampling" = default ] && sampling_key=""
"$weft" weave --detail fiber --repeats 5x5 -o "$out/poplin5.glb" > /dev/null
for config in back front; do
  y=$([ "$config" = back ] && echo -1 || echo 1)
  cat > "$out/$config.json" <<EOF
{
  "gltf": "poplin5.glb",
  "materials": {
    "warp": {"type": "fiber_table",
             "params": {"file": "$table", "interpolation": "cell"$sampling_key}},
    "weft": {"type": "fiber_table",
             "params": {"file": "$table", "interpolation": "cell"$sampling_key}}
  },
  "lights": [{"type": "parallel", "irradiance": 3.141592653589793, "direction": [0, $y, 0]}],
  "camera": {"type": "orthographic", "position": [-0.005, 0.008660254037844387, 0],
             "look_at": [0, 0, 0], "up": [0, 1, 0], "half_width": 0.000635,
             "half_height": 0.0007331},
  "render": {"width": 222, "height": 256, "spp": 16, "seed": 1, "spectral": true}
}
EOF
  cpu=()
  for seed in 1 2; do
    t=$( { /usr/bin/time -f "%U %S" "$weft" render "$out/$config.json" --spp "$spp" \
      --seed "$seed" --threads 2 --quiet -o "$out/$config-$sampling-$spp-$seed.exr" 2>&1 >&3; } \
      3>&1 | tail -1)
    cpu+=("$(echo "$t" | awk '{printf "%.1f", $1 + $2}')")
  done
  a="$out/$config-$sampling-$spp-1.exr" b="$out/$config-$sampling-$spp-2.exr"
  stat() { oiiotool "$@" --printstats 2>&1 | awk '/Stats Avg/ {print $3, $4, $5}'; }
  d2=$(stat "$a" "$b" --sub --dup --mul)
  ma=$(stat "$a")
  mb=$(stat "$b")
  echo "$config $sampling ${spp}spp cpu_s ${cpu[*]} | $d2 | $ma | $mb" | awk -F'|' '{
    split($2, d, " "); split($3, a, " "); split($4, b, " ");
    printf "%s noise", $1;
    for (c = 1; c <= 3; ++c) printf " %.3f", sqrt(d[c]) / ((a[c] + b[c]) / 2);
    printf "  means %.4g %.4g %.4g / %.4g %.4g %.4g\n", a[1], a[2], a[3], b[1], b[2], b[3] }'
done
