#!/usr/bin/env bash
# The main job on the bundled demo survey: build, generate the demo survey
# (deterministically, on first use), process it, print where the report is.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
"$here/scripts/build.sh" "$here/build"
zebrageo="$here/build/tools/zebrageo"
survey="$here/datasets/demo"
results="$here/results/demo"
if [ ! -f "$survey/survey.yaml" ]; then
  echo "demo: generating the demo survey in $survey" >&2
  rm -rf "$survey.partial"
  "$zebrageo" simulate --preset demo --seed 1 -o "$survey.partial"
  mv "$survey.partial" "$survey"
fi
"$zebrageo" check "$survey"
mkdir -p "$results"
"$zebrageo" run "$survey" -o "$results"
echo "demo: report at $results/report.html"
