#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Installs the dependencies, then builds and runs the whole test suite twice:
# Release with warnings as errors, and AddressSanitizer + UndefinedBehaviorSanitizer.
# Both suites replay every fuzz seed and regression input through the fuzz targets' code. With
# MCOPT_FUZZ_SECONDS > 0, each libFuzzer target then runs that long (scripts/fuzz.sh,
# docs/developers/fuzzing.md); CI leaves it at 0: the clang fuzz build took five to six minutes
# of a 45-minute budget (docs/developers/lab-notes/ci-budget.md). Set MCOPT_SKIP_SANITIZE=1 to
# run only the first suite.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
jobs="$(env -u OMP_NUM_THREADS -u OMP_THREAD_LIMIT nproc)"
"$root/scripts/install-deps.sh"

cmake --preset release -S "$root"
cmake --build "$root/build/release" --parallel "$jobs"
(cd "$root/build/release" && ctest --output-on-failure --parallel "$jobs")

if [ "${MCOPT_SKIP_SANITIZE:-0}" != "1" ]; then
  cmake --preset sanitize -S "$root"
  cmake --build "$root/build/sanitize" --parallel "$jobs"
  (cd "$root/build/sanitize" && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
     ctest --output-on-failure --parallel "$jobs")
fi

fuzz_seconds="${MCOPT_FUZZ_SECONDS:-0}"
if [ "$fuzz_seconds" != "0" ]; then
  # A smoke run of seconds a target: its build, not its executions, is the time; built at -O0
  # (docs/developers/fuzzing.md). Longer runs keep the fuzz preset's -O1.
  if [ "$fuzz_seconds" -le 60 ]; then
    MCOPT_FUZZ_OPTIMISATION="${MCOPT_FUZZ_OPTIMISATION:--O0 -g1}" "$root/scripts/fuzz.sh" "$fuzz_seconds"
  else
    "$root/scripts/fuzz.sh" "$fuzz_seconds"
  fi
fi
