#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Builds the libFuzzer targets (the `fuzz` preset: clang, ASan, UBSan) and runs each for
# SECONDS (default 60) from its seed corpus in tests/fuzz/corpus/<target>/ plus the inputs it
# found before (build/fuzz/corpus/<target>/), after replaying every regression input of
# tests/fuzz/regressions/<target>/. Exits non-zero on a finding: a crash, a sanitizer report,
# an exception other than the CLI's InputError, a hang (> 10 s an input), a leak, or more than
# 2 GiB of memory; the input is left in build/fuzz/findings/. docs/developers/fuzzing.md.
#   scripts/fuzz.sh [SECONDS] [TARGET...]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
seconds="${1:-60}"
shift || true
"$root/scripts/install-deps.sh"

targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  mapfile -t targets < <(sed -n 's/^set(MCOPT_FUZZ_TARGETS \(.*\))$/\1/p' "$root/tests/fuzz/targets.cmake" | tr ' ' '\n')
fi
# MCOPT_FUZZ_OPTIMISATION (default "-O1 -g1"): the flags of the fuzz build. CI's 20-second smoke
# runs build at "-O0 -g1" (scripts/test.sh): half the compile time, fewer executions a second.
cmake --preset fuzz -S "$root" -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="${MCOPT_FUZZ_OPTIMISATION:--O1 -g1}" >/dev/null
cmake --build "$root/build/fuzz" --target "${targets[@]/#/fuzz_}"

build="$root/build/fuzz"
# Third-party leaks only (urdfdom's, on files it rejects): tests/fuzz/lsan.supp says which.
export LSAN_OPTIONS="suppressions=$root/tests/fuzz/lsan.supp${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
mkdir -p "$build/findings"

# One target: its regression inputs, then SECONDS of fuzzing. Prints its summary line to
# $build/fuzz_<target>.summary and exits non-zero on a finding.
fuzz_target() {
  local t="$1" exe="$build/tests/fuzz/fuzz_$1" log="$build/fuzz_$1.log" summary="$build/fuzz_$1.summary"
  local common=(-timeout=10 -rss_limit_mb=2048 -close_fd_mask=1 "-artifact_prefix=$build/findings/$t-")
  mkdir -p "$build/corpus/$t"
  if [ -d "$root/tests/fuzz/regressions/$t" ] && [ -n "$(ls -A "$root/tests/fuzz/regressions/$t")" ]; then
    if ! "$exe" "${common[@]}" "$root/tests/fuzz/regressions/$t"/* > "$build/fuzz_$t.regressions.log" 2>&1; then
      printf '%-16s a regression input fails again: %s\n' "$t" "$build/fuzz_$t.regressions.log" > "$summary"
      return 1
    fi
  fi
  local result status=0
  if "$exe" "${common[@]}" -max_total_time="$seconds" -print_final_stats=1 \
       "$build/corpus/$t" "$root/tests/fuzz/corpus/$t" > "$log" 2>&1; then
    result="no finding"
  else
    result="FINDING (see $log and $build/findings/)"
    status=1
  fi
  local runs rate
  runs="$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)"
  rate="$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)"
  printf '%-16s %12s executions %8s /s  %s\n' "$t" "${runs:-?}" "${rate:-?}" "$result" > "$summary"
  return $status
}

# libFuzzer runs a target on one core: the targets run side by side, as many at a time as
# there are cores, so that CI's SECONDS a target take SECONDS × targets / cores of its time.
cores="$(env -u OMP_NUM_THREADS -u OMP_THREAD_LIMIT nproc)"
status=0
running=()
for t in "${targets[@]}"; do
  echo "fuzz: $t: $seconds s"
  fuzz_target "$t" &
  running+=($!)
  if [ ${#running[@]} -ge "$cores" ]; then
    wait "${running[0]}" || status=1
    running=("${running[@]:1}")
  fi
done
for pid in "${running[@]}"; do wait "$pid" || status=1; done
printf 'fuzz: %s s a target, %s at a time\n' "$seconds" "$cores"
for t in "${targets[@]}"; do printf '  %s' "$(cat "$build/fuzz_$t.summary")"; echo; done
exit $status
