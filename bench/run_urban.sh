#!/usr/bin/env bash
# End-to-end timing of `zebrageo run` on the urban preset, seed 1 (issue 8:
# under 3 minutes on 2 cores). Prints the wall and CPU time, the peak memory
# (from the kernel and from report.json), the stage timings of report.json,
# and the reconstruction, registration and pose scores against truth/ when
# ../shared/tools is present.
#
# Usage: bench/run_urban.sh [BUILD_DIR] [SURVEY] [WORK_DIR]
#   SURVEY    an urban seed-1 survey (default: /tmp/presets/urban if present,
#             else one is simulated into WORK_DIR, ~6 min of CPU)
#   WORK_DIR  where the copy and the results go (default /tmp/zebrageo-bench-urban)
# ZEBRAGEO_THREADS (default 2) is passed to --threads.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$here/build}"
survey_in="${2:-}"
work="${3:-/tmp/zebrageo-bench-urban}"
threads="${ZEBRAGEO_THREADS:-2}"
zebrageo="$build/tools/zebrageo"
[[ -x "$zebrageo" ]] || { echo "no $zebrageo: build first (scripts/build.sh)"; exit 1; }
mkdir -p "$work"
if [[ -z "$survey_in" && -f /tmp/presets/urban/survey.yaml ]]; then
  survey_in=/tmp/presets/urban
fi
survey="$work/survey"
if [[ -n "$survey_in" ]]; then
  # A private copy: the source may be read-only or shared.
  [[ -f "$survey/survey.yaml" ]] || { rm -rf "$survey"; cp -r "$survey_in" "$survey"; }
else
  [[ -f "$survey/survey.yaml" ]] || "$zebrageo" simulate --preset urban --seed 1 -o "$survey"
fi
results="$work/results"
rm -rf "$results"
echo "zebrageo run on $(nproc) cores, --threads $threads: $survey"
/usr/bin/time -v -o "$work/time.txt" \
  "$zebrageo" --log-level warning run "$survey" -o "$results" --threads "$threads" \
  2>"$work/run.log" >/dev/null
wall=$(grep "Elapsed (wall clock)" "$work/time.txt" | awk '{print $NF}')
user=$(grep "User time" "$work/time.txt" | awk '{print $NF}')
sys=$(grep "System time" "$work/time.txt" | awk '{print $NF}')
rss_kb=$(grep "Maximum resident" "$work/time.txt" | awk '{print $NF}')
echo "wall $wall, user ${user} s, system ${sys} s, peak RSS $((rss_kb / 1024)) MB"
python3 - "$results/report.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
print("stage timings (report.json):")
for stage, s in r.get("timings_s", {}).items():
    print(f"  {stage:12s} {s:8.1f} s")
print(f"peak memory (report.json): {r.get('peak_memory_mb', float('nan')):.0f} MB")
print(f"warnings: {len(r.get('warnings', []))}")
PY
scorer="$here/../shared/tools/score_results.py"
if [[ -x /usr/bin/python3 && -f "$scorer" ]]; then
  for mode in reconstruct match poses; do
    echo "$mode: $(/usr/bin/python3 "$scorer" "$mode" "$survey" "$results" | tail -1)" || true
  done
fi
