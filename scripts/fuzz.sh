#!/usr/bin/env bash
# Builds the parsers' libFuzzer targets with clang (ASan+UBSan) and runs
# each for a bounded time. Usage: scripts/fuzz.sh [SECONDS_PER_TARGET]
# The seed corpus comes from a simulated survey (geometry only) when the
# zebrageo command is built, plus small hand-written seeds.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
seconds="${1:-30}"
build="$here/build-fuzz"
"$here/scripts/setup.sh"
if ! command -v clang++ >/dev/null 2>&1; then
  echo "fuzz: clang++ is needed (apt-get install clang)" >&2
  exit 1
fi
CC=clang CXX=clang++ cmake -S "$here" -B "$build" -G Ninja \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DZEBRAGEO_FUZZ=ON -DZEBRAGEO_WERROR=ON \
  >/dev/null
cmake --build "$build" -j "$(nproc)" --target fuzzers

corpus="$build/corpus"
rm -rf "$corpus"
mkdir -p "$corpus"/{trajectory,rig,exposures,roadmarks,stage_outputs,ins,calibration}
survey="$build/seed-survey"
if [ -x "$here/build/tools/zebrageo" ] && \
   "$here/build/tools/zebrageo" --log-level error simulate --preset demo \
     --seed 1 --no-images -o "$survey" >/dev/null 2>&1; then
  head -c 20000 "$survey/trajectory.csv" > "$corpus/trajectory/demo.csv"
  cp "$survey/rig.yaml" "$corpus/rig/demo.yaml"
  head -c 20000 "$survey/exposures.csv" > "$corpus/exposures/demo.csv"
  head -c 60000 "$survey/roadmarks.geojson" > "$corpus/roadmarks/demo.geojson"
fi
cp "$here"/tests/fuzz/seeds/trajectory/* "$corpus/trajectory/"
cp "$here"/tests/fuzz/seeds/rig/* "$corpus/rig/"
cp "$here"/tests/fuzz/seeds/exposures/* "$corpus/exposures/"
cp "$here"/tests/fuzz/seeds/roadmarks/* "$corpus/roadmarks/"
cp "$here"/tests/fuzz/seeds/stage_outputs/* "$corpus/stage_outputs/"
cp "$here"/tests/fuzz/seeds/ins/* "$corpus/ins/"
cp "$here"/tests/fuzz/seeds/calibration/* "$corpus/calibration/"

failed=0
for target in trajectory rig exposures roadmarks stage_outputs ins \
    calibration; do
  echo "fuzz: fuzz_$target for $seconds s" >&2
  if ! (cd "$build" && "./tests/fuzz/fuzz_$target" -max_total_time="$seconds" \
          -max_len=65536 -rss_limit_mb=2048 -print_final_stats=0 \
          "$corpus/$target" 2> "$build/fuzz_$target.log"); then
    echo "fuzz: fuzz_$target FAILED, see $build/fuzz_$target.log" >&2
    tail -40 "$build/fuzz_$target.log" >&2
    failed=1
  else
    echo "fuzz: fuzz_$target ok ($(grep -c . "$build/fuzz_$target.log") log lines)" >&2
  fi
done
exit "$failed"
