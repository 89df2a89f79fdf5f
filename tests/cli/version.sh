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
# The BLAS kernels (docs/performance.md "The BLAS kernels"): summary.json names OpenBLAS's set;
# they use the CPU's widest vectors OpenBLAS has kernels for (an OpenBLAS too old for the CPU
# falls back to SSE3 "Prescott" unless sheardiff asks for them), and a caller's
# OPENBLAS_CORETYPE is kept.
"$py" - r/summary.json <<'PY' || fail "blas_kernels"
import json, sys
k = json.load(open(sys.argv[1])).get("blas_kernels", "missing")
if k is None: sys.exit(0)  # not OpenBLAS
width = {"Prescott": 0, "Core2": 0, "Penryn": 0, "Dunnington": 0, "Nehalem": 0, "Atom": 0,
         "Sandybridge": 1, "Haswell": 2, "Zen": 2, "SkylakeX": 3, "Cooperlake": 3,
         "SapphireRapids": 3}
flags = set()
for line in open("/proc/cpuinfo"):
    if line.startswith("flags"): flags = set(line.split(":", 1)[1].split()); break
cpu = 3 if {"avx512f", "avx512bw", "avx512vl", "avx512dq"} <= flags else 2 if {"avx2", "fma"} <= flags else 0
if k not in width: sys.exit(f"blas_kernels = {k!r}, not an OpenBLAS x86-64 kernel set")
if width[k] < cpu: sys.exit(f"blas_kernels = {k!r} on a CPU with {'AVX-512' if cpu == 3 else 'AVX2'}")
PY
if [ "$("$py" -c 'import json; print(json.load(open("r/summary.json"))["blas_kernels"])')" != None ]; then
  OPENBLAS_CORETYPE=Haswell "$bin" run run.toml --out r2 > run2.out 2>&1 || fail "run: $(cat run2.out)"
  grep -q '"blas_kernels": "Haswell"' r2/summary.json || fail "OPENBLAS_CORETYPE=Haswell not kept"
fi

echo "ok: --version '$out', GitVersion.cmake, summary.json, run.log header and BLAS kernels"
