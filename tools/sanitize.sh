#!/usr/bin/env bash
# AddressSanitizer + UndefinedBehaviorSanitizer build of the library, the CLI and the unit
# tests (issue 6), then the unit tests with every sanitizer report fatal.
#
#   bash tools/sanitize.sh [-j JOBS] [--all] [--build-dir DIR] [-- EXTRA CTEST ARGS]
#
# Configures DIR (default build-asan/) with -DSHEARDIFF_SANITIZE=ON (-O2 -g with frame pointers,
# so that reports carry usable stacks and the tests stay fast), builds unit_tests and sheardiff, and runs
# `ctest -L unit`. --all runs every ctest test instead (the CLI corpus and the random-config
# fuzz run then exercise the sanitized sheardiff too; the libFuzzer smoke is left out).
# Exit status: 0 clean, non-zero on any build failure, test failure or sanitizer report.
set -euo pipefail
cd "$(dirname "$0")/.."

jobs=$(nproc) build=build-asan all=0 extra=()
while (($#)); do
  case $1 in
    -j) jobs=$2; shift 2 ;;
    --all) all=1; shift ;;
    --build-dir) build=$2; shift 2 ;;
    --) shift; extra=("$@"); break ;;
    *) echo "sanitize.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done

# Any report stops the process with a non-zero status; UBSan prints a stack. LeakSanitizer
# stays on (ASan's default on Linux).
export ASAN_OPTIONS=${ASAN_OPTIONS:-halt_on_error=1:abort_on_error=1:detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1:check_initialization_order=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}

t0=$SECONDS
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O2 -g" \
  -DSHEARDIFF_SANITIZE=ON -DSHEARDIFF_BENCH=OFF >/dev/null
cmake --build "$build" -j "$jobs" --target unit_tests sheardiff
t1=$SECONDS
echo "sanitize: build took $((t1 - t0)) s"

if ((all)); then
  ctest --test-dir "$build" --output-on-failure -j "$jobs" -E '^fuzz_config_smoke$' "${extra[@]}"
else
  ctest --test-dir "$build" --output-on-failure -j "$jobs" -L unit "${extra[@]}"
fi
echo "sanitize: tests took $((SECONDS - t1)) s (total $((SECONDS - t0)) s)"
