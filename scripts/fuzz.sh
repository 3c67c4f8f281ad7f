#!/usr/bin/env bash
# Builds the libFuzzer harnesses (tests/fuzz, clang with ASan/UBSan) and runs each for S seconds
# (default 30) on its seeds: the bundled files of its format. A crash, a leak, an allocation
# above 2 GB or an input taking more than 20 s fails the run; libFuzzer writes the input that did
# it to ${WEFT_FUZZ_DIR}/artifacts. Harnesses run WEFT_FUZZ_JOBS (default 2) at a time.
# Usage: scripts/fuzz.sh [--seconds S] [--runs N] [harness...]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=30
runs=-1
harnesses=()
while [ $# -gt 0 ]; do
  case "$1" in
    --seconds) seconds=$2; shift 2 ;;
    --runs) runs=$2; shift 2 ;;
    -h|--help) sed -n 2,5p "$0"; exit 0 ;;
    *) harnesses+=("$1"); shift ;;
  esac
done
all=(fuzz_scene_description fuzz_fiber_spec fuzz_weave_options fuzz_table_exr fuzz_wif fuzz_nbrdf
  fuzz_inplane_csv fuzz_gltf fuzz_glb fuzz_job_part)
[ ${#harnesses[@]} -gt 0 ] || harnesses=("${all[@]}")

if ! command -v clang++ >/dev/null; then
  # Debian's clang brings libFuzzer (libclang-common-14-dev); install it where we may.
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  if command -v apt-get >/dev/null && { [ -z "$SUDO" ] || sudo -n true 2>/dev/null; }; then
    $SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq \
      --no-install-recommends clang
  fi
fi
if ! command -v clang++ >/dev/null; then
  echo "fuzz: SKIPPED: clang++ not found and not installable here (Debian: apt-get install clang)" >&2
  exit 0
fi
build=${WEFT_FUZZ_BUILD_DIR:-build-fuzz}
# WEFT_FUZZ_TESTS names test programs to build in the same instrumented build and run before the
# fuzzers (CI's sanitizer pass: the libraries are compiled once for both).
read -r -a tests <<<"${WEFT_FUZZ_TESTS:-}"
with_tests=OFF
[ ${#tests[@]} -eq 0 ] || with_tests=ON
# Line tables are all a sanitizer's stack trace needs, and compile faster than full debug info.
cmake -S . -B "$build" -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -gline-tables-only -DNDEBUG" -DWEFT_FUZZ=ON \
  -DCMAKE_UNITY_BUILD=ON \
  -DWEFT_BUILD_TESTS="$with_tests" -DWEFT_BUILD_BENCH=OFF >/dev/null
cmake --build "$build" -j "${WEFT_JOBS:-2}" --target "${harnesses[@]}" "${tests[@]}"
# The test programs run two at a time (each mostly on one thread); any failure stops the script.
test_pids=()
for t in "${tests[@]}"; do
  echo "== ASan/UBSan: $t"
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    "$build/tests/$t" --gtest_brief=1 &
  test_pids+=($!)
  if [ ${#test_pids[@]} -ge 2 ]; then wait "${test_pids[0]}"; test_pids=("${test_pids[@]:1}"); fi
done
for p in "${test_pids[@]}"; do wait "$p"; done

# Seeds per harness: the bundled files of that format.
seeds() {
  case "$1" in
    fuzz_scene_description) ls scenes/examples/*.json ;;
    fuzz_fiber_spec) ls fiber/presets/*.json ;;
    fuzz_weave_options) ls tests/fuzz/seeds/weave/*.json ;;
    fuzz_table_exr) ls tests/fuzz/seeds/table/*.exr ;;
    fuzz_wif) ls scenes/data/wif/*.wif ;;
    fuzz_nbrdf) ls materials/data/measured/*/*.txt materials/data/measured/*/*.csv ;;
    fuzz_inplane_csv) ls materials/data/measured/*/inplane.csv ;;
    fuzz_gltf) ls scenes/examples/*.gltf tests/scenes/data/*.gltf ;;
    fuzz_glb) ls tests/fuzz/seeds/glb/*.glb ;;
    fuzz_job_part) ls tests/fuzz/seeds/part/* ;;
  esac
}

out=${WEFT_FUZZ_DIR:-$build/fuzz-runs}
mkdir -p "$out/artifacts"
export ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=0
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
# One harness: seeds in read-only, the corpus folder collects what libFuzzer finds; its verdict
# goes to $out/$h.status so that harnesses can run side by side.
run_one() {
  local h=$1 corpus="$out/corpus/$1" seed_dir="$out/seeds/$1"
  mkdir -p "$corpus"
  rm -rf "$seed_dir" && mkdir -p "$seed_dir"
  for f in $(seeds "$h"); do cp "$f" "$seed_dir/"; done
  if "$build/tests/fuzz/$h" -max_total_time="$seconds" -runs="$runs" -timeout=20 \
      -rss_limit_mb=2048 -max_len=1048576 -print_final_stats=1 \
      -artifact_prefix="$out/artifacts/$h-" "$corpus" "$seed_dir" 2>"$out/$h.log"; then
    echo ok >"$out/$h.status"
  else
    echo failed >"$out/$h.status"
  fi
}
# Harnesses run ${WEFT_FUZZ_JOBS:-2} at a time (each is single-threaded), so the whole run takes
# about seconds x harnesses / jobs.
jobs_max=${WEFT_FUZZ_JOBS:-2}
for h in "${harnesses[@]}"; do
  rm -f "$out/$h.status"
  while [ "$(jobs -rp | wc -l)" -ge "$jobs_max" ]; do wait -n || true; done
  echo "== $h: ${seconds} s"
  run_one "$h" &
done
wait
failed=()
for h in "${harnesses[@]}"; do
  if [ "$(cat "$out/$h.status" 2>/dev/null)" = ok ]; then
    echo "$h: $(grep -E "^stat::number_of_executed_units" "$out/$h.log" | tail -1)"
  else
    echo "== $h failed:"; tail -40 "$out/$h.log"
    failed+=("$h")
  fi
done
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz: FAILED: ${failed[*]} (inputs in $out/artifacts)" >&2
  exit 1
fi
echo "fuzz: all ${#harnesses[@]} harnesses ran clean"
