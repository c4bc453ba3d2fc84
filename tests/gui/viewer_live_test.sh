#!/bin/sh
# nadir-viewer --live over UDP multicast: once it listens, `nadir log play` replays
# the truth and estimates of a 10 s run at 4x; the viewer must then have drawn a
# live run holding every truth pose sent, and have written a screenshot. It waits
# on conditions (listening, every pose come), never on a time a loaded machine
# may not keep.
#   viewer_live_test.sh VIEWER NADIR RUN_DIR OUT_DIR
set -eu
viewer=$1 nadir=$2 run=$3 out=$4
url="udpm://239.255.76.67:7853?ttl=0"
rm -rf "$out" && mkdir -p "$out"

# What will be sent: the log's truth poses.
sent=$("$nadir" log info "$run/run.lcmlog" | awk '$1 == "POSE_TRUTH" { print $2 }')
[ -n "$sent" ] && [ "$sent" -gt 100 ] || { echo "no truth in $run/run.lcmlog: '$sent'" >&2; exit 1; }

"$viewer" --live --url "$url" --scenario "$run/scenario.yaml" --screenshot "$out/live.png" \
  --until-truth-poses "$sent" --wait 100 >"$out/viewer.txt" 2>"$out/viewer.err" &
viewer_pid=$!
# Until it listens (its terrain built, subscribed), or it has ended.
until grep -q "^nadir-viewer: listening" "$out/viewer.txt"; do
  kill -0 "$viewer_pid" 2>/dev/null || break
  sleep 0.1
done
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
# Every truth pose sent arrived, and the run's estimate sources came along.
truth=$(sed -n 's/^run live: \([0-9]*\) truth poses.*/\1/p' "$out/viewer.txt")
[ "$truth" = "$sent" ] || { echo "live run holds '$truth' truth poses of the $sent sent" >&2; exit 1; }
grep -q "^run live: .* estimates" "$out/viewer.txt" || { echo "no estimates drawn" >&2; exit 1; }
# Following live: the playback time is the newest truth's.
times=$(sed -n 's/^time \([0-9.]*\) s \/ \([0-9.]*\) s$/\1 \2/p' "$out/viewer.txt")
[ -n "$times" ] && echo "$times" | awk '{ exit !($1 == $2 && $2 > 5) }' ||
  { echo "not at the newest truth: '$times'" >&2; exit 1; }
echo "ok"
