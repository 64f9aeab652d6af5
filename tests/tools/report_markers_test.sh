#!/usr/bin/env bash
# ctest report_markers: checks the results of the small_demo_run fixture
# (tests/tools/small_demo_run.sh) in headless Chromium (puppeteer-core,
# tests/server/js/check_report.mjs) that every crossing with ground control
# is visible in the report's plots (issue 47). Exit 77 (skipped) without
# Chromium, Node.js or the npm packages (scripts/setup.sh).
# Usage: report_markers_test.sh FIXTURE_DIR SOURCE_DIR [SCREENSHOT_DIR]
set -euo pipefail
fixture="$1"
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
node "$js/check_report.mjs" "$fixture/results" $shots
