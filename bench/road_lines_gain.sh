#!/usr/bin/env bash
# Road lines as control (issue 9): the cross-track and vertical RMSE of the
# camera positions between crossings, zebra crossings alone against zebras
# plus road lines, on simulated presets.
#   bench/road_lines_gain.sh BUILD_DIR [PRESET...]      (default: sparse outage)
# Surveys go to ${WORK:-/tmp}/road-lines-gain/PRESET (simulated once, seed 1;
# SURVEY_ROOT=DIR takes DIR/PRESET instead). Both figures come from the full
# pipeline, as a user runs it: `zebrageo run` and `zebrageo run --no-lines`,
# each timed.
set -euo pipefail
build="${1:?usage: $0 BUILD_DIR [PRESET...]}"
shift
presets=("$@")
[ ${#presets[@]} -gt 0 ] || presets=(sparse outage)
here="$(cd "$(dirname "$0")/.." && pwd)"
score="$here/../shared/tools/score_results.py"
work="${WORK:-/tmp}/road-lines-gain"
mkdir -p "$work"
for preset in "${presets[@]}"; do
  if [ -n "${SURVEY_ROOT:-}" ]; then
    survey="$SURVEY_ROOT/$preset"
  else
    survey="$work/$preset"
    [ -d "$survey" ] || "$build/tools/zebrageo" simulate --preset "$preset" --seed 1 -o "$survey"
  fi
  rm -rf "$work/$preset-lines" "$work/$preset-zebra"
  start=$(date +%s.%N)
  "$build/tools/zebrageo" --log-level warning run "$survey" -o "$work/$preset-lines"
  middle=$(date +%s.%N)
  "$build/tools/zebrageo" --log-level warning run "$survey" -o "$work/$preset-zebra" --no-lines
  end=$(date +%s.%N)
  echo "== $preset: run $(awk "BEGIN{printf \"%.1f\", $middle - $start}") s, run --no-lines $(awk "BEGIN{printf \"%.1f\", $end - $middle}") s (wall)"
  /usr/bin/python3 "$score" lines "$survey" "$work/$preset-zebra" "$work/$preset-lines" || true
  /usr/bin/python3 "$score" poses "$survey" "$work/$preset-zebra" || true
  /usr/bin/python3 "$score" poses "$survey" "$work/$preset-lines" || true
done
