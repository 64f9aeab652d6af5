#!/usr/bin/env bash
# Road lines as control (issue 9): the cross-track and vertical RMSE of the
# camera positions between crossings, zebra crossings alone against zebras
# plus road lines, on simulated presets.
#   bench/road_lines_gain.sh BUILD_DIR [PRESET...]      (default: sparse outage)
# Surveys go to ${WORK:-/tmp}/road-lines-gain/PRESET (simulated once, seed 1).
# `zebrageo run` with lines first; the zebra-only figures come from
# `zebrageo adjust --no-lines` on a copy of its reconstruct/match outputs
# (the same as `zebrageo run --no-lines`: only the adjustment differs).
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
  survey="$work/$preset"
  [ -d "$survey" ] || "$build/tools/zebrageo" simulate --preset "$preset" --seed 1 -o "$survey"
  "$build/tools/zebrageo" --log-level warning run "$survey" -o "$work/$preset-lines"
  rm -rf "$work/$preset-zebra"
  mkdir -p "$work/$preset-zebra"
  cp "$work/$preset-lines"/{reconstructed_bands.csv,reconstructed_lines.csv,matches.csv,crossing_decisions.csv} "$work/$preset-zebra/"
  "$build/tools/zebrageo" --log-level warning adjust "$survey" -o "$work/$preset-zebra" --no-lines
  echo "== $preset"
  /usr/bin/python3 "$score" lines "$survey" "$work/$preset-zebra" "$work/$preset-lines" || true
  /usr/bin/python3 "$score" poses "$survey" "$work/$preset-zebra" || true
  /usr/bin/python3 "$score" poses "$survey" "$work/$preset-lines" || true
done
