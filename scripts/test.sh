#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Installs the dependencies, builds and runs the whole test suite in Release with warnings as
# errors, then runs part of it again under AddressSanitizer + UndefinedBehaviorSanitizer.
# MCOPT_SANITIZE says which part (docs/developers/index.md, "The CI budget"):
#   libraries  (the default, CI's) the tests of core, inner_qp, sensitivity and outer_nlp: every
#              library an optimisation runs through, the kernels and the NLP, without the
#              commands' whole runs;
#   all        every test of the sanitizer tree: also the command-line tests (whole optimisations
#              through `mcopt`) and the fuzz seeds and regression inputs, replayed through the fuzz
#              targets' code (the Release suite replays them too);
#   none       the Release suite alone (MCOPT_SKIP_SANITIZE=1 says the same).
# The whole sanitizer suite took 37 minutes on its own (build 27 min, tests 10 min, at 8d1c23b:
# docs/developers/lab-notes/ci-budget.md). With MCOPT_FUZZ_SECONDS > 0, each libFuzzer target
# then runs that long (scripts/fuzz.sh, docs/developers/fuzzing.md); CI leaves it at 0.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
jobs="$(env -u OMP_NUM_THREADS -u OMP_THREAD_LIMIT nproc)"
"$root/scripts/install-deps.sh"
# The same BLAS kernels on every AVX2 processor, for the library tests that run Ipopt in their
# own process too (the mcopt command sets this itself: docs/developers/determinism.md).
if [ -z "${OPENBLAS_CORETYPE:-}" ] && grep -qw avx2 /proc/cpuinfo && grep -qw fma /proc/cpuinfo; then
  export OPENBLAS_CORETYPE=Haswell
fi

cmake --preset release -S "$root"
cmake --build "$root/build/release" --parallel "$jobs"
(cd "$root/build/release" && ctest --output-on-failure --parallel "$jobs")

sanitize="${MCOPT_SANITIZE:-libraries}"
[ "${MCOPT_SKIP_SANITIZE:-0}" != "1" ] || sanitize=none
case "$sanitize" in
  libraries)
    targets=(mcopt-tests-core mcopt-tests-inner mcopt-tests-sensitivity mcopt-tests-outer)
    tests='^mcopt-tests-(core|inner|sensitivity|outer):' ;;
  all) targets=(all); tests='' ;;
  none) targets=() ;;
  *) echo "scripts/test.sh: MCOPT_SANITIZE=$sanitize: expected libraries, all or none" >&2; exit 2 ;;
esac
if [ "${#targets[@]}" -gt 0 ]; then
  cmake --preset sanitize -S "$root"
  cmake --build "$root/build/sanitize" --parallel "$jobs" --target "${targets[@]}"
  (cd "$root/build/sanitize" && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
     ctest --output-on-failure --parallel "$jobs" ${tests:+--tests-regex "$tests"})
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
