#!/usr/bin/env python3
"""Do two zebrageo binaries give the same results? (issue 44)

Runs `zebrageo run SURVEY -o RESULTS` with both binaries on the demo survey,
the field cases of ../shared/datasets/field-cases and two simulated presets,
and compares the two results folders file by file: every file of either
folder must be in the other; numbers equal to 1e-9 (relative above 1),
everything else as text. Timings are left out: JSON members named as in
TIMING_KEYS, and in text "<number> s" / "<number> ms" (the comment lines of
the CSVs, the brief reports, report.html), and run_state.json (the
resume's bookkeeping, whose fingerprints name the binary).

Usage:
  bench/results_identity.py BASELINE CANDIDATE [--work DIR] [--only NAME...]
  bench/results_identity.py --compare FOLDER_A FOLDER_B

BASELINE is main's binary before the change (a refactor must not change a
number); the surveys are simulated with BASELINE into DIR/surveys once, and
BASELINE's results are kept in DIR/<binary id>/ and reused. Besides `run`,
the demo also goes through the stage commands one by one (reconstruct
--lines, match, adjust, report). Exit status 0 when every folder matches,
1 if not.
"""

import argparse
import hashlib
import json
import math
import os
import re
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
SHARED = os.path.normpath(os.path.join(HERE, "..", "..", "shared"))
FIELD_CASES = os.path.join(SHARED, "datasets", "field-cases")

# Simulated surveys: name -> `zebrageo simulate` arguments. Small, so that
# a comparison of two binaries takes minutes: the demo, a short urban
# street with parked vehicles and every database fault, and a random
# survey (mixed faults, multipath, jitter, road lines).
SIMULATED = {
    "demo": ["--preset", "demo", "--seed", "1"],
    "urban": ["--preset", "urban", "--seed", "3", "--set", "road_length_m=400",
              "--set", "num_crossings=5", "--set", "image_width=640",
              "--set", "image_height=480", "--set", "focal_px=560"],
    "random12": ["--preset", "random", "--seed", "12",
                 "--max-road-length", "250"],
}

TIMING_KEYS = {"timings_s", "seconds", "time_s", "time_in_seconds",
               "wall_time_s", "elapsed_s", "peak_memory_mb", "fingerprint",
               "stage_fingerprints"}
# The lock holds a pid; run_state.json is the resume's bookkeeping (which
# stages ran, their fingerprints), not a result.
IGNORED_FILES = {".zebrageo.lock", "run_state.json"}
NUMBER = re.compile(r"^[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$")
TIMING = re.compile(r"[-+]?\d+(\.\d+)?(e[-+]?\d+)?\s?m?s\b")
# report.html's tables of timings (stage: seconds) and peak memory.
HTML_TIMING = re.compile(
    r"(<th>(reconstruct|match|adjust|report|total|seconds|[a-z_ ]*time_s|"
    r"peak_memory_mb)</th><td>)[-+0-9.e]*(</td>)")
PEAK_MEMORY = re.compile(r"Peak memory: [0-9.]+ MB")
SPLIT = re.compile(r"([\s,;:\[\]{}()\"=<>/]+)")


def numbers_equal(a, b):
    return abs(a - b) <= 1e-9 * max(1.0, abs(a), abs(b))


def tokens_equal(a, b):
    if a == b:
        return True
    if NUMBER.match(a) and NUMBER.match(b):
        return numbers_equal(float(a), float(b))
    return False


def compare_text(text_a, text_b, name, problems):
    def masked(text):
        text = PEAK_MEMORY.sub("Peak memory: <m> MB", text)
        return TIMING.sub("<t>", HTML_TIMING.sub(r"\1<t>\3", text))

    lines_a = masked(text_a).splitlines()
    lines_b = masked(text_b).splitlines()
    if len(lines_a) != len(lines_b):
        problems.append(f"{name}: {len(lines_a)} lines vs {len(lines_b)}")
        return
    for i, (la, lb) in enumerate(zip(lines_a, lines_b)):
        if la == lb:
            continue
        ta, tb = SPLIT.split(la), SPLIT.split(lb)
        if len(ta) != len(tb) or not all(map(tokens_equal, ta, tb)):
            problems.append(f"{name}:{i + 1}: {la[:160]!r} vs {lb[:160]!r}")
            return


def compare_json(a, b, path, problems):
    if len(problems) > 20:
        return
    if isinstance(a, dict) and isinstance(b, dict):
        keys_a = set(a) - TIMING_KEYS
        keys_b = set(b) - TIMING_KEYS
        if keys_a != keys_b:
            problems.append(f"{path}: keys {sorted(keys_a ^ keys_b)} in one only")
            return
        for key in sorted(keys_a):
            compare_json(a[key], b[key], f"{path}.{key}", problems)
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            problems.append(f"{path}: {len(a)} items vs {len(b)}")
            return
        for i, (x, y) in enumerate(zip(a, b)):
            compare_json(x, y, f"{path}[{i}]", problems)
    elif isinstance(a, bool) or isinstance(b, bool):
        if a is not b:
            problems.append(f"{path}: {a} vs {b}")
    elif isinstance(a, (int, float)) and isinstance(b, (int, float)):
        if not numbers_equal(float(a), float(b)):
            problems.append(f"{path}: {a} vs {b}")
    elif isinstance(a, str) and isinstance(b, str):
        compare_text(a, b, path, problems)
    elif a != b:
        problems.append(f"{path}: {a!r} vs {b!r}")


def files_under(folder):
    found = set()
    for root, _, files in os.walk(folder):
        for f in files:
            rel = os.path.relpath(os.path.join(root, f), folder)
            if os.path.basename(rel) not in IGNORED_FILES:
                found.add(rel)
    return found


def compare_folders(a, b):
    """Returns (files compared, files byte-identical, problems)."""
    problems = []
    files_a, files_b = files_under(a), files_under(b)
    for f in sorted(files_a ^ files_b):
        problems.append(f"{f}: only in {a if f in files_a else b}")
    identical = 0
    common = sorted(files_a & files_b)
    for f in common:
        with open(os.path.join(a, f), "rb") as fa, \
                open(os.path.join(b, f), "rb") as fb:
            data_a, data_b = fa.read(), fb.read()
        if data_a == data_b:
            identical += 1
            continue
        try:
            text_a, text_b = data_a.decode(), data_b.decode()
        except UnicodeDecodeError:
            problems.append(f"{f}: binary files differ")
            continue
        if f.endswith(".json") or f.endswith(".geojson"):
            try:
                ja, jb = json.loads(text_a), json.loads(text_b)
            except ValueError:
                compare_text(text_a, text_b, f, problems)
            else:
                compare_json(ja, jb, f, problems)
        else:
            compare_text(text_a, text_b, f, problems)
    return len(common), identical, problems


def binary_id(path):
    digest = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()[:12]


def zebrageo(binary, args, log):
    with open(log, "w") as out:
        return subprocess.call([binary, "--log-level", "warning"] + args,
                               stdout=out, stderr=subprocess.STDOUT)


def surveys(work, baseline, only):
    """name -> survey folder: simulated with the baseline, then the field
    cases (skipped with a message when ../shared is absent)."""
    found = {}
    for name, args in SIMULATED.items():
        if only and name not in only:
            continue
        folder = os.path.join(work, "surveys", name)
        if not os.path.isfile(os.path.join(folder, "survey.yaml")):
            partial = folder + ".partial"
            shutil.rmtree(partial, ignore_errors=True)
            os.makedirs(os.path.dirname(folder), exist_ok=True)
            print(f"simulating {name}", flush=True)
            if zebrageo(baseline, ["simulate"] + args + ["-o", partial],
                        folder + ".log") != 0:
                sys.exit(f"simulate {name} failed: see {folder}.log")
            os.rename(partial, folder)
        found[name] = folder
    if os.path.isdir(FIELD_CASES):
        for name in sorted(os.listdir(FIELD_CASES)):
            path = os.path.join(FIELD_CASES, name)
            if os.path.isfile(os.path.join(path, "survey.yaml")) and (
                    not only or name in only):
                found[name] = path
    else:
        print(f"field cases skipped: {FIELD_CASES} is absent")
    return found


# The stage commands one by one, on the demo (`run` does the same in one
# process, through the same stages).
# `report` last: since issue 44 `adjust` writes the whole report (one writer
# for report.json) where it wrote a brief one before; after `report` both
# binaries' folders hold the whole report.
STAGE_COMMANDS = [["reconstruct", "--lines"], ["match"], ["adjust"],
                  ["report"]]


def run_all(binary, name, survey, out_root):
    """Results of `run` and (demo only) of the stage commands; returns the
    folders written: {label: folder}."""
    folders = {}
    run_folder = os.path.join(out_root, name, "run")
    if not os.path.isfile(os.path.join(run_folder, "report.json")):
        shutil.rmtree(run_folder, ignore_errors=True)
        os.makedirs(os.path.dirname(run_folder), exist_ok=True)
        status = zebrageo(binary, ["run", survey, "-o", run_folder],
                          run_folder + ".log")
        with open(run_folder + ".status", "w") as f:
            f.write(f"{status}\n")
    folders["run"] = run_folder
    if name == "demo":
        stages = os.path.join(out_root, name, "stages")
        if not os.path.isfile(os.path.join(stages, "poses.csv")):
            shutil.rmtree(stages, ignore_errors=True)
            for command in STAGE_COMMANDS:
                zebrageo(binary, [command[0], survey, "-o", stages] +
                         command[1:], f"{stages}.{command[0]}.log")
        folders["stages"] = stages
    return folders


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("binaries", nargs="*", help="BASELINE CANDIDATE")
    parser.add_argument("--work", default="/tmp/zebrageo-identity",
                        help="surveys and results (reused between calls)")
    parser.add_argument("--only", nargs="*", default=[],
                        help="survey names (demo, urban, random12, a field "
                             "case's folder name)")
    parser.add_argument("--compare", nargs=2, metavar="FOLDER",
                        help="only compare two results folders")
    args = parser.parse_args()
    if args.compare:
        compared, identical, problems = compare_folders(*args.compare)
        for p in problems:
            print("  " + p)
        print(f"{compared} files, {identical} byte-identical, "
              f"{len(problems)} differences")
        return 1 if problems else 0
    if len(args.binaries) != 2:
        parser.error("give BASELINE and CANDIDATE (or --compare A B)")
    baseline, candidate = map(os.path.abspath, args.binaries)
    work = os.path.abspath(args.work)
    same_binary = binary_id(baseline) == binary_id(candidate)
    failed = 0
    for name, survey in surveys(work, baseline, set(args.only)).items():
        outputs = []
        for k, binary in enumerate((baseline, candidate)):
            # The same binary twice: two runs (is the run deterministic?).
            again = "-again" if k == 1 and same_binary else ""
            root = os.path.join(work, binary_id(binary) + again)
            outputs.append(run_all(binary, name, survey, root))
        for label in outputs[0]:
            a, b = outputs[0][label], outputs[1][label]
            status = [open(f + ".status").read().strip()
                      if os.path.exists(f + ".status") else "-"
                      for f in (a, b)]
            compared, identical, problems = compare_folders(a, b)
            if status[0] != status[1]:
                problems.insert(0, f"exit status {status[0]} vs {status[1]}")
            verdict = "same" if not problems else "DIFFERENT"
            print(f"{name:22s} {label:7s} {verdict}: {compared} files, "
                  f"{identical} byte-identical (exit {status[1]})", flush=True)
            for p in problems[:20]:
                print("    " + p)
            failed += bool(problems)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
