#!/usr/bin/env bash
# The shipped quick sweep end to end on the local backend with 2 workers, then its results
# checked for shape and trends (check_fits.py). Usage: sweep_quick.sh SHEARDIFF_BIN REPO WORK
set -euo pipefail
bin=$(realpath "$1"); repo=$(realpath "$2"); work=$3
rm -rf "$work"; mkdir -p "$work"
"$bin" sweep "$repo/configs/sweep_quick.toml" --out "$work/out" --jobs 2
/usr/bin/python3 "$repo/tests/sweep/check_fits.py" "$work/out" 4
