#!/usr/bin/env python3
"""The never-worse promise on head-locked content (scene `hud`, eval/scene_hud.h), per case and method.

Reads one or more steadyxr-eval output folders (timeseries.csv: the whole image; overlay.csv: the
overlay's own pixels, both eyes) and prints, relative to `none` in the same case: the mean RMSE
(whole image and overlay) and the worst frame's RMSE over none's in that frame (whole and overlay;
none's RMSE floored at half an 8-bit step's RMSE as eval/metrics.h does). Exit status 1 when a
method named by --check breaks the promise on either (mean above none, a frame above --limit).

  python3 eval/overlay_report.py OUT [OUT ...] [--check default] [--limit 1.10]
  python3 eval/overlay_report.py STRESS_OUT/runs/* --column rmse_border   # a stress draw's HUD cases
  python3 eval/overlay_report.py OUT --column rmse_border --from-frame 48  # after the head-locked switch's
                                                                          # first epochs (rounds 41-43)
"""

import argparse
import csv
import math
import os
import sys
from collections import defaultdict

# eval/metrics.h kEightBitRmseFloor: the RMSE of a uniform +-half-step rounding error.
EIGHT_BIT_RMSE_FLOOR = 1.0 / (255.0 * math.sqrt(12.0))


def read_series(path, column, from_frame=0):
    """{(case, method): {frame: value}}, frames from_frame on; a frame whose set is empty (-1: a resolved
    edge out of view, resolved_edges.csv) has no value"""
    series = defaultdict(dict)
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            if int(row["frame"]) >= from_frame and float(row[column]) >= 0:
                series[(row["scenario"], row["method"])][int(row["frame"])] = float(row[column])
    return series


def ratios(method_frames, none_frames):
    frames = sorted(set(method_frames) & set(none_frames))
    mean_m = sum(method_frames[k] for k in frames) / len(frames)
    mean_n = sum(none_frames[k] for k in frames) / len(frames)
    worst = max(method_frames[k] / max(none_frames[k], EIGHT_BIT_RMSE_FLOOR) for k in frames)
    return mean_m / max(mean_n, EIGHT_BIT_RMSE_FLOOR), worst


def main(argv):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("dirs", nargs="+")
    p.add_argument("--check", action="append", default=[], help="methods whose promise decides the exit status")
    p.add_argument("--limit", type=float, default=1.10, help="worst frame / none's allowed (issue 14)")
    p.add_argument("--column", default="rmse_overlay",
                   help="overlay.csv column: rmse_overlay (the dilated mask), rmse_core (the overlay's own "
                        "pixels), rmse_border (the one-pixel ring of world pixels around it)")
    p.add_argument("--from-frame", type=int, default=0, help="only frames from this one on (both columns)")
    args = p.parse_args(argv)
    rows = []
    # A stress draw's runs (OUT/runs/*) mix head-locked cases with others: only folders that have an
    # overlay.csv are read.
    with_overlay = [d for d in args.dirs if os.path.exists(f"{d}/overlay.csv")]
    if len(with_overlay) < len(args.dirs):
        print(f"skipped {len(args.dirs) - len(with_overlay)} folder(s) without overlay.csv (no head-locked content)",
              file=sys.stderr)
    for d in with_overlay:
        whole = read_series(f"{d}/timeseries.csv", "rmse", args.from_frame)
        overlay = read_series(f"{d}/overlay.csv", args.column, args.from_frame)
        for (case, method), frames in sorted(overlay.items()):
            if method == "none" or (case, "none") not in overlay:
                continue
            wm, ww = ratios(whole[(case, method)], whole[(case, "none")])
            om, ow = ratios(frames, overlay[(case, "none")])
            rows.append((case, method, wm, ww, om, ow))
    if not rows:
        print("no head-locked case with none and another method in " + ", ".join(args.dirs))
        return 2
    print(f"{'case':48} {'method':24} {'mean/none':>9} {'worst/none':>10} {'overlay mean/none':>17} "
          f"{'overlay worst/none':>18}")
    for case, method, wm, ww, om, ow in rows:
        print(f"{case:48} {method:24} {wm:9.3f} {ww:10.3f} {om:17.3f} {ow:18.3f}")
    broken = 0
    print("\nper method: cases, mean of mean/none, cases mean > none, cases worst > limit (whole | overlay)")
    for method in dict.fromkeys(r[1] for r in rows):
        rs = [r for r in rows if r[1] == method]
        n = len(rs)
        line = (f"{method:24} {n:4d}  whole {sum(r[2] for r in rs) / n:.3f} {sum(r[2] > 1 for r in rs):3d} "
                f"{sum(r[3] > args.limit for r in rs):3d} (worst {max(r[3] for r in rs):.2f}x)  overlay "
                f"{sum(r[4] for r in rs) / n:.3f} {sum(r[4] > 1 for r in rs):3d} "
                f"{sum(r[5] > args.limit for r in rs):3d} (worst {max(r[5] for r in rs):.2f}x)")
        print(line)
        if method in args.check:
            broken += sum(r[2] > 1 or r[3] > args.limit or r[4] > 1 or r[5] > args.limit for r in rs)
    return 1 if broken else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
