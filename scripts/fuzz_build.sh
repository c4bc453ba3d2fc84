# Sourced by scripts/fuzz.sh and scripts/sanitize.sh: the build directory of the
# fuzz targets and the sanitizer build (Clang, -O1, NADIR_FUZZ=ON, no Qt viewers
# or benchmarks), configured the first time.
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${NADIR_FUZZ_BUILD_DIR:-$root/build-fuzz}"
jobs="${NADIR_JOBS:-$(nproc)}"

configure_fuzz_build() {
  command -v clang++ >/dev/null || { printf 'error: clang++ is missing: ./nadir setup installs it\n' >&2; return 1; }
  [ -f "$build_dir/CMakeCache.txt" ] && return 0
  local generator=()
  command -v ninja >/dev/null && generator=(-G Ninja)
  CC=clang CXX=clang++ cmake -S "$root" -B "$build_dir" "${generator[@]}" -DNADIR_FUZZ=ON \
    -DNADIR_BUILD_GUI=OFF -DNADIR_BUILD_BENCH=OFF -DCMAKE_BUILD_TYPE=Debug \
    -DCMAKE_C_FLAGS_DEBUG="-O1 -g1" -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g1" >&2
}
