#!/usr/bin/env bash
# An existing run is never changed without the user saying so (issue 16, finding 2). It used
# to be: a finished run was overwritten without a word; `run` without --resume on an
# interrupted run deleted its checkpoint and restarted from strain 0; a new run without
# trajectory output left the old trajectory.h5 and analysis.h5 beside its config, and
# `analyse` then analysed them with the new J.
#
#   run_dir_protect.sh SHEARDIFF WORK_DIR
set -uo pipefail
bin=$(realpath "$1"); work=$2
rm -rf "$work"; mkdir -p "$work"; cd "$work" || exit 1
fail() { echo "FAIL: $*"; exit 1; }
expect() {  # expect CODE TEXT -- sheardiff ARGS...: exit CODE and TEXT on stderr
  local code=$1 text=$2 rc=0; shift 3
  "$bin" "$@" > cmd.out 2> cmd.err || rc=$?
  [ "$rc" = "$code" ] || fail "'sheardiff $*': exit $rc, expected $code: $(cat cmd.err)"
  [ -z "$text" ] || grep -qF -- "$text" cmd.err || fail "'sheardiff $*': stderr lacks '$text': $(cat cmd.err)"
}
snapshot() { (cd "$1" && find . -type f -print0 | sort -z | xargs -0 sha256sum); }

cat > run.toml <<'TOML'
[scene]
type = "simple_shear"
[particles]
N = 60
[run]
strain = 0.6
[output]
frame_strain = 0.01
checkpoint_strain = 0.05
[analysis]
msd_window_lo = 0.1
msd_window_hi = 0.3
reference_times = 20
TOML

# A finished run is refused, byte for byte untouched.
"$bin" run run.toml --out fin > /dev/null 2>&1 || fail "first run"
snapshot fin > fin.sha
expect 2 "fin holds a finished run (summary.json); it is left as it is" -- run run.toml --out fin
expect 2 "holds a finished run" -- run run.toml --out fin --set flow.J=0.02
snapshot fin | diff -q fin.sha - > /dev/null || fail "the refused runs changed the finished run"

# --overwrite replaces it, and nothing of the old run survives: without trajectory output
# and no diffusion analysis there is no trajectory.h5 or analysis.h5 any more, and analyse
# says so.
expect 0 "" -- run run.toml --out fin --overwrite --set output.trajectory=false \
  --set analysis.diffusion=false --set flow.J=0.02
[ -e fin/trajectory.h5 ] && fail "the old trajectory.h5 survived --overwrite"
[ -e fin/analysis.h5 ] && fail "the old analysis.h5 survived --overwrite"
grep -q "^J = 0.02" fin/config.toml || fail "config.toml is not the new run's"
[ "$(grep -c '^===' fin/run.log)" = 1 ] || fail "the old run.log survived --overwrite"
expect 2 "output.trajectory = false: there is no trajectory to analyse" -- analyse fin

# --overwrite would delete the config it is given.
expect 2 "fin/config.toml is the config.toml of the run in fin, which --overwrite deletes" -- run fin/config.toml --out fin --overwrite
[ -e fin/config.toml ] || fail "--overwrite deleted the config it was running"

# An interrupted run: forgetting --resume is refused, the checkpoint untouched; --resume goes on.
"$bin" run run.toml --out int > int.out 2>&1 &
pid=$!
for _ in $(seq 400); do [ -e int/checkpoint.bin ] && break; sleep 0.02; done
kill -TERM "$pid"; wait "$pid"; rc=$?
[ "$rc" = 143 ] || fail "SIGTERM: exit $rc"
snapshot int > int.sha
expect 2 "int holds an interrupted run (checkpoint.bin); it is left as it is. Continue it with \`sheardiff run CONFIG --resume int\`" -- run run.toml --out int
snapshot int | diff -q int.sha - > /dev/null || fail "the refused run changed the interrupted run"
expect 0 "" -- run run.toml --resume int
[ -e int/summary.json ] && [ ! -e int/checkpoint.bin ] || fail "the resumed run did not finish"

# A run killed before its first checkpoint: refused without --resume, restarted by it.
mkdir early && : > early/trajectory.h5
"$bin" check run.toml --set output.trajectory=false > early/config.toml || fail "check"
expect 2 "stopped before its first checkpoint (config.toml, trajectory.h5)" -- run run.toml --out early
expect 0 "no checkpoint was written before the run stopped: starting again from strain 0" -- run run.toml --resume early --set output.trajectory=false
[ -e early/trajectory.h5 ] && fail "the partial trajectory.h5 survived the restart"
# Resuming with another configuration is refused (exit 2), whatever the state, naming each key
# that changed with its old and new value.
expect 2 "the configuration differs from the one the run was started with (" -- run run.toml --resume int --set flow.J=0.05
grep -qF "flow.J: 0.01 -> 0.05" cmd.err || fail "the refusal does not name flow.J: $(cat cmd.err)"
# Keys that follow from a change (here output.frame_strain left to J, and the sample spacing
# derived from it) are named apart from the change the user made.
expect 2 "(flow.J: 0.01 -> 0.05; and, following from them, analysis.sample_strain, output.frame_strain;" -- run run.toml --resume int --set flow.J=0.05 --set output.frame_strain=0
# Nothing to resume.
mkdir empty
expect 2 "--resume empty: there is no run there to resume" -- run run.toml --resume empty
expect 2 "nope: no such directory" -- run run.toml --resume nope
[ -e nope ] && fail "--resume created a directory"
# A run of spheres recorded by a sheardiff older than contact.sliding_stiffness (its config.toml
# does not name the key) ran "none", which a file of spheres no longer defaults to. Its own
# record given back (`run DIR/config.toml --resume DIR`) extends it as the run it was; the
# user's file that does not name the key is refused, naming the key and how to keep "none".
cat > spheres.toml <<'TOML'
[scene]
type = "pressure_shear"
dimension = 3
[particles]
N = 64
phi_init_spheres = 0.5
[flow]
J = 0.03
[contact]
ktilde = 1e3
[run]
strain = 0.1
[steady]
window = 0.05
[analysis]
diffusion = false
[output]
trajectory = false
TOML
"$bin" run spheres.toml --out old --set contact.sliding_stiffness=none > /dev/null 2>&1 || fail "spheres run"
grep -q '^sliding_stiffness = "none"$' old/config.toml || fail "the record does not name the law"
sed -i '/^sliding_stiffness = /d' old/config.toml
expect 2 "contact.sliding_stiffness: \"none\" -> \"sideways\"" -- run spheres.toml --resume old --set run.strain=0.15
grep -qF -- "--set contact.sliding_stiffness=none" cmd.err || fail "no hint to keep the law: $(cat cmd.err)"
expect 0 "" -- run old/config.toml --resume old --set run.strain=0.15
grep -qF '"strain": 0.15' old/summary.json || fail "the record's extension did not reach strain 0.15"
expect 0 "" -- run spheres.toml --resume old --set run.strain=0.2 --set contact.sliding_stiffness=none
echo "run_dir_protect: finished and interrupted runs refused untouched; --overwrite left no stale file; --resume continued or restarted; a pre-key record of spheres continued as it ran"
