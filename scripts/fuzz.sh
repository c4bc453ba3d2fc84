#!/usr/bin/env bash
# Builds nadir's fuzz targets (Clang, libFuzzer, AddressSanitizer and
# UndefinedBehaviorSanitizer) and runs them (docs/reliability.md).
#   scripts/fuzz.sh                 every target for 60 s
#   scripts/fuzz.sh TARGET [SECONDS] one target (lcm_log, messages, scenario, sweep,
#                                    trajectory, dem, imagery, flight_log)
#   scripts/fuzz.sh all SECONDS     every target, one after the other
# The seeds are fuzz/corpus/TARGET (kept in the repository); what a run finds
# grows the corpus in $NADIR_FUZZ_BUILD_DIR/corpus/TARGET. A crash, a hang
# (one input over 1 s), a leak or an input over 2 GB of memory stops the
# target, keeps its input in $NADIR_FUZZ_BUILD_DIR/artifacts/TARGET/ and
# makes this script fail.
set -euo pipefail

source "$(dirname "${BASH_SOURCE[0]}")/fuzz_build.sh"
all_targets=(lcm_log messages scenario sweep trajectory dem imagery flight_log)

die() { printf 'fuzz.sh: error: %s\n' "$*" >&2; exit 1; }

target="${1:-all}"
seconds="${2:-60}"
[[ "$seconds" =~ ^[1-9][0-9]*$ ]] || die "SECONDS must be a whole number of seconds above 0, not '$seconds'"
if [ "$target" = all ]; then
  targets=("${all_targets[@]}")
else
  [[ " ${all_targets[*]} " == *" $target "* ]] || die "no fuzz target '$target' (there are: ${all_targets[*]})"
  targets=("$target")
fi

configure_fuzz_build || exit 1
cmake --build "$build_dir" --parallel "$jobs" --target "${targets[@]/#/nadir_fuzz_}" >&2

failed=()
for name in "${targets[@]}"; do
  corpus="$build_dir/corpus/$name"
  artifacts="$build_dir/artifacts/$name"
  mkdir -p "$corpus" "$artifacts"
  dict=()
  [ -f "$root/fuzz/dict/$name.dict" ] && dict=(-dict="$root/fuzz/dict/$name.dict")
  log="$build_dir/fuzz-$name.log"
  printf 'fuzz.sh: %s for %s s\n' "$name" "$seconds" >&2
  status=0
  "$build_dir/bin/nadir-fuzz-$name" -max_total_time="$seconds" -timeout=1 -rss_limit_mb=2048 \
    -print_final_stats=1 -artifact_prefix="$artifacts/" "${dict[@]}" \
    "$corpus" "$root/fuzz/corpus/$name" >"$log" 2>&1 || status=$?
  # The last status line: "#N DONE cov: C ft: F corp: ... exec/s: E ..."
  summary="$(grep -E '^#[0-9]+' "$log" | tail -1 || true)"
  execs="$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)"
  printf "%-11s %s s  %s runs  cov: %s\n" "$name" "$seconds" "${execs:-?}" "${summary#*cov: }"
  if [ "$status" -ne 0 ]; then
    printf 'fuzz.sh: %s FAILED (exit %d): see %s; the input is in %s\n' "$name" "$status" "$log" "$artifacts" >&2
    grep -E 'ERROR: |SUMMARY: |==[0-9]+==|Test unit written' "$log" | head -8 >&2 || true
    failed+=("$name")
  fi
done
[ ${#failed[@]} -eq 0 ] || die "failed: ${failed[*]}"
