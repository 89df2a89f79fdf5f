#!/usr/bin/env bash
# The full stress grid (issue 6, docs/stability.md): discs/spheres x 6 J x 5 ktilde x
# dense/dilute x implicit/heun x adaptive/fixed dt = 480 points, one at a time, each capped at
# CAP seconds.
#
#   bash tests/stress/run_full.sh [BUILD_DIR] [CAP]      (defaults: build, 30)
#
# Writes tests/stress/last_full.md (the table for docs/stability.md) and last_full.json.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
build=${1:-$here/../../build}
cap=${2:-30}
exec /usr/bin/python3 "$here/stress_grid.py" --bin "$(realpath "$build/sheardiff")" --grid full \
  --cap "$cap" --known "$here/known_failures.txt" \
  --markdown "$here/last_full.md" --json "$here/last_full.json"
