#!/usr/bin/env bash
# Renders a report.html in headless Chromium (Debian's `chromium`) and checks
# that it really renders: the DOM after layout holds every section and the
# inline SVG plots, and a screenshot is not blank.
#
# Usage: scripts/check_report_render.sh REPORT_HTML [SCREENSHOT_PNG]
# Exit: 0 rendered, 1 a check failed, 77 chromium is absent (ctest: skipped).
set -euo pipefail
html="${1:?usage: $0 REPORT_HTML [SCREENSHOT_PNG]}"
shot="${2:-}"
chromium="${CHROMIUM:-$(command -v chromium || command -v chromium-browser || true)}"
if [[ -z "$chromium" ]]; then
  echo "SKIP: chromium not installed (scripts/setup.sh installs it)"
  exit 77
fi
[[ -f "$html" ]] || { echo "no such file: $html"; exit 1; }
url="file://$(cd "$(dirname "$html")" && pwd)/$(basename "$html")"
work="$(mktemp -d "${TMPDIR:-/tmp}/zebrageo-render.XXXXXX")"
trap 'rm -rf "$work"' EXIT
# No network, no first-run chores, a throwaway profile: the report must
# render from the file alone.
flags=(--headless --no-sandbox --disable-gpu --disable-quic --no-first-run
  --disable-background-networking --disable-component-update --disable-sync
  --user-data-dir="$work/profile" --window-size=1100,2400
  --virtual-time-budget=5000)

timeout 120 "$chromium" "${flags[@]}" --dump-dom "$url" >"$work/dom.html" \
  2>"$work/dom.log" || { echo "chromium --dump-dom failed:"; tail -5 "$work/dom.log"; exit 1; }

fail=0
need() {  # need LABEL MIN-COUNT PATTERN
  local n
  n=$(grep -o -- "$3" "$work/dom.html" | wc -l)
  if (( n < $2 )); then
    echo "FAIL: $1: found $n, want >= $2 ($3)"
    fail=1
  else
    echo "ok: $1 ($n)"
  fi
}
need "report title" 1 "<h1>zebrageo report"
for section in Warnings Accuracy Trajectory "Ground control residuals" \
  Crossings "Database faults found" "Stretches without control" \
  "Road lines" "Stage timings"; do
  need "section $section" 1 "<h2>$section</h2>"
done
need "inline SVG plots" 4 "<svg"
need "road-line control plot" 1 "Road-line control per stretch"
need "plot lines or markers" 4 "<polyline\|<circle\|<path\|<rect"
if grep -q -- "NaN\|>nan<\|>inf<" "$work/dom.html"; then
  echo "FAIL: NaN or inf in the rendered page"
  fail=1
fi

png="${shot:-$work/shot.png}"
timeout 120 "$chromium" "${flags[@]}" --screenshot="$png" "$url" \
  >"$work/shot.log" 2>&1 || { echo "chromium --screenshot failed:"; tail -5 "$work/shot.log"; exit 1; }
[[ -s "$png" ]] || { echo "FAIL: no screenshot written"; exit 1; }
py=/usr/bin/python3
if [[ -x "$py" ]] && "$py" -c "import cv2" 2>/dev/null; then
  # Not blank: enough non-white pixels, and some colour (the plots).
  "$py" - "$png" <<'EOF' || fail=1
import sys
import cv2
import numpy as np
img = cv2.imread(sys.argv[1])
if img is None:
    print("FAIL: screenshot unreadable"); sys.exit(1)
ink = float(np.mean(img.min(axis=2) < 200))
spread = img.max(axis=2).astype(int) - img.min(axis=2).astype(int)
colour = float(np.mean(spread > 60))
print(f"screenshot {img.shape[1]}x{img.shape[0]}: {100 * ink:.1f}% ink, {100 * colour:.2f}% colour")
sys.exit(0 if ink > 0.02 and colour > 0.002 else 1)
EOF
else
  size=$(stat -c %s "$png")
  echo "screenshot $size bytes (no python3 with cv2: size check only)"
  (( size > 20000 )) || { echo "FAIL: screenshot looks blank"; fail=1; }
fi
[[ -n "$shot" ]] && echo "screenshot: $shot"
exit $fail
