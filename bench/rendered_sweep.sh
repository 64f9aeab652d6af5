#!/usr/bin/env bash
# Issue 17's rendered sweep: N random surveys of the random preset (short
# streets, rendered images of 1024x768 and up), each through `zebrageo run`
# as a user runs it, scored with ../shared/tools/score_results.py (match,
# poses, reconstruct) and the reconstruction's recall by range bin (0-11 m,
# 11-15 m). Prints a table per survey and a summary (median, p95, worst; H
# RMSE on surveys with at least 3 crossings; wrong matches; recall; false
# bands) and whether the issue's "Done when" for this sweep is met (exit 1
# if not).
#
# Usage: bench/rendered_sweep.sh [N] [BUILD_DIR]
#   N          surveys (default 30), seeds FIRST_SEED.. (default 1)
#   BUILD_DIR  default: build
# Environment: WORK (default /tmp/zebrageo-rendered-sweep) holds the surveys
# (kept: a rerun renders only what is missing) and the results (redone);
# MAX_ROAD_LENGTH (default 300 m) keeps the streets short: 30 surveys
# render and run in about 30-60 minutes on 2 idle cores; ZEBRAGEO_THREADS
# (default 2); SEEDS (e.g. "6 10 25") runs those seeds instead of N from
# FIRST_SEED: the random preset's outage kind (issue 43) is seeds 6 10 25
# 44 58 101 103 115 116 122 (with MAX_ROAD_LENGTH=700).
# JUNCTIONS=N (issue 51) gives every survey N junctions (side streets with
# crossings across them); unset, the random preset draws them (half the
# surveys). The table bins recall by crossing across the road driven and
# across a side street.
# SIM_SET="key=value ..." (issue 52) passes each item to simulate as --set
# (e.g. SIM_SET="ladder_probability=0.5", or the paint beside crossings and
# trucks on them; a survey already rendered under WORK is not rendered
# again: give the sweep its own WORK); the table bins recall of ladder
# crossings apart too.
# AVENUES=1 (issue 52) makes every survey an avenue (AVENUES=-1 one
# in five; unset or 0, none).
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
n="${1:-30}"
build="${2:-$here/build}"
[[ "$build" = /* ]] || build="$PWD/$build"
zebrageo="$build/tools/zebrageo"
[[ -x "$zebrageo" ]] || { echo "no $zebrageo: build first (scripts/build.sh)"; exit 1; }
[[ -f "$here/../shared/tools/score_results.py" ]] || {
  echo "no ../shared/tools/score_results.py beside the repository"; exit 1; }
work="${WORK:-/tmp/zebrageo-rendered-sweep}"
first="${FIRST_SEED:-1}"
max_length="${MAX_ROAD_LENGTH:-300}"
threads="${ZEBRAGEO_THREADS:-2}"
mkdir -p "$work"
sim_set=()
for item in ${SIM_SET:-}; do sim_set+=(--set "$item"); done
scores="$work/scores.jsonl"
: > "$scores"
seeds="${SEEDS:-$(seq "$first" $((first + n - 1)))}"
for seed in $seeds; do
  survey="$work/random-$seed"
  results="$work/random-$seed-results"
  if [[ ! -f "$survey/survey.yaml" ]]; then
    rm -rf "$survey"
    "$zebrageo" --log-level error simulate --preset random --seed "$seed" \
      --max-road-length "$max_length" ${JUNCTIONS:+--junctions "$JUNCTIONS"} \
      ${AVENUES:+--avenues "$AVENUES"} \
      "${sim_set[@]}" -o "$survey"
  fi
  rm -rf "$results"
  start=$(date +%s.%N)
  set +e
  "$zebrageo" --log-level error run "$survey" -o "$results" \
    --threads "$threads" >"$work/random-$seed-run.log" 2>&1
  code=$?
  set -e
  seconds=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }')
  /usr/bin/python3 "$here/bench/rendered_sweep.py" score "$survey" "$results" \
    "$code" "$seconds" >>"$scores" || echo "random-$seed: scoring failed"
  echo "random-$seed: exit $code, $(tail -1 "$scores" | /usr/bin/python3 -c \
    'import json,sys; r=json.load(sys.stdin); print(r["match"], "|", r["poses"])')"
done
echo
/usr/bin/python3 "$here/bench/rendered_sweep.py" table "$scores"
