#!/usr/bin/env bash
# ctest console_output (issue 47, point 6): `zebrageo run` as a person sees
# it on a terminal (a pseudo-terminal from util-linux's `script`): every log
# line on a line of its own, never glued to a progress bar; every bar ends
# as a full bar "done in X s" on its own line; bars show the time left; no
# source file names at the default log level (they are there with
# --log-level debug); one closing line with the results folder and the
# headline figure. Exit 77 (skipped) without `script`.
# The survey is the small_demo_run fixture's (tests/tools/small_demo_run.sh);
# the runs write their own results folder.
# Usage: console_output_test.sh ZEBRAGEO_BINARY FIXTURE_DIR
set -euo pipefail
zebrageo="$1"
survey="$2/survey"
command -v script >/dev/null || { echo "SKIP: no script (util-linux)"; exit 77; }
work="$(mktemp -d "${TMPDIR:-/tmp}/zebrageo-console-test.XXXXXX")"
trap 'rm -rf "$work"' EXIT
script -q -e -c "'$zebrageo' run '$survey' -o '$work/results'" \
  "$work/tty" >/dev/null
"$zebrageo" --log-level debug run "$survey" -o "$work/results" \
  --from adjust >"$work/debug.out" 2>"$work/debug.err"
python3 - "$work" <<'PY'
import re, sys
work = sys.argv[1]
raw = open(f"{work}/tty", encoding="utf-8", errors="replace", newline="").read()
raw = raw.split("\n", 1)[1] if raw.startswith("Script started") else raw
raw = re.sub(r"\nScript done.*", "", raw, flags=re.S)
failures = []
clock = r"\d\d:\d\d:\d\d "
# A log line starts the terminal's line: after a newline, or after a
# carriage return that clears the bar.
for m in re.finditer(clock, raw):
    before = raw[max(0, m.start() - 4):m.start()]
    if m.start() and not (before.endswith("\n") or before.endswith("\r\x1b[K")):
        failures.append("log line glued to: " + repr(raw[max(0, m.start() - 60):m.end() + 20]))
# What the terminal shows: per line, what the last carriage return left.
shown = []
for line in raw.replace("\r\n", "\n").split("\n"):
    last = line.split("\r")[-1].replace("\x1b[K", "")
    if last.strip():
        shown.append(last)
bars = [l for l in shown if re.match(r"[a-z ]+ \[[#.]{30}\]", l)]
if not bars:
    failures.append("no progress bar shown")
for bar in bars:
    if not re.search(r"\[#{30}\] done in [\d.]+ s$", bar):
        failures.append("a bar that does not end as done: " + repr(bar))
if not re.search(r"\] \d+/\d+ [\d.]+ s, ~[\d.]+ s left", raw):
    failures.append("no time left shown on a bar")
for line in shown:
    if re.search(r"\w+\.cc:\d+\]", line):
        failures.append("source file name at the default log level: " + line)
        break
if not re.match(rf"done: {re.escape(work)}/results \(report\.html\): \d+ crossings matched; "
                r"(check|control) points RMSE horizontal [\d.]+ cm", shown[-1]):
    failures.append("closing line: " + repr(shown[-1]))
debug = open(f"{work}/debug.err").read()
if not re.search(r"^I\d{4,8} [\d:.]+ +\d+ \w+\.cc:\d+\] ", debug, re.M):
    failures.append("--log-level debug: no glog prefix with the source file")
for f in failures:
    print("FAIL:", f)
print(f"{len(bars)} bars, {len(shown)} lines shown; last: {shown[-1]}")
sys.exit(1 if failures else 0)
PY
