#!/usr/bin/env bash
# Emergency stops at random moments during jobs on the emulated array, N
# trials (default 1000): prints how many actions the device received after a
# stop had answered (must be 0). The ctest runs the same test with 20.
# Usage: scripts/estop_trials.sh [N] [BUILD_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
trials="${1:-1000}"
build="${2:-build}"
HJ_ESTOP_TRIALS="$trials" "$build/hj_tests" --gtest_filter='EmergencyStopTrials.*' | grep -E '\[estop trials\]|OK|FAILED'
