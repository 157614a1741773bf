#!/usr/bin/env bash
# Runs each libFuzzer harness (tests/fuzz) for SECONDS (default 60) from a
# seed corpus (protocol lines, ../shared/data files per goal format, sidecars,
# sessions and frames, and meshes naming files outside their upload);
# prints executions and crashes per target. Crashing inputs are kept in
# BUILD_DIR/fuzz-crashes/TARGET/ (add each as a regression test).
# Builds BUILD_DIR (default build-fuzz) with clang, ASan and UBSan first
# (clang and libFuzzer: HJ_FUZZ_DEPS=1 docker/install-deps.sh).
# Usage: scripts/fuzz.sh [SECONDS] [BUILD_DIR] [TARGET...]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
build="${2:-build-fuzz}"
shift $(( $# > 2 ? 2 : $# ))
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(fuzz_protocol fuzz_line_buffer
  fuzz_goal_csv fuzz_goal_png fuzz_goal_terrain_rgb fuzz_goal_terrarium fuzz_goal_tif fuzz_goal_hgt
  fuzz_goal_stl fuzz_goal_obj fuzz_goal_gltf fuzz_goal_glb fuzz_goal_ply fuzz_goal_3mf
  fuzz_mesh_upload_gltf fuzz_mesh_upload_obj fuzz_sidecar fuzz_session fuzz_frame_csv)

cmake -S . -B "$build" -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DHJ_BUILD_FUZZERS=ON -DHJ_BUILD_TESTS=OFF \
  -DCMAKE_CXX_FLAGS_RELEASE="-O1 -DNDEBUG" \
  -DHJ_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build "$build" -j2 --target "${targets[@]}"

seed() {  # TARGET DIR: fills the seed corpus
  local target="$1" dir="$2" i=0
  mkdir -p "$dir"
  case "$target" in
    fuzz_protocol)
      for line in "7 hello" "8 jam 0 3" "9 set_pressure 301" "3 fault stall 500" "5 fault refuse 2" \
        "ok 1 protocol=1 rows=3 cols=4 cell_mm=38 max_pressure_pa=3450 grid=77,58,0,0,2,2" \
        "err 4 unsafe unsafe pressure 9 kPa" "pressure_pa=301 jammed=000100000000 pinned=00000000000000000000" \
        "frame 3 2 0 0 2 2 0,1,nan,2.5,3,4"; do
        for p in 0 1 2 3 4; do printf "\\x$(printf %02x $p)%s" "$line" >"$dir/seed-$((i++))"; done
      done ;;
    fuzz_line_buffer) printf '\x10\x03a\nbb\r\nccc' >"$dir/seed-0" ;;
    fuzz_goal_terrain_rgb | fuzz_goal_terrarium) seed fuzz_goal_png "$dir" ;;
    fuzz_goal_hgt)  # the harness repeats the input to fill a tile; the first 7 bytes name it
      printf 'N37W122\x00\x10\x00\x20\x80\x00' >"$dir/seed-0"; printf 'S01E001\x12\x34' >"$dir/seed-1" ;;
    fuzz_goal_*)
      local ext="${target#fuzz_goal_}"
      find ../shared/data -name "*.$ext" -size -2M -exec cp {} "$dir/" \; 2>/dev/null || true
      [ "$ext" = gltf ] && printf '{"asset":{"version":"2.0"}}' >"$dir/seed-min.gltf"
      [ "$ext" = stl ] && printf 'solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 1\nendloop\nendfacet\nendsolid t\n' >"$dir/seed-min.stl"
      [ "$ext" = ply ] && printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 1\n3 0 1 2\n' >"$dir/seed-min.ply"
      [ "$ext" = obj ] && printf 'v 0 0 0\nv 1 0 0\nv 0 1 1\nf 1 2 3\n' >"$dir/seed-min.obj"
      true ;;
    fuzz_mesh_upload_gltf)  # buffers and images that name the decoys beside the upload, and one inside
      local tri='"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","max":[1,1,1],"min":[0,0,0]}],"bufferViews":[{"buffer":0,"byteLength":36}],"nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}],"scene":0'
      for uri in ../secret.bin /etc/hostname file:///etc/passwd buffer.bin ./../secret.bin 'data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAIA/'; do
        printf '{"asset":{"version":"2.0"},"buffers":[{"uri":"%s","byteLength":36}],%s}' "$uri" "$tri" >"$dir/seed-$((i++)).gltf"
      done
      printf '{"asset":{"version":"2.0"},"images":[{"uri":"../secret.png"}],"textures":[{"source":0}],%s}' "$tri" >"$dir/seed-$((i++)).gltf" ;;
    fuzz_mesh_upload_obj)
      for lib in ../secret.mtl /etc/passwd secret.mtl; do
        printf 'mtllib %s\nv 0 0 0\nv 1 0 0\nv 0 1 1\nusemtl m\nf 1 2 3\n' "$lib" >"$dir/seed-$((i++))"
      done ;;
    fuzz_sidecar)
      cp ../shared/data/dem/*.json "$dir/"
      printf '{"orientation":{"north_up_numpy":"a.T[::-1, :]"},"georef":{"geotransform":[0,1,0,0,0,-1],"crs":"WGS 84"},"units":"metres"}' >"$dir/seed-0" ;;
    fuzz_session)
      local s
      for s in ../shared/data/sessions/*/*/session.json; do cp "$s" "$dir/seed-$((i++)).json"; done ;;
    fuzz_frame_csv)  # two bytes of expected size (rows, columns) first
      local f
      for f in $(find ../shared/data/sessions -name '*.csv' | head -20); do
        { printf '\x0e\x13'; cat "$f"; } >"$dir/seed-$((i++))"
      done
      printf '\x01\x02nan,1.5\r\n' >"$dir/seed-$((i++))" ;;
  esac
}

printf '%-24s %12s %8s\n' target executions crashes
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
  printf '%-24s %12s %8s\n' "$target" "$execs" "$found"
done
