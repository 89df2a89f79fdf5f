#!/usr/bin/env bash
# `sheardiff sweep --backend slurm` end to end through a real single-node Slurm on localhost
# (tests/slurm/local_slurm.sh installs slurm-wlm + munge if missing and starts the daemons):
# a job array of the unfinished points with the sweep's % throttle, and a collect job that
# depends on it and writes sweep.csv and fits.json. Exit 77 (ctest: skipped) with the reason
# where Slurm cannot be installed. Usage: sweep_slurm.sh SHEARDIFF_BIN REPO_DIR WORK_DIR
set -uo pipefail
bin=$(realpath "$1"); repo=$(realpath "$2"); work=$3
ls=$repo/tests/slurm/local_slurm.sh
fail() { echo "sweep_slurm: FAIL: $*" >&2; exit 1; }

was_running=0
bash "$ls" running 2>/dev/null && was_running=1
bash "$ls" start; rc=$?
((rc == 77)) && exit 77
((rc == 0)) || fail "local_slurm.sh start exited $rc"
cleanup() {
  local rc=$?
  if ((rc != 0)); then
    for f in "$work"/out/logs/*; do [[ -s $f ]] && { echo "--- $f" >&2; tail -5 "$f" >&2; }; done
    bash "$ls" status >&2
  fi
  ((was_running)) || bash "$ls" stop
  exit $rc
}
trap cleanup EXIT
trap 'exit 1' INT TERM

rm -rf "$work"; mkdir -p "$work"; cd "$work" || fail "cd $work"
cat > tiny.toml <<TOML
[sweep]
base = "$repo/configs/quick.toml"
backend = "slurm"
[sweep.set]
"particles.N" = 60
"run.strain" = 5.0
"steady.window" = 0.5
"steady.measure_strain" = 1.0
# A machinery test: its 1-strain windows are transients; the stationarity verdict (tested in
# test_stationarity.cpp) is relaxed so that every point counts as done.
"steady.drift_z" = 100.0
"steady.bulk_load_tolerance" = 1.0
[sweep.axes]
"flow.J" = [0.1, 0.05, 0.02, 0.01]
[slurm]
throttle = 2
time = "00:10:00"
mem_per_task = "500M"
TOML
# One point finished beforehand: the array must leave it out.
"$bin" sweep tiny.toml --out out --point 0 > point0.log 2>&1 || fail "point 0 locally"
"$bin" sweep tiny.toml --out out > submit.log 2>&1 || { cat submit.log; fail "submission"; }
cat submit.log
grep -q '^#SBATCH --array=1,2,3%2$' out/slurm/array.sbatch || fail "array line: $(grep array out/slurm/array.sbatch)"
read -r arr col < <(/usr/bin/python3 -c "import json; j=json.load(open('out/slurm/jobs.json')); print(j['array'], j['collect'])")
deadline=$((SECONDS + 300))
while [[ -n $(squeue -h -j "$arr,$col" -o %i 2>/dev/null) ]]; do
  ((SECONDS < deadline)) || { squeue >&2; fail "jobs not done after 300 s"; }
  sleep 1
done
info=$(scontrol -o show job "$arr"; scontrol -o show job "$col")
[[ $(grep -c 'JobState=COMPLETED' <<<"$info") == 4 ]] || fail "not 3 array tasks + collect completed:"$'\n'"$info"
ls out/logs/slurm-"$arr"_{1,2,3}.out > /dev/null || fail "array task logs missing"
ls out/logs/slurm-collect-"$col".out > /dev/null || fail "collect log missing"
[[ $(grep -c '^[^,]*,"\?done' out/sweep.csv) == 4 ]] || fail "sweep.csv: $(cut -d, -f1,2 out/sweep.csv)"
/usr/bin/python3 -c "
import json, math
f = json.load(open('out/fits.json'))
assert f['finished'] == 4 and len(f['groups']) == 1, f
fit = f['groups'][0]['fits']['phi_of_J']
assert math.isfinite(fit['phi_c']) and fit['phi_c'] > 0.5, fit
" || fail "fits.json"
# Submitting again once everything is finished sends no array, only a collect job.
"$bin" sweep tiny.toml --out out > resubmit.log 2>&1 || fail "resubmission"
grep -q "job array none" resubmit.log || fail "resubmission sent an array: $(cat resubmit.log)"
echo "sweep_slurm: array $arr (3 points, %2) + collect $col completed; sweep.csv and fits.json complete"
