#!/usr/bin/env bash
# The fabric scene's memory estimate (`weft bake fabric --json`: scene_memory_estimate_bytes,
# fabric_scene_bytes) against the run's measured peak RSS (GNU time's getrusage maximum), on a
# small, a medium and a large sample; fails when a run's peak is not within a factor of ten of
# its estimate. docs/PERFORMANCE.md ("Memory of the fabric scene") records its output.
#   scripts/fabric-memory.sh [WEFT] [small|medium|large ...]   (default: all three)
# Runs in a scratch folder (the red-cotton fiber table is baked into its .weft-cache on first use;
# set WEFT_CACHE to a folder holding one to skip that). Needs /usr/bin/time and python3.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
weft="$(realpath "${1:-$root/build/tools/weft}")"
shift || true
cases=("$@")
[ ${#cases[@]} -gt 0 ] || cases=(small medium large)
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
[ -n "${WEFT_CACHE:-}" ] && cp -r "$WEFT_CACHE" "$work/.weft-cache"
cd "$work"
draft="$root/scenes/data/wif/8452.wif"
status=0
for c in "${cases[@]}"; do
  case "$c" in
    small) args=(--method raytrace --detail yarn) ;;                       # the bundled poplin
    medium) echo '{"sides": 8, "segments-per-crossing": 8}' >coarse-weave.json
            args=(--method raytrace --detail yarn --wif "$draft" --weave coarse-weave.json) ;;
    large) args=(--method raytrace --detail yarn --wif "$draft") ;;
    *) echo "unknown case $c" >&2; exit 2 ;;
  esac
  /usr/bin/time -f '%M %e' -o time.txt "$weft" bake fabric "${args[@]}" -R 1 --samples 100 \
    --quiet --json -o "$c.exr" >"$c.json"
  read -r rss_kb seconds <time.txt
  python3 - "$c" "$c.json" "$rss_kb" "$seconds" <<'EOF' || status=1
import json, sys
case, path, rss_kb, seconds = sys.argv[1], sys.argv[2], float(sys.argv[3]), sys.argv[4]
est = json.load(open(path))["scene_memory_estimate_bytes"]
peak = rss_kb * 1024
ratio = peak / est
print(f"{case}: estimate {est / 1e9:.2f} GB, peak RSS {peak / 1e9:.2f} GB, "
      f"peak / estimate {ratio:.2f}, {seconds} s wall")
sys.exit(0 if 0.1 <= ratio <= 10 else 1)
EOF
done
exit $status
