#!/usr/bin/env bash
# Builds the libFuzzer targets (the `fuzz` preset: clang, ASan, UBSan) and runs each for
# SECONDS (default 60) from its seed corpus in tests/fuzz/corpus/<target>/ plus the inputs it
# found before (build/fuzz/corpus/<target>/), after replaying every regression input of
# tests/fuzz/regressions/<target>/. Exits non-zero on a finding: a crash, a sanitizer report,
# an exception other than the CLI's InputError, a hang (> 10 s an input), a leak, or more than
# 2 GiB of memory; the input is left in build/fuzz/findings/. docs/fuzzing.md.
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
cmake --preset fuzz -S "$root" >/dev/null
cmake --build "$root/build/fuzz" --target "${targets[@]/#/fuzz_}"

build="$root/build/fuzz"
# Third-party leaks only (urdfdom's, on files it rejects): tests/fuzz/lsan.supp says which.
export LSAN_OPTIONS="suppressions=$root/tests/fuzz/lsan.supp${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
mkdir -p "$build/findings"
status=0
summary=()
for t in "${targets[@]}"; do
  exe="$build/tests/fuzz/fuzz_$t"
  mkdir -p "$build/corpus/$t"
  log="$build/fuzz_$t.log"
  common=(-timeout=10 -rss_limit_mb=2048 -close_fd_mask=1 "-artifact_prefix=$build/findings/$t-")
  if [ -d "$root/tests/fuzz/regressions/$t" ] && [ -n "$(ls -A "$root/tests/fuzz/regressions/$t")" ]; then
    echo "fuzz: $t: regression inputs"
    if ! "$exe" "${common[@]}" "$root/tests/fuzz/regressions/$t"/* > "$build/fuzz_$t.regressions.log" 2>&1; then
      echo "fuzz: $t: a regression input fails again: $build/fuzz_$t.regressions.log"
      status=1
      continue
    fi
  fi
  echo "fuzz: $t: $seconds s"
  if "$exe" "${common[@]}" -max_total_time="$seconds" -print_final_stats=1 \
       "$build/corpus/$t" "$root/tests/fuzz/corpus/$t" > "$log" 2>&1; then
    result="no finding"
  else
    result="FINDING (see $log and $build/findings/)"
    status=1
  fi
  runs="$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)"
  rate="$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)"
  summary+=("$(printf '%-16s %12s executions %8s /s  %s' "$t" "${runs:-?}" "${rate:-?}" "$result")")
done
printf 'fuzz: %s s a target\n' "$seconds"
printf '  %s\n' "${summary[@]}"
exit $status
