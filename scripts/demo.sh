#!/usr/bin/env bash
# The end-to-end demo (README, first command): builds the server, the device
# emulator and the clients, starts the emulator and the server on loopback
# (free ports, chosen by the system and read back), waits until the server
# sees the device, then as a client: plans a real DEM with live progress and
# streamed snapshots, sends the plan to the emulated device with a capture,
# prints how far the captured surface is from the predicted one, zooms into
# the DEM with the Python client (a repeat comes from the cache), starts the
# web viewer (clients/web, docs/web.md) and prints its address, and stops
# every program on exit, whatever happens. HJ_DEMO_KEEP=1 keeps the stack up
# after the demo, until Ctrl-C, to look around in the browser.
#
#   bash scripts/demo.sh [OUT_DIR]      (default hapticjam-demo-remote/)
#   HJ_DEMO_KEEP=1 HJ_WEB_LISTEN=127.0.0.1:8080 bash scripts/demo.sh
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-hapticjam-demo-remote}
BUILD=${HJ_BUILD_DIR:-build}
DEM=../shared/data/dem/volcano_maunga_whau.csv
ROWS=3 COLS=4

fail() { echo "demo: $*" >&2; exit 1; }
[ -f "$DEM" ] || fail "no DEM at $DEM: keep the shared/ folder beside this checkout"

echo "== build"
[ -f "$BUILD/build.ninja" ] || cmake -S . -B "$BUILD" -G Ninja >/dev/null
cmake --build "$BUILD" --target hapticjam hapticjam-server hapticjam-device-emulator hj_python_stubs
HJ="$BUILD/hapticjam"
SERVER_BIN="$BUILD/server/hapticjam-server"
EMULATOR_BIN="$BUILD/src/device/hapticjam-device-emulator"

rm -rf "$OUT" && mkdir -p "$OUT"
LOGS="$OUT/logs" && mkdir -p "$LOGS"
pids=()
cleanup() {
  local status=$?
  for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null || true; done
  for pid in "${pids[@]}"; do wait "$pid" 2>/dev/null || true; done
  [ $status -eq 0 ] || echo "demo: FAILED (exit $status); logs in $LOGS/" >&2
  exit $status
}
trap cleanup EXIT
trap 'exit 130' INT TERM

# Waits up to $2 seconds for a line matching $3 in file $1; prints the match.
wait_for_line() {
  local file=$1 seconds=$2 pattern=$3 pid=$4
  for _ in $(seq $((seconds * 10))); do
    if grep -m1 -E "$pattern" "$file" 2>/dev/null; then return 0; fi
    kill -0 "$pid" 2>/dev/null || { cat "$file" >&2; fail "$(basename "$file" .log) exited before it was ready"; }
    sleep 0.1
  done
  fail "no '$pattern' from $(basename "$file" .log) in ${seconds} s"
}

echo "== start the device emulator and the server on loopback"
"$EMULATOR_BIN" --listen 127.0.0.1:0 --rows $ROWS --cols $COLS --noise-mm 1 --seed 7 >"$LOGS/emulator.log" 2>&1 &
pids+=($!)
EMULATOR_PORT=$(wait_for_line "$LOGS/emulator.log" 20 'listening on 127\.0\.0\.1:[0-9]+' "${pids[0]}" |
  sed -E 's/.*127\.0\.0\.1:([0-9]+).*/\1/')
"$SERVER_BIN" --listen 127.0.0.1:0 --device 127.0.0.1:$EMULATOR_PORT --workers 2 --db "$OUT/queue.db" \
  --map volcano=$DEM >"$LOGS/server.out" 2>"$LOGS/server.log" &
pids+=($!)
SERVER_PORT=$(wait_for_line "$LOGS/server.out" 20 'listening on port [0-9]+' "${pids[1]}" | sed -E 's/.*port ([0-9]+).*/\1/')
export HAPTICJAM_SERVER=127.0.0.1:$SERVER_PORT
echo "emulator on 127.0.0.1:$EMULATOR_PORT, server on $HAPTICJAM_SERVER"

# Ready when the server answers and its device link is up.
for i in $(seq 100); do
  if "$HJ" remote status --timeout 2 2>/dev/null | grep -q ': connected'; then break; fi
  [ "$i" -lt 100 ] || fail "the server did not connect to the emulator in 20 s (see $LOGS/server.log)"
  sleep 0.2
done
"$HJ" remote status

echo "== plan $DEM (the server's map volcano) on the server (progress and snapshots streamed)"
# The server's map of the DEM, so that the viewer's first page, asking the same, is answered from the cache.
"$HJ" remote plan --map volcano --rows $ROWS --cols $COLS --out "$OUT/plan" --snapshots

echo "== send the plan to the emulated device, capture, compare"
"$HJ" remote submit "$OUT/plan/plan.json" --capture --wait --out "$OUT/device" --name "demo: volcano"
"$HJ" remote watch --once --recent 3

PYTHON=/usr/bin/python3
command -v "$PYTHON" >/dev/null || PYTHON=python3
echo "== start the web viewer"
PYTHONPATH="$BUILD/clients/python:clients/python:clients/web" "$PYTHON" -m hapticjam_web --server "$HAPTICJAM_SERVER" \
  --listen "${HJ_WEB_LISTEN:-127.0.0.1:0}" --map volcano=$DEM --dataset demo-baseline=../shared/data/sessions/demo-baseline \
  >"$LOGS/web.out" 2>"$LOGS/web.log" &
pids+=($!)
VIEWER=$(wait_for_line "$LOGS/web.out" 20 'listening on http://[^ ]+' "${pids[2]}" | sed -E 's/.*(http:[^ ]+).*/\1/')
echo "viewer: ${VIEWER}#plan?map=volcano&rows=$ROWS&cols=$COLS&segments=0&auto=1 (the demo's plan; no token needed)"
[ "${HJ_DEMO_KEEP:-0}" = 1 ] || echo "        (it stops with the demo; HJ_DEMO_KEEP=1 bash scripts/demo.sh keeps it up)"

echo "== zoom into the DEM with the Python client (the last two regions come from the cache)"
PYTHONPATH="$BUILD/clients/python:clients/python" "$PYTHON" clients/python/examples/map_zoom.py \
  --server "$HAPTICJAM_SERVER" --map volcano --rows $ROWS --cols $COLS

echo "demo: done; plan, snapshots, captured frames and logs in $OUT/"
if [ "${HJ_DEMO_KEEP:-0}" = 1 ]; then
  echo "demo: HJ_DEMO_KEEP=1: the emulator, the server and the viewer stay up at ${VIEWER}; Ctrl-C stops them"
  trap 'exit 0' INT TERM  # stopping them now is the plan, not a failure
  wait "${pids[1]}"
fi
