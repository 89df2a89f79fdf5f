#!/usr/bin/env bash
# Which sheardiff made a result (issue 17, part 3): there was no --version, and summary.json had
# no version, git hash, seed, date or host. Checks `sheardiff --version`, the hash CMake takes
# from the source tree (cmake/GitVersion.cmake: a checkout, a changed tracked file, a folder that
# is not a checkout, a subfolder of someone else's checkout), and the keys of a run's summary.
#
#   version.sh SHEARDIFF SOURCE_DIR WORK_DIR
set -uo pipefail
bin=$(realpath "$1"); src=$(realpath "$2"); work=$3
rm -rf "$work"; mkdir -p "$work"; cd "$work" || exit 1
fail() { echo "FAIL: $*"; exit 1; }
py=/usr/bin/python3

# --version: exit 0, one line, with or without a subcommand after it.
out=$("$bin" --version) || fail "--version exited $?"
echo "$out"
[[ "$out" =~ ^sheardiff\ [0-9]+\.[0-9]+\.[0-9]+\ \(git\ ([0-9a-f]{4,40}(-dirty)?|unknown)\)$ ]] ||
  fail "--version printed '$out'"
hash=$(sed 's/.*(git \(.*\))/\1/' <<< "$out")
# Built from a checkout, it names a commit of it (HEAD at the last build).
if git -C "$src" rev-parse --show-toplevel > /dev/null 2>&1 &&
   [ "$(realpath "$(git -C "$src" rev-parse --show-toplevel)")" = "$src" ]; then
  git -C "$src" cat-file -e "${hash%-dirty}^{commit}" 2> /dev/null ||
    fail "the hash $hash is not a commit of $src"
fi
[ "$("$bin" --version run 2>&1)" = "$out" ] || fail "--version before a subcommand"

# The hash GitVersion.cmake computes (at configure time and at every build).
gv() { cmake -DSOURCE_DIR="$1" -P "$src/cmake/GitVersion.cmake" 2>&1; }
mkdir plain
[ "$(gv plain)" = unknown ] || fail "not a checkout: '$(gv plain)', expected unknown"
git init -q repo && echo a > repo/file.txt && mkdir repo/sub &&
  git -C repo add file.txt && git -C repo -c user.name=t -c user.email=t@t commit -qm one ||
  fail "git init"
want=$(git -C repo rev-parse --short HEAD)
[ "$(gv repo)" = "$want" ] || fail "a clean checkout: '$(gv repo)', expected $want"
echo b > repo/untracked.txt
[ "$(gv repo)" = "$want" ] || fail "an untracked file is not a change: '$(gv repo)'"
echo b >> repo/file.txt
[ "$(gv repo)" = "$want-dirty" ] || fail "a changed file: '$(gv repo)', expected $want-dirty"
[ "$(gv repo/sub)" = unknown ] || fail "a subfolder of another checkout: '$(gv repo/sub)'"

# summary.json: version, git hash, host, seed, start and end (ISO 8601 UTC).
cat > run.toml <<'TOML'
[scene]
type = "simple_shear"
[particles]
N = 30
[run]
strain = 0.05
seed = 12
[output]
frame_strain = 0.01
TOML
"$bin" run run.toml --out r > run.out 2>&1 || fail "run: $(cat run.out)"
"$py" - r/summary.json "$hash" <<'PY' || fail "summary.json"
import json, re, socket, sys
s = json.load(open(sys.argv[1]))
iso = re.compile(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ$")
want = {"git_hash": sys.argv[2], "host": socket.gethostname(), "seed": 12}
bad = [f"{k} = {s.get(k)!r}, expected {v!r}" for k, v in want.items() if s.get(k) != v]
if not re.fullmatch(r"\d+\.\d+\.\d+", str(s.get("version"))): bad.append(f"version {s.get('version')!r}")
for k in ("started", "finished"):
    if not iso.match(str(s.get(k))): bad.append(f"{k} = {s.get(k)!r}")
if not bad and s["started"] > s["finished"]: bad.append("started after finished")
sys.exit("; ".join(bad) if bad else 0)
PY
grep -q "^=== .*, sheardiff .* (git $hash): " r/run.log || fail "run.log header: $(head -1 r/run.log)"
echo "ok: --version '$out', GitVersion.cmake, summary.json and run.log header"
