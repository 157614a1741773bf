#!/usr/bin/env bash
# N kill -9 of hapticjam-server (default 200) at random moments while three
# clients submit, cancel and resume against the device emulator; prints the
# counts of every check after each restart (scripts/crash_campaign.py).
# Usage: scripts/crash_campaign.sh [N] [BUILD_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
kills="${1:-200}"
build="$(cd "${2:-build}" && pwd)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
PYTHONPATH="$build/clients/python:$PWD/clients/python" /usr/bin/python3 scripts/crash_campaign.py "$build" "$kills" "$work"
