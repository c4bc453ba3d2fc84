# Sourced by scripts/fuzz.sh and scripts/sanitize.sh: the build directory of the
# fuzz targets and the sanitizer build (Clang, -O1 or $NADIR_FUZZ_OPT,
# NADIR_FUZZ=ON, no Qt viewers or benchmarks), configured the first time, and
# the sanitizers' settings.
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${NADIR_FUZZ_BUILD_DIR:-$root/build-fuzz}"
jobs="${NADIR_JOBS:-$(nproc)}"
optimisation="${NADIR_FUZZ_OPT:--O1}"

# What scripts/sanitize.sh --readers builds and tests, and .ci/run fuzzes: the
# code that reads bytes from outside (logs, messages, parameters, terrain files,
# flight logs, metrics files) and its test programs, which need none of the
# nodes. The scenario and sweep targets need them all (a build as long as the
# whole suite's).
readers_test_programs=(core_test lcmtypes_test codec_test terrain_readers_test logs_test)
readers_fuzz_targets=(lcm_log messages trajectory dem imagery flight_log)

configure_fuzz_build() {
  command -v clang++ >/dev/null || { printf 'error: clang++ is missing: ./nadir setup installs it\n' >&2; return 1; }
  [ -f "$build_dir/CMakeCache.txt" ] && return 0
  local generator=()
  command -v ninja >/dev/null && generator=(-G Ninja)
  CC=clang CXX=clang++ cmake -S "$root" -B "$build_dir" "${generator[@]}" -DNADIR_FUZZ=ON \
    -DNADIR_BUILD_GUI=OFF -DNADIR_BUILD_BENCH=OFF -DCMAKE_BUILD_TYPE=Debug \
    -DCMAKE_C_FLAGS_DEBUG="$optimisation -g1" -DCMAKE_CXX_FLAGS_DEBUG="$optimisation -g1" >&2
}

# The sanitizers' options for every program run from here (a caller's own win).
export_sanitizer_options() {
  export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0:strict_string_checks=1:detect_stack_use_after_return=1}"
  export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
  # Mesa unloads its driver when a program ends its EGL display; what the
  # driver's globals still held then looks leaked to LeakSanitizer. Kept loaded,
  # the driver's globals are seen and nothing is reported.
  local driver
  for driver in /usr/lib/*/dri/swrast_dri.so; do
    [ -f "$driver" ] && export LD_PRELOAD="$driver${LD_PRELOAD:+:$LD_PRELOAD}"
    break
  done
}
