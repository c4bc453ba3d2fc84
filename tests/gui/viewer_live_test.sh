#!/bin/sh
# nadir-viewer --live over UDP multicast: while it listens, `nadir log play` replays
# the truth and estimates of a 10 s run at 4x; the viewer must then have drawn a
# live run holding them, and have written a screenshot.
#   viewer_live_test.sh VIEWER NADIR RUN_DIR OUT_DIR
set -eu
viewer=$1 nadir=$2 run=$3 out=$4
url="udpm://239.255.76.67:7853?ttl=0"
rm -rf "$out" && mkdir -p "$out"

"$viewer" --live --url "$url" --scenario "$run/scenario.yaml" \
  --screenshot "$out/live.png" --wait 12 >"$out/viewer.txt" 2>"$out/viewer.err" &
viewer_pid=$!
# Time for the viewer to build the terrain and subscribe.
sleep 4
"$nadir" log play "$run/run.lcmlog" --url "$url" --speed 4 --channels 'POSE_.*' >/dev/null
status=0
wait "$viewer_pid" || status=$?
cat "$out/viewer.txt"
if [ "$status" -ne 0 ]; then
  echo "nadir-viewer exited with $status:" >&2
  cat "$out/viewer.err" >&2
  exit 1
fi
[ -s "$out/live.png" ] || { echo "no screenshot" >&2; exit 1; }
# The replayed truth is 10 s at the sim's pose rate: hundreds of poses, and the
# run's estimate sources came along.
truth=$(sed -n 's/^run live: \([0-9]*\) truth poses.*/\1/p' "$out/viewer.txt")
[ -n "$truth" ] && [ "$truth" -gt 100 ] || { echo "live run missing or short: '$truth'" >&2; exit 1; }
grep -q "^run live: .* estimates" "$out/viewer.txt" || { echo "no estimates drawn" >&2; exit 1; }
# Following live: the playback time is the newest truth's.
times=$(sed -n 's/^time \([0-9.]*\) s \/ \([0-9.]*\) s$/\1 \2/p' "$out/viewer.txt")
[ -n "$times" ] && echo "$times" | awk '{ exit !($1 == $2 && $2 > 5) }' ||
  { echo "not at the newest truth: '$times'" >&2; exit 1; }
echo "ok"
