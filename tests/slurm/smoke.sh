#!/usr/bin/env bash
# End-to-end smoke test of the local single-node Slurm (tests/slurm/local_slurm.sh): the
# submission pattern a sweep uses, a throttled job array plus a job that depends on all of it.
#
#   smoke.sh [--keep]     (--keep: leave the cluster running afterwards)
#
# 1. local_slurm.sh start (installs slurm-wlm/munge if missing; exit 77 passes through).
# 2. sbatch --array=0-2%2: each task writes out_<task id> and its start/end times, sleeping
#    2 s, so tasks 0 and 1 must overlap (CR_CPU: one CPU per task) and never 3 at once (%2).
# 3. sbatch --dependency=afterany:<array id>: concatenates out_0..out_2 into all.txt; it must
#    not start before every array task has ended.
# 4. Waits by polling `squeue -j` (no accounting database here, so no sacct), then checks the
#    files and `scontrol show job` (state COMPLETED, exit 0:0, user root, dependency order).
# 5. Stops the cluster on exit (trap), unless it was already running before this script, in
#    which case it is left as it was found (someone else is using it).
#
# Jobs are submitted as whoever runs this (root here): plain sbatch, no --uid.
# Exit 0 on success, 77 when Slurm cannot be brought up here (reason on stderr), 1 on failure.
set -uo pipefail

here=$(cd "$(dirname "$0")" && pwd)
ls=$here/local_slurm.sh
keep=0
[[ ${1:-} == --keep ]] && keep=1
timeout_s=${SMOKE_TIMEOUT:-120}
t0=$SECONDS

fail() { echo "slurm smoke: FAIL: $*" >&2; exit 1; }

was_running=0
bash "$ls" running 2>/dev/null && was_running=1
bash "$ls" start
rc=$?
((rc == 77)) && exit 77
((rc == 0)) || fail "local_slurm.sh start exited $rc"
t_start=$((SECONDS - t0))

work=$(mktemp -d /tmp/slurm-smoke.XXXXXX)
chmod 755 "$work"
cleanup() {
  local rc=$?
  if ((rc != 0)) && [[ -d $work ]]; then
    echo "--- $work:" >&2; ls -l "$work" >&2
    for f in "$work"/slurm-*.out; do [[ -s $f ]] && { echo "--- $f" >&2; cat "$f" >&2; }; done
    bash "$ls" status >&2
  fi
  if ((!keep && !was_running)); then bash "$ls" stop; fi
  rm -rf "$work"
  exit $rc
}
trap cleanup EXIT
trap 'exit 1' INT TERM

cd "$work" || fail "cannot cd to $work"
task='t=$SLURM_ARRAY_TASK_ID; date +%s.%N > start_$t; echo $t > out_$t; sleep 2; date +%s.%N > end_$t'
arr=$(sbatch --parsable --job-name=smoke-array --array=0-2%2 -D "$work" -o "slurm-%A_%a.out" --wrap "$task") ||
  fail "sbatch of the array failed"
arr=${arr%%;*}
dep=$(sbatch --parsable --job-name=smoke-gather --dependency=afterany:"$arr" --kill-on-invalid-dep=yes \
        -D "$work" -o "slurm-%j.out" --wrap 'date +%s.%N > start_gather; cat out_0 out_1 out_2 > all.txt') ||
  fail "sbatch of the dependent job failed"
dep=${dep%%;*}
echo "slurm smoke: array job $arr, dependent job $dep"

# Poll until neither job is known to squeue any more (finished, whatever the outcome).
deadline=$((SECONDS + timeout_s))
while [[ -n $(squeue -h -j "$arr,$dep" -o %i 2>/dev/null) ]]; do
  ((SECONDS < deadline)) || { squeue -j "$arr,$dep" >&2; fail "jobs not done after $timeout_s s"; }
  sleep 0.5
done
t_jobs=$((SECONDS - t0 - t_start))

# Every job (each array task and the gather job) ended COMPLETED with exit code 0:0, as root.
info=$(scontrol -o show job "$arr"; scontrol -o show job "$dep") || fail "scontrol show job failed"
n=$(grep -c . <<<"$info")
((n == 4)) || fail "expected 4 job records (3 tasks + 1), got $n:"$'\n'"$info"
bad=$(grep -v 'JobState=COMPLETED' <<<"$info"; grep -v 'ExitCode=0:0' <<<"$info")
[[ -z $bad ]] || fail "a job did not complete cleanly:"$'\n'"$bad"
grep -q 'UserId=root(0)' <<<"$info" || [[ $(id -u) != 0 ]] || fail "jobs did not run as root"

[[ $(cat all.txt 2>/dev/null) == $'0\n1\n2' ]] || fail "all.txt is not 0,1,2: $(cat all.txt 2>&1)"

# Timing checks: at most 2 tasks at a time (the %2 throttle), tasks 0 and 1 overlapping (two
# CPUs, CR_CPU), and the gather job starting after the last task ended (the dependency).
python3 - <<'EOF' || fail "timing checks failed"
import sys
iv = [(float(open(f"start_{t}").read()), float(open(f"end_{t}").read())) for t in range(3)]
events = sorted([(s, 1) for s, _ in iv] + [(e, -1) for _, e in iv])
cur = peak = 0
for _, d in events:
    cur += d
    peak = max(peak, cur)
gather = float(open("start_gather").read())
print(f"slurm smoke: peak concurrent array tasks {peak}, gather started "
      f"{gather - max(e for _, e in iv):.1f} s after the last task ended")
ok = True
if peak > 2:
    print("  more than 2 tasks at once despite %2", file=sys.stderr); ok = False
import os
if len(os.sched_getaffinity(0)) >= 2 and peak < 2:
    print("  tasks did not run concurrently (expected 2 at once on >= 2 CPUs)", file=sys.stderr); ok = False
if gather < max(e for _, e in iv):
    print("  dependent job started before the array finished", file=sys.stderr); ok = False
sys.exit(0 if ok else 1)
EOF

echo "slurm smoke: OK (start ${t_start} s, jobs ${t_jobs} s, total $((SECONDS - t0)) s before stop)"
