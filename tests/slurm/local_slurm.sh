#!/usr/bin/env bash
# A real single-node Slurm cluster on this machine, for end-to-end tests of sweeps submitted
# through sbatch (job arrays, dependencies).
#
#   local_slurm.sh start     install if missing, configure, start munged/slurmctld/slurmd, wait
#                            until the node is idle; does nothing if our cluster already runs
#   local_slurm.sh stop      cancel our jobs, stop slurmd and slurmctld (and munged if we
#                            started it); no daemon of ours is left behind
#   local_slurm.sh status    sinfo and squeue
#   local_slurm.sh running   exit 0 if our cluster is up and its node answers, 1 otherwise
#
# Exit codes: 0 ok, 77 cannot be done here (ctest SKIP_RETURN_CODE; reason on stderr), 1 error.
#
# Why it looks the way it does:
# * No systemd: on these machines PID 1 is not systemd (containers; here gVisor), so
#   `systemctl start` does not work. The daemons are started directly: munged as user munge
#   (runuser), slurmctld and slurmd as root; each daemonizes and writes a pid file under
#   $LOCAL_SLURM_DIR/run, and `stop` kills those pids only (never by process name).
# * No daemon is started by apt: packages are installed with a policy-rc.d that forbids it
#   (the one already there is kept), so the only daemons running are the ones started here.
# * No cgroups: a container's cgroup tree is not ours to manage (read-only or fake v1 mounts),
#   so ProctrackType=proctrack/linuxproc (follows jobs via /proc), TaskPlugin=task/none,
#   JobAcctGatherType=jobacct_gather/none; no cgroup plugin is loaded, so no cgroup.conf.
# * No accounting database: AccountingStorageType=accounting_storage/none, JobCompType=none.
#   `sacct` does not work; use `squeue -j` and `scontrol show job` (jobs stay visible to
#   scontrol for MinJobAge=600 s after they end).
# * Hostname: the node is NodeName=$(hostname -s) with NodeAddr=127.0.0.1, and
#   SlurmctldHost=$(hostname -s)(127.0.0.1), so nothing depends on DNS or /etc/hosts.
# * Resources: CPUs=$(nproc) and RealMemory from `free -m`; SelectType=select/cons_tres with
#   CR_CPU, so each array task takes one CPU and `nproc` tasks run at once (memory is not a
#   consumable). SlurmdParameters=config_overrides: a node whose hardware probe (hwloc, which
#   in a container may see the host) differs from the configuration is not drained.
# * Jobs run as root: as root, plain `sbatch ...` works (DisableRootJobs defaults to NO);
#   no --uid is needed.
# * The configuration is /etc/slurm/slurm.conf (where every client looks, so the sweep under
#   test calls plain sbatch/squeue). It carries a marker line; a slurm.conf without the marker
#   belongs to someone else and is never overwritten (exit 77).
# * State, spool, logs and pid files live in $LOCAL_SLURM_DIR (default
#   /var/lib/sheardiff-local-slurm); every fresh start clears the saved state (slurmctld -c), so
#   job ids start again from 1. Daemon logs: $LOCAL_SLURM_DIR/log/*.log.
# * Scheduling latency: SchedulerParameters=bf_interval=1 so a throttled array task or a job
#   whose dependency is now met starts within about a second instead of the default 30 s.
#
# Seen on Debian 12 (slurm-wlm 22.05.8, munge 0.5.15) in a gVisor container:
# * `start` takes about 15-20 s when it has to install (9 packages, --no-install-recommends)
#   and 1-2 s when slurm is installed; `stop` about 3-4 s.
# * The munge package's postinst creates /etc/munge/munge.key (munge:munge 0400); the key is
#   only created here when missing. munged needs /run/munge (no tmpfiles without systemd).
# * slurmctld and slurmd delete their pid files while shutting down, so `stop` reads the pids
#   first and waits on the processes; munged takes 1-2 s to exit after SIGTERM.
# * slurmd needs no cgroup.conf with these plugins. The logs show "mpi/pmix: can not load PMIx
#   library" errors: 22.05 loads every MPI plugin even with MpiDefault=none; harmless.
set -uo pipefail

DIR=${LOCAL_SLURM_DIR:-/var/lib/sheardiff-local-slurm}
CONF=/etc/slurm/slurm.conf
MARKER="# written by sheardiff tests/slurm/local_slurm.sh"
NODE=$(hostname -s)
WAIT_IDLE=${LOCAL_SLURM_WAIT:-60}
RUN=$DIR/run

skip() { echo "local_slurm: skipped: $*" >&2; exit 77; }
die() { echo "local_slurm: error: $*" >&2; exit 1; }
log() { echo "local_slurm: $*" >&2; }

pid_alive() {  # pid_alive PIDFILE NAME: the pid in PIDFILE is alive and is the program NAME
  local pid
  [[ -s $1 ]] || return 1
  pid=$(<"$1") && [[ $pid =~ ^[0-9]+$ ]] || return 1
  [[ $(cat "/proc/$pid/comm" 2>/dev/null) == "$2" ]]
}

munge_works() { command -v munge >/dev/null && munge -n 2>/dev/null | unmunge >/dev/null 2>&1; }

node_state() { timeout 10 sinfo -h -N -n "$NODE" -o %T 2>/dev/null | head -n1; }

running() {
  pid_alive "$RUN/slurmctld.pid" slurmctld && pid_alive "$RUN/slurmd.pid" slurmd || return 1
  timeout 10 scontrol ping 2>/dev/null | grep -q UP || return 1
  case $(node_state) in idle*|mix*|alloc*|comp*) return 0 ;; *) return 1 ;; esac
}

install_packages() {
  local missing=()
  command -v munged >/dev/null || missing+=(munge)
  for p in slurmctld slurmd sbatch; do command -v $p >/dev/null || { missing+=(slurm-wlm); break; }; done
  ((${#missing[@]})) || return 0
  [[ $(id -u) == 0 ]] || skip "slurm-wlm/munge are not installed and we are not root"
  command -v apt-get >/dev/null || skip "slurm-wlm/munge are not installed and there is no apt-get"
  log "installing ${missing[*]} (apt-get)"
  # Forbid the packages' maintainer scripts to start daemons (no init system to own them).
  local prc=/usr/sbin/policy-rc.d ours=0
  if [[ ! -e $prc ]]; then printf '#!/bin/sh\nexit 101\n' >"$prc"; chmod 755 "$prc"; ours=1; fi
  local args=(-y -q --no-install-recommends -o Dpkg::Options::=--force-confold install "${missing[@]}")
  local ok=0
  DEBIAN_FRONTEND=noninteractive apt-get "${args[@]}" >"$DIR/log/apt.log" 2>&1 && ok=1
  if ((!ok)); then  # package lists may be missing or stale
    DEBIAN_FRONTEND=noninteractive apt-get -q update >>"$DIR/log/apt.log" 2>&1 &&
      DEBIAN_FRONTEND=noninteractive apt-get "${args[@]}" >>"$DIR/log/apt.log" 2>&1 && ok=1
  fi
  ((ours)) && rm -f "$prc"
  ((ok)) || { tail -n 5 "$DIR/log/apt.log" >&2; skip "apt-get install ${missing[*]} failed (no network or no package source?), see $DIR/log/apt.log"; }
}

start_munge() {
  # A munged that already answers is used as it is: ours from an earlier start (the marker
  # file says so and `stop` will end it), or someone else's (no marker: left alone).
  munge_works && return 0
  id munge >/dev/null 2>&1 || die "user munge does not exist (broken munge package?)"
  install -d -m 0700 -o munge -g munge /etc/munge /var/lib/munge /var/log/munge
  install -d -m 0755 -o munge -g munge /run/munge
  if [[ ! -s /etc/munge/munge.key ]]; then
    log "creating /etc/munge/munge.key"
    if command -v mungekey >/dev/null; then mungekey --create --keyfile=/etc/munge/munge.key
    else dd if=/dev/urandom of=/etc/munge/munge.key bs=1024 count=1 status=none; fi
  fi
  # munged refuses a key readable by others or not owned by its user.
  chown munge:munge /etc/munge/munge.key && chmod 0400 /etc/munge/munge.key
  rm -f /run/munge/munged.pid
  runuser -u munge -- /usr/sbin/munged >>"$DIR/log/munged.start.log" 2>&1 ||
    runuser -u munge -- /usr/sbin/munged --force >>"$DIR/log/munged.start.log" 2>&1 ||
    { cat "$DIR/log/munged.start.log" >&2; die "munged does not start"; }
  for _ in $(seq 50); do munge_works && break; sleep 0.2; done
  munge_works || die "munged started but munge -n | unmunge fails"
  touch "$RUN/munged.ours"
}

write_conf() {
  if [[ -e $CONF ]] && ! grep -qxF "$MARKER" "$CONF"; then
    skip "$CONF exists and was not written by this script; not touching a real cluster's configuration"
  fi
  local cpus mem
  cpus=$(nproc)
  mem=$(free -m | awk '/^Mem:/ {print $2}')
  [[ $mem =~ ^[0-9]+$ ]] || mem=1024
  mkdir -p /etc/slurm
  cat >"$CONF.tmp" <<EOF
$MARKER
# Single-node test cluster; see that script for why each setting is what it is.
ClusterName=sheardiff-local
SlurmctldHost=$NODE(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CryptoType=crypto/munge
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
SwitchType=switch/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
SchedulerParameters=bf_interval=1,sched_min_interval=100000
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
ReturnToService=2
SlurmdParameters=config_overrides
StateSaveLocation=$DIR/state
SlurmdSpoolDir=$DIR/spool
SlurmctldPidFile=$RUN/slurmctld.pid
SlurmdPidFile=$RUN/slurmd.pid
SlurmctldLogFile=$DIR/log/slurmctld.log
SlurmdLogFile=$DIR/log/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
MailProg=/bin/true
SlurmctldTimeout=30
SlurmdTimeout=30
MessageTimeout=10
InactiveLimit=0
KillWait=5
MinJobAge=600
Waittime=0
NodeName=$NODE NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=debug Nodes=$NODE Default=YES MaxTime=INFINITE State=UP
EOF
  mv "$CONF.tmp" "$CONF"
}

dump_logs() {
  for f in slurmctld slurmd; do
    [[ -s $DIR/log/$f.log ]] && { echo "--- $DIR/log/$f.log (tail)" >&2; tail -n 15 "$DIR/log/$f.log" >&2; }
  done
}

start_daemon() {  # start_daemon NAME ARGS...: run the daemon, wait for its pid file
  local name=$1; shift
  rm -f "$RUN/$name.pid"
  "$name" "$@" >>"$DIR/log/$name.start.log" 2>&1 || { cat "$DIR/log/$name.start.log" >&2; dump_logs; die "$name failed to start"; }
  for _ in $(seq 100); do pid_alive "$RUN/$name.pid" "$name" && return 0; sleep 0.1; done
  dump_logs; die "$name did not stay up"
}

cmd_start() {
  local t0=$SECONDS
  if running; then log "already running (node $NODE $(node_state))"; return 0; fi
  [[ $(id -u) == 0 ]] || skip "not root: cannot start slurm daemons"
  mkdir -p "$DIR/log" "$RUN" || skip "cannot create $DIR"
  install_packages
  # Anything half up from an earlier run (one daemon dead, node down) is restarted from scratch.
  stop_slurm_daemons
  rm -rf "$DIR/state" "$DIR/spool"
  mkdir -p "$DIR/state" "$DIR/spool"
  write_conf
  start_munge
  start_daemon slurmctld -c
  start_daemon slurmd
  local st=""
  for _ in $(seq $((WAIT_IDLE * 2))); do
    st=$(node_state)
    case $st in
      idle*) log "up in $((SECONDS - t0)) s: node $NODE idle, $(nproc) CPUs"; return 0 ;;
      drain*|down*|fail*) timeout 10 scontrol update nodename="$NODE" state=resume >/dev/null 2>&1 ;;
    esac
    sleep 0.5
  done
  timeout 10 scontrol show node "$NODE" >&2
  dump_logs
  die "node $NODE not idle after ${WAIT_IDLE} s (state: ${st:-no answer})"
}

pid_of() {  # pid_of PIDFILE NAME: print the pid in PIDFILE if it is alive and is NAME
  pid_alive "$1" "$2" && cat "$1"
}

alive() { [[ -n $1 && $(cat "/proc/$1/comm" 2>/dev/null) == "$2" ]]; }  # alive PID NAME

stop_pid() {  # stop_pid PID NAME: wait up to 10 s for it to go (after a polite request), TERM, KILL
  local pid=$1 name=$2
  alive "$pid" "$name" || return 0
  for _ in $(seq 50); do alive "$pid" "$name" || return 0; sleep 0.2; done
  kill -TERM "$pid" 2>/dev/null
  for _ in $(seq 50); do alive "$pid" "$name" || return 0; sleep 0.2; done
  log "$name ($pid) ignores SIGTERM, killing"; kill -KILL "$pid" 2>/dev/null; sleep 0.2
}

stepds() {  # pids of slurmstepd processes (job step supervisors, forked by our slurmd)
  local f
  for f in /proc/[0-9]*/comm; do
    [[ $(cat "$f" 2>/dev/null) == slurmstepd ]] && { f=${f#/proc/}; echo "${f%/comm}"; }
  done
}

stop_slurm_daemons() {
  # Pids are read before anything stops: the daemons remove their pid files while shutting down.
  local ctld sd p
  ctld=$(pid_of "$RUN/slurmctld.pid" slurmctld)
  sd=$(pid_of "$RUN/slurmd.pid" slurmd)
  if [[ -n $ctld ]]; then
    # Cancel our cluster's jobs first, so that no slurmstepd or job outlives the daemons.
    local jobs
    jobs=$(timeout 10 squeue -h -o %A 2>/dev/null | sort -u | tr '\n' ' ')
    if [[ -n ${jobs// } ]]; then
      timeout 10 scancel $jobs 2>/dev/null
      for _ in $(seq 30); do [[ -z $(timeout 10 squeue -h -o %A 2>/dev/null) ]] && break; sleep 0.5; done
    fi
    timeout 10 scontrol shutdown >/dev/null 2>&1  # slurmctld and every slurmd
  elif [[ -n $sd ]]; then
    kill -TERM "$sd" 2>/dev/null
  fi
  [[ -n $sd ]] && stop_pid "$sd" slurmd
  [[ -n $ctld ]] && stop_pid "$ctld" slurmctld
  # A job step's slurmstepd may still be finishing its cleanup: give it time to end by itself
  # (only while our slurmd was running is any slurmstepd ours).
  if [[ -n $sd ]]; then
    for _ in $(seq 50); do [[ -z $(stepds) ]] && break; sleep 0.2; done
    for p in $(stepds); do log "slurmstepd $p still running"; done
  fi
  rm -f "$RUN/slurmd.pid" "$RUN/slurmctld.pid"
}

cmd_stop() {
  [[ -d $RUN ]] || return 0
  stop_slurm_daemons
  if [[ -e $RUN/munged.ours ]]; then
    local m; m=$(pid_of /run/munge/munged.pid munged)
    [[ -n $m ]] && { kill -TERM "$m" 2>/dev/null; stop_pid "$m" munged; }
    rm -f "$RUN/munged.ours"
  fi
  log "stopped"
}

cmd_status() {
  if ! command -v sinfo >/dev/null; then echo "slurm is not installed"; return 1; fi
  local rc=0
  running && echo "local slurm: running" || { echo "local slurm: not running"; rc=1; }
  timeout 10 sinfo 2>&1
  timeout 10 squeue 2>&1
  return $rc
}

case ${1:-} in
  start) cmd_start ;;
  stop) cmd_stop ;;
  status) cmd_status ;;
  running) running ;;
  *) echo "usage: $0 start|stop|status|running" >&2; exit 2 ;;
esac
