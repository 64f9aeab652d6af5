#!/usr/bin/env bash
# ctest report_render: checks the report.html of the small_demo_run
# fixture (tests/tools/small_demo_run.sh) in headless Chromium
# (scripts/check_report_render.sh). Exit 77 (skipped) without chromium.
# Usage: report_render_test.sh FIXTURE_DIR SOURCE_DIR
set -euo pipefail
fixture="$1"
source_dir="$2"
if ! command -v chromium >/dev/null && ! command -v chromium-browser >/dev/null; then
  echo "SKIP: chromium not installed (scripts/setup.sh installs it)"
  exit 77
fi
"$source_dir/scripts/check_report_render.sh" "$fixture/results/report.html"
