#!/usr/bin/env bash
# ctest report_render: processes a small simulated survey with the real
# zebrageo binary and checks its report.html in headless Chromium
# (scripts/check_report_render.sh). Exit 77 (skipped) without chromium.
# Usage: report_render_test.sh ZEBRAGEO_BINARY SOURCE_DIR
set -euo pipefail
zebrageo="$1"
source_dir="$2"
if ! command -v chromium >/dev/null && ! command -v chromium-browser >/dev/null; then
  echo "SKIP: chromium not installed (scripts/setup.sh installs it)"
  exit 77
fi
work="$(mktemp -d "${TMPDIR:-/tmp}/zebrageo-render-test.XXXXXX")"
trap 'rm -rf "$work"' EXIT
# A small survey (80 m, 2 crossings, 640x480 images): a few seconds.
"$zebrageo" --log-level error simulate --preset demo --seed 1 \
  --set road_length_m=80 --set num_crossings=2 --set num_stale_crossings=0 \
  --set min_crossing_spacing_m=25 --set image_width=640 --set image_height=480 \
  --set focal_px=560 --set supersampling=2 --set exposure_spacing_m=4 \
  -o "$work/survey" >/dev/null
"$zebrageo" --log-level error run "$work/survey" -o "$work/results" >/dev/null
"$source_dir/scripts/check_report_render.sh" "$work/results/report.html"
