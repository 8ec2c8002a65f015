#!/usr/bin/env python3
"""CI: the dynamic-resolution study (`steadyxr-eval --render-sizes`, eval/render_size_study.h) in a tiny run.

The app renders its frames at 1, 0.9, 0.8, 0.9, ... of the eye size (96 px) over the zone plate under
tremor. Checked by
what the filter core does with it (layer/core/src/filter_submit.cpp, prepareEyes): plain `taa` starts
afresh at each change of size, so at the changing sizes it gives exactly what it gives with the history
dropped at each change (with the history kept, the planted bug, it was 1.87x `none`'s); the default keeps
its history across the changes, below what it gives dropping it, and keeps the never-worse promise
(mean and every frame); its shimmer (temporal error against the truth on the full size's grid) at the
changing sizes is below none's and below what it gives dropping the history. `none` is its own reference (ratio 1), and fractions outside 0.25-1 and --ppd
stop the run with exit 2 and a message.
usage: run_render_sizes_small.py STEADYXR_EVAL OUT_DIR"""
import csv
import os
import shutil
import sys

from eval_run import assert_refused, run_eval

exe, out = sys.argv[1], sys.argv[2]
shutil.rmtree(out, ignore_errors=True)
run_eval([exe, "--out", out, "--scenes", "imageviewer", "--images", "zoneplate", "--motions", "tremor-1x",
          "--resolution", "96", "--frames", "24", "--render-sizes", "1,0.9,0.8,0.9", "--no-progress"], tail=1500)
with open(os.path.join(out, "render_sizes.csv")) as f:
    rows = {(r["method"], r["mode"]): r for r in csv.DictReader(f)}
expected = {("none", "fixed"), ("none", "changing")} | {
    (m, mode) for m in ("taa", "default") for mode in ("fixed", "changing", "changing-dropped")}
assert set(rows) == expected, sorted(rows)


def ratio(method, mode):
    return float(rows[(method, mode)]["rmse_vs_none"])


assert ratio("none", "fixed") == 1.0 and ratio("none", "changing") == 1.0
print(f"taa / none at the changing sizes: {ratio('taa', 'changing'):.3f}, dropping at each change "
      f"{ratio('taa', 'changing-dropped'):.3f}")
assert rows[("taa", "changing")]["rmse"] == rows[("taa", "changing-dropped")]["rmse"], \
    "taa kept its history across a change of the render size"
print(f"default / none: fixed {ratio('default', 'fixed'):.3f}, changing {ratio('default', 'changing'):.3f}, "
      f"dropping {ratio('default', 'changing-dropped'):.3f}")
assert ratio("default", "changing") < ratio("default", "changing-dropped"), \
    "the default's history does not help across changes of the render size"
assert ratio("default", "changing") <= 1.0, "the default is above none at the changing sizes"
assert float(rows[("default", "changing")]["worst_frame_vs_none"]) <= 1.10, "a frame above 1.10x none's"


# Shimmer: the temporal error against the truth, each frame shown at the full size (the compositor's grid).
def shimmer(method, mode):
    return float(rows[(method, mode)]["temporal_error_vs_none"])


assert rows[("none", "fixed")]["low_speed"] == "1", "tremor is a low-head-speed case"
assert shimmer("none", "fixed") == 1.0 and shimmer("none", "changing") == 1.0
assert rows[("taa", "changing")]["temporal_error"] == rows[("taa", "changing-dropped")]["temporal_error"]
print(f"default shimmer / none's: fixed {shimmer('default', 'fixed'):.3f}, changing {shimmer('default', 'changing'):.3f}, "
      f"dropping {shimmer('default', 'changing-dropped'):.3f}")
assert shimmer("default", "changing") < shimmer("default", "changing-dropped") <= 1.0, \
    "the default's history does not calm the changing sizes' shimmer"

assert_refused(exe, os.path.join(out, "bad"), ["--render-sizes", "1,0.1"], "--render-sizes takes fractions")
assert_refused(exe, os.path.join(out, "bad"), ["--render-sizes", "1,0.5", "--ppd", "20"], "leave out --ppd")
print("ok")
