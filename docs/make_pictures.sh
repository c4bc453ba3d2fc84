#!/usr/bin/env bash
# Renders the pictures in docs/images: with `nadir snapshot`, what the 1280x960
# downward camera sees at 10, 50 and 300 m above ground over the procedural
# world and over Zion National Park (SRTM DEM, Landsat 8 imagery at 30 m); with
# nadir-viewer, the demo's run; with nadir-plot, the thesis's flight; with nadir run,
# the rover's gate course and slalom.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
nadir="$root/build/bin/nadir"
data="$root/tests/data/terrain"
out="$root/docs/images"
mkdir -p "$out"
common=(--set camera.pixel_format=rgb8 --set yaw_deg=20)
zion=(--set world.kind=files --set "world.dem_path=$data/zion_srtm.tif"
      --set "world.imagery_red_path=$data/zion_landsat_b4.tif"
      --set "world.imagery_green_path=$data/zion_landsat_b3.tif"
      --set "world.imagery_blue_path=$data/zion_landsat_b2.tif")
"$nadir" snapshot "${common[@]}" "${zion[@]}" --set agl_m=3000 --out "$out/zion_3000m.png"
for agl in 10 50 300; do
  "$nadir" snapshot "${common[@]}" --set agl_m=$agl --set north_m=-180 --set east_m=260 \
    --out "$out/procedural_${agl}m.png"
  "$nadir" snapshot "${common[@]}" "${zion[@]}" --set agl_m=$agl --out "$out/zion_${agl}m.png"
done

# The trajectory viewer on the demo's run at 140 s (run `./nadir demo` first).
if [[ -d "$root/out/demo" ]]; then
  xvfb-run -a -s "-screen 0 1400x1000x24" "$root/build/bin/nadir-viewer" "$root/out/demo" \
    --at 140 --screenshot "$out/nadir_viewer.png" >/dev/null
fi

# The plot viewer on the runs under out, showing the thesis's test flight (run
# `./nadir run thesis-oscillating --no-images --out out/thesis-oscillating` first).
if [[ -d "$root/out/thesis-oscillating" ]]; then
  (cd "$root" && QT_QPA_PLATFORM=offscreen build/bin/nadir-plot out --run thesis-oscillating \
    --figure top_view --screenshot "$out/nadir_plot_window.png")
fi

# The calibration window after the virtual checkerboard's 60 views.
QT_QPA_PLATFORM=offscreen "$root/build/bin/nadir-calib" --virtual \
  --screenshot "$out/nadir_calib.png" >/dev/null

# The closed loop: the rover's path through the gates, the slalom and the number 8, and its
# steering approaching each gate (the runs' course.png and steering.png).
"$nadir" run gates --out "$root/out/pictures-gates" --force --no-images >/dev/null
cp "$root/out/pictures-gates/course.png" "$out/gates_course.png"
cp "$root/out/pictures-gates/steering.png" "$out/gates_steering.png"
"$nadir" run slalom --out "$root/out/pictures-slalom" --force --no-images >/dev/null
cp "$root/out/pictures-slalom/course.png" "$out/slalom_course.png"
"$nadir" run number8 --out "$root/out/pictures-number8" --force --no-images >/dev/null
cp "$root/out/pictures-number8/course.png" "$out/number8_course.png"
