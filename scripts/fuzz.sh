#!/usr/bin/env bash
# Builds nadir's fuzz targets (Clang, libFuzzer, AddressSanitizer and
# UndefinedBehaviorSanitizer) and runs them (docs/reliability.md).
#   scripts/fuzz.sh                         every target for 60 s
#   scripts/fuzz.sh TARGET... [SECONDS]     these targets (lcm_log, messages, scenario,
#                                           sweep, trajectory, dem, imagery, flight_log)
#   scripts/fuzz.sh all SECONDS             every target
#   scripts/fuzz.sh readers SECONDS         the targets .ci/run fuzzes (no node needed)
# Targets run $NADIR_JOBS at a time (default: one per core). The seeds are
# fuzz/corpus/TARGET and the inputs a fuzzer once failed on fuzz/regressions/TARGET
# (both kept in the repository); what a run finds grows the corpus in
# $NADIR_FUZZ_BUILD_DIR/corpus/TARGET. A crash, a hang (one input over
# $NADIR_FUZZ_TIMEOUT s, default 1), a leak or an input over 2 GB of memory
# stops the target, keeps its input in $NADIR_FUZZ_BUILD_DIR/artifacts/TARGET/
# and makes this script fail. NADIR_FUZZ_SEED fixes libFuzzer's random seed.
set -euo pipefail

source "$(dirname "${BASH_SOURCE[0]}")/fuzz_build.sh"
all_targets=(lcm_log messages scenario sweep trajectory dem imagery flight_log)

die() { printf 'fuzz.sh: error: %s\n' "$*" >&2; exit 1; }

args=("$@")
seconds=60
if [ ${#args[@]} -gt 0 ] && [[ "${args[-1]}" =~ ^[0-9]+$ ]]; then
  seconds="${args[-1]}"
  unset 'args[-1]'
fi
[[ "$seconds" =~ ^[1-9][0-9]*$ ]] || die "SECONDS must be a whole number of seconds above 0, not '$seconds'"
timeout_s="${NADIR_FUZZ_TIMEOUT:-1}"
seed="${NADIR_FUZZ_SEED:-0}"  # 0: libFuzzer picks one
[[ "$seed" =~ ^[0-9]+$ ]] || die "NADIR_FUZZ_SEED must be a whole number, not '$seed'"
[[ "$timeout_s" =~ ^[1-9][0-9]*$ ]] || die "NADIR_FUZZ_TIMEOUT must be a whole number of seconds above 0, not '$timeout_s'"
[ ${#args[@]} -gt 0 ] || args=(all)
targets=()
for name in "${args[@]}"; do
  case "$name" in
    all) targets+=("${all_targets[@]}") ;;
    readers) targets+=("${readers_fuzz_targets[@]}") ;;
    *)
      [[ " ${all_targets[*]} " == *" $name "* ]] ||
        die "no fuzz target '$name' (there are: ${all_targets[*]}; or all, readers)"
      targets+=("$name")
      ;;
  esac
done

declare -A seen
unique=()
for name in "${targets[@]}"; do
  [ -n "${seen[$name]:-}" ] || unique+=("$name")
  seen[$name]=1
done
targets=("${unique[@]}")

configure_fuzz_build || exit 1
cmake --build "$build_dir" --parallel "$jobs" --target "${targets[@]/#/nadir_fuzz_}" >&2

# One target for $seconds; its exit status is the fuzzer's.
fuzz_one() {
  local name="$1"
  local corpus="$build_dir/corpus/$name" artifacts="$build_dir/artifacts/$name"
  mkdir -p "$corpus" "$artifacts"
  local inputs=("$corpus" "$root/fuzz/corpus/$name") dict=()
  [ -d "$root/fuzz/regressions/$name" ] && inputs+=("$root/fuzz/regressions/$name")
  [ -f "$root/fuzz/dict/$name.dict" ] && dict=(-dict="$root/fuzz/dict/$name.dict")
  "$build_dir/bin/nadir-fuzz-$name" -max_total_time="$seconds" -timeout="$timeout_s" \
    -rss_limit_mb=2048 -seed="$seed" -print_final_stats=1 -artifact_prefix="$artifacts/" "${dict[@]}" \
    "${inputs[@]}" >"$build_dir/fuzz-$name.log" 2>&1
}

printf 'fuzz.sh: %s for %s s each, %s at a time\n' "${targets[*]}" "$seconds" "$jobs" >&2
# Each target in the background, its exit status in a file beside its log.
for name in "${targets[@]}"; do
  while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do wait -n || true; done
  rm -f "$build_dir/fuzz-$name.status"
  { status=0; fuzz_one "$name" || status=$?; echo "$status" >"$build_dir/fuzz-$name.status"; } &
done
wait

failed=()
for name in "${targets[@]}"; do
  status="$(cat "$build_dir/fuzz-$name.status" 2>/dev/null || echo "?")"
  log="$build_dir/fuzz-$name.log"
  # The last status line: "#N DONE cov: C ft: F corp: ... exec/s: E ..."
  summary="$(grep -E '^#[0-9]+' "$log" | tail -1 || true)"
  execs="$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)"
  printf "%-11s %s s  %s runs  cov: %s\n" "$name" "$seconds" "${execs:-?}" "${summary#*cov: }"
  if [ "$status" != 0 ]; then
    printf 'fuzz.sh: %s FAILED (exit %s): see %s; the input is in %s\n' "$name" "$status" "$log" \
      "$build_dir/artifacts/$name" >&2
    grep -E 'ERROR: |SUMMARY: |==[0-9]+==|Test unit written' "$log" | head -8 >&2 || true
    failed+=("$name")
  fi
done
[ ${#failed[@]} -eq 0 ] || die "failed: ${failed[*]}"
