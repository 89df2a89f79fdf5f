#!/usr/bin/env bash
# Two binaries of sheardiff compared as a sweep runs them: two runs at once on the 2 cores
# (seeds 1 and 2), each pair twice, for binary A and then binary B; prints every run's wall and
# CPU (user + sys) seconds, its steps, and the ratio of the mean wall times A / B. The runs are
# short pressure-cell runs from the random packing (configs/pressure_shear.toml). Stop anything
# else running on the machine first.
#
#   bench/two_workers.sh OLD_BINARY NEW_BINARY [N J STRAIN]     (default 1000 1e-3 0.1)
set -euo pipefail
a=$(realpath "$1"); b=$(realpath "$2"); n=${3:-1000}; j=${4:-1e-3}; strain=${5:-0.1}
root=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
timed() {  # binary seed -> "wall cpu steps" of one run
  local t0 t1 cpu steps
  t0=$(date +%s.%N)
  /usr/bin/time -f "%U %S" -o "$work/time$2" "$1" run "$root/configs/pressure_shear.toml" \
    --out "$work/run$2" --overwrite -q --set particles.N="$n" --set flow.J="$j" \
    --set run.strain="$strain" --set output.frame_strain=0.01 --set run.seed="$2" > /dev/null 2>&1
  t1=$(date +%s.%N)
  cpu=$(awk '{print $1 + $2}' "$work/time$2")
  steps=$(grep -o '"steps": [0-9]*' "$work/run$2/summary.json" | awk '{print $2}')
  echo "$(awk -v a="$t0" -v b="$t1" 'BEGIN { print b - a }') $cpu $steps"
}
declare -A sum=([A]=0 [B]=0)
for round in 1 2; do
  for which in A B; do
    bin=$a; [ "$which" = B ] && bin=$b
    timed "$bin" 1 > "$work/r1" & timed "$bin" 2 > "$work/r2" & wait
    for s in 1 2; do
      read -r wall cpu steps < "$work/r$s"
      printf '%s round %d seed %d: wall %.2f s, cpu %.2f s, %d steps\n' "$which" "$round" "$s" "$wall" "$cpu" "$steps"
      sum[$which]=$(awk -v s="${sum[$which]}" -v w="$wall" 'BEGIN { print s + w }')
    done
  done
done
awk -v a="${sum[A]}" -v b="${sum[B]}" -v n="$n" -v j="$j" -v s="$strain" 'BEGIN {
  printf "N = %s, J = %s, %s strain: mean wall A %.2f s, B %.2f s, A / B = %.2f\n", n, j, s, a / 4, b / 4, a / b }'
