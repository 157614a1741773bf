#!/usr/bin/env bash
# Builds docker/Dockerfile's image with podman, starts docker/compose.yaml's
# stack (emulator + server) with podman-compose, and smoke-tests it from the
# host with the C++ and Python clients: gRPC health, auth, a streamed plan, a
# job submitted to the emulated device and captured, the queue surviving a
# server restart, a clean stop. Then the image's default command (the offline
# demo). Not part of CI (no container runtime there; it takes ~15-30 min).
#
#   bash docker/verify.sh            (as root; results and logs in docker-verify/)
#
# Needs: podman, podman-compose (Debian 12 packages), the host build's
# build/hapticjam and Python stubs (built here if missing), ../shared beside
# the checkout. Without Docker Hub, the base image debian:12 is made locally
# with debootstrap from the Debian mirror apt uses (docker/README.md).
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-docker-verify}
PROJECT=hjverify
SERVER=127.0.0.1:50051
DEM=../shared/data/dem/volcano_maunga_whau.csv
HJ=build/hapticjam
BASE=docker.io/library/debian:12
token() { awk -v role="$1" '$2 == role {print $3; exit}' docker/auth.example; }
ADMIN=$(token admin) OPERATOR=$(token operator) VIEWER=$(token preview)

fail() { echo "verify: FAILED: $*" >&2; exit 1; }
step() { echo; echo "== $*"; }
command -v podman >/dev/null || fail "no podman (apt-get install podman podman-compose)"
command -v podman-compose >/dev/null || fail "no podman-compose (apt-get install podman-compose)"
[ -f "$DEM" ] || fail "no DEM at $DEM: keep the shared/ folder beside this checkout"
rm -rf "$OUT" && mkdir -p "$OUT"

step "base image $BASE"
if ! podman image exists "$BASE" && ! timeout 60 podman pull -q "$BASE"; then
  echo "cannot pull $BASE: making it with debootstrap from the Debian mirror"
  command -v debootstrap >/dev/null || fail "no debootstrap (apt-get install debootstrap)"
  rootfs=$(mktemp -d)
  debootstrap --variant=minbase bookworm "$rootfs" http://deb.debian.org/debian >"$OUT/debootstrap.log"
  # The sources of the official image (bookworm, -updates, -security); no
  # package lists, no downloaded packages.
  rm -f "$rootfs/etc/apt/sources.list"
  rm -rf "$rootfs"/var/lib/apt/lists/* "$rootfs"/var/cache/apt/archives/*.deb "$rootfs"/var/cache/apt/*.bin
  cat >"$rootfs/etc/apt/sources.list.d/debian.sources" <<'EOF'
Types: deb
URIs: http://deb.debian.org/debian
Suites: bookworm bookworm-updates
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg

Types: deb
URIs: http://deb.debian.org/debian-security
Suites: bookworm-security
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
EOF
  tar --numeric-owner -C "$rootfs" -c . | podman import --change 'CMD ["bash"]' - "$BASE" >/dev/null
  rm -rf "$rootfs"
fi

# Some sandboxes refuse crun's defaults: raising RLIMIT_NOFILE/NPROC (no
# CAP_SYS_RESOURCE) and hybrid cgroups v1+v2 ("cgroups in hybrid mode not
# supported"). Then run with runc and the host's lower limits.
if ! podman run --rm "$BASE" true 2>"$OUT/runtime-check.log"; then
  echo "podman's defaults fail here ($(tail -1 "$OUT/runtime-check.log")): using runc and lower ulimits"
  command -v runc >/dev/null || fail "no runc (apt-get install runc)"
  export CONTAINERS_CONF=$PWD/$OUT/containers.conf
  cat >"$CONTAINERS_CONF" <<'EOF'
[containers]
default_ulimits = ["nofile=10000:10000", "nproc=4096:4096"]
[engine]
runtime = "runc"
EOF
  podman run --rm "$BASE" true || fail "containers do not start here even with runc"
fi

step "build the image (docker/Dockerfile, context: the repository root)"
start=$(date +%s)
podman build -f docker/Dockerfile -t hapticjam:latest . >"$OUT/build.log" 2>&1 ||
  { tail -30 "$OUT/build.log"; fail "image build (log: $OUT/build.log)"; }
echo "built in $(($(date +%s) - start)) s; $(podman image inspect hapticjam:latest --format '{{.Size}}' |
  awk '{printf "%.0f MB", $1 / 1e6}')"

step "host clients"
[ -x "$HJ" ] && [ -d build/clients/python/hapticjam ] || {
  [ -f build/build.ninja ] || cmake -S . -B build -G Ninja >/dev/null
  cmake --build build --target hapticjam hj_python_stubs; }
export PYTHONPATH=build/clients/python:clients/python

compose() { podman-compose -p "$PROJECT" -f docker/compose.yaml "$@"; }
cleanup() {
  local status=$?
  compose logs >"$OUT/compose.log" 2>&1 || true
  compose down -v >>"$OUT/compose-down.log" 2>&1 || true
  [ $status -eq 0 ] && echo "verify: all passed (results in $OUT/)" || echo "verify: FAILED (logs in $OUT/)" >&2
  exit $status
}
trap cleanup EXIT

# grpc.health.v1.Health/Check without generated stubs: request {service},
# answer {status}: 1 SERVING, 2 NOT_SERVING. Health needs no token.
health() {
  /usr/bin/python3 - "$SERVER" "$1" <<'EOF'
import sys, grpc
server, service = sys.argv[1], sys.argv[2].encode()
check = grpc.insecure_channel(server).unary_unary("/grpc.health.v1.Health/Check")
reply = check(b"\x0a" + bytes([len(service)]) + service, timeout=5)
print({b"\x08\x01": "SERVING", b"\x08\x02": "NOT_SERVING"}.get(reply, reply.hex()))
EOF
}
wait_serving() {
  for _ in $(seq 120); do
    [ "$(health hapticjam.v1.DeviceService 2>/dev/null)" = SERVING ] && return 0
    sleep 0.5
  done
  fail "the server's DeviceService is not SERVING after 60 s"
}

step "podman-compose up (emulator, server)"
compose down -v >/dev/null 2>&1 || true
compose up -d >"$OUT/compose-up.log" 2>&1 || { cat "$OUT/compose-up.log"; fail "compose up"; }
wait_serving
echo "health: PlanningService $(health hapticjam.v1.PlanningService), DeviceService $(health hapticjam.v1.DeviceService)"

step "auth: no token is refused; the emulator is connected"
set +e
"$HJ" remote status --server $SERVER >/dev/null 2>"$OUT/no-token.err"; code=$?
set -e
[ $code -eq 26 ] || fail "remote status without a token: exit $code, expected 26 (UNAUTHENTICATED)"
echo "no token: exit 26 UNAUTHENTICATED"
"$HJ" remote status --server $SERVER --token "$ADMIN" | tee "$OUT/status.txt"
grep -q ': connected' "$OUT/status.txt" || fail "the server does not see the emulator"
"$HJ" remote planners --server $SERVER --token "$VIEWER" | tee "$OUT/planners.txt"

step "a streamed plan of $DEM"
"$HJ" remote plan "$DEM" --rows 3 --cols 4 --out "$OUT/plan" --snapshots --server $SERVER --token "$OPERATOR"
[ -f "$OUT/plan/plan.json" ] || fail "no plan.json"
ls "$OUT/plan" | grep -q snapshot || fail "no snapshots were streamed"

step "submit: a preview token is refused; the operator's job runs on the emulated device, capture, compare"
set +e
"$HJ" remote submit "$OUT/plan/plan.json" --server $SERVER --token "$VIEWER" >/dev/null 2>"$OUT/wrong-role.err"; code=$?
set -e
[ $code -eq 17 ] || fail "remote submit with a preview token: exit $code, expected 17 (PERMISSION_DENIED)"
echo "preview token submitting: exit 17 PERMISSION_DENIED"
"$HJ" remote submit "$OUT/plan/plan.json" --capture --wait --out "$OUT/device" --name "verify: volcano" \
  --server $SERVER --token "$OPERATOR" | tee "$OUT/submit.txt"
"$HJ" remote watch --once --recent 3 --server $SERVER --token "$OPERATOR" | tee "$OUT/watch.txt"
job=$(sed -nE 's/.*job ([0-9]+).*/\1/p' "$OUT/submit.txt" | head -1)
[ -n "$job" ] || fail "no job id in the submit output"

step "Python client: map zoom (the repeat from the cache)"
/usr/bin/python3 clients/python/examples/map_zoom.py --server $SERVER --token "$VIEWER" --dem "$DEM"

step "restart the server container: job $job is still in the queue database (volume)"
compose restart server >/dev/null 2>&1 || podman restart "${PROJECT}_server_1" >/dev/null
wait_serving
"$HJ" remote job "$job" --server $SERVER --token "$OPERATOR" | tee "$OUT/job-after-restart.txt"
grep -q done "$OUT/job-after-restart.txt" || fail "job $job is not 'done' after the restart"

step "stop: both programs end on SIGTERM"
start=$(date +%s)
compose stop >/dev/null 2>&1
echo "stopped in $(($(date +%s) - start)) s"
podman ps -a --filter "name=${PROJECT}_" --format '{{.Names}} {{.Status}}' | tee "$OUT/stopped.txt"

step "the image's default command: the offline demo"
podman run --rm hapticjam:latest >"$OUT/demo.log" 2>&1 || { tail "$OUT/demo.log"; fail "demo"; }
tail -3 "$OUT/demo.log"
