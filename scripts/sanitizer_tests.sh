#!/usr/bin/env bash
# The test suite once more, built with AddressSanitizer + UndefinedBehaviorSanitizer (build-asan/;
# -O0 -g1, the gaussians module -O1: see below). Any ASan/UBSan report or leak in sadsplat's code
# fails the run (LeakSanitizer suppressions for third-party libraries in tests/sanitizers/). The
# CUDA sources, the benchmark programs (no test runs them; the Release build compiles them) and
# the install/package test are left out (no GPU here; the package test builds a second project).
#   bash scripts/sanitizer_tests.sh
set -euo pipefail
cd "$(dirname "$0")/.."
# No precompiled headers here: at -O0 with the sanitizers' instrumentation the sources spend little
# of their time parsing, and making the headers cost what they saved (2 cores, 2026-11-28: 2107 s
# of compiler time and 644 s of wall with them; 2057 s and 638 s without, a clone built earlier
# that day on another machine start).
# -O0 -g1 (line tables: stack traces keep file and line) compiles in half the time of -O1 -g
# (2 cores, 2026-11-26: 9 min 37 s for the whole build; one LibTorch-heavy unity file 86 s at
# -O1 -g, 41 s at -O0 -g1) and the tests take as long: the module whose loops they run,
# gaussians (CPU rasterizer, SSIM, Adam), stays at -O1 (modules/gaussians/CMakeLists.txt).
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-O0 -g1" \
  -DCMAKE_C_FLAGS_DEBUG="-O0 -g1" -DSADSPLAT_SANITIZE=address,undefined \
  -DSADSPLAT_WITH_CUDA=OFF -DSADSPLAT_BUILD_BENCHMARKS=OFF -DCMAKE_UNITY_BUILD=ON \
  -DSADSPLAT_PRECOMPILE_HEADERS=OFF >/dev/null
start=$SECONDS
cmake --build build-asan
echo "[stage] sanitizer build: $(( SECONDS - start )) s"
supp=$(pwd)/tests/sanitizers
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:detect_odr_violation=0:allocator_may_return_null=1"
export LSAN_OPTIONS="suppressions=$supp/lsan_suppressions.txt:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:suppressions=$supp/ubsan_suppressions.txt"
# The views, reports and charts render through Mesa's software OpenGL, whose JIT-compiled code LSan sees
# as leaks from an unknown module (no stack to suppress by): those tests run with ASan and UBSan
# but without the leak check.
viz_tests="^(ViewScreenshot|SplatMode|Report|FrontierCharts)\."
# The tests of tests/sanitizers/release_only.txt run in the Release pass only (why: that file);
# SADSPLAT_ASAN_ALL=1 runs them here too (the package test never: it builds a second project).
release_only=$(grep -v '^#' tests/sanitizers/release_only.txt | grep -v '^\s*$' | paste -sd'|')
left_out="$release_only"
[ "${SADSPLAT_ASAN_ALL:-0}" = 1 ] && left_out="^Package\\."
ctest --test-dir build-asan --output-on-failure -j 2 -E "$left_out|$viz_tests" --timeout 900
ASAN_OPTIONS="$ASAN_OPTIONS:detect_leaks=0" \
  ctest --test-dir build-asan --output-on-failure -j 2 -R "$viz_tests" --timeout 900
