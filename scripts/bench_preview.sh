#!/usr/bin/env bash
# Preview speed of hapticjam-server (issue 4, "Speed"): for 1 and 2 workers,
# calls per second and p50/p99 latency with 1, 4 and 16 concurrent clients on
# a 6 x 8 array (the Maunga Whau DEM, each request a new region), then the latency of a cached repeat (`hapticjam remote bench`).
#   bash scripts/bench_preview.sh [SECONDS_PER_LEVEL]   (default 5; after a build)
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${HJ_BUILD_DIR:-build}
SECONDS_PER_LEVEL=${1:-5}
work=$(mktemp -d)
server_pid=""
trap '[ -n "$server_pid" ] && kill "$server_pid" 2>/dev/null; wait 2>/dev/null; rm -rf "$work"' EXIT
for workers in 1 2; do
  "$BUILD/server/hapticjam-server" --listen 127.0.0.1:0 --workers "$workers" --db "$work/q$workers.db" \
    >"$work/server.out" 2>/dev/null &
  server_pid=$!
  for _ in $(seq 100); do grep -q 'listening on port' "$work/server.out" && break; sleep 0.1; done
  port=$(sed -nE 's/.*listening on port ([0-9]+).*/\1/p' "$work/server.out")
  [ -n "$port" ] || { echo "bench: the server did not start" >&2; exit 1; }
  echo "== $workers worker(s)"
  "$BUILD/hapticjam" remote bench --server 127.0.0.1:$port --rows 6 --cols 8 --clients 1,4,16 --seconds "$SECONDS_PER_LEVEL" \
    --goal ../shared/data/dem/volcano_maunga_whau.csv
  kill "$server_pid"; wait "$server_pid" 2>/dev/null || true; server_pid=""
done
