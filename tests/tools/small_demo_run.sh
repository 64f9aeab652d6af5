#!/usr/bin/env bash
# ctest fixture small_demo_run: simulates one small survey (120 m, 3
# crossings, 640x480 images; a few seconds) into DIR/survey and processes it
# with the real zebrageo binary into DIR/results, once for the tests that
# read what a person sees of a run (report_render, report_markers,
# console_output). Its last crossing lies at the east end of the
# ground-control plot, where another plot's clip path used to hide it.
# Usage: small_demo_run.sh ZEBRAGEO_BINARY DIR        (setup)
#        small_demo_run.sh --clean DIR                 (cleanup)
set -euo pipefail
if [ "$1" = --clean ]; then
  rm -rf "$2"
  exit 0
fi
zebrageo="$1"
dir="$2"
rm -rf "$dir"
mkdir -p "$dir"
"$zebrageo" --log-level error simulate --preset demo --seed 1 \
  --set road_length_m=120 --set num_crossings=3 --set num_stale_crossings=0 \
  --set min_crossing_spacing_m=25 --set image_width=640 --set image_height=480 \
  --set focal_px=560 --set supersampling=2 --set exposure_spacing_m=4 \
  -o "$dir/survey" >/dev/null
"$zebrageo" --log-level error run "$dir/survey" -o "$dir/results" >/dev/null
