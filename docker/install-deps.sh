#!/usr/bin/env bash
# Installs everything hapticjam builds with, from Debian 12 packages only.
# Used by the README's commands, .ci/run and docker/Dockerfile.
set -euo pipefail
packages=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev libsuitesparse-dev libopenblas-dev nlohmann-json3-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libboost-dev libboost-system-dev
  libprotobuf-dev protobuf-compiler libgrpc++-dev protobuf-compiler-grpc
  libopencv-dev libassimp-dev libsqlite3-dev libgdal-dev libceres-dev
  python3 python3-grpcio python3-protobuf openssl
  libjs-three chromium chromium-driver python3-selenium
)
# Optional: clang and its libFuzzer/sanitizer runtimes for scripts/fuzz.sh (not used by CI).
[ "${HJ_FUZZ_DEPS:-0}" = 1 ] && packages+=(clang libclang-rt-dev)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO="sudo"
echo "install-deps: installing ${missing[*]}"
$SUDO apt-get update -q
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
