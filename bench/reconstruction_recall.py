#!/usr/bin/env python3
"""Reconstruction recall by range (issue 17, item 3): the field cases and a
set of varied simulated surveys, reconstructed and scored against truth.

  bench/reconstruction_recall.py BUILD_DIR [--sims N] [--tag TAG]
                                 [--work DIR] [--score-only] [--misses]

For every survey it runs `zebrageo reconstruct` (one thread, CPU time
measured) and scores reconstructed_bands.csv with the independent scorer of
../shared/tools/score_results.py, imported as a module so that visibility
is exactly its own: a truth band is in view in an exposure when its four
corners project at least 5 px inside both images of a stereo pair and its
centre is within 15 m of that pair's left camera, on every k-th exposure
(k = exposures // 60). Those bands are binned by that range (0-8, 8-11,
11-15 m); a reconstructed band whose centre is more than 0.3 m from every
truth band is false. Vertex RMSE is over the bands within 10 m,
all-4-within-3cm over the bands that are not false (the scorer's figures).

Surveys:
  field: ../shared/datasets/field-cases/* (read in place; skipped if absent)
  sim:   N surveys (default 24) from `zebrageo simulate --preset demo`, each
         with its own seed and knobs drawn from it (SimKnobs below): image
         size (1024x768 and up), camera height, baseline, pitch, skew, band
         lengths, paint wear, sun, noise, blur, parked vehicles. Written once
         to WORK/sims/simNN (regenerated when the knobs change).
Results go to WORK/results-TAG/NAME (WORK defaults to /tmp/zebrageo-recall),
so two tags (before, after) can be compared with --score-only.

Prints one row per survey, then per group (field, sim): the pooled recall
per bin and the median / 5th percentile / worst of the per-survey recalls
(for RMSE: median / 95th percentile / worst), false bands and CPU time per
stereo pair (image decoding included).
"""
import argparse
import json
import math
import os
import random
import resource
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
SHARED = os.path.normpath(os.path.join(HERE, "..", "..", "shared"))
sys.path.insert(0, os.path.join(SHARED, "tools"))
import score_results as sr  # noqa: E402

BINS = [(0.0, 8.0), (8.0, 11.0), (11.0, 15.0)]
BIN_NAMES = ["0-8", "8-11", "11-15"]
FIELD = ["amiens-short", "amiens-short-jittery", "buenos-aires"]


def sim_knobs(index):
    """The --set knobs of simulated survey `index`: drawn from its seed."""
    rng = random.Random(7919 * (index + 1))
    width, height, focal = rng.choice([(1024, 768, 880)] * 4 + [(1280, 960, 1100), (1600, 1200, 1380),
                                                                 (1920, 1080, 1400)])
    knobs = {
        "road_length_m": 90, "num_crossings": 2, "num_stale_crossings": 0, "min_crossing_spacing_m": 30,
        "image_width": width, "image_height": height, "focal_px": focal,
        "camera_height_m": round(rng.uniform(1.8, 2.8), 2),
        "stereo_baseline_m": round(rng.uniform(0.6, 1.3), 2),
        "camera_pitch_down_deg": round(rng.uniform(12.0, 24.0), 1),
        "road_width_m": round(rng.uniform(7.0, 11.0), 1),
        "skew_probability": 0.5, "max_skew_deg": round(rng.uniform(10.0, 30.0), 1),
        "min_band_length_m": 2.5, "max_band_length_m": round(rng.uniform(3.0, 6.0), 1),
        "paint_wear": round(rng.uniform(0.1, 0.6), 2),
        "sun_elevation_deg": round(rng.uniform(20.0, 70.0), 1),
        "sun_azimuth_deg": round(rng.uniform(0.0, 360.0), 1),
        "start_heading_deg": round(rng.uniform(0.0, 360.0), 1),
        "parked_vehicles_per_100m": round(rng.uniform(2.0, 10.0), 1),
        "occluding_vehicle_probability": round(rng.uniform(0.2, 0.6), 2),
        "noise_sigma": round(rng.uniform(1.0, 3.0), 2),
        "blur_sigma_px": round(rng.uniform(0.5, 1.0), 2),
    }
    return knobs


def make_sim(build, folder, index):
    knobs = sim_knobs(index)
    stamp = os.path.join(folder, "knobs.json")
    if os.path.isfile(stamp) and json.load(open(stamp)) == knobs:
        return
    subprocess.run(["rm", "-rf", folder], check=True)
    cmd = [os.path.join(build, "tools", "zebrageo"), "--log-level", "warning", "simulate", "--preset", "demo",
           "--seed", str(index + 1), "-o", folder]
    for k, v in knobs.items():
        cmd += ["--set", f"{k}={v}"]
    subprocess.run(cmd, check=True)
    json.dump(knobs, open(stamp, "w"), indent=1)


def reconstruct(build, survey, results):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(["rm", "-rf", results], check=True)
    subprocess.run([os.path.join(build, "tools", "zebrageo"), "--log-level", "warning", "reconstruct", survey,
                    "-o", results, "--threads", "1"], check=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)


def in_view(s, exposure_id):
    """truth band key -> range (m) to the left camera of the first pair that sees it fully."""
    out = {}
    rig = s.rig
    t = s.times[exposure_id]
    try:
        for pair in rig.get("stereo_pairs", []):
            s.rig = dict(rig, stereo_pairs=[pair])
            keys = s.visible_pairs(exposure_id)
            centre = s.camera_pose(s.truth, t, pair[0])[1]
            for k in keys:
                r = float(np.linalg.norm(s.bands[k].mean(axis=0) - centre))
                out[k] = min(out.get(k, math.inf), r)
    finally:
        s.rig = rig
    return out


def score(survey, results):
    s = sr.Survey(survey)
    rec = sr.reconstructed(s, results)
    found, errs_close, correct, false = {}, [], 0, 0
    false_list = []
    bin_reported, bin_correct, bin_worst = [0] * len(BINS), [0] * len(BINS), [0.0] * len(BINS)
    for bid, b in rec.items():
        key, dc, errs = sr.nearest_band(s, b["enu"])
        if key is None or dc > 0.3:
            false += 1
            false_list.append((b["exposure_id"], round(b["range"], 1), round(dc, 2)))
            continue
        found.setdefault(b["exposure_id"], set()).add(key)
        correct += int(np.all(errs < 0.03))
        rb = next(i for i, (lo, hi) in enumerate(BINS) if b["range"] <= hi or i == len(BINS) - 1)
        bin_reported[rb] += 1
        bin_correct[rb] += int(np.all(errs < 0.03))
        bin_worst[rb] = max(bin_worst[rb], float(np.max(errs)))
        if b["range"] <= 10.0:
            errs_close += list(errs)
    exposures = sorted({r["exposure_id"] for r in s.expo})
    visible = [0] * len(BINS)
    detected = [0] * len(BINS)
    misses = []
    for e in exposures[:: max(1, len(exposures) // 60)]:
        for key, r in in_view(s, e).items():
            b = next(i for i, (lo, hi) in enumerate(BINS) if r <= hi or i == len(BINS) - 1)
            visible[b] += 1
            hit = key in found.get(e, set())
            detected[b] += hit
            if not hit:
                misses.append((e, key, round(r, 1)))
    n_pairs = len(exposures) * max(1, len(s.rig.get("stereo_pairs", [])))
    return dict(visible=visible, detected=detected, false=false, false_list=false_list, pairs=n_pairs,
                sq_close=float(np.sum(np.square(errs_close))), n_close=len(errs_close), correct=correct,
                reported=len(rec) - false, misses=misses,
                bin_reported=bin_reported, bin_correct=bin_correct, bin_worst=bin_worst)


def ratio(a, b):
    return a / b if b else float("nan")


def fmt_pct(x):
    return "  n/a" if math.isnan(x) else f"{100 * x:5.1f}"


def summarise(name, rows):
    print(f"\n== {name}: {len(rows)} surveys")
    pooled_v = [sum(r["visible"][b] for r in rows) for b in range(len(BINS))]
    pooled_d = [sum(r["detected"][b] for r in rows) for b in range(len(BINS))]
    for b, bn in enumerate(BIN_NAMES):
        per = sorted(ratio(r["detected"][b], r["visible"][b]) for r in rows if r["visible"][b])
        if not per:
            continue
        print(f"recall {bn:>5} m: pooled {fmt_pct(ratio(pooled_d[b], pooled_v[b]))}% ({pooled_d[b]}/{pooled_v[b]}),"
              f" per survey median {fmt_pct(float(np.median(per)))}%, p5 {fmt_pct(float(np.percentile(per, 5)))}%,"
              f" worst {fmt_pct(per[0])}%")
    v11 = pooled_v[0] + pooled_v[1]
    d11 = pooled_d[0] + pooled_d[1]
    print(f"recall within 11 m pooled {fmt_pct(ratio(d11, v11))}% ({d11}/{v11})")
    rmse = sorted(math.sqrt(r["sq_close"] / r["n_close"]) for r in rows if r["n_close"])
    if rmse:
        print(f"vertex RMSE (<=10 m) cm: median {100 * float(np.median(rmse)):.2f}, "
              f"p95 {100 * float(np.percentile(rmse, 95)):.2f}, worst {100 * rmse[-1]:.2f}")
    all4 = sorted(ratio(r["correct"], r["reported"]) for r in rows if r["reported"])
    pooled_all4 = ratio(sum(r["correct"] for r in rows), sum(r["reported"] for r in rows))
    print(f"all-4-within-3cm: pooled {fmt_pct(pooled_all4)}%, median {fmt_pct(float(np.median(all4)))}%, "
          f"worst {fmt_pct(all4[0])}%")
    for b, bn in enumerate(BIN_NAMES):
        n = sum(r["bin_reported"][b] for r in rows)
        c = sum(r["bin_correct"][b] for r in rows)
        w = max(r["bin_worst"][b] for r in rows)
        print(f"  reconstructed at {bn:>5} m: {n} bands, all-4-within-3cm {fmt_pct(ratio(c, n))}%, "
              f"worst vertex {100 * w:.1f} cm")
    print(f"false bands: {sum(r['false'] for r in rows)} in {sum(r['pairs'] for r in rows)} pairs")
    cpu = [r["cpu_per_pair"] for r in rows if r.get("cpu_per_pair")]
    if cpu:
        print(f"CPU per pair (reconstruct, one thread, image decoding included): median {1e3 * np.median(cpu):.0f} ms, "
              f"worst {1e3 * max(cpu):.0f} ms")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("build")
    ap.add_argument("--sims", type=int, default=24)
    ap.add_argument("--tag", default="current")
    ap.add_argument("--work", default=os.environ.get("WORK", "/tmp/zebrageo-recall"))
    ap.add_argument("--score-only", action="store_true", help="score existing results, do not reconstruct")
    ap.add_argument("--misses", action="store_true", help="list every missed band in view and every false band")
    ap.add_argument("--only", default="", help="comma-separated survey names to run (default: all)")
    a = ap.parse_args()
    build = os.path.abspath(a.build)
    surveys = []
    field_root = os.path.join(SHARED, "datasets", "field-cases")
    for name in FIELD:
        if os.path.isdir(os.path.join(field_root, name)):
            surveys.append(("field", name, os.path.join(field_root, name)))
    for i in range(a.sims):
        surveys.append(("sim", f"sim{i:02d}", os.path.join(a.work, "sims", f"sim{i:02d}")))
    only = set(a.only.split(",")) if a.only else None
    rows = {"field": [], "sim": []}
    print(f"{'survey':<22} {'size':>9} {'0-8':>11} {'8-11':>11} {'11-15':>11} {'false':>5} {'rmse cm':>7} "
          f"{'all4':>6} {'ms/pair':>7}")
    for group, name, folder in surveys:
        if only and name not in only:
            continue
        if group == "sim" and not a.score_only:
            make_sim(build, folder, int(name[3:]))
        results = os.path.join(a.work, f"results-{a.tag}", name)
        cpu = None
        if not a.score_only:
            cpu = reconstruct(build, folder, results)
        if not os.path.isfile(os.path.join(results, "reconstructed_bands.csv")):
            print(f"{name}: no results in {results}")
            continue
        r = score(folder, results)
        r["cpu_per_pair"] = cpu / r["pairs"] if cpu else None
        cam = sr.Survey(folder).cams
        first = next(iter(cam.values()))
        size = f"{first['w']}x{first['h']}"
        cells = " ".join(f"{r['detected'][b]:>4}/{r['visible'][b]:<4}{'':>2}" for b in range(len(BINS)))
        rmse = math.sqrt(r["sq_close"] / r["n_close"]) if r["n_close"] else float("nan")
        cpu_cell = "" if cpu is None else f"{1e3 * r['cpu_per_pair']:7.0f}"
        all4 = fmt_pct(ratio(r["correct"], r["reported"]))
        print(f"{name:<22} {size:>9} {cells} {r['false']:>5} {100 * rmse:7.2f} {all4:>6} {cpu_cell}")
        if a.misses:
            for e, key, rng in sorted(r["misses"], key=lambda m: m[2]):
                print(f"    missed exposure {e} band {key} at {rng} m")
            for e, rng, dc in r["false_list"]:
                print(f"    FALSE band exposure {e} at {rng} m ({dc} m from the nearest truth band)")
        rows[group].append(r)
    for group in ("field", "sim"):
        if rows[group]:
            summarise(group, rows[group])


if __name__ == "__main__":
    main()
