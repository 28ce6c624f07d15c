#!/usr/bin/env bash
# Builds the libFuzzer targets (clang, ASan + UBSan, fuzz/) and runs each for a given time.
#   bash scripts/fuzz.sh SECONDS_PER_TARGET [TARGET ...]
# New inputs go to build-fuzz/corpus/<target>/ (the committed seeds in fuzz/corpus/<target>/ are
# read, never written); crashes, leaks and timeouts to build-fuzz/crashes/<target>/. Prints per
# target: seconds, executions, corpus size, and the crash files. A crash input belongs in
# tests/regression/ as a test once fixed.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:?usage: fuzz.sh SECONDS_PER_TARGET [TARGET ...]}
shift
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(gaussian_ply pcd splat_formats scene_cache colmap json)
if [ ! -f build-fuzz/build.ninja ]; then
  CC=clang CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DSADSPLAT_BUILD_FUZZERS=ON -DSADSPLAT_BUILD_TESTS=OFF -DSADSPLAT_WITH_VTK=OFF \
    -DSADSPLAT_WITH_OPEN3D=OFF -DSADSPLAT_WITH_CUDA=OFF >/dev/null
fi
cmake --build build-fuzz --target fuzzers >/dev/null
for t in "${targets[@]}"; do
  mkdir -p "build-fuzz/corpus/$t" "build-fuzz/crashes/$t"
  log="build-fuzz/fuzz_$t.log"
  touch "$log.start"
  start=$(date +%s)
  # ASan's leak check stays on: a leak is a failure like a crash.
  "build-fuzz/bin/fuzz_$t" "build-fuzz/corpus/$t" "fuzz/corpus/$t" -max_total_time="$seconds" \
    -timeout=10 -rss_limit_mb=4096 -max_len=65536 -print_final_stats=1 \
    -artifact_prefix="build-fuzz/crashes/$t/" >"$log" 2>&1 || true
  execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo 0)
  # Only the findings of this run (the folder keeps those of earlier runs).
  new=$(find "build-fuzz/crashes/$t" -type f -newer "$log.start" -printf '%f ' 2>/dev/null || true)
  echo "$t: $(($(date +%s) - start)) s, $execs executions, corpus $(ls "build-fuzz/corpus/$t" | wc -l) files," \
       "new findings: ${new:-none}"
done
