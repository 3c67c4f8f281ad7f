#!/usr/bin/env bash
# The speed goals of docs/PERFORMANCE.md ("Before and after, one run") measured in one run,
# each against a baseline build of an earlier revision on the same machine, the two programs run
# in turns: "before" is the baseline program with its defaults, "after" this tree's.
#   raytrace  the fiber-level fabric ray trace (bundled poplin, R = 8, 40 000 particles per bin,
#             one fiber table for both, baked once by the baseline): CPU seconds to 1 % relative
#             noise per channel, CPU seconds x (noise / 1 %)^2, over WEFT_SEEDS seeds;
#   bake      the fiber bake (`weft bench bake red-cotton`): photons per band and CPU seconds for a
#             1 % table error, the baseline's default against this tree's variants
#             WEFT_BAKE_VARIANTS (default plain+mirror, mirror folding alone, and
#             nee+mirror+s4+strat, the default bake: its fewest-photons options);
#   render    the path tracer's rays per second over the same rays through bare Embree
#             (`weft bench render`, ratio_replay), both bundled benchmark scenes, the median of
#             WEFT_RENDER_RUNS (default 3) runs of each program in turns, with their range (the
#             ratio of one run spreads by about 0.05 on a shared machine);
#   backlit   the fiber-level render lit from behind and in front (scripts/fiber-render-noise.sh,
#             16 spp, a spectral red-cotton table at R = 8, 200 000 photons, baked once by the
#             baseline): pixel noise of two seeds and CPU seconds, so noise at equal time follows;
#   fit       `weft verify --quality default --fit`: wall and CPU time, convergence (this tree
#             only unless WEFT_FIT_BASELINE=1: the baseline's takes about an hour);
#   verify    `weft verify --quality default` (scripts/demo.sh's), cold (an empty bake cache) and
#             warm (the cold run's cache): wall and CPU time, the estimate printed before the work,
#             and this tree's time by stage (metrics.json "seconds") in verify-stages.md
#             (WEFT_VERIFY_BASELINE=0: this tree's alone).
# Writes ${WEFT_OUT:-out/perf-goals}/goals.md (the table) and goals.json, with every program's
# own output beside them.
# Environment: WEFT_OUT; WEFT_BASELINE (git revision, default 0c7d278: the code the goals were
# set against); WEFT_BASELINE_BIN (a weft built from it; else it is built into
# ${WEFT_BASELINE_BUILD:-build-baseline} from `git archive`); WEFT_BIN (this tree's weft, default
# build/tools/weft); WEFT_THREADS (default 2); WEFT_SEEDS (default 2); WEFT_GOALS (comma list,
# default raytrace,bake,render,backlit,fit,verify); WEFT_PARTICLES (default 40000).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
out=${WEFT_OUT:-out/perf-goals}
mkdir -p "$out"
out=$(cd "$out" && pwd)
threads=${WEFT_THREADS:-2}
seeds=${WEFT_SEEDS:-2}
goals=",${WEFT_GOALS:-raytrace,bake,render,backlit,fit,verify},"
particles=${WEFT_PARTICLES:-40000}
rev=${WEFT_BASELINE:-0c7d278}
new=$(realpath "${WEFT_BIN:-build/tools/weft}")
[ -x "$new" ] || { echo "perf-goals.sh: $new not found; run scripts/build.sh first" >&2; exit 1; }
command -v python3 > /dev/null || { echo "perf-goals.sh: python3 is needed" >&2; exit 1; }
[ -x /usr/bin/time ] || { echo "perf-goals.sh: /usr/bin/time (Debian package time) is needed" >&2; exit 1; }

if [ -n "${WEFT_BASELINE_BIN:-}" ]; then
  old=$(realpath "$WEFT_BASELINE_BIN")
else
  bdir=$(realpath -m "${WEFT_BASELINE_BUILD:-build-baseline}")
  if [ ! -x "$bdir/build/tools/weft" ] || [ "$(cat "$bdir/revision" 2> /dev/null)" != "$rev" ]; then
    echo "== baseline: building $rev into $bdir"
    rm -rf "$bdir" && mkdir -p "$bdir/src"
    git archive "$rev" | tar -x -C "$bdir/src"
    launcher=()
    command -v ccache > /dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
    cmake -S "$bdir/src" -B "$bdir/build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
      -DWEFT_BUILD_TESTS=OFF -DWEFT_BUILD_BENCH=OFF -DWEFT_BUILD_PYTHON=OFF "${launcher[@]}" > "$out/baseline-cmake.log" 2>&1 ||
      { echo "perf-goals.sh: configuring $rev failed; see $out/baseline-cmake.log" >&2; exit 1; }
    cmake --build "$bdir/build" -j "${WEFT_JOBS:-2}" --target weft > "$out/baseline-build.log" 2>&1 ||
      { echo "perf-goals.sh: building $rev failed; see $out/baseline-build.log" >&2; exit 1; }
    echo "$rev" > "$bdir/revision"
  fi
  old=$bdir/build/tools/weft
fi
echo "before: $old ($rev)"
echo "after:  $new ($(git rev-parse --short HEAD)$(git diff --quiet || echo ', with local changes'))"

# timed NAME CMD...: runs CMD in its own folder $out/NAME (the fiber bake cache stays per
# program), stdout to NAME.out; its CPU seconds (user + system) to NAME.cpu, wall to NAME.wall.
timed() {
  local name=$1
  shift
  mkdir -p "$out/$name"
  (cd "$out/$name" && /usr/bin/time -f "%U %S %e" -o "$out/$name.time" "$@" > "$out/$name.out" 2> "$out/$name.err")
  awk '{print $1 + $2 > "'"$out/$name.cpu"'"; print $3 > "'"$out/$name.wall"'"}' "$out/$name.time"
}

if [[ $goals == *,raytrace,* ]]; then
  echo "== fabric ray trace ($seeds seeds, $particles per bin, R 8)"
  [ -f "$out/fiber.exr" ] || (cd "$out" && "$old" bake fiber red-cotton --bands rgb --resolution 8 --quiet -o fiber.exr > fiber.log)
  for seed in $(seq 1 "$seeds"); do
    for who in before after; do
      bin=$old && [ $who = after ] && bin=$new
      timed "raytrace-$who-$seed" "$bin" bake fabric --fiber "$out/fiber.exr" --method raytrace \
        --detail fiber -R 8 --samples "$particles" --threads "$threads" --seed "$seed" --json \
        --quiet -o table.exr
    done
  done
fi

if [[ $goals == *,bake,* ]]; then
  echo "== fiber bake (bench bake, 4 seeds)"
  timed "bake-before" "$old" bench bake red-cotton --photons 2000,8000,32000 --seeds 4 \
    --threads "$threads" --json
  # Mirror folding alone, and this tree's default bake (its fewest-photons options).
  timed "bake-after" "$new" bench bake red-cotton --photons 2000,8000,32000 --seeds 4 \
    --threads "$threads" --json --estimators "${WEFT_BAKE_VARIANTS:-plain+mirror,nee+mirror+s4+strat}"
fi

if [[ $goals == *,render,* ]]; then
  runs=${WEFT_RENDER_RUNS:-3}
  echo "== path tracer against bare Embree (bench render, $runs runs each in turns)"
  rm -f "$out"/render-before-*.out "$out"/render-after-*.out
  for run in $(seq 1 "$runs"); do
    for who in before after; do
      bin=$old && [ $who = after ] && bin=$new
      timed "render-$who-$run" "$bin" bench render --threads "$threads" --json
    done
  done
fi

if [[ $goals == *,backlit,* ]]; then
  echo "== fiber-level render lit from behind and in front"
  [ -f "$out/fiber-spectral.exr" ] || (cd "$out" && "$old" bake fiber red-cotton --resolution 8 \
    --photons 200000 --quiet -o fiber-spectral.exr > fiber-spectral.log)
  for who in before after; do
    bin=$old && [ $who = after ] && bin=$new
    WEFT=$bin bash "$root/scripts/fiber-render-noise.sh" "$out/fiber-spectral.exr" \
      "$out/backlit-$who" 16 default > "$out/backlit-$who.out"
  done
fi

if [[ $goals == *,fit,* ]]; then
  echo "== verify --quality default --fit (after)"
  timed "fit-after" "$new" verify --quality default --fit --threads "$threads" --yes-long -o fit
  if [ "${WEFT_FIT_BASELINE:-0}" = 1 ]; then
    echo "== verify --quality default --fit (before)"
    timed "fit-before" "$old" verify --quality default --fit --threads "$threads" --yes-long -o fit
  fi
fi

if [[ $goals == *,verify,* ]]; then
  whos="before after" && [ "${WEFT_VERIFY_BASELINE:-1}" = 0 ] && whos=after
  for who in $whos; do
    bin=$old && [ $who = after ] && bin=$new
    echo "== verify --quality default ($who: cold, then warm)"
    rm -rf "$out/verify-cold-$who" "$out/verify-warm-$who"
    timed "verify-cold-$who" "$bin" verify --quality default --threads "$threads" -o report
    # Warm: the same run again on the cold run's bake cache (fiber tables, colour matches).
    mkdir -p "$out/verify-warm-$who"
    cp -r "$out/verify-cold-$who/.weft-cache" "$out/verify-warm-$who/" 2> /dev/null || true
    timed "verify-warm-$who" "$bin" verify --quality default --threads "$threads" -o report
  done
fi

python3 "$root/scripts/perf_goals_table.py" "$out" "$rev" "$seeds"
cat "$out/goals.md"
