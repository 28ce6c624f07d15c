#!/usr/bin/env bash
# Builds the libFuzzer targets (clang, ASan + UBSan, fuzz/) and runs each for a given time.
#   bash scripts/fuzz.sh SECONDS_PER_TARGET [TARGET ...]
# New inputs go to build-fuzz/corpus/<target>/ (the committed seeds in fuzz/corpus/<target>/ are
# read, never written); crashes, leaks and timeouts to build-fuzz/crashes/<target>/. Prints per
# target: wall and CPU seconds, executions, corpus size, and the crash files. A crash input
# belongs in fuzz/regressions/<target>/ once fixed (tests/fuzz replays it in every build).
# The fuzzers run from a copy of their binaries (build-fuzz/run/), so that the build directory
# can be rebuilt while a long run goes on; FUZZ_NICE=19 lets them yield the CPU to other work.
# FUZZ_TIMEOUT (seconds, default 10) is libFuzzer's per-input limit: raise it when the fuzzers
# share the CPU with other work, or a starved process reports a "timeout" that is none.
# With the kernel's autogroup scheduling (Debian's default) `nice` only ranks processes inside one
# session: FUZZ_NICE also lowers this session's group, so start the script in its own session
# (`setsid bash scripts/fuzz.sh ...`) or it lowers the shell it was started from as well.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ -n "${FUZZ_NICE:-}" ] && [ -w /proc/self/autogroup ]; then
  echo "$FUZZ_NICE" > /proc/self/autogroup 2>/dev/null || true
fi
seconds=${1:?usage: fuzz.sh SECONDS_PER_TARGET [TARGET ...]}
shift
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(gaussian_ply pcd splat_formats scene_cache colmap json train_config checkpoint label_png
                                  las georeference transforms_json annotations photo)
if [ ! -f build-fuzz/build.ninja ]; then
  CC=clang CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DSADSPLAT_BUILD_FUZZERS=ON -DSADSPLAT_BUILD_TESTS=OFF -DSADSPLAT_WITH_VTK=OFF \
    -DSADSPLAT_WITH_OPEN3D=OFF -DSADSPLAT_WITH_CUDA=OFF >/dev/null
fi
cmake --build build-fuzz --target fuzzers >/dev/null
mkdir -p build-fuzz/run
for t in "${targets[@]}"; do
  mkdir -p "build-fuzz/corpus/$t" "build-fuzz/crashes/$t"
  log="build-fuzz/fuzz_$t.log"
  touch "$log.start"
  start=$(date +%s)
  runner="build-fuzz/run/fuzz_$t.$$"
  cp "build-fuzz/bin/fuzz_$t" "$runner"
  # ASan's leak check stays on: a leak is a failure like a crash.
  /usr/bin/time -f "%U %S" -o "$log.cpu" nice -n "${FUZZ_NICE:-0}" "$runner" "build-fuzz/corpus/$t" "fuzz/corpus/$t" -max_total_time="$seconds" \
    -timeout="${FUZZ_TIMEOUT:-10}" -rss_limit_mb=4096 -max_len=65536 -print_final_stats=1 \
    -artifact_prefix="build-fuzz/crashes/$t/" >"$log" 2>&1 || true
  rm -f "$runner"
  cpu=$(awk '{printf "%d", $1 + $2}' "$log.cpu" 2>/dev/null || echo "?")
  execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo 0)
  # Only the findings of this run (the folder keeps those of earlier runs).
  new=$(find "build-fuzz/crashes/$t" -type f -newer "$log.start" -printf '%f ' 2>/dev/null || true)
  echo "$t: $(($(date +%s) - start)) s wall, $cpu s CPU, $execs executions, corpus $(ls "build-fuzz/corpus/$t" | wc -l) files," \
       "new findings: ${new:-none}"
done
