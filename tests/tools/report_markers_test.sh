#!/usr/bin/env bash
# ctest report_markers: processes a small simulated survey with the real
# zebrageo binary and checks in headless Chromium (puppeteer-core,
# tests/server/js/check_report.mjs) that every crossing with ground control
# is visible in the report's plots (issue 47). Exit 77 (skipped) without
# Chromium, Node.js or the npm packages (scripts/setup.sh).
# Usage: report_markers_test.sh ZEBRAGEO_BINARY SOURCE_DIR [SCREENSHOT_DIR]
set -euo pipefail
zebrageo="$1"
source_dir="$2"
shots="${3:-}"
js="$source_dir/tests/server/js"
if [ ! -x /usr/bin/chromium ]; then
  echo "SKIP: /usr/bin/chromium missing (scripts/setup.sh installs it)"
  exit 77
fi
if ! command -v node >/dev/null || [ ! -d "$js/node_modules" ]; then
  echo "SKIP: node or tests/server/js/node_modules missing (scripts/setup.sh)"
  exit 77
fi
work="$(mktemp -d "${TMPDIR:-/tmp}/zebrageo-markers-test.XXXXXX")"
trap 'rm -rf "$work"' EXIT
# A small survey (120 m, 3 crossings, 640x480 images): a few seconds. Its
# last crossing lies at the east end of the ground-control plot, where
# another plot's clip path used to hide it.
"$zebrageo" --log-level error simulate --preset demo --seed 1 \
  --set road_length_m=120 --set num_crossings=3 --set num_stale_crossings=0 \
  --set min_crossing_spacing_m=25 --set image_width=640 --set image_height=480 \
  --set focal_px=560 --set supersampling=2 --set exposure_spacing_m=4 \
  -o "$work/survey" >/dev/null
"$zebrageo" --log-level error run "$work/survey" -o "$work/results" >/dev/null
node "$js/check_report.mjs" "$work/results" $shots
