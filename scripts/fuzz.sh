#!/usr/bin/env bash
# Runs each libFuzzer harness (tests/fuzz) for SECONDS (default 60) from a
# seed corpus (protocol lines, and ../shared/data files per goal format);
# prints executions and crashes per target. Crashing inputs are kept in
# BUILD_DIR/fuzz-crashes/TARGET/ (add each as a regression test).
# Builds BUILD_DIR (default build-fuzz) with clang, ASan and UBSan first.
# Usage: scripts/fuzz.sh [SECONDS] [BUILD_DIR] [TARGET...]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
build="${2:-build-fuzz}"
shift $(( $# > 2 ? 2 : $# ))
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(fuzz_protocol fuzz_line_buffer fuzz_goal_csv fuzz_goal_png fuzz_goal_stl fuzz_goal_obj fuzz_goal_gltf fuzz_goal_ply)

cmake -S . -B "$build" -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DHJ_BUILD_FUZZERS=ON -DHJ_BUILD_TESTS=OFF \
  -DHJ_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build "$build" -j2 --target "${targets[@]}"

seed() {  # TARGET DIR: fills the seed corpus
  local target="$1" dir="$2" i=0
  mkdir -p "$dir"
  case "$target" in
    fuzz_protocol)
      for line in "7 hello" "8 jam 0 3" "9 set_pressure 301" "3 fault stall 500" \
        "ok 1 protocol=1 rows=3 cols=4 cell_mm=38 max_pressure_pa=3450 grid=77,58,0,0,2,2" \
        "err 4 unsafe unsafe pressure 9 kPa" "pressure_pa=301 jammed=000100000000 pinned=00000000000000000000" \
        "frame 3 2 0 0 2 2 0,1,nan,2.5,3,4"; do
        for p in 0 1 2 3 4; do printf "\\x$(printf %02x $p)%s" "$line" >"$dir/seed-$((i++))"; done
      done ;;
    fuzz_line_buffer) printf '\x10\x03a\nbb\r\nccc' >"$dir/seed-0" ;;
    fuzz_goal_*)
      local ext="${target#fuzz_goal_}"
      find ../shared/data -name "*.$ext" -size -2M -exec cp {} "$dir/" \; 2>/dev/null || true
      [ "$ext" = gltf ] && printf '{"asset":{"version":"2.0"}}' >"$dir/seed-min.gltf"
      ;;
  esac
}

printf '%-18s %12s %8s\n' target executions crashes
for target in "${targets[@]}"; do
  corpus="$build/fuzz-corpus/$target"
  crashes="$build/fuzz-crashes/$target"
  mkdir -p "$crashes"
  [ -d "$corpus" ] || seed "$target" "$corpus"
  log="$build/fuzz-$target.log"
  "$build/tests/fuzz/$target" -max_total_time="$seconds" -print_final_stats=1 -rss_limit_mb=2048 \
    -artifact_prefix="$crashes/" -fork=1 -ignore_crashes=1 "$corpus" >"$log" 2>&1 || true
  # -fork prints a running total "#N: cov: ..."; the last one is the count.
  execs=$( (grep -oE '^#[0-9]+' "$log" || true) | tail -1 | tr -d '#')
  found=$(find "$crashes" -type f | wc -l)
  printf '%-18s %12s %8s\n' "$target" "$execs" "$found"
done
