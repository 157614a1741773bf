#!/usr/bin/env bash
# Builds everything with AddressSanitizer and UndefinedBehaviorSanitizer
# (CMake option HJ_SANITIZE) in BUILD_DIR (default build-asan) and runs the
# whole test suite there. CPU-heavy: not part of .ci/run.
# LEAKS=1 also reports leaks (off by default: gRPC, GDAL and OpenCV keep
# allocations alive until exit). HJ_TEST_TIMEOUT (default 3600 s) is the
# per-test limit: the instrumented calibration tests run several times slower.
# HJ_TEST_TIME_SCALE (default 10) multiplies the tests' own hang bounds.
# Usage: scripts/sanitize.sh [BUILD_DIR] [extra ctest arguments...]
set -euo pipefail
cd "$(dirname "$0")/.."
build="${1:-build-asan}"
shift $(( $# > 0 ? 1 : 0 ))
# -O1: the sanitizers' usual level; at -O3 gcc takes several times longer
# to compile the Eigen-heavy sources with the instrumentation.
cmake -S . -B "$build" -G Ninja -DHJ_SANITIZE=ON -DHJ_BUILD_BENCHMARKS=OFF -DCMAKE_CXX_FLAGS_RELEASE="-O1 -DNDEBUG" \
  -DHJ_TEST_TIMEOUT="${HJ_TEST_TIMEOUT:-3600}"
cmake --build "$build" -j2
export ASAN_OPTIONS="detect_leaks=${LEAKS:-0}:abort_on_error=1"
export HJ_TEST_TIME_SCALE="${HJ_TEST_TIME_SCALE:-10}"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
ctest --test-dir "$build" -j2 --output-on-failure "$@"
