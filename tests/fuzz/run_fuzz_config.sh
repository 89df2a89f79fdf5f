#!/usr/bin/env bash
# Brief libFuzzer run of the config parser and validator (tests/fuzz/fuzz_config.cpp, issue 6).
#
#   run_fuzz_config.sh --work DIR [--seconds 30] [--binary FUZZ_CONFIG] [--source ROOT]
#
# Without --binary the fuzzer is built first with clang++ (standalone tests/fuzz/CMakeLists.txt,
# into DIR/build, incremental), so that the default g++ build can run it too. Exits 77 (ctest
# SKIP_RETURN_CODE) with the reason when clang++ or its libFuzzer runtime is not installed.
#
# Seeds: configs/*.toml and the malformed-config corpus tests/config_corpus/ (copied into
# DIR/seeds); a dictionary of every section, key and choice is read from docs/config.md. New
# inputs accumulate in DIR/corpus between runs; a crash leaves DIR/artifacts/crash-* (replay it
# with `FUZZ_CONFIG FILE`) and fails the run.
set -euo pipefail

work="" seconds=30 binary="" root=$(cd "$(dirname "$0")/../.." && pwd)
while (($#)); do
  case $1 in
    --work) work=$2; shift 2 ;;
    --seconds) seconds=$2; shift 2 ;;
    --binary) binary=$2; shift 2 ;;
    --source) root=$2; shift 2 ;;
    *) echo "run_fuzz_config.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done
[[ -n $work ]] || { echo "run_fuzz_config.sh: --work DIR is required" >&2; exit 2; }
mkdir -p "$work"
work=$(cd "$work" && pwd)

if [[ -z $binary ]]; then
  cxx=${SHEARDIFF_FUZZ_CXX:-}
  if [[ -z $cxx ]]; then
    for c in clang++ clang++-14 clang++-15 clang++-16; do
      if command -v "$c" >/dev/null; then cxx=$(command -v "$c"); break; fi
    done
  fi
  if [[ -z $cxx ]]; then
    echo "SKIP: no clang++ on this machine (libFuzzer needs clang; Debian: clang-14 libclang-rt-14-dev)"
    exit 77
  fi
  probe=$(mktemp -d)
  trap 'rm -rf "$probe"' EXIT
  echo 'extern "C" int LLVMFuzzerTestOneInput(const unsigned char*, unsigned long) { return 0; }' \
    > "$probe/p.cpp"
  if ! "$cxx" -fsanitize=fuzzer,address,undefined "$probe/p.cpp" -o "$probe/p" 2>"$probe/err"; then
    echo "SKIP: $cxx cannot link -fsanitize=fuzzer,address,undefined (libFuzzer runtime missing;"
    echo "      Debian: libclang-rt-14-dev): $(head -c 300 "$probe/err")"
    exit 77
  fi
  if [[ ! -f $work/build/build.ninja ]]; then
    cmake -S "$root/tests/fuzz" -B "$work/build" -G Ninja -DCMAKE_CXX_COMPILER="$cxx" \
      -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
  fi
  t0=$SECONDS
  cmake --build "$work/build" -j 2 >"$work/build.log" 2>&1 || { cat "$work/build.log"; exit 1; }
  echo "fuzz_config built with $cxx in $((SECONDS - t0)) s"
  binary=$work/build/fuzz_config
fi

# Seeds and dictionary.
rm -rf "$work/seeds"
mkdir -p "$work/seeds" "$work/corpus" "$work/artifacts"
for f in "$root"/configs/*.toml "$root"/tests/config_corpus/*.toml "$root"/tests/config_corpus/*/*.toml; do
  [[ -f $f ]] && cp "$f" "$work/seeds/$(basename "$(dirname "$f")")_$(basename "$f")"
done
{
  for t in '[' ']' '=' '\"' '.' '\x0a' '\x00' true false nan inf -inf 1e-3 0 -1 1e18; do
    printf '"%s"\n' "$t"
  done
  sed -n 's/^| `\([a-z_]*\)\.\([A-Za-z0-9_]*\)` |.*/\1 \2/p' "$root/docs/config.md" |
    while read -r sec key; do
      printf '"[%s]"\n"%s"\n"%s = "\n"%s.%s="\n' "$sec" "$key" "$key" "$sec" "$key"
    done
  grep -o 'one of[^|]*' "$root/docs/config.md" | grep -o '"[a-z_]*"' | tr -d '"' |
    while read -r word; do printf '"\\"%s\\""\n' "$word"; done
} | sort -u > "$work/config.dict"

echo "fuzzing parse_config for $seconds s: $(ls "$work/seeds" | wc -l) seeds, $(ls "$work/corpus" | wc -l) inputs kept from earlier runs"
set +e
"$binary" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=4096 \
  -print_final_stats=1 -dict="$work/config.dict" -artifact_prefix="$work/artifacts/" \
  "$work/corpus" "$work/seeds" >"$work/fuzz.log" 2>&1
rc=$?
set -e
grep -E "^(#[0-9]+ +DONE|stat::number_of_executed_units|stat::new_units_added|Done [0-9]+ runs)" "$work/fuzz.log" || true
if ((rc != 0)); then
  echo "FAIL: the fuzzer found a problem (exit $rc):"
  grep -v -E "^#[0-9]+ +(NEW|REDUCE|pulse|INITED)" "$work/fuzz.log" | tail -60
  for a in "$work"/artifacts/*; do
    [[ -f $a ]] || continue
    echo "--- $a"
    head -c 2000 "$a" | od -c | head -40
  done
  exit 1
fi
echo "ok: no crash, sanitizer report or exception other than ConfigError ($(ls "$work/corpus" | wc -l) inputs in the corpus)"
