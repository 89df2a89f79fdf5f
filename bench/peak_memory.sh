#!/usr/bin/env bash
# Peak resident memory of pressure-cell runs (docs/performance.md, "Memory"): discs N = 1000
# (with and without three velocity intervals) and spheres N = 500, 1000, 2000, each at J = 1e-2
# from a start near its steady fraction. Steady state is declared early (a 0.1-strain window,
# loose tolerances) so that the streaming diffusion accumulators are allocated and fed for
# 0.2 strain; no trajectory. Peak memory does not depend on the machine's load; the run times
# printed are not benchmarks. Usage (from the repository root, after the build):
#   bash bench/peak_memory.sh [OUT_DIR]       # default runs/peak_memory; prints one line a run
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
out="$(realpath -m "${1:-runs/peak_memory}")"
mkdir -p "$out"
cd "$root/configs"
common=(--set steady.window=0.1 --set steady.h_tolerance=1 --set steady.mu_tolerance=10
        --set steady.measure_strain=0.2 --set run.strain=1 --set output.trajectory=false
        --set output.frame_strain=0 --set flow.J=1e-2)
discs=(--set particles.N=1000 --set particles.phi_init=0.74 --set particles.mix=volume)
spheres=(--set scene.dimension=3 --set particles.aspect=1.5 --set particles.phi_init_spheres=0.52)
run() {
  local name=$1
  shift
  rm -rf "${out:?}/$name"
  /usr/bin/time -f "%M" -o "$out/$name.peak_kb" "$root/build/sheardiff" run pressure_shear.toml \
    --out "$out/$name" --quiet "${common[@]}" "$@" > "$out/$name.out" 2>&1 ||
    { echo "$name failed: see $out/$name.out" >&2; return 1; }
  printf '%-28s peak resident memory %6.1f MB\n' "$name" "$(awk '{print $1 * 1024 / 1e6}' "$out/$name.peak_kb")"
}
run discs_1000 "${discs[@]}"
run discs_1000_three_intervals "${discs[@]}" --set 'analysis.velocity_intervals=[0.0035, 0.01, 0.035]'
run spheres_500 "${spheres[@]}" --set particles.N=500
run spheres_1000 "${spheres[@]}" --set particles.N=1000
run spheres_2000 "${spheres[@]}" --set particles.N=2000
