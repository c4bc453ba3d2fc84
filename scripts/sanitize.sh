#!/usr/bin/env bash
# The test suite under AddressSanitizer and UndefinedBehaviorSanitizer
# (docs/reliability.md), in the fuzz targets' build directory: Clang, -O1, the
# Qt viewers and the whole-flight tests that need them (tests/run, tests/gui)
# not built, and the tests named below left out.
#   scripts/sanitize.sh [ctest arguments...]            the whole suite
#   scripts/sanitize.sh --readers [ctest arguments...]  only the readers of outside
#       bytes and their tests (scripts/fuzz_build.sh lists the programs) and the
#       fuzz inputs' replays: what .ci/run builds
set -euo pipefail

source "$(dirname "${BASH_SOURCE[0]}")/fuzz_build.sh"

die() { printf 'sanitize.sh: error: %s\n' "$*" >&2; exit 1; }

# Left out, and why (docs/reliability.md); the ordinary suite runs them all.
excluded=(
  # minutes of rendered flight at full resolution, slowed three to five times
  'FeatureVoFlight\.'
  'VirtualBoard\.RenderedCornersMatchTheLensModel'
  # over its 300 s limit under the sanitizers (8 s in the ordinary build)
  'DirectVo\.FollowsAClimb$'
  # built by Clang, the widest corner reaches 298.4 px of the 300 px it asks
  'VirtualCalibration\.FisheyeModelAt640x480$'
)

selection=()
targets=()
if [ "${1:-}" = --readers ]; then
  shift
  label_regex="^($(IFS='|'; echo "${readers_test_programs[*]}")|fuzz)\$"
  selection=(-L "$label_regex")
  # their fuzz targets need every node (scripts/fuzz_build.sh)
  excluded+=('FuzzReplay\.(scenario|sweep)$')
  targets=(--target "${readers_test_programs[@]}" "${readers_fuzz_targets[@]/#/nadir_fuzz_replay_}")
fi

configure_fuzz_build || exit 1
cmake --build "$build_dir" --parallel "$jobs" "${targets[@]}" >&2 ||
  die "the sanitizer build failed (see above)"

export_sanitizer_options
exclude_regex="$(IFS='|'; echo "${excluded[*]}")"
exec ctest --test-dir "$build_dir" --output-on-failure --no-label-summary -j "$jobs" \
  -E "$exclude_regex" \
  "${selection[@]}" "$@"
