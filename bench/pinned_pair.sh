#!/usr/bin/env bash
# Two binaries of sheardiff compared run against run: the old and the new binary at once, each
# pinned to one of the 2 cores, the cores swapped every round, the same pressure-cell run from
# the random packing (configs/pressure_shear.toml, seed 1). For a change meant to leave the
# trajectory bit-identical the two runs take the same steps, so their CPU times compare the
# cost of the same work under the same load. Prints each pair's CPU seconds (user + sys) and
# new / old - 1, then the geometric mean of new / old over the rounds: with an even number of
# rounds a core's own speed cancels from it (on this VM one core has run 25 % slower than the
# other for minutes). Stop anything else running on the machine first.
#
#   bench/pinned_pair.sh OLD_BINARY NEW_BINARY [N J STRAIN ROUNDS [KEY=VALUE ...]]
#   (default 1000 1e-4 0.3 2; each KEY=VALUE is passed to both runs as --set, e.g.
#   scene.dimension=3 particles.aspect=1.5 particles.phi_init_spheres=0.52 for spheres)
set -euo pipefail
a=$(realpath "$1"); b=$(realpath "$2"); n=${3:-1000}; j=${4:-1e-4}; strain=${5:-0.3}
rounds=${6:-2}
extra=()
for kv in "${@:7}"; do extra+=(--set "$kv"); done
root=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
start() {  # binary core tag
  taskset -c "$2" /usr/bin/time -f "%U %S" -o "$work/time$3" "$1" run \
    "$root/configs/pressure_shear.toml" --out "$work/run$3" --overwrite -q \
    --set particles.N="$n" --set flow.J="$j" --set run.strain="$strain" \
    --set analysis.diffusion=false "${extra[@]}" > /dev/null 2>&1
}
logsum=0
for round in $(seq 1 "$rounds"); do
  core_a=$(( (round - 1) % 2 )); core_b=$(( 1 - core_a ))
  start "$a" "$core_a" A & pa=$!
  start "$b" "$core_b" B & pb=$!
  wait "$pa" "$pb"
  cpu_a=$(awk '{print $1 + $2}' "$work/timeA"); cpu_b=$(awk '{print $1 + $2}' "$work/timeB")
  steps_a=$(grep -o '"steps": [0-9]*' "$work/runA/summary.json" | awk '{print $2}')
  steps_b=$(grep -o '"steps": [0-9]*' "$work/runB/summary.json" | awk '{print $2}')
  d=$(awk -v a="$cpu_a" -v b="$cpu_b" 'BEGIN { print b / a - 1 }')
  printf 'round %d: old (core %d) %.2f s, %d steps; new (core %d) %.2f s, %d steps; new/old - 1 = %+.1f %%\n' \
    "$round" "$core_a" "$cpu_a" "$steps_a" "$core_b" "$cpu_b" "$steps_b" "$(awk -v d="$d" 'BEGIN { print 100 * d }')"
  logsum=$(awk -v s="$logsum" -v d="$d" 'BEGIN { print s + log(1 + d) }')
done
awk -v s="$logsum" -v r="$rounds" -v n="$n" -v j="$j" -v t="$strain" 'BEGIN {
  printf "N = %s, J = %s, %s strain: geometric mean new/old - 1 over %d rounds = %+.1f %%\n", n, j, t, r, 100 * (exp(s / r) - 1) }'
