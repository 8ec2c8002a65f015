#!/usr/bin/env python3
"""CI: `steadyxr-eval --app-msaa 4`, an app that renders with 4x MSAA and submits the resolved image.

Checked against the eval's own `msaa4` baseline, which renders the same MSAA image on its own path: with
--app-msaa 4, `none` (the app's image) is that image to the bit, in every frame, and so is `taa`'s first
frame (no history yet: the filter's output is its input, which is how the test sees that the filters read
the MSAA image); without it, the same frame of `none` and `taa` is the 1-sample render, which differs from
`msaa4` on the wires' edges. The default keeps the never-worse promise against the MSAA image. Bad values
stop the run with exit 2 and a message.
usage: run_app_msaa_small.py STEADYXR_EVAL OUT_DIR"""
import csv
import os
import shutil
import sys

from eval_run import assert_refused, run_eval

exe, out = sys.argv[1], sys.argv[2]
shutil.rmtree(out, ignore_errors=True)


def run(folder, extra):
    run_eval([exe, "--out", folder, "--scenes", "thin", "--motions", "tremor-1x", "--methods",
              "none,taa,default,msaa4", "--resolution", "64", "--frames", "8", "--warp-steps", "0", "--no-sweeps",
              "--no-progress"] + extra, tail=1500)
    with open(os.path.join(folder, "timeseries.csv")) as f:
        frames = {(r["method"], int(r["frame"])): float(r["rmse"]) for r in csv.DictReader(f)}
    with open(os.path.join(folder, "results.csv")) as f:
        rows = {r["method"]: r for r in csv.DictReader(f)}
    return frames, rows


one, one_rows = run(os.path.join(out, "one_sample"), [])
msaa, msaa_rows = run(os.path.join(out, "app_msaa4"), ["--app-msaa", "4"])
print(f"frame 0 RMSE: 1 sample {one[('none', 0)]:.5f}, MSAA {msaa[('none', 0)]:.5f}")
assert one[("none", 0)] == one[("taa", 0)] != one[("msaa4", 0)], "without --app-msaa the app's image is 1 sample"
assert msaa[("none", 0)] == msaa[("taa", 0)] == msaa[("msaa4", 0)], "the filters did not take the MSAA image"
assert all(msaa[("none", f)] == msaa[("msaa4", f)] for f in range(8)), "none is not the MSAA image in every frame"
assert one[("msaa4", 0)] == msaa[("msaa4", 0)], "the msaa4 baseline changed with --app-msaa"
assert msaa_rows["none"]["samples"] == "4" and one_rows["none"]["samples"] == "1", "the samples column"
default, none = float(msaa_rows["default"]["rmse"]), float(msaa_rows["none"]["rmse"])
print(f"with the app's 4x MSAA: default / none {default / none:.3f}")
assert default <= none, "the default is above the app's MSAA image"
assert max(msaa[("default", f)] / msaa[("none", f)] for f in range(8)) <= 1.10, "a frame above 1.10x none's"

assert_refused(exe, os.path.join(out, "bad"), ["--app-msaa", "3"], "bad value for --app-msaa")
assert_refused(exe, os.path.join(out, "bad"), ["--app-msaa", "4", "--render-sizes", "1,0.9"],
               "leave out --ppd, --cant and --app-msaa")
print("--app-msaa: the app's MSAA image is the filters' input and none")
