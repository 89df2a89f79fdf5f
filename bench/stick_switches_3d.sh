#!/usr/bin/env bash
# Which sliding contacts of spheres the implicit integrator switches to sticking, on the states
# where it switches them (docs/performance.md, "Spheres"): a development measurement, not a
# feature. It applies bench/stick_switches_3d.diff (a counter in
# ForceBalanceOf::stick_reversed_sliding, printed every 200 steps when SHEARDIFF_DIAG_STICK is
# set) to a clone of the committed tree in a temporary folder, builds sheardiff there (about 15
# minutes on 2 cores) and runs N spheres in the cell of configs/sweep_3d.toml at J from a random
# start near its steady volume fraction for STRAIN strains. Per line, averaged over 200 steps:
#   sliding/step     contacts that enter a step sliding
#   switched/step    of those, switched to sticking (xi . s < 0, the default stick rule), all
#                    passes of the step
#   wall             ... of which with a wall sphere
#   cycle2           ... of which were also switched the step before (a contact flip-flopping)
#   cos              mean cosine between the stretch xi and the slip s of the switched ones
#   |s|dt/|xi|       mean slip over the step in units of the (capped) stretch
#   coulomb-inside / coulomb-through: how many of them the stick rule "coulomb" would also
#                    switch, because the trial stretch ends inside the cone / the slip carries
#                    the stretch through zero (docs/model.md section 7)
#
#   bash bench/stick_switches_3d.sh [N=500] [J=1e-3] [STRAIN=0.3] [PHI_INIT=0.55]
set -euo pipefail
n=${1:-500} j=${2:-1e-3} strain=${3:-0.3} phi=${4:-0.55}
root=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d /tmp/stick_switches_XXXX)
git clone -q "$root" "$work/src"
git -C "$work/src" apply "$root/bench/stick_switches_3d.diff"
cmake -S "$work/src" -B "$work/build" -G Ninja -DCMAKE_BUILD_TYPE=Release > "$work/cmake.log"
ninja -C "$work/build" sheardiff > "$work/build.log"
(cd "$root/configs" && SHEARDIFF_DIAG_STICK=1 "$work/build/sheardiff" run pressure_shear.toml \
  --out "$work/run" --set scene.dimension=3 --set particles.N="$n" --set particles.aspect=1.5 \
  --set flow.J="$j" --set particles.phi_init_spheres="$phi" --set run.strain="$strain" \
  --set steady.window=1 --set analysis.diffusion=false --set output.frame_strain=0 \
  --set output.trajectory=false 2>&1 | grep '^DIAG')
echo "(build and run in $work)"
